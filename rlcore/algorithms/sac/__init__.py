"""Soft actor-critic (article 004): config, agent, training loop.

May import: rlcore.algorithms' shared modules, networks, hyperparams, environments.vector, training; never
models, runs, sweeps, api or cli.
"""
import numpy as np

from rlcore.algorithms.family import Family, needs_vector_observations
from rlcore.algorithms.sac.config import SACConfig


def run_training(spec):
    from rlcore.algorithms.sac.train import train as train_sac

    return train_sac(spec)


def build_agent(observation_space, action_space, cfg):
    from rlcore.algorithms.sac.agent import SACAgent

    return SACAgent(observation_space.shape[0], action_space.shape[0], cfg)


def load_policy(path, obs_shape, action_space, cfg):
    from rlcore.networks.acting import MeanActionPolicy

    return MeanActionPolicy(path, obs_shape, action_space.shape[0], (cfg.log_std_min, cfg.log_std_max))


def acting_network(model):
    """tanh of the Gaussian mean: the action SAC is evaluated with (the actor outputs [mean, log_std])."""
    import keras

    act_dim = model.output_shape[-1] // 2
    obs = keras.Input(model.input_shape[1:], name=model.inputs[0].name)
    mean = model(obs)[:, :act_dim]
    return keras.Model(obs, keras.ops.tanh(mean), name="mean_action")


def misfit(observation_space, action_space):
    from gymnasium import spaces

    if not isinstance(action_space, spaces.Box) or len(action_space.shape) != 1:
        return f"it needs continuous actions (a 1-D Box), and the env's are {action_space}"
    if not (np.all(np.isfinite(action_space.low)) and np.all(np.isfinite(action_space.high))):
        return f"it needs finite action bounds to rescale its [-1, 1] actions to, and the env's are {action_space}"
    return needs_vector_observations(observation_space)


FAMILY = Family(
    kind="sac", description="soft actor-critic with twin critics and a learned temperature",
    config=SACConfig, train=run_training, build_agent=build_agent, policy_file="actor.h5", load_policy=load_policy,
    export_output="mean action tanh(mu(s)) in [-1, 1], the action SAC is evaluated with", misfit=misfit,
    acting_network=acting_network, variants={"sac": ("SAC (actions rescaled to [-1, 1])", {})},
    discrete=False, stochastic=True)

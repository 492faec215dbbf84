"""Advantage actor-critic (articles 000 and 002): config, agent, training loop over the env pool.

May import: rlcore.algorithms' shared modules, networks, hyperparams, environments.vector, training; never
models, runs, sweeps, api or cli.
"""
from rlcore.algorithms.a2c.config import A2CConfig
from rlcore.algorithms.family import Family, discrete_on_vectors_or_images


def run_training(spec):
    from rlcore.algorithms.a2c.train import train as train_a2c

    return train_a2c(spec)


def build_agent(observation_space, action_space, cfg):
    from rlcore.algorithms.a2c.agent import A2CAgent

    return A2CAgent(observation_space.shape, int(action_space.n), cfg)


def load_policy(path, obs_shape, action_space, cfg):
    from rlcore.networks.acting import Policy

    return Policy(path, obs_shape, int(action_space.n), stochastic=True)


FAMILY = Family(
    kind="a2c", description="advantage actor-critic with n-step returns",
    config=A2CConfig, train=run_training, build_agent=build_agent, policy_file="actor.h5", load_policy=load_policy,
    export_output="action probabilities pi(a|s) (greedy action = argmax)", misfit=discrete_on_vectors_or_images,
    variants={"a2c": ("A2C", {})}, stochastic=True, env_pool=True)

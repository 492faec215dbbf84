"""PPO with GAE over the env pool (article 001): config, agent, training loop, rollout log, halving by rule.

May import: rlcore.algorithms' shared modules, networks, hyperparams, environments.vector, training; never
models, runs, sweeps, api or cli.
"""
from rlcore.algorithms.family import Family, discrete_on_vectors_or_images
from rlcore.algorithms.ppo.config import PPOConfig


def run_training(spec):
    from rlcore.algorithms.ppo.train import train as train_ppo

    return train_ppo(spec)


def build_agent(observation_space, action_space, cfg):
    from rlcore.algorithms.ppo.agent import PPOAgent

    return PPOAgent(observation_space.shape, int(action_space.n), cfg)


def load_policy(path, obs_shape, action_space, cfg):
    from rlcore.networks.acting import Policy

    return Policy(path, obs_shape, int(action_space.n), logits=True, stochastic=True)


def acting_network(model):
    """The policy logits, without the value head."""
    import keras

    return keras.Model(model.inputs[0], model.outputs[0], name="policy")


FAMILY = Family(
    kind="ppo", description="PPO with a clipped surrogate and GAE; an MLP body, or a CNN for images",
    config=PPOConfig, train=run_training, build_agent=build_agent, policy_file="actor_critic.h5", load_policy=load_policy,
    export_output="policy logits, pi = softmax(logits) (greedy action = argmax)", misfit=discrete_on_vectors_or_images,
    acting_network=acting_network, variants={"ppo": ("PPO (MLP body; CNN for images)", {})},
    stochastic=True, env_pool=True)

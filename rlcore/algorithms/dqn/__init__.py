"""DQN, Double DQN, Dueling DQN and Dueling Double DQN (article 000): config, agent, training loop.

May import: rlcore.algorithms' shared modules, networks, hyperparams, environments.vector, training; never
models, runs, sweeps, api or cli.
"""
from rlcore.algorithms.dqn.config import DQNConfig
from rlcore.algorithms.family import Family, discrete_on_vectors_or_images


def run_training(spec):
    from rlcore.algorithms.dqn.train import train as train_dqn

    return train_dqn(spec)


def build_agent(observation_space, action_space, cfg):
    from rlcore.algorithms.dqn.agent import DQNAgent

    return DQNAgent(observation_space.shape, int(action_space.n), cfg)


def load_policy(path, obs_shape, action_space, cfg):
    from rlcore.networks.acting import Policy

    return Policy(path, obs_shape, int(action_space.n))


FAMILY = Family(
    kind="dqn", description="Q-learning with replay and a target network; double and dueling are switches",
    config=DQNConfig, train=run_training, build_agent=build_agent, policy_file="q_network.h5", load_policy=load_policy,
    export_output="Q-values, one per action (greedy action = argmax)", misfit=discrete_on_vectors_or_images,
    variants={"dqn": ("DQN", {}), "ddqn": ("Double DQN", {"double": True}),
              "dueling_dqn": ("Dueling DQN", {"dueling": True}),
              "dueling_ddqn": ("Dueling Double DQN", {"dueling": True, "double": True})})

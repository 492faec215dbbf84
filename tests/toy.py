"""A tiny contextual-bandit episode env and an Experiment around it, for fast learning tests.

Each step shows a sign s = +-1 in the observation; action 1 pays +1 when s > 0, action 0 pays
+1 when s < 0. Ten steps per episode: a random policy scores ~5, the optimal one 10.
"""
import dataclasses

import gymnasium as gym
import numpy as np

from rlcore.algorithms.a2c import train as a2c
from rlcore.algorithms.a2c.config import A2CConfig
from rlcore.algorithms.dqn import train as dqn
from rlcore.algorithms.dqn.config import DQNConfig
from rlcore.algorithms.ppo import train as ppo
from rlcore.algorithms.ppo.config import PPOConfig
from rlcore.algorithms.sac import train as sac
from rlcore.algorithms.sac.config import SACConfig
from rlcore.environments.experiment import AlgoSpec, Experiment, Goal

TRAINERS = {"dqn": dqn, "a2c": a2c, "ppo": ppo, "sac": sac}  # each module's train(spec) runs one run


class SignEnv(gym.Env):
    def __init__(self, max_episode_steps=10, render_mode=None):
        self.observation_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)
        self.action_space = gym.spaces.Discrete(2)
        self.length = max_episode_steps or 10
        self.render_mode = render_mode

    def _obs(self):
        return np.array([self.sign, 0.5], np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.t = 0
        self.sign = self.np_random.choice([-1.0, 1.0])
        return self._obs(), {}

    def step(self, action):
        reward = float((action == 1) == (self.sign > 0))
        self.t += 1
        self.sign = self.np_random.choice([-1.0, 1.0])
        return self._obs(), reward, False, self.t >= self.length, {}

    def render(self):
        frame = np.zeros((64, 64, 3), np.uint8)
        frame[:, : 32 if self.sign > 0 else 64] = 200
        return frame


def make_env(render_mode=None, max_episode_steps=10):
    return SignEnv(max_episode_steps, render_mode)


DQN = DQNConfig(hidden=(16,), lr=5e-3, buffer_size=2000, batch_size=32, learn_every=1, learning_starts=32,
                tau=0.05, eps_decay=0.9, eps_end=0.02, gamma=0.5, max_episodes=80, max_episode_steps=10,
                stop_score=9.5, window=10, checkpoint_every=20)
A2C = A2CConfig(actor_hidden=(16,), critic_hidden=(16,), actor_lr=1e-2, critic_lr=1e-2, num_envs=4,
                n_steps=5, gamma=0.5, reward_scale=1.0, max_episodes=400, max_episode_steps=10,
                stop_score=9.5, window=20, checkpoint_every=40)

EXPERIMENT = Experiment(
    name="toy", description="sign bandit", make_env=make_env, solved_score=9.0,
    algos={"dqn": AlgoSpec("dqn", "dqn", "DQN", {"default": DQN}),
           "a2c": AlgoSpec("a2c", "a2c", "A2C", {"default": A2C})},
    eval_seed_base=10_000)


def spec(algo, tmp_path, **overrides):
    from rlcore.training.spec import RunSpec

    experiment = {"ppo": IMAGE_EXPERIMENT, "sac": REACH_EXPERIMENT}.get(algo, EXPERIMENT)
    cfg = dataclasses.replace(experiment.preset(algo, None), **overrides)
    return RunSpec(experiment, algo, "default", cfg, seed=0, wandb_mode="off", run_dir=tmp_path / algo,
                   command="pytest", progress=False)


class ImageSignEnv(gym.Env):
    """The sign task seen as a uint8 picture (left half bright when s > 0), for the CNN of PPO.

    ``info["score"]`` counts correct actions; ``info["won"]`` is true once 8 of 10 were right.
    """

    def __init__(self, max_episode_steps=10, render_mode=None):
        self.observation_space = gym.spaces.Box(0, 255, (8, 8, 2), np.uint8)
        self.action_space = gym.spaces.Discrete(2)
        self.length = max_episode_steps or 10
        self.render_mode = render_mode

    def _obs(self):
        obs = np.zeros((8, 8, 2), np.uint8)
        obs[:, :4 if self.sign > 0 else 8, 0] = 255
        return obs

    def _info(self):
        return {"score": self.score, "won": self.score >= 8}

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.t, self.score = 0, 0
        self.sign = self.np_random.choice([-1.0, 1.0])
        return self._obs(), self._info()

    def step(self, action):
        reward = float((action == 1) == (self.sign > 0))
        self.t, self.score = self.t + 1, self.score + int(reward)
        self.sign = self.np_random.choice([-1.0, 1.0])
        return self._obs(), reward, self.t >= self.length, False, self._info()

    def render(self):
        return np.repeat(self._obs()[:, :, :1], 3, axis=2)


def make_image_env(render_mode=None, max_episode_steps=10):
    return ImageSignEnv(max_episode_steps, render_mode)


PPO = PPOConfig(num_envs=2, vec="inline", n_steps=16, epochs=4, minibatch=16, lr=1e-3, gamma=0.5,
                gae_lambda=0.9, entropy_coef=0.0, max_episodes=600, max_episode_steps=0,
                stop_score=1e9, window=10, checkpoint_rollouts=4, stop_success_share=0.9)

IMAGE_EXPERIMENT = Experiment(
    name="toy_image", description="sign bandit as pictures", make_env=make_image_env, solved_score=None,
    algos={"ppo": AlgoSpec("ppo", "ppo", "PPO", {"default": PPO})},
    eval_seed_base=10_000, goal=Goal("won", progress_key="score"), eval_episodes=10)


class ReachEnv(gym.Env):
    """Continuous toy: the observation is a target t in [-0.8, 0.8]^2, the reward -|a - t|_1 / 2.

    Ten steps per episode: a random policy scores about -5, a perfect one 0.
    """

    def __init__(self, max_episode_steps=10, render_mode=None):
        self.observation_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)
        self.action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)
        self.length = max_episode_steps or 10
        self.render_mode = render_mode

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.t = 0
        self.target = self.np_random.uniform(-0.8, 0.8, 2).astype(np.float32)
        return self.target.copy(), {}

    def step(self, action):
        reward = -float(np.abs(np.asarray(action) - self.target).sum()) / 2
        self.t += 1
        self.target = self.np_random.uniform(-0.8, 0.8, 2).astype(np.float32)
        return self.target.copy(), reward, False, self.t >= self.length, {"t": self.t}

    def render(self):
        return np.zeros((32, 32, 3), np.uint8)


def make_reach_env(render_mode=None, max_episode_steps=10):
    return ReachEnv(max_episode_steps, render_mode)


SAC = SACConfig(actor_hidden=(32, 32), critic_hidden=(32, 32), actor_lr=3e-3, critic_lr=3e-3, alpha_lr=3e-3,
                gamma=0.5, batch_size=64, buffer_size=5000, learning_starts=200, updates_per_call=2,
                max_env_steps=2500, max_episodes=10**6, max_episode_steps=0, stop_score=1e9, window=10,
                checkpoint_every=50, init_alpha=0.1)

REACH_EXPERIMENT = Experiment(
    name="toy_reach", description="continuous reach", make_env=make_reach_env, solved_score=-1.0,
    algos={"sac": AlgoSpec("sac", "sac", "SAC", {"default": SAC})}, eval_seed_base=10_000)

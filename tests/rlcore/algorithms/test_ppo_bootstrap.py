"""The PPO trainer bootstraps an episode cut by a time limit from the value of its final observation
(not from the first observation of the next episode, which the pool has already reset to)."""
import dataclasses

import gymnasium as gym
import numpy as np

from rlcore.algorithms.ppo import train as ppo_trainer
from rlcore.algorithms.ppo.agent import PPOAgent
from rlcore.environments.experiment import AlgoSpec, Experiment
from rlcore.training.spec import RunSpec
from tests.toy import PPO

LIMIT = 5


class StepCounterEnv(gym.Env):
    """Never terminates; every pixel of the observation holds the number of steps taken so far."""

    observation_space = gym.spaces.Box(0, 255, (4, 4, 1), np.uint8)
    action_space = gym.spaces.Discrete(2)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.t = 0
        return np.zeros((4, 4, 1), np.uint8), {}

    def step(self, action):
        self.t += 1
        return np.full((4, 4, 1), self.t, np.uint8), 1.0, False, False, {}


def make_counter_env(render_mode=None, max_episode_steps=None):
    return gym.wrappers.TimeLimit(StepCounterEnv(), max_episode_steps)


def test_time_limited_steps_bootstrap_from_the_final_observation(tmp_path, monkeypatch):
    cfg = dataclasses.replace(PPO, n_steps=12, num_envs=2, max_episode_steps=LIMIT, max_env_steps=24,
                              minibatch=8, stop_success_share=0.0)
    exp = Experiment(name="counter", description="step counter", make_env=make_counter_env,
                     solved_score=None, algos={"ppo": AlgoSpec("ppo", "ppo", "PPO", {"default": cfg})})
    # V(s) = the step count the observation shows, so a bootstrap from the reset observation gives 0
    def fake_policy_and_values(self, obs):
        return np.full((len(obs), 2), 0.5, np.float32), obs[:, 0, 0, 0].astype(np.float32)

    captured = {}

    def capture_update(self, obs, actions, logp, values, next_values, rewards, terminated, dones, rng):
        captured.update(values=values.copy(), next_values=next_values.copy(), terminated=terminated.copy(),
                        dones=dones.copy())
        return {"loss": 0.0, "policy_loss": 0.0, "value_loss": 0.0, "entropy": 0.0, "approx_kl": 0.0,
                "clip_fraction": 0.0}

    monkeypatch.setattr(PPOAgent, "policy_and_values", fake_policy_and_values)
    monkeypatch.setattr(PPOAgent, "update", capture_update)
    ppo_trainer.train(RunSpec(exp, "ppo", "default", cfg, seed=0, wandb_mode="off", run_dir=tmp_path / "run",
                              command="pytest", progress=False))

    cut = (captured["dones"] == 1) & (captured["terminated"] == 0)
    assert cut.sum() == 4, "12 steps of 2 envs with a limit of 5 cut each env twice (steps 5 and 10)"
    np.testing.assert_array_equal(np.argwhere(cut)[:, 0], [4, 4, 9, 9])
    np.testing.assert_array_equal(captured["next_values"][cut], LIMIT)
    # everywhere else the next value is the one the agent saw at the next step (the last row: V(s_T))
    rest = ~cut
    rest[-1] = False
    np.testing.assert_array_equal(captured["next_values"][:-1][rest[:-1]], captured["values"][1:][rest[:-1]])
    np.testing.assert_array_equal(captured["next_values"][-1], [2, 2])  # 12 = 5 + 5 + 2 steps in

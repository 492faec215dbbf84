"""RemoteEnv (issue 65): an env stepped in a worker process, as MuJoCo's frames are drawn. A worker that cannot
build its env is one line; a process that ends with an error while the env is open still exits, and leaves
no worker behind (the worker ignores the stop signals, so multiprocessing's own SIGTERM at exit would not)."""
import subprocess
import sys
from functools import partial
from pathlib import Path

import gymnasium as gym
import numpy as np
import psutil
import pytest

from rlcore.environments.remote import RemoteEnv, draws_with_opengl
from rlcore.errors import UserError

ROOT = Path(__file__).resolve().parents[3]


def test_it_steps_and_renders_as_the_env_itself_would():
    env = RemoteEnv(partial(gym.make, "CartPole-v1", render_mode="rgb_array"), "CartPole-v1")
    try:
        obs, _ = env.reset(seed=3)
        np.testing.assert_array_equal(obs, gym.make("CartPole-v1").reset(seed=3)[0])
        assert env.step(0)[0].shape == (4,) and env.render().shape[-1] == 3
    finally:
        env.close()
    assert not env._process.is_alive()


def test_an_env_the_worker_cannot_build_is_one_line():
    with pytest.raises(UserError, match=r"^NoSuch-v0 could not start: .*NoSuch"):
        RemoteEnv(partial(gym.make, "NoSuch-v0"), "NoSuch-v0")


def test_an_error_while_the_env_is_open_ends_the_process_and_its_worker():
    script = ("from functools import partial\nimport gymnasium as gym\n"
              "from rlcore.environments.remote import RemoteEnv\n"
              "env = RemoteEnv(partial(gym.make, 'CartPole-v1'), 'CartPole-v1')\nenv.reset(seed=0)\n"
              "print(env._process.pid, flush=True)\nraise SystemExit(3)\n")
    done = subprocess.run([sys.executable, "-c", script], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert done.returncode == 3, done.stderr
    assert not psutil.pid_exists(int(done.stdout.split()[0])) or psutil.Process(
        int(done.stdout.split()[0])).status() == psutil.STATUS_ZOMBIE


def test_only_mujoco_envs_draw_through_opengl():
    assert draws_with_opengl("gymnasium.envs.mujoco.half_cheetah_v5:HalfCheetahEnv")
    assert not draws_with_opengl("gymnasium.envs.box2d.lunar_lander:LunarLander")
    assert not draws_with_opengl("my_mujoco_free_envs:Chase")

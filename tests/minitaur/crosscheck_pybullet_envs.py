"""Manual cross-check (not collected by pytest): our Minitaur vs pybullet's own MinitaurBulletEnv.

pybullet's env needs the unmaintained ``gym`` package, which this project never depends on, so this
runs in a throwaway venv:

    python3.13 -m venv /tmp/gymcheck
    /tmp/gymcheck/bin/pip install pybullet "gym==0.26.2" "setuptools<70" gymnasium numpy
    /tmp/gymcheck/bin/python tests/minitaur/crosscheck_pybullet_envs.py

Both envs run with the randomizer off and the same uniformly random actions for up to 1000 steps;
the script prints the largest observation and reward differences and both returns.
"""
import importlib.util
import os
import sys
import types
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from minitaur.env import MinitaurEnv  # noqa: E402  ours first: theirs puts a `minitaur` module on sys.path

# import pybullet_envs.bullet without pybullet_envs/__init__.py (registrations for an older gym)
_spec = importlib.util.find_spec("pybullet_envs")
_pkg = types.ModuleType("pybullet_envs")
_pkg.__path__ = [os.path.dirname(_spec.origin)]
sys.modules["pybullet_envs"] = _pkg
from pybullet_envs.bullet.minitaur_gym_env import MinitaurBulletEnv  # noqa: E402


def main(steps: int = 1000, scale: float = 1.0) -> None:
    theirs, ours = MinitaurBulletEnv(env_randomizer=None), MinitaurEnv(randomize=False)
    o1, (o2, _) = np.array(theirs.reset()), ours.reset(seed=0)
    worst_obs, worst_reward, returns = float(np.abs(o1 - o2).max()), 0.0, [0.0, 0.0]
    rng = np.random.default_rng(0)
    for t in range(steps):
        action = rng.uniform(-1, 1, 8) * scale
        o1, r1, d1, _ = theirs.step(action)
        o2, r2, d2, _, _ = ours.step(action)
        worst_obs = max(worst_obs, float(np.abs(np.array(o1) - o2).max()))
        worst_reward = max(worst_reward, abs(r1 - r2))
        returns[0] += r1
        returns[1] += r2
        if d1 or d2:
            print(f"episode ended at step {t + 1}: theirs {d1}, ours {d2}")
            break
    print(f"steps {t + 1}: max |obs diff| {worst_obs:.2e}, max |reward diff| {worst_reward:.2e}, "
          f"returns theirs {returns[0]:.6f} ours {returns[1]:.6f}")


if __name__ == "__main__":
    main()

"""Probe (twenty-first session): from the states of 1-3's old gap crossings, how often does the
checkpoint's policy, sampling from pi, cross the gap at x ~800?

The checkpoint keeps, in envs 0, 1, 4 and 7, routes from the level's start past x 900: the crossings
of the first ~2,100 episodes (env 2's is one of its own episodes, which fell). Each is replayed
with ``keep="furthest"`` on a 10 spacing, which gives the route's own state at every 10 x; from a
few of them, 8 episodes each are played until they pass x 880 or end. (Run at rollout 257, the
checkpoint kept them under the 300 spacing's points 3 and 4 and the filter was on those keys; from
rollout 258 they are kept under "1", the point of ``--restart-x 630``.) Run from the repo root:

    python long_runs/mario_ppo/1-3/probe_crossings.py
"""
import tempfile
from pathlib import Path

import numpy as np

from mario_ppo.env import make_env
from mario_ppo.restarts import Restarts
from rlcore.policies import load_policy
from rlcore.snapshot import model_from_checkpoint

RUN = Path("long_runs/mario_ppo/1-3")
POINTS, TRIES, PAST = (59, 60, 61, 62, 63, 64), 8, 880
ENVS = ("0", "1", "2", "4", "7")

z = np.load(RUN / "checkpoint.npz")
routes = {k: z[k] for k in z.files if k.startswith("array/env/") and k.split("/")[2] in ENVS}
with tempfile.TemporaryDirectory() as tmp:
    model_from_checkpoint(RUN, tmp, "mario_ppo", "ppo")
    _, _, policy = load_policy(tmp)
rng = np.random.default_rng(0)
env = make_env(world=1, stage=3, frames="history", score_reward=0.025, stall_steps=40,
               stall_outcome="death", restart_every=10, restart_share=1.0, restart_keep="furthest")
restarts = env
while not isinstance(restarts, Restarts):
    restarts = restarts.env
for name, route in routes.items():
    restarts._snapshots, restarts._reach = {}, {}
    restarts.restart_routes = {"1": route}
    states = dict(restarts._snapshots)
    row = []
    for point in POINTS:
        crossed = 0
        for trial in range(TRIES):
            restarts._snapshots = {point: states[point]}  # the only point: every reset starts there
            obs, info = env.reset(seed=trial)
            while True:
                obs, _, terminated, truncated, info = env.step(policy.sample(obs[None], rng)[0])
                if terminated or truncated or info["x_pos"] > PAST:
                    break
            crossed += info["x_pos"] > PAST
        row.append(f"x {point * 10}: {crossed}/{TRIES}")
    print(name, ", ".join(row), flush=True)
env.close()

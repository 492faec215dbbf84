#!/usr/bin/env python3
"""Mario PPO recipes side by side: what a recipe costs per env step, and how many env steps its runs
needed. Prints JSON, one line per measurement.

  python benchmarks/mario_recipe.py --rollouts 3                      # default vs flag, alternating
  python benchmarks/mario_recipe.py --recipes default flag flag:epochs=4 --rounds 2
  python benchmarks/mario_recipe.py --skip-speed --runs results/sweeps/mario_ppo__1-1/seed=*

Two halves, because a run to the bar takes hours and the machine's speed moves from hour to hour:
  speed   each recipe ("PRESET" or "PRESET:field=value,...") trains --rollouts rollouts from random weights
          on --level, the recipes in turn (A B A B over --rounds), in one sitting; per recipe the median
          collect and update seconds of a rollout (the first rollout, which compiles, left out) and the
          env steps/s they make (transitions / (collect + update));
  runs    for each run folder given, the env steps, episodes and wall seconds at which the success share
          of the last 100 episodes from the level's start first reached 0.5, 0.8, 0.9 and 0.95
          (metrics.csv; the machine a run trained on is in its meta.json).
The CPU-seconds to a share are then its env steps / the recipe's env steps/s, both per recipe.
"""
from __future__ import annotations

import argparse
import contextlib
import dataclasses
import json
import os
import sys
import tempfile
from pathlib import Path

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402
from common import emit  # noqa: E402

SHARES = (0.5, 0.8, 0.9, 0.95)


def parse_recipe(text: str, precision: str):
    """'flag:epochs=4,num_envs=16' -> (name, config) of the mario_ppo preset with those fields set;
    ``precision`` unless the recipe names its own ('flag:precision=float32')."""
    from mario_ppo.experiment import EXPERIMENT

    preset, _, changes = text.partition(":")
    cfg = dataclasses.replace(EXPERIMENT.preset("ppo", preset), precision=precision)
    for change in filter(None, changes.split(",")):
        field, _, value = change.partition("=")
        kind = type(getattr(cfg, field))
        cfg = dataclasses.replace(cfg, **{field: kind(value)})
    return text, cfg


def time_rollouts(cfg, rollouts: int, world: int, stage: int) -> dict:
    """Train ``rollouts`` rollouts in a scratch folder; the median collect/update seconds per rollout."""
    import pandas as pd

    from mario_ppo.experiment import EXPERIMENT
    from rlcore.algorithms.ppo import train as ppo
    from rlcore.training.spec import RunSpec

    steps = rollouts * cfg.n_steps * cfg.num_envs
    cfg = dataclasses.replace(cfg, max_env_steps=steps, world=world, stage=stage,
                              checkpoint_rollouts=10**6)
    folder = Path(tempfile.mkdtemp(prefix="bench_recipe_"))
    spec = RunSpec(EXPERIMENT, "ppo", "bench", cfg, 0, "off", folder, command="benchmark", progress=False)
    with contextlib.redirect_stdout(sys.stderr):
        ppo.train(spec)
    table = pd.read_csv(folder / "rollouts.csv").iloc[1:]  # the first rollout compiles the update
    collect, update = float(table["collect_seconds"].median()), float(table["update_seconds"].median())
    transitions = cfg.n_steps * cfg.num_envs
    return {"transitions_per_rollout": transitions, "epochs": cfg.epochs, "minibatch": cfg.minibatch,
            "precision": cfg.precision,
            "collect_s": round(collect, 2), "update_s": round(update, 2),
            "env_steps_per_s": round(transitions / (collect + update), 1)}


def bench_speed(recipes: list[str], rounds: int, rollouts: int, level: str, precision: str) -> None:
    world, stage = (int(x) for x in level.split("-"))
    parsed = [parse_recipe(text, precision) for text in recipes]
    seen: dict[str, list[dict]] = {name: [] for name, _ in parsed}
    for round_ in range(rounds):
        for name, cfg in parsed:
            row = time_rollouts(cfg, rollouts, world, stage)
            seen[name].append(row)
            emit(bench="recipe_speed", recipe=name, round=round_, level=level, **row)
    for name, rows in seen.items():
        emit(bench="recipe_speed_median", recipe=name, level=level, precision=rows[0]["precision"], rounds=rounds,
             env_steps_per_s=round(float(np.median([r["env_steps_per_s"] for r in rows])), 1),
             collect_s=round(float(np.median([r["collect_s"] for r in rows])), 2),
             update_s=round(float(np.median([r["update_s"] for r in rows])), 2))


def steps_to_shares(run: Path) -> dict:
    """Env steps, episodes and wall seconds at which the run's success share first reached each share."""
    import pandas as pd

    metrics = pd.read_csv(run / "metrics.csv")
    if "restarted" in metrics:  # restarted episodes are out of the stop rule's share
        metrics = metrics[metrics["restarted"].fillna(0) == 0]
    share = metrics["success"].rolling(100).mean()
    out = {}
    for mark in SHARES:
        hit = np.flatnonzero(share.to_numpy() >= mark - 1e-9)
        if len(hit):
            row = metrics.iloc[hit[0]]
            out[str(mark)] = {"env_steps": int(row["env_steps"]), "episode": int(row["episode"]),
                              "wall_seconds": round(float(row["wall_seconds"]))}
        else:
            out[str(mark)] = None
    return out


def bench_runs(runs: list[Path]) -> None:
    for run in runs:
        meta_file = next((p for p in (run / "model" / "meta.json", run / "meta.json") if p.is_file()), None)
        meta = json.loads(meta_file.read_text()) if meta_file else {}
        emit(bench="recipe_run", run=str(run), preset=meta.get("preset"), cpu=meta.get("cpu"),
             env_steps=meta.get("env_steps"), first_reached=steps_to_shares(run))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], epilog=__doc__.split("\n\n", 1)[1],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--recipes", nargs="+", default=["default", "flag"],
                        help="PRESET or PRESET:field=value,... of mario_ppo, timed in turn")
    parser.add_argument("--rounds", type=int, default=2, help="times each recipe is timed (A B A B ...)")
    parser.add_argument("--rollouts", type=int, default=3, help="rollouts per timing (the first one compiles)")
    parser.add_argument("--level", default="1-1", help="world-stage to time on")
    parser.add_argument("--precision", default="bfloat16", choices=["float32", "bfloat16"],
                        help="of every recipe that does not name its own")
    parser.add_argument("--skip-speed", action="store_true", help="only read the runs given")
    parser.add_argument("--runs", nargs="*", type=Path, default=[], help="run folders to read steps to shares from")
    args = parser.parse_args()
    if not args.skip_speed:
        bench_speed(args.recipes, args.rounds, args.rollouts, args.level, args.precision)
    bench_runs(args.runs)


if __name__ == "__main__":
    main()

"""Runs in progress outlive a refactor: checkpoints written by the code before the layout of 2026-12-03
(tests/data/runs_before_relayout, made by commit be7fabe's `main.py train`) resume with today's code
through the plain resume command, their counters going on from the checkpoint, and evaluate as runs in
progress. Mario's own runs in progress are resumed in the expensive test below."""
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from rlcore.files.checkpoint import read_checkpoint_state
from tests.test_cli import run as cli

ROOT = Path(__file__).resolve().parents[3]
OLD = ROOT / "tests" / "data" / "runs_before_relayout"
RUNS = {"dqn": ("CartPole-v1", ["--episodes", "6"]), "a2c": ("CartPole-v1", ["--episodes", "6"]),
        "ppo": ("CartPole-v1", ["--steps", "768"]), "sac": ("Pendulum-v1", ["--episodes", "2"])}
QUIET = ["--wandb", "off", "--no-progress", "--final-eval-episodes", "1"]


@pytest.mark.parametrize("algo", sorted(RUNS))
def test_a_run_stopped_by_the_old_code_resumes_and_evaluates(algo, tmp_path, capsys):
    env, budget = RUNS[algo]
    run_dir = tmp_path / algo
    shutil.copytree(OLD / algo, run_dir)
    before = read_checkpoint_state(run_dir / "checkpoint.npz")
    code, out, err = cli(capsys, "evaluate", env, algo, "--model", str(run_dir), "--episodes", "1")
    assert code == 0 and "return" in out, err
    code, out, err = cli(capsys, "train", env, algo, "--resume", str(run_dir), *budget, *QUIET)
    assert code == 0, err
    meta = json.loads((run_dir / "model" / "meta.json").read_text())
    budgets = ("max_episodes", "max_env_steps")  # what the resume changed, and nothing else
    assert meta["env_steps"] > before["env_steps"]
    assert {k: v for k, v in meta["config"].items() if k not in budgets} == \
        {k: v for k, v in before["config"].items() if k not in budgets}
    assert meta["commands"][0] == before["commands"][0]  # the old run's first command heads its story
    assert np.isfinite(meta["evaluation"]["mean"])


@pytest.mark.expensive
def test_the_mario_runs_in_progress_resume_with_todays_code(tmp_path, capsys):
    """Every Mario run in long_runs/ resumes for one more rollout (about a minute each on 2 cores)."""
    runs = sorted(p.parent for p in (ROOT / "long_runs" / "mario_ppo").glob("*/checkpoint.npz"))
    if not runs:
        pytest.skip("no Mario run in progress in long_runs/mario_ppo")
    for run in runs:
        copy = tmp_path / run.name
        shutil.copytree(run, copy, ignore=shutil.ignore_patterns("wandb", "model"))
        before = read_checkpoint_state(copy / "checkpoint.npz")
        steps = before["env_steps"] + before["config"]["n_steps"] * before["config"]["num_envs"]
        code, out, err = cli(capsys, "train", "mario_ppo", "ppo", "--resume", str(copy), "--steps", str(steps),
                             "--wandb", "off", "--no-progress", "--final-eval-episodes", "0")
        assert code == 0, err
        assert read_checkpoint_state(copy / "checkpoint.npz")["env_steps"] == steps

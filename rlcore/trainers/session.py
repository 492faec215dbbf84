"""What every training run shares: run folder, episode book-keeping, console/progress output,
tracking, checkpoint cadence, Ctrl-C handling and the final model folder with its ``meta.json``.
"""
from __future__ import annotations

import contextlib
import platform
import shlex
import signal
import sys
import threading
import time
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import Callable

import numpy as np
from tqdm import tqdm

from rlcore.atomic import write_json
from rlcore.checkpoint import read_checkpoint_state
from rlcore.errors import UserError
from rlcore.hparams import to_dict
from rlcore.plotting import plot_run
from rlcore.tracking import Tracker
from rlcore.trainers.episodes import EpisodeBook
from rlcore.trainers.periodic_eval import PeriodicEvaluation

RUNS_DIR = Path("runs")
CHECKPOINT_FILE = "checkpoint.npz"


class Interrupted(Exception):
    """Raised after Ctrl-C once the checkpoint is safely written."""

    def __init__(self, checkpoint: Path):
        super().__init__(f"interrupted; checkpoint saved to {checkpoint}; continue with --resume {checkpoint.parent}")
        self.checkpoint = checkpoint


@dataclass
class RunSpec:
    """Everything that defines a training run (what ``main.py train`` parsed)."""
    experiment: object  # rlcore.experiment.Experiment
    algo: str
    preset: str
    config: object
    seed: int
    wandb_mode: str = "auto"
    run_dir: Path | None = None
    resume: bool = False
    command: str = field(default_factory=lambda: " ".join(shlex.quote(a) for a in ["python", *sys.argv]))
    progress: bool = True
    # on_progress(row, table): every row the run logs (episodes, evaluations, rollouts), as it comes
    on_progress: Callable[[dict, str], None] | None = None
    # a file whose appearance stops the run at its next safe point, with a checkpoint (sweeps' Ctrl-C)
    stop_file: Path | None = None

    @property
    def kind(self) -> str:
        return self.experiment.algo(self.algo).kind


def new_run_dir(experiment: str, algo: str, seed: int) -> Path:
    stamp = datetime.now().strftime("%Y%m%d-%H%M%S")
    return RUNS_DIR / f"{experiment}__{algo}__{seed}__{stamp}"


def latest_run_dir(experiment: str, algo: str) -> Path:
    runs = sorted(RUNS_DIR.glob(f"{experiment}__{algo}__*/{CHECKPOINT_FILE}"), key=lambda p: p.stat().st_mtime)
    if not runs:
        raise UserError(f"no run of {experiment} {algo} with a checkpoint under {RUNS_DIR}/ to resume")
    return runs[-1].parent


def check_resumable(spec: RunSpec) -> dict:
    """The checkpoint's state, after checking it belongs to this experiment and algorithm."""
    state = read_checkpoint_state(spec.run_dir / CHECKPOINT_FILE)
    found = (state.get("experiment"), state.get("algo"))
    if found != (spec.experiment.name, spec.algo):
        raise UserError(f"checkpoint in {spec.run_dir} is from {found[0]} {found[1]}, "
                        f"not {spec.experiment.name} {spec.algo}; pick the matching run")
    return state


def package_versions() -> dict:
    """Versions of Python and of the packages a run's numbers depend on (those installed)."""
    from importlib.metadata import PackageNotFoundError, version

    found = {"python": platform.python_version()}
    for dist in ("tensorflow", "tensorflow-cpu", "keras", "gymnasium", "numpy", "box2d", "nes-py",
                 "gym-super-mario-bros", "pybullet"):
        try:
            found[dist] = version(dist)
        except PackageNotFoundError:
            pass
    return found


class TrainingSession:
    """Context for one run: owns the tracker, progress bar, book and the Ctrl-C flag."""

    def __init__(self, spec: RunSpec, resumed_state: dict | None = None, progress_unit: str = "episode"):
        self.spec = spec
        exp, cfg = spec.experiment, spec.config
        self.run_dir = spec.run_dir
        self.run_dir.mkdir(parents=True, exist_ok=True)
        state = resumed_state or {}
        self.book = EpisodeBook(cfg.window, exp.solved_score, state.get("returns"))
        self.book.solved_episode = state.get("solved_episode")
        self.env_steps = int(state.get("env_steps", 0))
        self.wall_seconds = float(state.get("wall_seconds", 0.0))
        self._started = time.perf_counter()
        self._steps_at_start = self.env_steps
        self.stop_requested = False
        self.evaluation = PeriodicEvaluation(cfg, state)
        # the command that started the run, then one per resume
        self.commands = list(state.get("commands", [])) + [spec.command]
        self.tracker = Tracker(self.run_dir, self.run_dir.name, self.describe(), spec.wandb_mode,
                               on_row=spec.on_progress,
                               wandb_id=state.get("wandb_id"))
        if resumed_state:
            dropped = self.tracker.drop_rows_after(self.env_steps)
            if dropped:
                print("resume: dropped rows logged after the checkpoint ("
                      + ", ".join(f"{n} from {name}" for name, n in dropped.items()) + ")", file=sys.stderr)
        # the bar counts episodes (DQN, A2C) or env steps (PPO: long episodes, a step budget)
        self.progress_unit = progress_unit
        by_steps = progress_unit == "step"
        self.progress = tqdm(total=(cfg.max_env_steps or None) if by_steps else cfg.max_episodes,
                             initial=self.env_steps if by_steps else self.book.episodes,
                             unit="step" if by_steps else "ep", unit_scale=by_steps,
                             disable=None if spec.progress else True, dynamic_ncols=True, leave=True)

    # ------------------------------------------------------------ bookkeeping
    def describe(self) -> dict:
        s = self.spec
        return {"experiment": s.experiment.name, "algo": s.algo, "kind": s.kind, "preset": s.preset,
                "seed": s.seed, "config": to_dict(s.config)}

    def elapsed(self) -> float:
        return self.wall_seconds + time.perf_counter() - self._started

    def end_episode(self, episode_return: float, extra: dict) -> None:
        """Log one finished episode to the book, CSV/wandb and the progress bar."""
        row = self.book.add(episode_return)
        row.update(env_steps=self.env_steps, wall_seconds=round(self.elapsed(), 2), **extra)
        self.tracker.log(row)
        rate = (self.env_steps - self._steps_at_start) / max(time.perf_counter() - self._started, 1e-9)
        if self.progress_unit == "episode":
            self.progress.update(1)
            self.progress.set_postfix(avg100=f"{self.book.average:.1f}", steps=self.env_steps,
                                      sps=f"{rate:.0f}", refresh=False)
        else:
            self.progress.set_postfix(episodes=self.book.episodes, avg100=f"{self.book.average:.1f}",
                                      refresh=False)

    def advance(self, steps: int) -> None:
        """Move a step-counting progress bar (``progress_unit="step"``)."""
        if self.progress_unit == "step":
            self.progress.update(steps)

    def maybe_evaluate(self, greedy_policy, snapshot) -> None:
        """When due, a periodic greedy evaluation (:class:`PeriodicEvaluation`), logged to evals.csv.

        ``greedy_policy(obs_batch) -> actions``; ``snapshot() -> weights`` of the model now.
        """
        if self.evaluation.due(self.env_steps):
            result = self.evaluation.run(self.spec.experiment, greedy_policy, snapshot, self.env_steps)
            self.tracker.log({"env_steps": self.env_steps, "episode": self.book.episodes, **result},
                             table="evals")

    def should_stop(self) -> bool:
        cfg = self.spec.config
        if self.spec.stop_file is not None and self.spec.stop_file.exists():
            self.stop_requested = True
        if self.stop_requested:
            return True
        if self.book.episodes >= cfg.max_episodes:
            return True
        if cfg.max_env_steps and self.env_steps >= cfg.max_env_steps:
            return True
        if self.evaluation.reached_stop_score():
            return True
        return self.book.full_window() and self.book.average >= cfg.stop_score

    def state(self, **extra) -> dict:
        """JSON-able counters for a checkpoint."""
        return {**self.describe(), "returns": self.book.returns, "solved_episode": self.book.solved_episode,
                "env_steps": self.env_steps, "wall_seconds": self.elapsed(),
                "wandb_id": self.tracker.wandb_id, **self.evaluation.state(), "commands": self.commands,
                **extra}

    def best_arrays(self) -> dict:
        return self.evaluation.best_arrays()

    def restore_best_arrays(self, arrays: dict) -> None:
        self.evaluation.restore_best_arrays(arrays)

    @property
    def checkpoint_path(self) -> Path:
        return self.run_dir / CHECKPOINT_FILE

    # --------------------------------------------------------------- Ctrl-C
    @contextlib.contextmanager
    def interruptible(self):
        """First Ctrl-C asks the loop to stop at a safe point (it checkpoints); the second aborts."""
        def handler(signum, frame):
            if self.stop_requested:
                raise KeyboardInterrupt
            self.stop_requested = True
            tqdm.write("\nCtrl-C: stopping at the next safe point and saving a checkpoint "
                       "(press again to abort without saving)")
        if threading.current_thread() is not threading.main_thread():
            yield  # a Ray trial runs in a worker thread: its sweep stops it through spec.stop_file
            return
        previous = signal.signal(signal.SIGINT, handler)
        try:
            yield
        finally:
            signal.signal(signal.SIGINT, previous)

    # ------------------------------------------------------------- finishing
    def finish(self, save_models, load_weights=None) -> Path:
        """Write the model folder: ``save_models(folder)`` writes the ``.h5`` files, then meta + plot.

        With ``keep_best``, ``load_weights(best_weights)`` first puts the best evaluation's weights back.
        """
        self.progress.close()
        self.tracker.close()
        kept_best = self.evaluation.keep_best and self.evaluation.best_weights is not None
        if kept_best:
            load_weights(self.evaluation.best_weights)
        model_dir = self.run_dir / "model"
        model_dir.mkdir(parents=True, exist_ok=True)
        files = [p.name for p in save_models(model_dir)]
        plot_name = plot_run(self.run_dir, model_dir, self.spec.experiment, self.describe())[0].name
        for table in sorted(self.run_dir.glob("*.csv")):  # metrics, evals, rollouts: all ship
            (model_dir / table.name).write_bytes(table.read_bytes())
        meta = {**self.describe(), "command": self.commands[0], "commands": self.commands,
                "env_steps": self.env_steps,
                "episodes": self.book.episodes, "wall_seconds": round(self.elapsed(), 1),
                "solved_episode": self.book.solved_episode,
                "final_average": round(self.book.average, 2), "model_files": files,
                "weights": "best periodic evaluation" if kept_best else "last",
                "best_eval": self.evaluation.best,
                "plot": plot_name, "versions": package_versions(),
                "finished": datetime.now(timezone.utc).isoformat(timespec="seconds")}
        write_json(model_dir / "meta.json", meta)
        return model_dir

    def interrupted(self) -> Interrupted:
        self.progress.close()
        self.tracker.close()
        return Interrupted(self.checkpoint_path)

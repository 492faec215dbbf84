"""One training run's companion: the trainer's loop asks it what to do and tells it what happened.

It puts together the parts that each own one thing:

    EpisodeBook          returns, moving average, successes            trainers/episodes.py
    Tracker              CSV tables and wandb                           tracking.py
    Progress             the console bar                                trainers/progress.py
    PeriodicEvaluation   greedy evaluations, best weights               trainers/periodic_eval.py
    StopRequest          Ctrl-C, SIGTERM and a sweep's stop file        trainers/stopping.py
    StopRules            budgets and goals                              trainers/stopping.py

and holds the run's counters (env steps, wall time, commands), which it writes into every
checkpoint's state and restores from it, and at the end into the model folder's meta.json
(:meth:`TrainingSession.finish`). A trainer reads like its article's loop::

    state, arrays = checkpoints.restore(spec, agent, rng, memory)
    session = TrainingSession(spec, state, resumed_arrays=arrays)
    with session.interruptible():
        while not session.should_stop():
            ...; session.env_steps += n; ...; session.end_episode(ret, extra)
    return session.conclude(checkpoint, agent.save)   # last checkpoint; Interrupted or the model
"""
from __future__ import annotations

import sys
import time
from datetime import datetime, timezone
from pathlib import Path

from rlcore.environments.seeding import training_env_seed
from rlcore.files.atomic import writable_folder, write_atomic, write_json
from rlcore.host.cpu import cpu_description
from rlcore.host.machine import package_versions
from rlcore.records.plotting import plot_run
from rlcore.training.episodes import EpisodeBook
from rlcore.training.periodic_eval import PeriodicEvaluation
from rlcore.training.progress import Progress
from rlcore.training.spec import CHECKPOINT_FILE, RunSpec
from rlcore.training.stopping import Interrupted, StopRequest, StopRules
from rlcore.training.tracking import Tracker


class TrainingSession:
    def __init__(self, spec: RunSpec, resumed_state: dict | None = None, progress_unit: str = "episode",
                 resumed_arrays: dict | None = None):
        self.spec = spec
        cfg = spec.config
        self.run_dir = spec.run_dir
        writable_folder(self.run_dir, "run folder")
        state = resumed_state or {}
        self.book = EpisodeBook(cfg.window, spec.experiment.solved_score, state.get("returns"),
                                state.get("successes"), state.get("counted_returns"))
        self.book.solved_episode = state.get("solved_episode")
        self.env_steps = int(state.get("env_steps", 0))
        self._wall_before, self._started = float(state.get("wall_seconds", 0.0)), time.perf_counter()
        # the command that started the run, then one per resume; beside each, where it took effect
        # (None for the commands of checkpoints written before 2026-11-27, which did not record it) and,
        # for a resume, the hyperparameters it changed (``changed``: name -> [before, after]; recorded
        # from 2026-11-27 on; `report --keep` of single runs reads it), and the wall seconds before it and
        # the CPU it ran on (from 2026-11-29: a run resumed on other machines has a pace per CPU)
        earlier = list(state.get("commands", []))
        starts = list(state.get("command_starts") or [])
        self.commands = earlier + [spec.command]
        self.command_starts = ([None] * (len(earlier) - len(starts)) + starts
                               + [{"env_steps": self.env_steps, "episodes": self.book.episodes,
                                   "wall_seconds": round(self._wall_before, 1), "cpu": cpu_description(),
                                   **({"rollouts": int(state["rollouts"])} if "rollouts" in state else {}),
                                   **({"changed": dict(spec.changes)} if resumed_state else {})}])
        self.evaluation = PeriodicEvaluation(cfg, state)
        self.evaluation.restore_best_arrays(resumed_arrays or {})
        self.stop = StopRequest(spec.stop_file)
        self.rules = StopRules(cfg)
        self.stop_reason: str | None = None
        self.tracker = Tracker(self.run_dir, self.run_dir.name, spec.describe(), spec.wandb_mode,
                               on_row=spec.on_progress, wandb_id=state.get("wandb_id"))
        if resumed_state:
            dropped = self.tracker.drop_rows_after(self.env_steps)
            if dropped:
                print("resume: dropped rows logged after the checkpoint ("
                      + ", ".join(f"{n} from {name}" for name, n in dropped.items()) + ")", file=sys.stderr)
            if damaged := self.tracker.damaged_rows:
                print("resume: dropped damaged rows (not text, or cells missing: a disk error or a bad copy) ("
                      + ", ".join(f"{n} from {name}" for name, n in damaged.items()) + ")", file=sys.stderr)
        self.progress = Progress(progress_unit, cfg, self.book.episodes, self.env_steps, spec.progress)

    # ------------------------------------------------------------ the loop's calls
    def fresh_env_seeds(self, n: int) -> list[int]:
        """Seeds for ``n`` envs starting new episodes now: from the run's seed and its episode count,
        so a resumed run reseeds where it stopped (``rlcore.environments.seeding``)."""
        return [training_env_seed(self.spec.seed, self.book.episodes + i) for i in range(n)]

    def elapsed(self) -> float:
        return self._wall_before + time.perf_counter() - self._started

    def end_episode(self, episode_return: float, extra: dict, success: bool | None = None,
                    counted: bool = True) -> None:
        """Log one finished episode (and whether it succeeded, for goal experiments; ``counted=False``:
        not toward the success share, an episode that did not start where evaluation starts)."""
        row = self.book.add(episode_return, success, counted)
        row.update(env_steps=self.env_steps, wall_seconds=round(self.elapsed(), 2), **extra)
        self.tracker.log(row)
        self.progress.episode(self.book, self.env_steps)

    def advance(self, steps: int) -> None:
        """Move a step-counting progress bar."""
        self.progress.steps(steps)

    def log_rollout(self, number: int, row: dict) -> None:
        """One row of rollouts.csv (on-policy trainers: one per update)."""
        self.tracker.log({"rollout": number, "env_steps": self.env_steps, **row}, table="rollouts")

    def maybe_evaluate(self, greedy_policy, snapshot) -> None:
        """When due, a periodic greedy evaluation (:class:`PeriodicEvaluation`), logged to evals.csv.

        ``greedy_policy(obs_batch) -> actions``; ``snapshot() -> weights`` of the model now.
        """
        if self.evaluation.due(self.env_steps):
            result = self.evaluation.run(self.spec.experiment, greedy_policy, snapshot, self.env_steps)
            self.tracker.log({"env_steps": self.env_steps, "episode": self.book.episodes, **result},
                             table="evals")

    @property
    def stop_requested(self) -> bool:
        """Ctrl-C, SIGTERM or the stop file: stop at the next safe point, checkpoint, raise ``Interrupted``."""
        return self.stop.poll()

    def should_stop(self) -> bool:
        """A stop was asked for, or a budget or goal of the config ended the run."""
        if self.stop_requested:
            return True
        self.stop_reason = self.rules.reason(self.book, self.env_steps, self.evaluation)
        return self.stop_reason is not None

    def interruptible(self):
        return self.stop.catching_stop_signals()

    # ------------------------------------------------------------ checkpoints
    @property
    def checkpoint_path(self) -> Path:
        return self.run_dir / CHECKPOINT_FILE

    def state(self, **extra) -> dict:
        """JSON-able counters for a checkpoint (``extra``: the trainer's own)."""
        return {**self.spec.describe(), "returns": self.book.returns, "successes": self.book.successes,
                # only when some episodes did not count (Mario's restarts); else they are the returns
                "counted_returns": (self.book.counted_returns
                                    if len(self.book.counted_returns) != self.book.episodes else None),
                "solved_episode": self.book.solved_episode, "env_steps": self.env_steps,
                "wall_seconds": self.elapsed(), "wandb_id": self.tracker.wandb_id,
                # what a resume keeps unless given again (recorded from 2026-11-28 on)
                "wandb_mode": self.spec.wandb_mode, "final_eval_episodes": self.spec.final_eval_episodes,
                **self.evaluation.state(), "commands": self.commands, "command_starts": self.command_starts,
                **extra}

    def best_arrays(self) -> dict:
        return self.evaluation.best_arrays()

    # ------------------------------------------------------------- the end
    def conclude(self, checkpoint, save_models, load_weights=None, **record) -> Path:
        """After the loop: ``checkpoint()`` once more; then raise :class:`Interrupted` if a stop was
        asked for, else write the model folder (:meth:`finish`) and return it."""
        checkpoint()
        if self.stop_requested:
            raise self.interrupted()
        return self.finish(save_models, load_weights, **record)

    def finish(self, save_models, load_weights=None, **record) -> Path:
        """Write the model folder: ``save_models(folder)`` writes the ``.h5`` files, then the plot, every CSV
        table and meta.json (what the run was, the commands that made it, its counters, the package versions).

        With ``keep_best``, ``load_weights(best_weights)`` first puts the best evaluation's weights
        back. ``record``: more for meta.json (e.g. PPO's ``init_from``).
        """
        self._close()
        kept_best = self.evaluation.keep_best and self.evaluation.best_weights is not None
        if kept_best:
            load_weights(self.evaluation.best_weights)
        book, describe = self.book, self.spec.describe()
        record = {"commands": self.commands, "command_starts": self.command_starts,
                  "env_steps": self.env_steps, "episodes": book.episodes,
                  "wall_seconds": round(self.elapsed(), 1), "solved_episode": book.solved_episode,
                  "final_average": round(book.average, 2), "stopped_by": self.stop_reason,
                  "weights": "best periodic evaluation" if kept_best else "last",
                  "best_eval": self.evaluation.best, **record}
        model_dir = writable_folder(self.run_dir / "model", "model folder")
        files = [p.name for p in save_models(model_dir)]
        plot_name = plot_run(self.run_dir, model_dir, self.spec.experiment, describe)[0].name
        for table in sorted(self.run_dir.glob("*.csv")):  # metrics, evals, rollouts: all ship
            write_atomic(model_dir / table.name, lambda p, data=table.read_bytes(): p.write_bytes(data))
        write_json(model_dir / "meta.json", {
            **describe, "command": record["commands"][0], **record, "model_files": files, "plot": plot_name,
            "versions": package_versions(), "cpu": cpu_description(),
            "finished": datetime.now(timezone.utc).isoformat(timespec="seconds")})
        return model_dir

    def interrupted(self) -> Interrupted:
        self._close()
        return Interrupted(self.checkpoint_path)

    def _close(self) -> None:
        self.progress.close()
        self.tracker.close()

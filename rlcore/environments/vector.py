"""The env pool: N environments stepped together, in-process or one process each over Pipes.

Both modes are Gymnasium's own vector envs (SyncVectorEnv, AsyncVectorEnv) with same-step
auto-reset: when an episode ends, ``infos["final_obs"]`` holds its last observation (for the
bootstrap of a truncated episode) and the returned observation already starts the next one.

Processes start with ``forkserver`` (``spawn`` where that is missing): forking a process that has
loaded TensorFlow can deadlock. Env factories must be picklable and live in TensorFlow-free
modules, so workers start without importing TensorFlow.

A worker that dies or stops answering raises :class:`EnvWorkerDied` naming the worker, and the
pool closes the rest: no hang, no process left behind.

Workers ignore SIGINT and SIGTERM. Ctrl-C in a terminal, GNU ``timeout`` and job schedulers signal
the whole process group; the trainer in the parent handles the signal (it stops at its next safe
point and writes a checkpoint) and then closes the pool, so the workers must still answer until then.
"""
from __future__ import annotations

import contextlib
import multiprocessing
import signal
import time
import warnings
from typing import Callable, Iterator, Sequence

import gymnasium as gym
import numpy as np

from rlcore.errors import UserError

VEC_MODES = ("inline", "processes")


class EnvWorkerDied(UserError):
    """An env worker process exited or stopped answering."""


class IgnoringStopSignals:
    """A picklable env factory that first makes its (worker) process ignore the stop signals (SIGINT,
    SIGTERM, SIGHUP): the trainer that owns the pool stops at a checkpoint and then closes it."""

    def __init__(self, make_env: Callable[[], gym.Env]):
        self.make_env = make_env

    def __call__(self) -> gym.Env:
        from rlcore.training.stopping import STOP_SIGNALS

        for number in STOP_SIGNALS:
            signal.signal(number, signal.SIG_IGN)
        return self.make_env()


def start_method() -> str:
    return "forkserver" if "forkserver" in multiprocessing.get_all_start_methods() else "spawn"


def bootstrap_observations(next_obs: np.ndarray, infos: dict) -> np.ndarray:
    """``next_obs`` with each finished env's row replaced by its final observation.

    With same-step auto-reset, ``next_obs`` of a finished env is already the next episode's first
    observation; a truncated episode must bootstrap from where it actually stopped.
    """
    if "_final_obs" not in infos:
        return next_obs
    boot = next_obs.copy()
    for i in np.flatnonzero(infos["_final_obs"]):
        boot[i] = infos["final_obs"][i]
    return boot


class EnvPool:
    """``num_envs`` copies of an env behind one batched ``reset`` / ``step`` / ``close``."""

    def __init__(self, env_fns: Sequence[Callable[[], gym.Env]], mode: str = "inline",
                 step_timeout: float = 60.0):
        if mode not in VEC_MODES:
            raise UserError(f"unknown vector mode {mode!r}; choose one of {', '.join(VEC_MODES)}")
        self.mode, self.step_timeout = mode, step_timeout
        autoreset = gym.vector.AutoresetMode.SAME_STEP
        if mode == "processes":
            self.envs = gym.vector.AsyncVectorEnv([IgnoringStopSignals(fn) for fn in env_fns],
                                                  context=start_method(), daemon=True,
                                                  autoreset_mode=autoreset)
        else:
            self.envs = gym.vector.SyncVectorEnv(env_fns, autoreset_mode=autoreset)
        self.num_envs = self.envs.num_envs
        self.single_observation_space = self.envs.single_observation_space
        self.single_action_space = self.envs.single_action_space
        self.closed = False

    def reset(self, seed: int | list[int] | None = None):
        return self._guard(lambda: self.envs.reset(seed=seed))

    def step(self, actions: np.ndarray):
        """(obs, rewards, terminated, truncated, infos) for all envs."""
        if self.mode == "inline":
            return self.envs.step(actions)

        def step():
            self.envs.step_async(actions)
            return self.envs.step_wait(timeout=self.step_timeout)
        return self._guard(step)

    def _guard(self, call):
        try:
            return call()
        except (EOFError, ConnectionResetError, BrokenPipeError, multiprocessing.TimeoutError) as exc:
            message = self._describe_failure(exc)
            self.close(terminate=True)
            raise EnvWorkerDied(message) from None

    def _describe_failure(self, exc: BaseException) -> str:
        processes = getattr(self.envs, "processes", [])
        deadline = time.monotonic() + 2.0  # a broken pipe can be seen before the dead worker is reaped
        while True:
            dead = [(i, p) for i, p in enumerate(processes) if not p.is_alive()]
            if dead or isinstance(exc, multiprocessing.TimeoutError) or time.monotonic() > deadline:
                break
            time.sleep(0.02)
        if not dead:
            if isinstance(exc, multiprocessing.TimeoutError):
                return f"env workers stopped answering: no reply within {self.step_timeout:g} s"
            return f"the pipe to the env workers broke ({type(exc).__name__}) though every worker is alive"
        parts = []
        for i, p in dead:
            how = (f"killed by signal {-p.exitcode}" if p.exitcode is not None and p.exitcode < 0
                   else f"exited with code {p.exitcode}")
            parts.append(f"env worker {i} (pid {p.pid}) {how}")
        return "; ".join(parts) + ": the env pool is closed; restart the run (or resume it)"

    def _terminate_workers(self) -> None:
        for process in self.envs.processes:
            if process.is_alive():
                process.terminate()
        for pipe in self.envs.parent_pipes:
            if pipe is not None:
                pipe.close()
        for process in self.envs.processes:
            process.join(timeout=5)
        self.envs.closed = True  # Gymnasium's __del__ would try to close it again

    def memory(self, name: str) -> list[dict] | None:
        """Each env's value of the attribute ``name`` (``Curriculum.memory``); None when the envs
        have no such attribute (Mario without restarts)."""
        if self.closed:
            raise RuntimeError("the env pool is closed: read its envs' memory before closing it")
        if not all(self._guard(lambda: self.envs.call("has_wrapper_attr", name))):
            return None
        return list(self._guard(lambda: self.envs.get_attr(name)))

    def give_memory(self, name: str, values: list[dict]) -> None:
        """Set each env's attribute ``name`` (one value per env), when the envs have it."""
        if all(self._guard(lambda: self.envs.call("has_wrapper_attr", name))):
            self._guard(lambda: self.envs.set_attr(name, values))

    def worker_pids(self) -> list[int]:
        return [p.pid for p in getattr(self.envs, "processes", [])]

    def close(self, terminate: bool = False) -> None:
        """Close every env; with processes, join every worker (terminating any that hang)."""
        if self.closed:
            return
        self.closed = True
        if self.mode == "processes":
            with warnings.catch_warnings():  # "close while waiting for step": expected after a death
                warnings.simplefilter("ignore")
                try:
                    self.envs.close(terminate=terminate, timeout=None if terminate else 10)
                except Exception:  # a dead worker's pipe breaks Gymnasium's own close: do it by hand
                    self._terminate_workers()
        else:
            self.envs.close()

    @contextlib.contextmanager
    def closed_on_error(self) -> Iterator[EnvPool]:
        """For a run's set-up between starting the pool and its ``with`` block (building the agent, loading
        a checkpoint or an ``--init-from`` model): an error there closes the workers first, politely, so
        they leave without a traceback of their own and only the error's one line is said."""
        try:
            yield self
        except BaseException:
            self.close()
            raise

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close(terminate=exc[0] is not None)


def final_info(infos: dict, key: str, i: int, default=0):
    """An info value of env ``i`` at the step its episode ended (same-step auto-reset)."""
    final = infos.get("final_info", {})
    mask = final.get(f"_{key}")  # Gymnasium marks which envs carry the key
    if key in final and (mask is None or mask[i]):
        return final[key][i]
    return default

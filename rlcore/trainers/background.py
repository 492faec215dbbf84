"""An update that runs in a worker thread while the trainer steps the env.

SAC on Minitaur spends its time in two places: pybullet's physics (the env step) and the compiled
gradient steps. TensorFlow releases the GIL while a compiled call runs, so the two can use the
machine's two cores side by side. The trainer submits an update and goes on stepping the env with
the actor it had; it collects the update before it submits the next one (and before anything that
reads the weights: an evaluation, a checkpoint, the end of the run). Acting therefore lags by one
call of updates, and nothing else changes: the minibatch, the noise and the collection points are
the same on every run, so a seed still reproduces its run.

With ``overlap=False`` the update runs at once, on the trainer's thread, as before.
"""
from __future__ import annotations

from concurrent.futures import Future, ThreadPoolExecutor
from typing import Callable


class BackgroundUpdate:
    def __init__(self, run: Callable, overlap: bool):
        self._run = run
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="update") if overlap else None
        self._pending: Future | None = None
        self._done = None  # the result of a synchronous update, until it is collected

    def submit(self, prepared) -> None:
        """Start ``run(prepared)``; the previous update must have been collected."""
        if self._pending is not None or self._done is not None:
            raise RuntimeError("collect() the previous update before submitting the next")
        if self._pool is None:
            self._done = self._run(prepared)
        else:
            self._pending = self._pool.submit(self._run, prepared)

    def collect(self):
        """The result of the update in flight (waiting for it), or None when there is none. An
        exception raised by the update is raised here."""
        if self._pending is not None:
            pending, self._pending = self._pending, None
            return pending.result()
        done, self._done = self._done, None
        return done

    def close(self) -> None:
        """Wait for an update in flight and stop the worker thread."""
        if self._pool is not None:
            self._pool.shutdown(wait=True)

    def __enter__(self) -> "BackgroundUpdate":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

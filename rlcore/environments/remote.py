"""An env in a process of its own, for frames TensorFlow's process cannot draw.

MuJoCo draws its frames through OpenGL; without a display that is EGL, and on a machine without a GPU
Mesa's software EGL, whose LLVM clashes with the one inside TensorFlow: in one process they end in a
segmentation fault (measured with MuJoCo 4.0 and TensorFlow 2.21, in either import order). So a video of
such an env steps it in a worker started by ``forkserver`` (``spawn`` where that is missing) that never
imports TensorFlow, over a Pipe, and the policy acts in the parent as always. TensorFlow-free.
"""
from __future__ import annotations

import multiprocessing
import weakref
from typing import Callable

import gymnasium as gym

from rlcore.environments.vector import IgnoringStopSignals, start_method
from rlcore.errors import UserError


def draws_with_opengl(entry_point: object) -> bool:
    """Whether an env's frames come from MuJoCo (its entry point lives in a ``mujoco`` module)."""
    module = entry_point if isinstance(entry_point, str) else getattr(entry_point, "__module__", "")
    return "mujoco" in str(module).split(":")[0].split(".")


def _serve(conn, make_env: Callable[[], gym.Env]) -> None:
    try:
        env = make_env()
    except Exception as exc:  # said by the parent, as one line
        conn.send(("error", f"{type(exc).__name__}: {exc}"))
        return
    conn.send(("ok", (env.observation_space, env.action_space, env.metadata)))
    while True:
        try:
            name, kwargs = conn.recv()
        except (EOFError, OSError):  # the parent is gone
            env.close()
            return
        if name == "close":
            env.close()
            conn.send(("ok", None))
            return
        try:
            conn.send(("ok", getattr(env, name)(**kwargs)))
        except Exception as exc:  # sent back whole: the parent raises it as one line
            conn.send(("error", f"{type(exc).__name__}: {exc}"))


def _end(conn, process) -> None:
    """The worker's end however the parent ends: it ignores the stop signals (the parent handles them), so
    at exit multiprocessing's SIGTERM would leave it, and the join, waiting for good."""
    conn.close()
    process.join(timeout=5)
    if process.is_alive():
        process.kill()
        process.join(timeout=5)


class RemoteEnv(gym.Env):
    """``make_env()`` built and stepped in a worker process; ``reset``, ``step``, ``render``, ``close``."""

    def __init__(self, make_env: Callable[[], gym.Env], name: str):
        context = multiprocessing.get_context(start_method())
        self._conn, child = context.Pipe()
        self._process = context.Process(target=_serve, args=(child, IgnoringStopSignals(make_env)), daemon=True)
        self._process.start()
        child.close()
        self._ended = weakref.finalize(self, _end, self._conn, self._process)
        self.name = name
        self.observation_space, self.action_space, self.metadata = self._receive("start")

    def _receive(self, what: str):
        try:
            reply = self._conn.recv()
        except EOFError:
            raise UserError(f"{self.name}: the process drawing its frames ended at {what} "
                            f"(exit code {self._process.exitcode})") from None
        status, value = reply
        if status == "error":
            hint = (" (MuJoCo draws through OpenGL: EGL, or MUJOCO_GL=osmesa where EGL is missing)"
                    if what == "render" else "")
            raise UserError(f"{self.name} could not {what}: {value}{hint}")
        return value

    def _call(self, name: str, **kwargs):
        self._conn.send((name, kwargs))
        return self._receive(name)

    def reset(self, *, seed=None, options=None):
        return self._call("reset", seed=seed, options=options)

    def step(self, action):
        return self._call("step", action=action)

    def render(self):
        return self._call("render")

    def close(self):
        if self._process.is_alive():
            try:
                self._call("close")
            except (UserError, BrokenPipeError, OSError):
                pass
        self._ended()

"""A quiet console: the known start-up noise of TensorFlow and pybullet is dropped, nothing else.

TensorFlow 2.21 logs through absl from C++, which ignores ``TF_CPP_MIN_LOG_LEVEL``: on a CPU-only
machine every start prints the absl banner, the oneDNN notice, "Could not find cuda drivers" and
"failed call to cuInit". pybullet prints ``argv[0]=`` on every connect. C code writes these to file
descriptors 1 and 2, so Python's own filters cannot see them: :func:`filtered_stderr` points both
at temporary files for the duration of a block, then writes back every line that is not in
:data:`NOISE`. Real warnings and errors still reach the console, only later. TensorFlow-free.
"""
from __future__ import annotations

import contextlib
import logging
import os
import re
import sys
import tempfile

NOISE = re.compile("|".join([
    r"^WARNING: All log messages before absl::InitializeLog\(\) is called are written to STDERR$",
    r"^I0000 .*port\.cc:\d+\] oneDNN custom operations are on",
    r"^I0000 .*cudart_stub\.cc:\d+\] Could not find cuda drivers",
    r"^I0000 .*cpu_feature_guard\.cc:\d+\] This TensorFlow binary is optimized",
    r"^To enable the following instructions: .*rebuild TensorFlow with the appropriate compiler flags\.$",
    r"^E0000 .*cuda_platform\.cc:\d+\] failed call to cuInit",
    r"^E0000 .*cuda_executor\.cc:\d+\] failed call to cuInit",
    r"^argv\[0\]=$",
    r"^pybullet build time: ",
    r"^Token authentication is enabled for this Ray cluster\.",  # local Ray keeps its token; no news
    r"^INFO: Created TensorFlow Lite XNNPACK delegate for CPU\.$",  # LiteRT, each interpreter (export check)
    r"^A\.L\.E: Arcade Learning Environment \(version [^)]*\)$",  # ale-py's banner, each import
    r"^\[Powered by Stella\]$",
    r"compiler attribute 'settotalmass' is deprecated",  # MuJoCo 4 on Gymnasium's own model files
]))

# SDL (pygame, which Gymnasium's classic-control and Box2D envs draw their frames with) starts a video
# driver and, on a machine without a display, prints "error: XDG_RUNTIME_DIR is invalid or not set": there
# no window can open anyway, and frames for a video need none, so SDL gets its dummy driver
if sys.platform.startswith("linux") and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")  # (macOS and Windows have displays without DISPLAY)
    # MuJoCo draws frames through OpenGL: without a display, through EGL (headless GPUs and Mesa alike);
    # MUJOCO_GL=osmesa where EGL is missing
    os.environ.setdefault("MUJOCO_GL", "egl")


def keep(line: str) -> bool:
    return not NOISE.search(line.rstrip("\n"))


def route_mujoco_warnings() -> None:
    """MuJoCo prints each warning and appends it to ``MUJOCO_LOG.TXT`` in the working folder; here a
    warning goes to stderr once, unless it is :data:`NOISE`, and no log file is left behind."""
    import mujoco

    def warn(message: str) -> None:
        if keep(message):
            print(f"MuJoCo warning: {message}", file=sys.stderr)
    mujoco.set_mju_user_warning(warn)


def _flush_c_stdio() -> None:
    """Flush C's stdio buffers (pybullet printf()s to a buffered stdout)."""
    try:
        import ctypes

        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError):  # no libc to call: nothing was buffered by it either
        pass


@contextlib.contextmanager
def filtered_stderr():
    """Run the block with fds 1 and 2 captured; afterwards write back the lines that are not noise."""
    streams = ((1, sys.stdout), (2, sys.stderr))
    for _, stream in streams:
        stream.flush()
    saved = {fd: os.dup(fd) for fd, _ in streams}
    captures = {fd: tempfile.TemporaryFile(mode="w+b") for fd, _ in streams}
    try:
        for fd, _ in streams:
            os.dup2(captures[fd].fileno(), fd)
        yield
    finally:
        _flush_c_stdio()
        for fd, stream in streams:
            stream.flush()
            os.dup2(saved[fd], fd)
            os.close(saved[fd])
            captures[fd].seek(0)
            text = captures[fd].read().decode(errors="replace")
            captures[fd].close()
            kept = [line for line in text.splitlines(True) if keep(line)]
            if kept:
                stream.write("".join(kept))
                stream.flush()


_loaded = False


def load_tensorflow() -> None:
    """Import TensorFlow and initialize its devices once, with the start-up noise dropped."""
    global _loaded
    if _loaded:
        return
    with filtered_stderr():
        import tensorflow as tf

        tf.config.list_physical_devices()  # the CUDA probe ("failed call to cuInit") happens here
    _loaded = True


#: Keras logs this through absl each time a model is saved as .h5, which the package does on purpose
logging.getLogger("absl").addFilter(
    lambda record: "You are saving your model as an HDF5 file" not in record.getMessage())

"""Play a policy in an ``rgb_array`` env and write the frames to MP4 (imageio + imageio-ffmpeg) or
to a small looping GIF (imageio's Pillow plugin), chosen by the file's suffix."""
from __future__ import annotations

import os
from functools import partial
from pathlib import Path

import imageio.v2 as imageio
import imageio.v3 as iio
import numpy as np

from rlcore.errors import UserError
from rlcore.files.atomic import atomic_path, library_writes
from rlcore.hyperparams.allowed import setting

VIDEO_SUFFIXES = (".mp4", ".gif")
GIF_WIDTH = 320  # frames wider than this are scaled down to it (Mario's 256 stay as they are)
GIF_FPS = 15  # about this many frames per second of play: every round(fps / 15)-th frame is kept


def _frames(env) -> list[np.ndarray]:
    """Every emulator frame of the last step when the env keeps them (Mario skips 4 per step),
    else the one rendered frame."""
    try:
        return env.get_wrapper_attr("frames")
    except AttributeError:
        return [env.render()]


def gif_every(fps: int) -> int:
    """A GIF keeps every n-th frame: GIF delays are whole hundredths of a second and browsers slow
    down delays under 20 ms, so a GIF plays near :data:`GIF_FPS` frames per second, in real time."""
    return max(1, round(fps / GIF_FPS))


class _Mp4:
    def __init__(self, path: Path, fps: int):
        # macro_block_size=1 keeps odd frame sizes (LunarLander is 600x400: fine either way)
        # ffmpeg says nothing on the console: a failed write is our one line (library_writes)
        self.path = path
        self.writer = imageio.get_writer(path, fps=fps, codec="libx264", macro_block_size=1, ffmpeg_log_level="quiet")
        self.frames = 0

    def add(self, frame: np.ndarray) -> None:
        with library_writes(self.path.parent):
            self.writer.append_data(frame)
        self.frames += 1

    def close(self) -> None:
        with library_writes(self.path.parent):
            self.writer.close()


class _Gif:
    """Keeps every ``every``-th frame, scaled to at most :data:`GIF_WIDTH` wide; a kept frame equal to
    the one before it lengthens that one's delay (as Pillow would), so the count written is exact."""

    def __init__(self, path: Path, fps: int, every: int):
        self.path, self.fps, self.every = path, fps, every
        self.kept: list[np.ndarray] = []
        self.shown_for: list[int] = []  # how many kept-frame slots each kept frame is shown for
        self.seen = 0

    def add(self, frame: np.ndarray) -> None:
        self.seen += 1
        if (self.seen - 1) % self.every:
            return
        small = _shrink(np.asarray(frame))
        if self.kept and np.array_equal(small, self.kept[-1]):
            self.shown_for[-1] += 1
        else:
            self.kept.append(small)
            self.shown_for.append(1)

    @property
    def frames(self) -> int:
        return len(self.kept)

    def close(self) -> None:
        if not self.kept:
            return
        # delays in ms, rounded on the running clock so the GIF keeps real time on average
        slot = 1000.0 * self.every / self.fps
        ends = np.cumsum(self.shown_for) * slot
        clock = np.round(np.concatenate([[0.0], ends]), -1)
        durations = [max(20, int(d)) for d in np.diff(clock)]
        # encoded in memory, then written in one call: a full disk is one OSError, not Pillow's flush
        # failing again in the plugin's __del__
        data = iio.imwrite("<bytes>", np.stack(self.kept), extension=".gif", loop=0,
                           duration=durations if len(durations) > 1 else durations[0])
        self.path.write_bytes(data)


def _shrink(frame: np.ndarray) -> np.ndarray:
    height, width = frame.shape[:2]
    if width <= GIF_WIDTH:
        return frame.copy()  # nes-py hands out a view of its screen, which the next step overwrites
    from PIL import Image

    size = (GIF_WIDTH, max(1, round(height * GIF_WIDTH / width)))
    return np.asarray(Image.fromarray(frame).resize(size, Image.Resampling.LANCZOS))


def video_path(out: str | os.PathLike, name: str) -> Path:
    """Where a video given as ``out`` goes: ``out`` itself if it names an MP4 or a GIF; ``out/NAME.mp4`` if
    it is a folder (one that exists, or a path that ends in '/' or has no suffix, made when written);
    else one clear error (:func:`check_video_path`)."""
    text = os.fspath(out)
    path = Path(text)
    if path.is_dir() or text.endswith(("/", os.sep)) or not path.suffix:
        path = path / f"{name}.mp4"
    return check_video_path(path)


def check_video_path(path: str | Path) -> Path:
    """``path`` if it names an MP4 or a GIF, else one clear error."""
    path = Path(path)
    if path.suffix.lower() not in VIDEO_SUFFIXES:
        raise UserError(f"{setting('out', str(path))}: give a file name ending in .mp4 or .gif, or a folder (for an MP4)")
    return path


def record_video(experiment, policy, path: str | Path, fps: int = 30, episodes: int = 1,
                 seed: int | None = None, max_episode_steps: int | None = None, make_env=None,
                 act=None) -> dict:
    """Write ``episodes`` episodes to ``path`` (``.mp4``, or ``.gif``: every :func:`gif_every`-th
    frame, at most :data:`GIF_WIDTH` wide, looping); return the frame count written, the episode
    returns and lengths, and for an experiment with a goal whether each episode reached it.

    Actions come from ``act(obs_batch, rng)`` (rng seeded per episode) when given, else greedily
    from ``policy(obs_batch)``. ``make_env(render_mode=...)`` builds the env when given.
    """
    path = check_video_path(path)
    gif = path.suffix.lower() == ".gif"
    seed = experiment.eval_seed_base if seed is None else seed
    make_env = make_env or partial(experiment.make_env, max_episode_steps=max_episode_steps)
    env = make_env(render_mode="rgb_array")
    act = act or (lambda obs, rng: policy(obs))
    returns, lengths, successes = [], [], []
    goal = getattr(experiment, "goal", None)
    success_key = goal.success_key if goal else None
    with atomic_path(path, then="render again") as tmp:
        writer = _Gif(tmp, fps, gif_every(fps)) if gif else _Mp4(tmp, fps)
        try:
            for episode in range(episodes):
                obs, _ = env.reset(seed=seed + episode)
                rng = np.random.default_rng(seed + episode)
                writer.add(env.render())
                total, done, length, info = 0.0, False, 0, {}
                while not done:
                    action = act(np.asarray(obs)[None], rng)[0]
                    obs, reward, terminated, truncated, info = env.step(action)
                    total += reward
                    length += 1
                    done = terminated or truncated
                    for frame in _frames(env):
                        writer.add(frame)
                returns.append(float(total))
                lengths.append(length)
                if success_key:
                    successes.append(bool(info.get(success_key, False)))
        finally:
            writer.close()
            env.close()  # also on an error or Ctrl-C: an env in a worker process (MuJoCo's) ends with it
    result = {"path": str(path), "frames": writer.frames, "returns": returns, "lengths": lengths,
              "fps": fps}
    if gif:
        result.update(every=writer.every, frames_played=writer.seen, bytes=path.stat().st_size)
    if success_key:
        result["success"] = successes
    return result

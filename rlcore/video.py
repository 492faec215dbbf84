"""Play a policy in an ``rgb_array`` env and write the frames to MP4 (imageio + imageio-ffmpeg)."""
from __future__ import annotations

from functools import partial
from pathlib import Path

import imageio.v2 as imageio
import numpy as np

from rlcore.atomic import atomic_path


def _frames(env) -> list[np.ndarray]:
    """Every emulator frame of the last step when the env keeps them (Mario skips 4 per step),
    else the one rendered frame."""
    try:
        return env.get_wrapper_attr("frames")
    except AttributeError:
        return [env.render()]


def record_video(experiment, policy, path: str | Path, fps: int = 30, episodes: int = 1,
                 seed: int | None = None, max_episode_steps: int | None = None, make_env=None,
                 act=None) -> dict:
    """Write ``episodes`` episodes to ``path``; return frame count and episode returns.

    Actions come from ``act(obs_batch, rng)`` (rng seeded per episode) when given, else greedily
    from ``policy(obs_batch)``. ``make_env(render_mode=...)`` builds the env when given.
    """
    seed = experiment.eval_seed_base if seed is None else seed
    make_env = make_env or partial(experiment.make_env, max_episode_steps=max_episode_steps)
    env = make_env(render_mode="rgb_array")
    act = act or (lambda obs, rng: policy(obs))
    returns, frames = [], 0
    with atomic_path(path) as tmp:
        # macro_block_size=1 keeps odd frame sizes (LunarLander is 600x400: fine either way)
        with imageio.get_writer(tmp, fps=fps, codec="libx264", macro_block_size=1) as writer:
            for episode in range(episodes):
                obs, _ = env.reset(seed=seed + episode)
                rng = np.random.default_rng(seed + episode)
                writer.append_data(env.render())
                frames += 1
                total, done = 0.0, False
                while not done:
                    action = act(np.asarray(obs)[None], rng)[0]
                    obs, reward, terminated, truncated, _ = env.step(action)
                    total += reward
                    done = terminated or truncated
                    for frame in _frames(env):
                        writer.append_data(frame)
                        frames += 1
                returns.append(float(total))
    env.close()
    return {"path": str(path), "frames": frames, "returns": returns, "fps": fps}

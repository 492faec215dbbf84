"""Play a policy in an ``rgb_array`` env and write the frames to MP4 (imageio + imageio-ffmpeg)."""
from __future__ import annotations

from pathlib import Path

import imageio.v2 as imageio
import numpy as np

from rlcore.atomic import atomic_path


def record_video(experiment, policy, path: str | Path, fps: int = 30, episodes: int = 1,
                 seed: int | None = None, max_episode_steps: int | None = None) -> dict:
    """Write ``episodes`` greedy episodes to ``path``; return frame count and episode returns."""
    seed = experiment.eval_seed_base if seed is None else seed
    env = experiment.make_env(render_mode="rgb_array", max_episode_steps=max_episode_steps)
    returns, frames = [], 0
    with atomic_path(path) as tmp:
        # macro_block_size=1 keeps odd frame sizes (LunarLander is 600x400: fine either way)
        with imageio.get_writer(tmp, fps=fps, codec="libx264", macro_block_size=1) as writer:
            for episode in range(episodes):
                obs, _ = env.reset(seed=seed + episode)
                writer.append_data(env.render())
                frames += 1
                total, done = 0.0, False
                while not done:
                    action = policy(np.asarray(obs, np.float32)[None])[0]
                    obs, reward, terminated, truncated, _ = env.step(action)
                    total += reward
                    done = terminated or truncated
                    writer.append_data(env.render())
                    frames += 1
                returns.append(float(total))
    env.close()
    return {"path": str(path), "frames": frames, "returns": returns, "fps": fps}

"""GIFs: `render --out NAME.gif` writes a small looping GIF whose frames are those it reports."""
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest
from PIL import Image

import main
from rlcore.environments.registry import get_experiment
from rlcore.models.video import GIF_WIDTH, _Gif, gif_every, record_video


def _durations(path: Path) -> list[int]:
    with Image.open(path) as gif:
        found = []
        for i in range(gif.n_frames):
            gif.seek(i)
            found.append(gif.info["duration"])
    return found


def test_a_gif_keeps_every_nth_frame_scaled_to_320_px(tmp_path):
    """LunarLander doing nothing falls for 40 steps: 41 frames that all differ, every 2nd kept."""
    exp = get_experiment("lunar_lander")
    out = tmp_path / "fall.gif"
    result = record_video(exp, lambda obs: np.zeros(len(obs), np.int64), out, fps=30, max_episode_steps=40)
    assert gif_every(30) == 2 and result["every"] == 2 and result["frames_played"] == 41
    frames = iio.imread(out, index=None)
    assert len(frames) == result["frames"] == 21  # frames 0, 2, ..., 40
    assert frames.shape[1:] == (213, GIF_WIDTH, 3)  # 600x400 scaled to 320 wide
    assert iio.immeta(out)["loop"] == 0  # loops for ever
    assert sum(_durations(out)) == 1400  # 21 kept frames of 2/30 s each: real time
    assert result["bytes"] == out.stat().st_size < 2_000_000


def test_repeated_frames_merge_into_one_longer_frame(tmp_path):
    red, blue = np.zeros((8, 8, 3), np.uint8), np.zeros((8, 8, 3), np.uint8)
    red[..., 0], blue[..., 2] = 255, 255
    gif = _Gif(tmp_path / "x.gif", fps=10, every=1)
    for frame in (red, red, blue, blue, blue, red):
        gif.add(frame)
    gif.close()
    assert gif.frames == 3 and len(iio.imread(tmp_path / "x.gif", index=None)) == 3
    assert _durations(tmp_path / "x.gif") == [200, 300, 100]


def test_render_writes_a_gif_and_refuses_other_suffixes(tmp_path, capsys):
    out = tmp_path / "lander.gif"
    assert main.main(["render", "lunar_lander", "dqn", "--seed", "1000000", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    count = int(printed.split(f"{out} (")[1].split(" frames")[0])
    assert len(iio.imread(out, index=None)) == count > 10
    assert main.main(["render", "lunar_lander", "dqn", "--out", str(tmp_path / "lander.avi")]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (f"error: --out {tmp_path / 'lander.avi'}: give a file name ending in .mp4 or .gif, "
                   "or a folder (for an MP4)")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["lander.gif"]


@pytest.mark.parametrize("fps,every", [(30, 2), (60, 4), (50, 3), (10, 1)])
def test_gif_frame_rate_stays_near_15(fps, every):
    assert gif_every(fps) == every

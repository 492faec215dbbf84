"""Images for the DQN family and A2C, and the atari and mujoco extras (issue 65): a short ``ALE/Pong-v5 dqn``
and ``HalfCheetah-v5 sac`` each train, resume, evaluate, render and export through the ordinary commands."""
import json

import imageio.v3 as iio
import numpy as np
import pytest

from rlcore import api
from tests.test_cli import run as cli

pytest.importorskip("ale_py", reason="the atari extra")
pytest.importorskip("mujoco", reason="the mujoco extra")

QUIET = ["--wandb", "off", "--no-progress", "--final-eval-episodes", "1"]
PONG_SMALL = ["--max-episode-steps", "40", "--batch-size", "8", "--learning-starts", "32", "--buffer-size", "300"]


def test_pong_dqn_learns_from_stacked_frames_and_every_command_takes_it(tmp_path, capsys):
    run_dir = tmp_path / "pong"
    code, out, err = cli(capsys, "train", "ALE/Pong-v5", "dqn", "--episodes", "2", *PONG_SMALL, *QUIET,
                         "--run-dir", str(run_dir))
    assert code == 0, err
    assert "Arcade Learning Environment" not in out + err and "Powered by Stella" not in out + err
    meta = json.loads((run_dir / "model" / "meta.json").read_text())
    assert meta["env"]["atari_preprocessing"]["frame_stack"] == 4
    with np.load(run_dir / "replay.npz") as replay:  # each frame once: 80 steps + 4 starting frames each
        assert replay["frames"].shape == (80 + 2 * 4, 84, 84) and replay["frames"].dtype == np.uint8
    code, out, err = cli(capsys, "train", "ALE/Pong-v5", "dqn", "--resume", str(run_dir), "--episodes", "3", *QUIET)
    assert code == 0 and "replay memory" not in err, err  # the frames came back with the checkpoint
    policy = api.load(run_dir)
    env = policy.make_env()
    obs, _ = env.reset(seed=0)
    assert obs.shape == (84, 84, 4) and obs.dtype == np.uint8 and 0 <= int(policy(obs[None])[0]) < 6
    env.close()
    code, out, err = cli(capsys, "evaluate", "ALE/Pong-v5", "dqn", "--model", str(run_dir), "--episodes", "1")
    assert code == 0 and "greedy return" in out, err
    gif = tmp_path / "pong.gif"
    code, out, err = cli(capsys, "render", "ALE/Pong-v5", "dqn", "--model", str(run_dir), "--out", str(gif))
    assert code == 0 and iio.imread(gif, index=0).shape[-1] in (3, 4), err
    code, out, err = cli(capsys, "export", "ALE/Pong-v5", "dqn", "--model", str(run_dir), "--format", "onnx",
                         "--out", str(tmp_path / "onnx"))
    assert code == 0 and "passed" in out, err
    record = json.loads((tmp_path / "onnx" / "export.json").read_text())
    assert record["network"]["input"]["shape"] == [None, 84, 84, 4] and record["network"]["input"]["dtype"] == "uint8"


def test_pong_dqn_learns_once_its_frame_memory_is_full_even_when_learning_starts_asks_for_all_of_it(tmp_path, capsys):
    """A frame memory's episode starts take slots, so it never holds --buffer-size transitions; the run still
    learns once the memory is full (it trained a random policy to the end before)."""
    run_dir = tmp_path / "full"
    code, out, err = cli(capsys, "train", "ALE/Pong-v5", "dqn", "--episodes", "2", "--max-episode-steps", "40",
                         "--batch-size", "8", "--buffer-size", "64", "--learning-starts", "64", *QUIET,
                         "--run-dir", str(run_dir))
    assert code == 0, err
    last = (run_dir / "model" / "metrics.csv").read_text().splitlines()
    header, row = last[0].split(","), last[-1].split(",")
    assert int(float(row[header.index("grad_steps")])) > 0


def test_pong_a2c_trains_on_frames_from_eight_envs(tmp_path, capsys):
    run_dir = tmp_path / "a2c"
    code, out, err = cli(capsys, "train", "ALE/Pong-v5", "a2c", "--steps", "80", "--max-episode-steps", "20",
                         *QUIET, "--run-dir", str(run_dir))
    assert code == 0, err
    code, out, err = cli(capsys, "evaluate", "ALE/Pong-v5", "a2c", "--model", str(run_dir), "--episodes", "1")
    assert code == 0 and "return" in out, err


def test_half_cheetah_sac_trains_renders_through_its_own_process_and_exports(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    run_dir = tmp_path / "cheetah"
    small = ["--learning-starts", "40", "--batch-size", "16", "--buffer-size", "500", "--actor-hidden", "16,16",
             "--critic-hidden", "16,16", "--max-episode-steps", "60"]
    code, out, err = cli(capsys, "train", "HalfCheetah-v5", "sac", "--episodes", "2", *small, *QUIET,
                         "--run-dir", str(run_dir))
    assert code == 0 and "settotalmass" not in out + err, err
    code, out, err = cli(capsys, "evaluate", "HalfCheetah-v5", "sac", "--model", str(run_dir), "--episodes", "1")
    assert code == 0 and "mean-action return" in out, err
    mp4 = tmp_path / "cheetah.mp4"
    code, out, err = cli(capsys, "render", "HalfCheetah-v5", "sac", "--model", str(run_dir), "--out", str(mp4))
    assert code == 0 and mp4.stat().st_size > 10_000, err  # MuJoCo's frames, drawn beside no TensorFlow
    code, out, err = cli(capsys, "export", "HalfCheetah-v5", "sac", "--model", str(run_dir), "--format", "tflite",
                         "--out", str(tmp_path / "tflite"))
    assert code == 0 and "passed" in out, err
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()  # MuJoCo's warnings are routed, not logged in the folder


@pytest.mark.parametrize("argv, words", [
    (["ALE/Pong-v5", "sac"], "sac does not fit ALE/Pong-v5: it needs continuous actions"),
    (["ALE/Pong-v5", "dqn", "--env-kwargs", "frameskip=4"], "frameskip is the Atari preprocessing's"),
    (["ALE/Pong-v5", "dqn", "--env-kwargs", "mode=99"], "--env-kwargs: ALE/Pong-v5 refused {'mode': 99}"),
    (["ALE/NoSuchGame-v5", "dqn"], "the games ale-py registers"),
])
def test_what_atari_refuses_is_one_line_before_any_folder(tmp_path, capsys, argv, words):
    code, out, err = cli(capsys, "train", *argv, "--steps", "10", "--run-dir", str(tmp_path / "run"), "--wandb", "off")
    assert code == 2 and words in err and len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "run").exists()

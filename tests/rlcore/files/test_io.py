"""Atomic writes, checkpoints, hyperparameter parsing, tracking (wandb offline) and MP4 output."""
import dataclasses
import json
import os
import signal
import subprocess
import sys
import textwrap

import imageio.v3 as iio
import numpy as np
import pytest

from rlcore.algorithms.dqn.config import DQNConfig
from rlcore.errors import UserError
from rlcore.files.atomic import atomic_path
from rlcore.files.checkpoint import load_checkpoint, save_checkpoint
from rlcore.hyperparams.flags import apply_overrides, from_dict, to_dict
from rlcore.models.video import record_video
from rlcore.training.tracking import Tracker, resolve_wandb_mode
from tests import toy


def test_failed_write_keeps_the_old_file(tmp_path):
    target = tmp_path / "model.h5"
    target.write_text("good")
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            tmp.write_text("half")
            raise RuntimeError("crash mid-save")
    assert target.read_text() == "good"
    assert list(tmp_path.iterdir()) == [target]  # no temp file left behind


def test_kill_mid_save_keeps_the_old_checkpoint(tmp_path):
    """A process killed while writing a large checkpoint leaves the previous one loadable."""
    target = tmp_path / "checkpoint.npz"
    np.savez(target, marker=np.array(1))
    script = textwrap.dedent(f"""
        import numpy as np, sys
        from rlcore.files.atomic import atomic_path
        with atomic_path({str(target)!r}) as tmp:
            with open(tmp, "wb") as f:
                f.write(b"partial")
                f.flush()
                print("writing", flush=True)
                sys.stdin.read()  # hang here until killed
    """)
    proc = subprocess.Popen([sys.executable, "-c", script], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                            text=True, cwd=os.getcwd())
    assert proc.stdout.readline().strip() == "writing"
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=10)
    with np.load(target) as data:
        assert int(data["marker"]) == 1


def test_checkpoint_round_trip_and_mismatch(tmp_path):
    from rlcore.algorithms.dqn.agent import DQNAgent

    agent = DQNAgent(4, 2, DQNConfig(hidden=(8,)))
    rng = np.random.default_rng(0)
    batch = (rng.normal(size=(16, 4)).astype(np.float32), rng.integers(0, 2, 16).astype(np.int32),
             rng.normal(size=16).astype(np.float32), rng.normal(size=(16, 4)).astype(np.float32),
             np.zeros(16, np.float32))
    agent.train_step(*batch)
    path = save_checkpoint(tmp_path / "c.npz", agent.models(), agent.optimizers(), {"steps": 7},
                           {"extra": np.arange(3)})
    fresh = DQNAgent(4, 2, DQNConfig(hidden=(8,)))
    state, arrays = load_checkpoint(path, fresh.models(), fresh.optimizers())
    assert state["steps"] == 7 and arrays["extra"].tolist() == [0, 1, 2]
    for a, b in zip(agent.optimizer.variables, fresh.optimizer.variables):
        np.testing.assert_array_equal(np.asarray(a), np.asarray(b))
    # the same next update from both: weights and Adam moments were restored
    agent.train_step(*batch)
    fresh.train_step(*batch)
    for a, b in zip(agent.q_network.get_weights(), fresh.q_network.get_weights()):
        np.testing.assert_allclose(a, b, rtol=1e-6)
    other = DQNAgent(4, 2, DQNConfig(hidden=(16,)))
    with pytest.raises(UserError, match="does not match this configuration"):
        load_checkpoint(path, other.models(), other.optimizers())


def test_hyperparameters_override_and_round_trip():
    cfg = apply_overrides(DQNConfig(), {"lr": 1e-4, "hidden": (32, 32), "double": True})
    assert (cfg.lr, cfg.hidden, cfg.double) == (1e-4, (32, 32), True)
    assert from_dict(DQNConfig, to_dict(cfg)) == cfg
    with pytest.raises(UserError, match="unknown hyperparameter"):
        apply_overrides(cfg, {"learning_rate": 1.0})


def test_wandb_modes(monkeypatch, tmp_path):
    monkeypatch.delenv("WANDB_API_KEY", raising=False)
    monkeypatch.delenv("WANDB_MODE", raising=False)  # the tests' own (tests/conftest.py)
    monkeypatch.setenv("NETRC", str(tmp_path / "no-netrc"))
    monkeypatch.setenv("HOME", str(tmp_path))
    assert resolve_wandb_mode("auto") == "offline"
    assert resolve_wandb_mode("off") == "disabled"
    monkeypatch.setenv("WANDB_API_KEY", "x" * 40)
    assert resolve_wandb_mode("auto") == "online"
    # wandb's own variable, where the user set it, decides for auto (not for a mode asked for by name)
    for value, mode in (("offline", "offline"), ("disabled", "disabled"), ("dryrun", "offline"), ("", "online")):
        monkeypatch.setenv("WANDB_MODE", value)
        assert resolve_wandb_mode("auto") == mode, value
    monkeypatch.setenv("WANDB_MODE", "offline")
    assert resolve_wandb_mode("online") == "online"
    with pytest.raises(UserError):
        resolve_wandb_mode("cloud")


def test_tracker_writes_csv_and_an_offline_wandb_run(tmp_path):
    tracker = Tracker(tmp_path, "test-run", {"lr": 1e-3}, wandb_mode="offline")
    for episode in range(1, 4):
        tracker.log({"episode": episode, "total_points": float(episode), "av_latest_points": 1.0,
                     "target_ave_scores": 200.0})
    run_id = tracker.wandb_id
    tracker.close()
    assert (tmp_path / "metrics.csv").read_text().splitlines()[-1] == "3,3.0,1.0,200.0"
    run_dirs = list((tmp_path / "wandb").glob(f"offline-run-*-{run_id}"))
    assert len(run_dirs) == 1
    assert (run_dirs[0] / f"run-{run_id}.wandb").stat().st_size > 0


def test_a_resumed_tracker_adds_a_new_column_to_the_header(tmp_path):
    tracker = Tracker(tmp_path, "test-run", {}, wandb_mode="off")
    tracker.log({"env_steps": 1, "loss": 0.5}, table="rollouts")
    tracker.close()
    resumed = Tracker(tmp_path, "test-run", {}, wandb_mode="off")
    resumed.log({"env_steps": 2, "loss": 0.25, "update_fraction": 1.0}, table="rollouts")
    resumed.close()
    lines = (tmp_path / "rollouts.csv").read_text().splitlines()
    assert lines == ["env_steps,loss,update_fraction", "1,0.5,", "2,0.25,1.0"]


def test_record_video_writes_a_decodable_mp4(tmp_path):
    out = tmp_path / "toy.mp4"
    result = record_video(toy.EXPERIMENT, lambda obs: np.ones(len(obs), np.int64), out, fps=30, episodes=2,
                          max_episode_steps=10)
    assert result["frames"] == 2 * 11  # reset frame + 10 steps, per episode
    frames = iio.imread(out, plugin="pyav") if _has_pyav() else np.stack(list(iio.imiter(out)))
    assert len(frames) == result["frames"]
    assert frames.shape[1:] == (64, 64, 3)


def _has_pyav():
    try:
        import av  # noqa: F401
        return True
    except ImportError:
        return False


def test_config_dataclasses_are_frozen():
    with pytest.raises(dataclasses.FrozenInstanceError):
        DQNConfig().lr = 1.0


def test_tracker_drops_rows_logged_after_a_checkpoint(tmp_path):
    tracker = Tracker(tmp_path, "test-run", {}, wandb_mode="off")
    for step in (10, 20, 30, 40):
        tracker.log({"episode": step // 10, "env_steps": step})
        tracker.log({"rollout": step // 10, "env_steps": step}, table="rollouts")
    tracker.close()
    (tmp_path / "notes.csv").write_text("a,b\n1,2\n")
    assert tracker.drop_rows_after(20) == {"metrics.csv": 2, "rollouts.csv": 2}
    assert (tmp_path / "metrics.csv").read_text().splitlines() == ["episode,env_steps", "1,10", "2,20"]
    assert (tmp_path / "rollouts.csv").read_text().splitlines()[-1] == "2,20"
    assert (tmp_path / "notes.csv").read_text() == "a,b\n1,2\n"
    assert tracker.drop_rows_after(20) == {}


def test_the_checkpoint_state_is_utf8_and_older_checkpoints_still_read(tmp_path):
    from rlcore.files.checkpoint import CHECKPOINT_VERSION, read_checkpoint_state

    state = {"returns": [1.5] * 1000, "name": "Mario 2-1 – ünïcode"}
    path = save_checkpoint(tmp_path / "new.npz", {}, {}, state)
    with np.load(path) as data:
        assert data["state_json"].dtype == np.uint8  # 1 byte per character, not a numpy string's 4
        assert data["state_json"].nbytes < 1.1 * len(json.dumps(state, ensure_ascii=False).encode())
    assert read_checkpoint_state(path) == {**state, "checkpoint_version": CHECKPOINT_VERSION}
    old = tmp_path / "old.npz"  # as written before: the JSON as a numpy string array, no version
    np.savez(old, state_json=np.array(json.dumps(state)))
    assert read_checkpoint_state(old) == state


def test_a_checkpoint_from_a_newer_format_is_refused_not_misread(tmp_path):
    from rlcore.files.checkpoint import CHECKPOINT_VERSION, read_checkpoint_state

    newer = tmp_path / "newer.npz"
    state = {"checkpoint_version": CHECKPOINT_VERSION + 1}
    np.savez(newer, state_json=np.frombuffer(json.dumps(state).encode(), np.uint8))
    with pytest.raises(UserError, match=f"format {CHECKPOINT_VERSION + 1}, newer than this package reads"):
        read_checkpoint_state(newer)


def test_every_agent_offers_what_the_shared_plumbing_calls():
    from rlcore.algorithms.a2c.agent import A2CAgent
    from rlcore.algorithms.dqn.agent import DQNAgent
    from rlcore.algorithms.ppo.agent import PPOAgent
    from rlcore.algorithms.protocol import Agent
    from rlcore.algorithms.sac.agent import SACAgent

    for agent_class in (DQNAgent, A2CAgent, PPOAgent, SACAgent):
        missing = [name for name in ("models", "optimizers", "sync_policy_weights", "save")
                   if not callable(getattr(agent_class, name, None))]
        assert not missing, (agent_class.__name__, missing)
        assert issubclass(agent_class, Agent)

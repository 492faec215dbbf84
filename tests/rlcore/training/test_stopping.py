"""StopRules (budgets and goals, and which one ended a run) and StopRequest (the stop file)."""
import dataclasses
import os
import signal

import pytest

from rlcore.algorithms.ppo.config import PPOConfig
from rlcore.hyperparams.base import EpisodeLoop
from rlcore.training.episodes import EpisodeBook
from rlcore.training.periodic_eval import PeriodicEvaluation
from rlcore.training.stopping import StopRequest, StopRules


def _reason(cfg, returns=(), successes=(), env_steps=0, best_eval=None):
    book = EpisodeBook(cfg.window, None, list(returns), list(successes))
    evaluation = PeriodicEvaluation(cfg, {"best_eval": best_eval})
    return StopRules(cfg).reason(book, env_steps, evaluation)


def test_each_rule_names_itself():
    cfg = EpisodeLoop(max_episodes=5, max_env_steps=100, window=2, stop_score=10.0, stop_eval_score=50.0)
    assert _reason(cfg) is None
    assert _reason(cfg, returns=[0] * 5) == "max_episodes 5"
    assert _reason(cfg, env_steps=100) == "max_env_steps 100"
    assert _reason(cfg, best_eval={"mean": 50.0}) == "stop_eval_score 50.0"
    assert _reason(cfg, best_eval={"mean": 49.9}) is None
    assert _reason(cfg, returns=[9, 11]) == "stop_score 10.0"  # mean of the last 2 is 10
    assert _reason(cfg, returns=[11]) is None  # the window is not full yet
    assert _reason(cfg, returns=[0, 0, 9, 11]) == "stop_score 10.0"  # only the last 2 count
    assert _reason(cfg, returns=[20, 8, 11]) is None  # nor the last return alone


def test_success_share_needs_a_full_window():
    cfg = PPOConfig(window=4, stop_success_share=0.75, stop_score=1e9, max_episodes=100)
    assert _reason(cfg, returns=[0] * 3, successes=[True] * 3) is None
    assert _reason(cfg, returns=[0] * 4, successes=[True, False, True, True]) == "stop_success_share 0.75"
    assert _reason(cfg, returns=[0] * 4, successes=[True, False, False, True]) is None
    late = [False, False, True, False, True, True]  # 3 of the last 4; 3 of all 6 would be 0.5
    assert _reason(cfg, returns=[0] * 6, successes=late) == "stop_success_share 0.75"
    assert _reason(cfg, returns=[0] * 6, successes=[True] * 3 + [False, True, False]) is None
    assert _reason(dataclasses.replace(cfg, stop_success_share=0.0), returns=[0] * 4, successes=[True] * 4) is None


def test_stop_file_is_seen_and_stays_seen(tmp_path, monkeypatch):
    monkeypatch.setattr(StopRequest, "FILE_CHECK_SECONDS", 0.0)
    stop = StopRequest(tmp_path / "STOP")
    assert not stop.poll()
    (tmp_path / "STOP").touch()
    assert stop.poll()
    (tmp_path / "STOP").unlink()
    assert stop.poll()  # once asked, the run stops at its next safe point


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_without_a_stop_file_a_signal_stops_and_a_second_one_aborts(signum, capsys):
    stop = StopRequest(None)
    assert not stop.poll()
    before = signal.getsignal(signum)
    with stop.catching_stop_signals():
        os.kill(os.getpid(), signum)
        assert stop.poll()  # the first: stop at the next safe point, with a checkpoint
        with pytest.raises(KeyboardInterrupt):  # the second: abort without saving
            os.kill(os.getpid(), signum)
    assert signal.getsignal(signum) is before  # the handler before the run is back
    assert "stopping at the next safe point" in capsys.readouterr().out

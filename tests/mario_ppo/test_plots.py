"""Mario's plots from `main.py plot`: a run still training, restarted episodes left out, the endings
map's shares, and titles that name the level."""
from pathlib import Path

import numpy as np
import pytest

from tests.test_cli import run


def write_run(run_dir: Path, rows: list[str]) -> None:
    """A Mario run folder as a training leaves it: metrics.csv (``rows``) and a checkpoint."""
    from rlcore.files.checkpoint import save_checkpoint

    (run_dir / "metrics.csv").write_text("\n".join(rows) + "\n")
    save_checkpoint(run_dir / "checkpoint.npz", {}, {}, {"experiment": "mario_ppo", "algo": "ppo",
                                                         "preset": "default", "seed": 0,
                                                         "config": {"window": 20}, "env_steps": 4096 * 7,
                                                         "returns": [0.0] * (len(rows) - 1),
                                                         "wall_seconds": 5400.0})


def test_plot_of_an_unfinished_mario_run(capsys, tmp_path):
    """A run with only a checkpoint and its metrics (training still going) gets its plots."""
    rows = ["episode,total_points,av_latest_points,target_ave_scores,x_pos,success,success_share"]
    rows += [f"{i},{i % 7 * 10},{30 + i / 10},0,{300 + 40 * i},{int(i == 20)},{0.05 * (i >= 20)}"
             for i in range(1, 31)]
    write_run(tmp_path, rows)
    code, out, err = run(capsys, "plot", str(tmp_path))
    assert code == 0, err
    written = [line.split()[-1] for line in out.splitlines()]
    assert [Path(p).name for p in written] == ["mario_ppo_Train_ppo.png", "mario_ppo_Progress_ppo.png",
                                              "mario_ppo_Endings_ppo.png"]
    assert all(Path(p).stat().st_size > 1000 for p in written)


def test_mario_plots_leave_out_restarted_episodes(capsys, tmp_path, monkeypatch):
    """Restarts start at x 2,900: their ends must not show in the endings map or the curves."""
    import rlcore.records.plotting as plotting
    rows = ["episode,total_points,av_latest_points,target_ave_scores,x_pos,success,success_share,restarted"]
    rows += [f"{i},{5 if i % 2 else 300},0,0,{3000 if i % 2 else 300 + i},0,0,{i % 2}" for i in range(1, 41)]
    write_run(tmp_path, rows)
    ended_at, kept, drawn = [], [], []  # what the endings map was given, the episodes kept, each curve's
    ending_shares, full_episodes = plotting.ending_shares, plotting.full_episodes

    def spy_ending_shares(x, *args, **kwargs):
        ended_at.extend(x)
        return ending_shares(x, *args, **kwargs)

    def spy_full_episodes(df, key):
        kept.append(full_episodes(df, key))
        return kept[-1]

    monkeypatch.setattr(plotting, "ending_shares", spy_ending_shares)
    monkeypatch.setattr(plotting, "full_episodes", spy_full_episodes)
    for name, full_at in (("plot_episode_scores", 1), ("plot_progress", 0)):  # where each takes the episodes
        monkeypatch.setattr(plotting, name, lambda *args, plot=getattr(plotting, name), at=full_at:
                            drawn.append(args[at]) or plot(*args))
    code, _, err = run(capsys, "plot", str(tmp_path))
    assert code == 0, err
    assert sorted(ended_at) == [300 + i for i in range(2, 41, 2)]  # the 20 episodes from the start
    assert len(kept) == 1 and len(kept[0]) == 20 and (kept[0]["restarted"] == 0).all()  # picked once
    assert len(drawn) == 2 and all(df is kept[0] for df in drawn)  # and the curves drew those


def test_ending_shares_say_where_each_block_of_episodes_ended():
    from rlcore.records.plotting import ending_shares

    # 10 episodes end at x 100, then 10 at x 900 (the farthest any got), then 5 split 450 / 900
    x = [100.0] * 10 + [900.0] * 10 + [450.0, 900.0, 450.0, 900.0, 450.0]
    starts, edges, shares = ending_shares(x, block=10, bins=9)
    assert starts.tolist() == [1, 11, 21] and edges[0] == 0 and edges[-1] == 900
    np.testing.assert_allclose(shares.sum(axis=0), 1.0)
    assert shares[1, 0] == 1.0 and shares[8, 1] == 1.0  # x 100 in bin [100, 200), x 900 in the last bin
    assert shares[4, 2] == pytest.approx(0.6) and shares[8, 2] == pytest.approx(0.4)


def test_a_plot_title_names_the_mario_level():
    from rlcore.environments.registry import get_experiment
    from rlcore.records.plotting import plot_title

    about = {"algo": "ppo", "preset": "default", "seed": 0, "config": {"world": 2, "stage": 1}}
    assert plot_title(get_experiment("mario_ppo"), about) == "mario_ppo ppo 2-1 (default preset, seed 0)"
    about = {"algo": "dqn", "preset": "article", "seed": 3, "config": {}}
    assert plot_title(get_experiment("lunar_lander"), about) == "lunar_lander dqn (article preset, seed 3)"


def test_a_deaths_plot_once_killed_by_is_logged(capsys, tmp_path):
    """A run resumed by code that logs `killed_by` gets the Deaths plot, from its first logged cause."""
    rows = ["episode,total_points,av_latest_points,target_ave_scores,x_pos,success,success_share,killed_by"]
    causes = [""] * 30 + ["10", "", "-1", "6", "10"] * 6  # logged from episode 31 on; "" is not a death
    rows += [f"{i},10,0,0,{300 + i},{int(c == '')},0,{c}" for i, c in enumerate(causes, start=1)]
    write_run(tmp_path, rows)
    code, out, err = run(capsys, "plot", str(tmp_path))
    assert code == 0, err
    assert Path(out.splitlines()[-1].split()[-1]).name == "mario_ppo_Deaths_ppo.png"


def test_cause_shares_are_the_shares_of_each_blocks_failures():
    import pandas as pd

    from rlcore.records.plotting import cause_shares

    causes = pd.Series([None, "fish", "pit", "fish", None, "goomba", "fish", "fish", "pit", None, None, None])
    shares = cause_shares(causes, block=3, most=2)
    assert list(shares.columns) == ["fish", "pit", "other"]
    np.testing.assert_allclose(shares.iloc[0], [0.5, 0.5, 0.0])      # fish, pit
    np.testing.assert_allclose(shares.iloc[1], [0.5, 0.0, 0.5])      # fish, goomba (other)
    np.testing.assert_allclose(shares.iloc[2], [2 / 3, 1 / 3, 0.0])  # fish, fish, pit
    assert shares.iloc[3].isna().all()                               # no failure in the last block

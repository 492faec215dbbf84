"""`main.py status RUN_DIR`: where a run stands, from its CSV tables."""
import json
from pathlib import Path

import pandas as pd

from tests.mario_ppo.test_plots import write_run
from tests.test_cli import run, status_lines

ROOT = Path(__file__).resolve().parents[2]
HEADER = ("episode,total_points,av_latest_points,target_ave_scores,env_steps,x_pos,success,success_share,"
          "restarted,killed_by")


def test_status_counts_flags_per_block_of_full_episodes_and_restarts_beside_them(capsys, tmp_path):
    rows = [HEADER]
    for i in range(1, 61):  # every 4th episode restarted; full episodes win when i % 5 == 0
        restarted = int(i % 4 == 0)
        won = int(i % 5 == 0)
        cause = "" if won else (-1 if i % 3 else 10)  # fell, or a grey Cheep-cheep
        rows.append(f"{i},{10 * i},0,0,{100 * i},{20 * i},{won},0,{restarted},{cause}")
    write_run(tmp_path, rows)
    lines = status_lines(capsys, tmp_path, "--block", "20", "--blocks", "2")
    assert lines[0] == ("mario_ppo ppo (default preset, seed 0): checkpoint at 28,672 env steps, 60 episodes, "
                        "1.5 h of training")
    df = pd.read_csv(tmp_path / "metrics.csv")
    full = df[df.restarted == 0]  # 45 episodes: the newest 40 in 2 blocks of 20
    for line, part in zip(lines[1:3], (full.iloc[5:25], full.iloc[25:45])):
        first, last = part.episode.iloc[0], part.episode.iloc[-1]
        partial = df[df.episode.between(first, last) & (df.restarted == 1)]
        assert line.startswith(f"episodes {first}-{last} (to env step {100 * last:,}): "
                               f"flag_get {part.success.sum()}/20 ({part.success.sum() / 20:.1%}) "
                               f"mean x_pos {part.x_pos.mean():,.0f}")
        assert line.endswith(f"| restarted {len(partial)} ({partial.success.sum()} flag_get)")
    span = df[df.episode >= full.episode.iloc[5]].killed_by.dropna()
    fell = (span == -1).mean()
    assert lines[3] == (f"killed_by over all episodes since {full.episode.iloc[5]:,} ({len(span)} failures): "
                        f"fell {fell:.0%}, grey Cheep-cheep {1 - fell:.0%}")
    assert len(lines) == 4


def test_status_says_where_the_restarted_episodes_of_a_block_started(capsys, tmp_path):
    rows = [HEADER + ",start_x"]
    for i in range(1, 21):  # odd episodes restarted, from x 600 in the first block, 590-600 in the second
        start = 40 if i % 2 == 0 else (600 if i < 11 else 590 + (i % 4 == 1) * 10)
        rows.append(f"{i},{10 * i},0,0,{100 * i},{700 + i},0,0,{i % 2},-1,{start}")
    write_run(tmp_path, rows)
    first, second = status_lines(capsys, tmp_path, "--block", "5", "--blocks", "2")[1:3]
    assert first.endswith("| restarted 4 (0 flag_get) from start_x 600")
    assert second.endswith("| restarted 4 (0 flag_get) from start_x 590-600")


def test_status_of_a_shipped_level_reads_its_meta_and_ends_at_its_last_episode(capsys):
    folder = ROOT / "saved_networks" / "mario_ppo" / "1-4"
    # one block of episodes, one of 20 rollouts
    head, resumes, block, rollouts = status_lines(capsys, folder, "--block", "100", "--blocks", "1")
    assert head.startswith("mario_ppo ppo (default preset, seed 0): model at 901,120 env steps, ")
    commands = json.loads((folder / "meta.json").read_text())["commands"]  # trained before resumes said where
    assert resumes == (f"resumed {len(commands) - 1} times; where and what they changed is not recorded (runs "
                       f"recorded it from 2026-11-27 on); the commands are in meta.json")
    df = pd.read_csv(folder / "metrics.csv").tail(100)
    wins = df.success.sum()
    assert block.startswith(f"episodes {df.episode.iloc[0]:,}-{df.episode.iloc[-1]:,} ")
    assert f"flag_get {wins}/100 ({wins / 100:.1%})" in block
    last = pd.read_csv(folder / "rollouts.csv").rollout.iloc[-1]
    assert rollouts.startswith(f"rollouts {last - 19}-{last}: flag_get ")


def test_status_of_a_folder_that_is_not_a_run_is_one_line(capsys, tmp_path):
    code, out, err = run(capsys, "status", str(tmp_path))
    assert code == 2 and err.strip() == f"error: no metrics.csv in {tmp_path}; give a run folder such as runs/<name>"
    code, _, err = run(capsys, "status", str(tmp_path), "--block", "0")
    assert code == 2 and len(err.strip().splitlines()) == 1 and "--block" in err


def test_status_shows_blocks_of_rollouts_with_update_sizes_and_the_learning_rate(capsys, tmp_path):
    """Whole blocks end at the newest rollout; a setting changed inside a block shows as first -> last."""
    write_run(tmp_path, [HEADER, "1,10,0,0,100,20,1,0,0,"])
    rows = ["rollout,env_steps,episodes_ended,successes,restarted_episodes,restarted_successes,entropy,"
            "approx_kl,clip_fraction,lr,entropy_coef"]
    for r in range(1, 8):  # 7 rollouts: blocks of 3 are 1, 2-4, 5-7
        rows.append(f"{r},{4096 * r},{10 + r},{r},4,{r % 3},{1.0 - r / 100},{r / 1000},{r / 100},"
                    f"{1e-4 if r < 6 else 5e-5},{'' if r < 3 else 0.003}")
    (tmp_path / "rollouts.csv").write_text("\n".join(rows) + "\n")
    lines = status_lines(capsys, tmp_path, "--rollout-block", "3", "--blocks", "2")[-2:]
    df = pd.read_csv(tmp_path / "rollouts.csv")
    for line, part in zip(lines, (df.iloc[1:4], df.iloc[4:7])):
        wins, starts = part.successes.sum(), (part.episodes_ended - part.restarted_episodes).sum()
        rwins = part.restarted_successes.sum()
        assert line.startswith(f"rollouts {part.rollout.iloc[0]}-{part.rollout.iloc[-1]}: "
                               f"flag_get {wins}/{starts} ({wins / starts:.1%}) | restarted {rwins}/12 "
                               f"({rwins / 12:.1%}) | entropy {part.entropy.mean():.2f}, "
                               f"approx KL {part.approx_kl.mean():.4f}, clip fraction {part.clip_fraction.mean():.3f}")
    # rollouts 1-2 predate the entropy_coef column (empty): the first block shows the one value it has
    assert lines[0].endswith("| lr 0.0001, entropy weight 0.003")
    assert lines[1].endswith("| lr 0.0001 -> 5e-05, entropy weight 0.003")


def test_status_says_where_the_success_share_stop_rule_stands(capsys, tmp_path):
    """A run stopped by --stop-success-share: the flags of the last `window` counted episodes against it,
    and before the window is full, how many of it have been played."""
    from rlcore.files.checkpoint import save_checkpoint

    rows = [HEADER] + [f"{i},10,0,0,{100 * i},20,{int(i % 4 == 0)},0,0," for i in range(1, 31)]
    (tmp_path / "metrics.csv").write_text("\n".join(rows) + "\n")
    for successes, words in (([i % 4 == 0 for i in range(1, 31)], "now 5 of 20 (25%)"),
                             ([True] * 12, "12 of those 20 episodes so far")):
        save_checkpoint(tmp_path / "checkpoint.npz", {}, {}, {
            "experiment": "mario_ppo", "algo": "ppo", "preset": "default", "seed": 0, "env_steps": 3000,
            "config": {"window": 20, "stop_success_share": 0.9}, "returns": [10.0] * 30, "successes": successes,
            "wall_seconds": 60.0})
        lines = status_lines(capsys, tmp_path)
        assert lines[1] == f"stops once flag_get comes in 90% of the last 20 episodes from the start: {words}"
    save_checkpoint(tmp_path / "checkpoint.npz", {}, {}, {
        "experiment": "mario_ppo", "algo": "ppo", "preset": "default", "seed": 0, "env_steps": 3000,
        "config": {"window": 20, "stop_success_share": 0.0}, "returns": [10.0] * 30, "wall_seconds": 60.0})
    assert not any(line.startswith("stops once") for line in status_lines(capsys, tmp_path))

"""long_runs/queue.py: issue 49's trainings one at a time, each step read from the folders' state; its
Mario command is the recipe the docs give, and every command it gives parses."""
import importlib.util
import json
import shlex
import signal
from pathlib import Path

from rlcore.command_line import build_parser
from rlcore.sweep import Sweep

ROOT = Path(__file__).resolve().parents[1]
spec = importlib.util.spec_from_file_location("long_runs_queue", ROOT / "long_runs" / "queue.py")
queue = importlib.util.module_from_spec(spec)
spec.loader.exec_module(queue)


def _parses(command):
    args = build_parser(command).parse_args(command)
    assert args.command == command[0]
    return args


def _finish(folder: Path, **meta):
    (folder / "model").mkdir(parents=True, exist_ok=True)
    (folder / "model" / "meta.json").write_text(json.dumps(meta))


def test_the_queue_runs_the_minitaur_sweep_then_each_mario_seed_then_its_further_evaluation(tmp_path):
    sweep = tmp_path / queue.MINITAUR
    sweep.mkdir(parents=True)
    Sweep("minitaur", "sac", "minitaur__sac", str(sweep), [0, 1]).save()
    _finish(sweep / "seed=0", evaluation={"mean": 18.6})
    steps = [queue.next_command(tmp_path)]
    assert steps[-1][:3] == ["sweep", "minitaur", "sac"] and "--resume" in steps[-1]
    _finish(sweep / "seed=1")  # trained, not evaluated: the sweep's resume evaluates it
    assert queue.next_command(tmp_path) == steps[-1]
    _finish(sweep / "seed=1", evaluation={"mean": 20.8})  # every trial evaluated: on to Mario, kept or not
    steps.append(queue.next_command(tmp_path))
    assert steps[-1][:3] == ["train", "mario_ppo", "ppo"] and steps[-1][steps[-1].index("--seed") + 1] == "0"
    seed0 = tmp_path / queue.mario_dir(0)
    seed0.mkdir(parents=True)
    (seed0 / "checkpoint.npz").write_bytes(b"")  # stopped at a checkpoint: the plain resume, nothing else
    steps.append(queue.next_command(tmp_path))
    assert steps[-1] == ["train", "mario_ppo", "ppo", "--resume", queue.mario_dir(0), "--wandb", "offline",
                         "--no-progress"]
    _finish(seed0)  # trained, but ended before its 10-episode evaluation: that evaluation, recorded
    steps.append(queue.next_command(tmp_path))
    assert steps[-1] == ["evaluate", "mario_ppo", "ppo", "--model", queue.mario_dir(0), "--record"]
    _finish(seed0, evaluation={"episodes": 10})
    steps.append(queue.next_command(tmp_path))
    assert steps[-1][:2] == ["evaluate", "mario_ppo"] and "--record-further" in steps[-1]
    _finish(seed0, evaluation={"episodes": 10}, further_evaluations=[{"episodes": 30}])
    steps.append(queue.next_command(tmp_path))
    assert steps[-1][steps[-1].index("--seed") + 1] == "1"
    for seed in queue.MARIO_SEEDS:
        _finish(tmp_path / queue.mario_dir(seed), evaluation={"episodes": 10}, further_evaluations=[{"episodes": 30}])
    assert queue.next_command(tmp_path) is None
    (tmp_path / queue.MARIO_KEPT).mkdir(parents=True)
    assert queue.next_command(tmp_path) is None
    for command in steps:
        _parses(command)


def test_the_queues_mario_command_is_the_recipe_the_docs_give(tmp_path):
    command = queue.next_command(tmp_path)  # nothing there yet: seed 0's first run
    documented = (ROOT / "long_runs" / "README.md").read_text()
    line = "python main.py train mario_ppo ppo --world 1 --stage 1 --seed S --stop-success-share 0.9 --precision bfloat16"
    assert line in documented.replace("\\\n    ", "")
    given = _parses(command)
    expected = _parses(shlex.split(line.replace("S", "0"))[2:] + ["--run-dir", queue.mario_dir(0)] + queue.QUIET)
    assert vars(given) == vars(expected)


def test_a_sweep_with_a_grid_is_waited_for_by_its_trials_names(tmp_path):
    sweep = tmp_path / queue.MINITAUR
    sweep.mkdir(parents=True)
    Sweep("minitaur", "sac", "minitaur__sac", str(sweep), [0], {"lr": [1e-3, 3e-4]}).save()
    _finish(sweep / "seed=0", evaluation={"mean": 1.0})  # not a trial of this sweep: its trials are lr=...__seed=0
    assert queue.next_command(tmp_path)[0] == "sweep"
    for name in ("lr=0.001__seed=0", "lr=0.0003__seed=0"):
        _finish(sweep / name, evaluation={"mean": 1.0})
    assert queue.next_command(tmp_path)[0] == "train"


def test_a_step_that_ends_well_but_changes_nothing_stops_the_queue(monkeypatch, capsys):
    """A sweep whose trial keeps failing exits 0 and leaves it unfinished: the queue would run it forever."""
    calls = []
    monkeypatch.setattr(queue, "next_command", lambda: ["sweep", "x", "--resume"])
    monkeypatch.setattr(queue.subprocess, "call", lambda argv, cwd: calls.append(argv) or 0)
    assert queue.main([]) == 1 and len(calls) == 1
    assert "left the folders as they were" in capsys.readouterr().out


def test_a_step_that_stops_or_fails_ends_the_queue_with_its_status(monkeypatch, capsys):
    before = {number: signal.getsignal(number) for number in (signal.SIGINT, signal.SIGTERM)}
    ran = []
    monkeypatch.setattr(queue, "next_command", lambda: ["train", "x"])
    monkeypatch.setattr(queue.subprocess, "call", lambda argv, cwd: ran.append(argv) or 130)  # stopped at a checkpoint
    assert queue.main([]) == 130 and len(ran) == 1
    assert "queue: stopped, exit status 130" in capsys.readouterr().out
    steps = iter([["evaluate", "x"], None])
    monkeypatch.setattr(queue, "next_command", lambda: next(steps))
    monkeypatch.setattr(queue.subprocess, "call", lambda argv, cwd: 0)
    assert queue.main([]) == 0 and "queue: nothing left to run" in capsys.readouterr().out
    assert {number: signal.getsignal(number) for number in before} == before  # the caller's handlers are back

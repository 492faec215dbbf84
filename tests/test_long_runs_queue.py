"""long_runs/queue.py: issue 63's trainings one at a time, each step read from the folders' state; every
level's command is the flag preset's recipe, and every command it gives parses."""
import importlib.util
import json
import signal
from pathlib import Path

from rlcore.cli.parser import build_parser

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


def test_the_queue_trains_each_run_in_order_resumes_it_then_evaluates_it_on_30_further_seeds(tmp_path):
    steps = [queue.next_command(tmp_path)]
    assert steps[-1] == queue.train_command("1-1", "1-1", [])
    first = tmp_path / queue.run_dir("1-1")
    first.mkdir(parents=True)
    (first / "checkpoint.npz").write_bytes(b"")  # stopped at a checkpoint: the plain resume, nothing else
    steps.append(queue.next_command(tmp_path))
    assert steps[-1] == ["train", "mario_ppo", "ppo", "--resume", queue.run_dir("1-1"), "--wandb", "offline",
                         "--no-progress"]
    _finish(first)  # trained, but ended before its evaluation: that evaluation, recorded
    steps.append(queue.next_command(tmp_path))
    assert steps[-1] == ["evaluate", "mario_ppo", "ppo", "--model", queue.run_dir("1-1"), "--episodes", "30",
                         "--record"]
    _finish(first, evaluation={"episodes": 30})
    steps.append(queue.next_command(tmp_path))
    assert steps[-1][:2] == ["evaluate", "mario_ppo"] and "--record-further" in steps[-1]
    _finish(first, evaluation={"episodes": 30}, further_evaluations=[{"episodes": 30}])
    steps.append(queue.next_command(tmp_path))  # the lever run: the same recipe with 4 epochs, stopped at 0.9
    assert steps[-1] == queue.train_command("1-1-epochs-4", "1-1", ["--epochs", "4", "--stop-success-share", "0.9"])
    for name, _, _ in queue.RUNS:
        _finish(tmp_path / queue.run_dir(name), evaluation={"episodes": 30}, further_evaluations=[{"episodes": 30}])
    assert queue.next_command(tmp_path) is None
    for command in steps:
        _parses(command)


def test_a_lever_run_trains_once_its_baselines_stop_is_known_and_the_baseline_then_resumes(tmp_path):
    """1-1 still training: while its flag share from the start stays below 0.9 it resumes; once it has reached 0.9
    (here at env step 11,000) the lever run's stop is fixed (1.5x that), so the lever trains, to its end and its
    evaluations, and then 1-1 resumes with the plain resume command."""
    baseline = tmp_path / queue.run_dir("1-1")
    baseline.mkdir(parents=True)
    (baseline / "checkpoint.npz").write_bytes(b"")
    rows = [f"{i},{int(i > 20)},{100 * i},0" for i in range(1, 121)]  # the last 100's share: 0.9 first at episode 110

    def episodes(count):
        (baseline / "metrics.csv").write_text("episode,success,env_steps,restarted\n" + "\n".join(rows[:count]) + "\n")
        return queue.next_command(tmp_path)

    def resume(name):
        return ["train", "mario_ppo", "ppo", "--resume", queue.run_dir(name), "--wandb", "offline", "--no-progress"]

    assert episodes(109) == resume("1-1")  # 0.89 at the most
    lever = queue.train_command("1-1-epochs-4", "1-1", ["--epochs", "4", "--stop-success-share", "0.9", "--steps", "16500"])
    assert episodes(110) == episodes(120) == lever
    assert [name for name, _, _ in queue.training_order(tmp_path)][:3] == ["1-1-epochs-4", "1-1", "2-1"]
    (tmp_path / queue.run_dir("1-1-epochs-4")).mkdir(parents=True)
    (tmp_path / queue.run_dir("1-1-epochs-4") / "checkpoint.npz").write_bytes(b"")
    assert queue.next_command(tmp_path) == resume("1-1-epochs-4")
    _finish(tmp_path / queue.run_dir("1-1-epochs-4"), evaluation={"episodes": 30}, further_evaluations=[{"episodes": 30}])
    assert queue.next_command(tmp_path) == resume("1-1")
    _parses(lever)
    _finish(baseline)  # a finished baseline keeps its place: its evaluation comes before any later run
    assert [name for name, _, _ in queue.training_order(tmp_path)] == [name for name, _, _ in queue.RUNS]


def test_the_later_levels_take_4_epochs_only_when_both_lever_runs_reached_0_9_for_fewer_cpu_seconds(tmp_path):
    """The baselines reached the flag share 0.9 at env step 11,000; 4 epochs are 1.23x (1-1) and 1.30x (2-1) faster
    per env step, so a lever run that reached it before 13,530 (1-1) or 14,300 (2-1) env steps was cheaper."""
    def run(name, first_flag_episode, finished=True):
        folder = tmp_path / queue.run_dir(name)
        folder.mkdir(parents=True, exist_ok=True)
        rows = [f"{i},{int(i > first_flag_episode)},{100 * i},0" for i in range(1, 201)]
        (folder / "metrics.csv").write_text("episode,success,env_steps,restarted\n" + "\n".join(rows) + "\n")
        (folder / "checkpoint.npz").write_bytes(b"")
        if finished:
            _finish(folder, evaluation={"episodes": 30}, further_evaluations=[{"episodes": 30}])

    run("1-1", 20)
    run("2-1", 20)  # both baselines: 0.9 first at episode 110, env step 11,000
    run("1-1-epochs-4", 44)  # 0.9 at 13,400: cheaper on 1-1
    run("2-1-epochs-4", 54, finished=False)  # 14,400, and still training
    assert queue.adopted("1-2", tmp_path) == [] and queue.next_command(tmp_path)[3] == "--resume"
    run("2-1-epochs-4", 54)
    assert not queue.levers_cheaper(tmp_path)  # 14,400 > 1.30 x 11,000 on 2-1
    assert queue.next_command(tmp_path) == queue.train_command("1-2", "1-2", [])
    run("2-1-epochs-4", 52)  # 14,200
    assert queue.levers_cheaper(tmp_path) and queue.adopted("1-2", tmp_path) == ["--epochs", "4"]
    assert queue.adopted("1-1", tmp_path) == queue.adopted("2-1", tmp_path) == []
    command = queue.next_command(tmp_path)
    assert command == queue.train_command("1-2", "1-2", ["--epochs", "4"]) and _parses(command).hp_epochs == 4
    run("1-1-epochs-4", 200)  # never reached 0.9: not cheaper
    assert queue.next_command(tmp_path) == queue.train_command("1-2", "1-2", [])


def test_every_level_has_one_run_of_the_recipe_and_only_levers_add_to_it():
    levels = [level for name, level, extra in queue.RUNS if not extra]
    assert sorted(levels) == sorted(queue.LEVELS) == sorted(set(levels))
    for name, level, extra in queue.RUNS:
        args = _parses(queue.train_command(name, level, extra))
        assert (args.preset, f"{args.hp_world}-{args.hp_stage}", args.final_eval_episodes) == ("flag", level, 30)
        assert extra in ([], ["--epochs", "4"])


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


def test_the_readme_gives_the_queues_command():
    documented = (ROOT / "long_runs" / "README.md").read_text().replace("\\\n    ", "")
    line = next(line for line in documented.splitlines() if line.startswith("python main.py train mario_ppo ppo --preset flag"))
    for level in queue.LEVELS:
        world, stage = level.split("-")
        given = line.replace("--world W --stage S", f"--world {world} --stage {stage}").replace("W-S", level)
        assert vars(_parses(given.split()[2:])) == vars(_parses(queue.train_command(level, level, [])))


def test_status_says_where_each_run_stands(tmp_path):
    lines = {name: queue.run_status(name, tmp_path) for name, _, _ in queue.RUNS}
    assert set(lines.values()) == {f"{name}: queued" for name in lines}
    run = tmp_path / queue.run_dir("1-1")
    run.mkdir(parents=True)
    (run / "checkpoint.npz").write_bytes(b"")
    (run / "metrics.csv").write_text("episode,success,env_steps,restarted\n1,1,100,0\n2,0,200,1\n3,0,300,0\n")
    assert queue.run_status("1-1", tmp_path) == ("1-1: in progress (a checkpoint kept); 300 env steps, 3 episodes, flag in 1 of "
                                                 "the last 2 from the start")
    _finish(run, env_steps=5000, stopped_by="stop_success_share 0.95",
            evaluation={"success_share": 0.9, "episodes": 30}, further_evaluations=[{"success_share": 1.0, "episodes": 30}])
    assert queue.run_status("1-1", tmp_path) == ("1-1: finished at 5,000 env steps (stop_success_share 0.95); flag on "
                                                 "unseen seeds: 27 of 30, 30 of 30")


def test_a_shipped_level_is_done_and_read_from_its_model_folder(tmp_path):
    """Once published, a level's run lives in saved_networks/ and its long_runs folder is deleted: the queue moves
    on, says where it went and draws its curve from there; a hand-steered model shipped there is not the run."""
    target = tmp_path / "saved_networks" / "mario_ppo" / "1-1"
    target.mkdir(parents=True)
    (target / "meta.json").write_text(json.dumps({"preset": "default", "env_steps": 7}))
    assert queue.shipped("1-1", tmp_path) is None and queue.next_command(tmp_path) == queue.train_command("1-1", "1-1", [])
    (target / "meta.json").write_text(json.dumps({"preset": "flag", "env_steps": 7, "stopped_by": "stop_success_share 0.95",
                                                  "evaluation": {"success_share": 0.9, "episodes": 30}}))
    (target / "metrics.csv").write_text("episode,success,env_steps,restarted\n" + "".join(
        f"{i},1,{100 * i},0\n" for i in range(1, 101)))
    assert queue.shipped("1-1", tmp_path) == target and queue.shipped("1-1-epochs-4", tmp_path) is None
    assert queue.next_command(tmp_path) == queue.train_command("1-1-epochs-4", "1-1", [  # its baseline read there
        "--epochs", "4", "--stop-success-share", "0.9", "--steps", "15000"])
    assert queue.run_status("1-1", tmp_path) == ("1-1: shipped to saved_networks/mario_ppo/1-1, finished at 7 env steps "
                                                 "(stop_success_share 0.95); flag on unseen seeds: 27 of 30")
    queue.plot(tmp_path / "plot.png", tmp_path)
    assert (tmp_path / "plot.png").stat().st_size > 0


def test_the_flag_curve_counts_the_last_100_episodes_from_the_levels_start(tmp_path):
    """Restarted episodes (begun mid-level) stay out of the share, as out of the recipe's stop rule; the
    curve starts at the 100th episode from the start. The figure is written whole, beside no other file."""
    metrics = tmp_path / queue.run_dir("1-1") / "metrics.csv"
    metrics.parent.mkdir(parents=True)
    rows = ["episode,success,env_steps,restarted"]
    for i in range(1, 161):  # every 4th episode restarted; from the start, every other one reaches the flag
        rows.append(f"{i},{int(i % 2 == 0)},{i * 100},{int(i % 4 == 0)}")
    metrics.write_text("\n".join(rows) + "\n")
    steps, shares = queue.flag_curve(metrics)
    from_start = [i for i in range(1, 161) if i % 4]
    assert len(steps) == len(from_start) - 99 and steps[0] == from_start[99] * 100
    window = from_start[-100:]
    assert shares[-1] == sum(i % 2 == 0 for i in window) / 100
    queue.plot(tmp_path / "flag_share.png", folders=tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["flag_share.png", "long_runs"]


def test_a_lever_run_stops_at_the_share_0_9_or_at_1_5x_its_baselines_env_steps_to_it(tmp_path):
    """4 epochs are 1.23x faster per env step: a lever run that needs 1.5x its baseline's env steps to the same
    share cannot be cheaper, so it stops there; where the baseline never reached 0.9, at the baseline's env steps."""
    baseline = tmp_path / queue.run_dir("2-1")
    baseline.mkdir(parents=True)
    header = "episode,success,env_steps,restarted\n"
    rows = [f"{i},{int(i >= 20)},{1000 * i},0" for i in range(1, 121)]  # episodes 10-109: 90 flags
    (baseline / "metrics.csv").write_text(header + "\n".join(rows) + "\n")
    assert queue.lever_limits("2-1", tmp_path) == ["--stop-success-share", "0.9", "--steps", str(round(1.5 * 109_000))]
    rows = [f"{i},{int(i % 2)},{1000 * i},0" for i in range(1, 201)]  # never past 0.5
    (baseline / "metrics.csv").write_text(header + "\n".join(rows) + "\n")
    assert queue.lever_limits("2-1", tmp_path) == ["--stop-success-share", "0.9", "--steps", "200000"]
    args = _parses(queue.train_command("2-1-epochs-4", "2-1", ["--epochs", "4", *queue.lever_limits("2-1", tmp_path)]))
    assert (args.hp_epochs, args.hp_stop_success_share, args.steps) == (4, 0.9, 200_000)

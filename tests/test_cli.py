"""main.py end to end: commands, and every bad input giving one clear line and a non-zero exit."""
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import main
from rlcore.environments import registry
from tests import toy

ROOT = Path(__file__).resolve().parents[1]


def run(capsys, *argv):
    try:
        code = main.main(list(argv))
    except SystemExit as exc:  # argparse
        code = exc.code
    out, err = capsys.readouterr()
    return code, out, err


def status_lines(capsys, run_dir, *options) -> list[str]:
    """The lines `main.py status RUN_DIR OPTIONS` prints, once it has exited 0."""
    code, out, err = run(capsys, "status", str(run_dir), *options)
    assert code == 0, err
    return out.splitlines()


@pytest.fixture
def dqn_model_dir(tmp_path):
    """An untrained LunarLander DQN model folder, written as training writes one."""
    from rlcore.algorithms.dqn.agent import DQNAgent
    from rlcore.algorithms.dqn.config import DQNConfig

    folder = tmp_path / "model"
    DQNAgent(8, 4, DQNConfig()).save(folder)
    (folder / "meta.json").write_text(json.dumps({"experiment": "lunar_lander", "algo": "dqn"}))
    return folder


@pytest.mark.parametrize("argv, message", [
    (["train", "moon_lander", "dqn"], "unknown experiment 'moon_lander'"),
    (["train", "lunar_lander", "dqn3"], "unknown algorithm 'dqn3'"),
    (["train", "lunar_lander", "dqn", "--preset", "fastest"], "unknown preset 'fastest'"),
    (["train", "lunar_lander", "dqn", "--learning-rate", "1"],  # Stable-Baselines3's name, not --learning-starts
     "unrecognized arguments: --learning-rate 1; did you mean --lr? "),
    (["train", "cartpole", "a2c", "--n-envs", "4", "--total-timesteps", "9"],
     "unrecognized arguments: --n-envs 4 --total-timesteps 9; did you mean --num-envs, --steps? "),
    (["train", "lunar_lander", "dqn", "--env", "x"], "did you mean the positional EXPERIMENT? "),
    (["train", "lunar_lander", "dqn", "--gama", "0.9"],
     "unrecognized arguments: --gama 0.9; did you mean --gamma? (see `main.py train EXPERIMENT ALGO --help`)"),
    (["evaluate", "cartpole", "a2c", "--epi", "3"],  # no abbreviation is taken for a flag
     "unrecognized arguments: --epi 3; did you mean --episodes? (see `main.py evaluate --help`)"),
    (["train", "lunar_lander", "dqn", "--lr", "fast"], "invalid float value: 'fast'"),
    (["evaluate", "lunar_lander", "dqn", "--model", "/nonexistent/model"], "/nonexistent/model: no such model folder"),
    (["evaluate", "cartpole", "a2c", "--model", "saved_networks/cartpole/a2c/meta.json"],
     "saved_networks/cartpole/a2c/meta.json is a file; give the model folder that holds it (saved_networks/cartpole/a2c)"),
    (["evaluate", "cartpole", "a2c", "--model", "docs"], "docs has no meta.json: not a model folder of this package"),
    (["render", "lunar_lander", "sac"], "unknown algorithm 'sac'"),
    (["evaluate", "mario_ppo", "ppo", "--model", "/nonexistent/1-1"], "no such model folder"),
    (["plot", "/nonexistent/run"], "/nonexistent/run: no such folder; give a run folder such as runs/<name>"),
    (["status", "docs"], "no metrics.csv in docs; give a run folder"),
    (["evaluate", "mario_ppo", "ppo", "--world", "8", "--stage", "4"], "no shipped model for level 8-4 in "),
    (["evaluate", "CartPole-v1", "dqn"], "no shipped model CartPole-v1 dqn in "),
    (["render", "lunar_lander", "dqn", "--world", "1"], "--world chooses among the shipped models of mario_ppo; "
                                                        "lunar_lander ships one model per algorithm"),
    (["evaluate", "mario_ppo", "ppo", "--world", "1", "--model", "x"], "either --model or --world/--stage"),
    (["evaluate", "mario_ppo", "ppo", "--stage", "0"], "argument --stage: 0 is invalid: allowed is a whole number "
                                                       "from 1 to 4"),
    (["render", "mario_ppo", "ppo", "--world", "9"], "argument --world: 9 is invalid: allowed is a whole number "
                                                     "from 1 to 8"),
])
def test_bad_input_is_one_line_and_exit_2(capsys, argv, message):
    code, out, err = run(capsys, *argv)
    assert code == 2
    assert message in err
    assert len(err.strip().splitlines()) == 1, err
    assert "Traceback" not in err


def test_a_model_of_another_environment_is_refused(capsys, tmp_path):
    """A Minitaur SAC actor (28 inputs) in a folder claiming to be LunarLander A2C."""
    from rlcore.algorithms.sac.agent import build_actor
    from rlcore.networks.saving import save_keras_model

    save_keras_model(build_actor(28, 8, (8,)), tmp_path / "actor.h5")
    (tmp_path / "meta.json").write_text(json.dumps({"experiment": "lunar_lander", "algo": "a2c"}))
    code, _, err = run(capsys, "evaluate", "lunar_lander", "a2c", "--model", str(tmp_path))
    assert code == 2 and "it was trained for another environment" in err


def test_truncated_model_file(capsys, dqn_model_dir):
    h5 = dqn_model_dir / "q_network.h5"
    h5.write_bytes(h5.read_bytes()[:500])
    code, _, err = run(capsys, "evaluate", "lunar_lander", "dqn", "--model", str(dqn_model_dir))
    assert code == 2 and "is damaged or not a Keras .h5 model" in err


def test_model_of_another_algorithm(capsys, dqn_model_dir):
    code, _, err = run(capsys, "render", "lunar_lander", "a2c", "--model", str(dqn_model_dir))
    assert code == 2 and "is lunar_lander dqn, not lunar_lander a2c" in err


def test_model_with_the_wrong_shape(capsys, dqn_model_dir):
    from rlcore.algorithms.dqn.agent import DQNAgent
    from rlcore.algorithms.dqn.config import DQNConfig

    DQNAgent(4, 2, DQNConfig()).save(dqn_model_dir)  # a CartPole-shaped net in a LunarLander folder
    code, _, err = run(capsys, "evaluate", "lunar_lander", "dqn", "--model", str(dqn_model_dir))
    assert code == 2 and "takes input (4,)" in err


def test_render_failure_leaves_no_video(capsys, dqn_model_dir, tmp_path):
    (dqn_model_dir / "q_network.h5").write_bytes(b"not hdf5")
    out = tmp_path / "v.mp4"
    code, _, _ = run(capsys, "render", "lunar_lander", "dqn", "--model", str(dqn_model_dir), "--out", str(out))
    assert code == 2 and not out.exists()


def test_ctrl_c_mid_render_keeps_the_earlier_video_whole(capsys, dqn_model_dir, tmp_path, monkeypatch):
    """Frames are being written when Ctrl-C comes: the video from before stays, no temporary file is left."""
    from gymnasium.envs.box2d.lunar_lander import LunarLander

    out = tmp_path / "videos" / "v.mp4"
    out.parent.mkdir()
    out.write_bytes(b"an earlier, good video")
    step, steps = LunarLander.step, []

    def interrupted_step(self, action):
        steps.append(action)
        if len(steps) == 20:
            raise KeyboardInterrupt
        return step(self, action)

    monkeypatch.setattr(LunarLander, "step", interrupted_step)
    code, _, err = run(capsys, "render", "lunar_lander", "dqn", "--model", str(dqn_model_dir), "--out", str(out))
    assert code == 130 and len(steps) == 20, err
    assert out.read_bytes() == b"an earlier, good video"
    assert [p.name for p in out.parent.iterdir()] == ["v.mp4"]


def test_resume_with_a_checkpoint_of_another_algorithm(capsys, tmp_path, monkeypatch):
    from rlcore.algorithms.dqn import train as dqn_trainer

    monkeypatch.setitem(registry.EXPERIMENT_MODULES, "toy", "tests.toy")
    spec = toy.spec("dqn", tmp_path, max_episodes=2, stop_score=99.0)
    dqn_trainer.train(spec)
    code, _, err = run(capsys, "train", "toy", "a2c", "--resume", str(spec.run_dir), "--wandb", "off")
    assert code == 2 and "is from toy dqn, not toy a2c" in err


def test_nan_during_training_stops_with_a_clear_error(capsys, tmp_path, monkeypatch):
    monkeypatch.setitem(registry.EXPERIMENT_MODULES, "toy", "tests.toy")
    monkeypatch.setattr(toy.SignEnv, "step", lambda self, a: (self._obs(), np.nan, False, False, {}))
    code, _, err = run(capsys, "train", "toy", "dqn", "--wandb", "off", "--no-progress",
                       "--run-dir", str(tmp_path / "run"), "--episodes", "3")
    assert code == 2 and "training diverged" in err


def test_wandb_online_without_network_fails_fast(capsys, tmp_path, monkeypatch):
    monkeypatch.setitem(registry.EXPERIMENT_MODULES, "toy", "tests.toy")
    monkeypatch.setenv("WANDB_API_KEY", "a" * 40)
    monkeypatch.setenv("WANDB_INIT_TIMEOUT", "5")
    monkeypatch.setenv("WANDB_BASE_URL", "http://127.0.0.1:9")  # nothing listens: as with no network
    started = time.monotonic()
    code, _, err = run(capsys, "train", "toy", "dqn", "--wandb", "online", "--no-progress",
                       "--run-dir", str(tmp_path / "run"), "--episodes", "2")
    assert code == 2 and "wandb could not start in online mode" in err
    assert time.monotonic() - started < 25  # within the 5 s asked for (plus start-up), not wandb's own 90 s


def test_list_and_help(capsys):
    code, out, _ = run(capsys, "list")
    assert code == 0
    for algo in ("dqn", "ddqn", "dueling_dqn", "dueling_ddqn", "a2c"):
        assert f"  {algo} " in out
    code, out, _ = run(capsys, "train", "lunar_lander", "dueling_ddqn", "--help")
    assert code == 0 and "--tau FLOAT" in out and "--updates-per-call" in out


def test_list_writes_each_shipped_score_as_the_readme_does(capsys):
    """`list` and the README's results table read the same meta.json: the same words and digits."""
    from tools.docgen.data import shipped_models
    from tools.docgen.main import score_text

    code, out, _ = run(capsys, "list")
    readme = (Path(main.__file__).parent / "README.md").read_text()
    models = [m for m in shipped_models() if m.evaluation]
    assert models
    for m in models:
        words = score_text(m)
        assert f"**{words}**" in readme
        shown = words.replace("±", "+-")
        assert (f"{m.name}: {shown} episodes" if "success_share" in m.evaluation else shown) in out, (m.slug, words)


def test_score_words_give_two_decimals_below_100_and_a_castles_axe():
    from rlcore.records.score_words import score_words

    assert score_words({"mean": 20.4512, "std": 3.987}, "minitaur", "sac") == "20.45 ± 3.99"
    assert score_words({"mean": 270.71, "std": 21.44}, "lunar_lander", "dqn", "+-") == "270.7 +- 21.4"
    assert score_words({"success_share": 0.8, "episodes": 10}, "mario_ppo", "1-4") == "axe in 8 of 10"
    assert score_words({"success_share": 0.5, "episodes": 30}, "mario_ppo", "1-1") == "flag in 15 of 30"


def test_the_evaluate_line_names_a_levels_success_from_the_models_meta():
    """`evaluate` on a castle says axe, as the README does: the level comes from the model's meta.json."""
    from rlcore.environments.registry import get_experiment
    from rlcore.models.shipping import model_name
    from rlcore.records.score_words import success_word

    mario = get_experiment("mario_ppo")
    assert model_name(mario, {"config": {"world": 2, "stage": 4}}) == "2-4"
    assert success_word("mario_ppo", model_name(mario, {"config": {"world": 2, "stage": 4}})) == "axe"
    assert success_word("mario_ppo", model_name(mario, {"config": {"world": 1, "stage": 2}})) == "flag"
    assert model_name(get_experiment("lunar_lander"), {"config": {"hidden": [64]}}) == ""
    assert model_name(mario, None) == ""


@pytest.mark.parametrize("argv", [[], *([name] for name in main.COMMANDS)])
def test_every_help_page_prints(capsys, argv):
    """`main.py --help` and each command's --help: exit 0 and a usage line, never a traceback."""
    code, out, _ = run(capsys, *argv, "--help")
    assert code == 0 and out.startswith("usage: main.py")
    if not argv:  # the top page names every command
        assert all(name in out for name in main.COMMANDS)


@pytest.mark.parametrize("signal_name", ["SIGINT"])
def test_ctrl_c_saves_a_checkpoint_and_resume_continues(tmp_path, signal_name, capsys):
    """A real SIGINT (Ctrl-C) to a real training process of the episode loop (DQN): exit 130, checkpoint
    written, resume continues. SIGTERM, and both signals to a whole process group with an env pool:
    tests/test_stop_signals.py (the same handler takes both)."""
    import signal
    import time

    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    run_dir = tmp_path / "run"
    cmd = [sys.executable, str(ROOT / "main.py"), "train", "lunar_lander", "dqn", "--wandb", "off",
           "--no-progress", "--run-dir", str(run_dir), "--final-eval-episodes", "0"]
    proc = subprocess.Popen(cmd, env=env, cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    deadline = time.time() + 120
    while not (run_dir / "metrics.csv").exists() or len((run_dir / "metrics.csv").read_text().splitlines()) < 4:
        assert time.time() < deadline and proc.poll() is None, proc.stderr.read() if proc.poll() else "slow"
        time.sleep(0.2)
    proc.send_signal(getattr(signal, signal_name))
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "checkpoint saved to" in err and "Traceback" not in err
    episodes_before = len((run_dir / "metrics.csv").read_text().splitlines()) - 1
    capsys.readouterr()
    # the resume in this process: nothing signals it; --wandb off and --final-eval-episodes 0 are the run's
    assert main.main(["train", "lunar_lander", "dqn", "--no-progress", "--resume", str(run_dir),
                      "--episodes", str(episodes_before + 3)]) == 0
    out = capsys.readouterr().out
    assert "evaluation (unseen seeds)" not in out and not (run_dir / "wandb").exists()
    assert "evaluation" not in json.loads((run_dir / "model" / "meta.json").read_text())
    assert f"resuming {run_dir} at episode {episodes_before}" in out
    assert "; changing max_episodes " in out and f" -> {episodes_before + 3:,}\n" in out  # what the resume changes
    rows = (run_dir / "metrics.csv").read_text().splitlines()[1:]
    assert [int(r.split(",")[0]) for r in rows] == list(range(1, episodes_before + 4))


def test_every_algorithm_builds_its_train_parser(capsys):
    """Hyperparameter flags must not collide with the CLI's own flags, for any preset."""
    from rlcore.environments.registry import experiment_names, get_experiment

    for name in experiment_names():
        for algo, spec in get_experiment(name).algos.items():
            for preset in spec.presets:
                parser = main.build_parser(["train", name, algo, "--preset", preset])
                args = parser.parse_args(["train", name, algo, "--preset", preset])
                assert args.algo == algo


@pytest.mark.parametrize("script", sorted(p.name for p in (ROOT / "benchmarks").glob("*.py") if p.name != "common.py"))
def test_benchmark_scripts_start(script):
    """Imports and --help only, for every script in benchmarks/: the measurements themselves are not tests."""
    done = subprocess.run([sys.executable, str(ROOT / "benchmarks" / script), "--help"], cwd=ROOT,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "JSON" in done.stdout


def test_shipped_models_are_found_from_any_working_directory(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, _ = run(capsys, "evaluate", "lunar_lander", "dqn", "--episodes", "2")
    assert code == 0 and "greedy return" in out
    from rlcore.environments.registry import get_experiment
    lander = get_experiment("lunar_lander")  # the task's number and ours, each named
    assert f"; the task's solved score {lander.solved_score:g}: " in out
    assert f"; the shipped model's bar ({lander.bar('dqn').describe()}): " in out
    assert f"met (on 2 episodes, where it is judged on {lander.eval_episodes})" in out  # met or not met, qualified
    code, out, _ = run(capsys, "list")
    assert code == 0 and "1-1: flag in" in out and "shipped: " in out


def test_evaluate_a_mario_level_by_world_and_stage(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, err = run(capsys, "evaluate", "mario_ppo", "ppo", "--world", "1", "--stage", "1",
                         "--episodes", "1")
    assert code == 0, err
    assert "saved_networks/mario_ppo/1-1): flag in " in out and " of 1 episodes (" in out


def test_evaluate_and_render_a_run_in_progress_and_a_finished_run_folder(capsys, tmp_path, monkeypatch):
    """--model RUN_DIR: a run without a model plays its last checkpoint (and --record is refused);
    a finished run's folder plays its model/."""
    from rlcore.algorithms.dqn import train as dqn_trainer
    from tests.rlcore.training.test_resume import _interrupt_after

    monkeypatch.setitem(registry.EXPERIMENT_MODULES, "toy", "tests.toy")
    spec = toy.spec("dqn", tmp_path, max_episodes=30, stop_score=99.0)
    _interrupt_after(12, dqn_trainer, spec)
    code, out, err = run(capsys, "evaluate", "toy", "dqn", "--model", str(spec.run_dir), "--episodes", "3")
    assert code == 0, err
    assert f"the last checkpoint of {spec.run_dir} (episode 12," in out and "last checkpoint): " in out
    code, _, err = run(capsys, "evaluate", "toy", "dqn", "--model", str(spec.run_dir), "--record")
    assert code == 2 and "is a run in progress" in err
    code, out, err = run(capsys, "render", "toy", "dqn", "--model", str(spec.run_dir), "--episodes", "1",
                         "--out", str(tmp_path / "in_progress.mp4"))
    assert code == 0 and (tmp_path / "in_progress.mp4").stat().st_size > 0, err
    spec.resume = True
    dqn_trainer.train(spec)  # finishes: model/ appears
    code, out, err = run(capsys, "evaluate", "toy", "dqn", "--model", str(spec.run_dir), "--episodes", "3")
    assert code == 0 and f"({spec.run_dir / 'model'}): " in out, err


def test_a_further_evaluation_plays_the_next_unseen_seeds_and_keeps_the_evaluation(capsys, tmp_path, monkeypatch):
    """evaluate --record-further: a held-out check added beside the model's evaluation, on seeds no
    recorded evaluation played; overlapping or seen seeds, both flags, a run in progress: one line each."""
    from rlcore.algorithms.dqn import train as dqn_trainer

    monkeypatch.setitem(registry.EXPERIMENT_MODULES, "toy", "tests.toy")
    spec = toy.spec("dqn", tmp_path, max_episodes=20, stop_score=99.0)
    dqn_trainer.train(spec)
    model = ["evaluate", "toy", "dqn", "--model", str(spec.run_dir)]
    code, _, err = run(capsys, *model, "--episodes", "5", "--record")
    assert code == 0, err
    meta_path = spec.run_dir / "model" / "meta.json"
    evaluation = json.loads(meta_path.read_text())["evaluation"]
    assert evaluation["seeds"] == "10000..10004"
    for seeds in ("10005..10007", "10008..10010"):
        code, out, err = run(capsys, *model, "--episodes", "3", "--record-further")
        assert code == 0 and "further evaluation (unseen seeds): greedy return" in out, err
    meta = json.loads(meta_path.read_text())
    assert meta["evaluation"] == evaluation
    assert [ev["seeds"] for ev in meta["further_evaluations"]] == ["10005..10007", "10008..10010"]
    assert all(len(ev["per_episode"]) == 3 and "machine" in ev for ev in meta["further_evaluations"])
    for argv, message in (
            (["--record-further", "--seed-base", "10002"], "seeds 10002..10004 overlap those of an evaluation "
                                                           "already recorded (10000..10004)"),
            (["--record-further", "--seed-base", "10006"], "seeds 10006..10008 overlap those of an evaluation "
                                                           "already recorded (10005..10007)"),
            (["--record-further", "--seed-base", "5"], "plays seeds 5..7, outside toy's unseen range 10000..1999999"),
            (["--record-further", "--record"], "give --record (the model's evaluation) or --record-further"),
            # a new evaluation over the further ones' seeds would leave them no longer held out
            (["--record", "--replace", "--episodes", "20"], "seeds 10000..10019 overlap those of a further "
                                                            "evaluation already recorded (10005..10007)"),
            # the recorded evaluation is not overwritten by a smaller try unless asked
            (["--record"], "meta.json records an evaluation already (" + f"{evaluation['mean']:.2f} +- "
                           f"{evaluation['std']:.2f}, 5 episodes on seeds 10000..10004); --record-further adds one "
                           "on other unseen seeds, --replace overwrites it"),
            (["--replace"], "--replace goes with --record")):
        code, _, err = run(capsys, *model, "--episodes", "3", *argv)
        assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err
    assert json.loads(meta_path.read_text()) == meta  # nothing written by a refused command
    shutil.rmtree(spec.run_dir / "model")  # a run in progress (a checkpoint, no model): nothing to record into
    code, _, err = run(capsys, *model, "--record-further")
    assert code == 2 and "--record-further writes into a model folder" in err and "is a run in progress" in err


def test_the_flags_that_choose_a_shipped_model_come_from_the_registry(capsys, monkeypatch, tmp_path):
    """An experiment that ships one model per value of a config field (Mario: world, stage) gets that
    field as a flag of evaluate/render/export, parsed and checked as the field is; nothing names Mario."""
    import dataclasses
    import types

    from rlcore.cli.parser import shipped_by_options
    from rlcore.environments.experiment import ShippedBy

    module = types.ModuleType("tests.toy_sized")
    module.EXPERIMENT = dataclasses.replace(toy.EXPERIMENT, name="toy_sized",
                                            shipped_by=ShippedBy(fields=("batch_size",), default="32", noun="size"))
    monkeypatch.setitem(sys.modules, "tests.toy_sized", module)
    monkeypatch.setitem(registry.EXPERIMENT_MODULES, "toy_sized", "tests.toy_sized")
    monkeypatch.setitem(registry.EXPERIMENT_MODULES, "toy", "tests.toy")
    monkeypatch.setenv("DEEPRL_MODELS", str(tmp_path))
    shipped_by_options.cache_clear()
    try:
        code, out, _ = run(capsys, "evaluate", "--help")
        assert code == 0 and "toy_sized: the shipped model of this batch_size (default 32)" in " ".join(out.split())
        code, _, err = run(capsys, "evaluate", "toy_sized", "dqn", "--batch-size", "64")
        assert code == 2 and f"no shipped model for size 64 in {tmp_path / 'toy_sized'}" in err
        code, _, err = run(capsys, "render", "toy_sized", "dqn", "--batch-size", "0")
        assert code == 2 and "argument --batch-size: 0 is invalid" in err
        code, _, err = run(capsys, "evaluate", "toy", "dqn", "--batch-size", "64")
        assert code == 2 and "--batch-size chooses among the shipped models of toy_sized; toy ships one model per algorithm" in err
        code, _, err = run(capsys, "evaluate", "toy_sized", "dqn", "--world", "2")
        assert code == 2 and ("--world chooses among the shipped models of mario_ppo; toy_sized ships one model "
                              "per size (--batch-size)") in err
    finally:
        shipped_by_options.cache_clear()


def test_a_shipped_by_folder_fills_the_values_not_given_from_its_default():
    from rlcore.environments.experiment import ShippedBy

    by = ShippedBy(fields=("world", "stage"), default="1-1", noun="level")
    assert by.default_values() == {"world": "1", "stage": "1"}
    assert [by.folder_from(given) for given in ({"world": 2}, {"stage": 4}, {"world": 8, "stage": 3}, {})] == [
        "2-1", "1-4", "8-3", "1-1"]


def test_the_installed_script_is_deeprl_and_says_its_version():
    """`pip install` puts the `deeprl` script and the packages in site-packages, no top-level `main`."""
    from importlib.metadata import distribution

    dist = distribution("deeprl-tf2")
    scripts = {e.name: e.value for e in dist.entry_points if e.group == "console_scripts"}
    assert scripts == {"deeprl": "rlcore.cli.main:main"}
    script = Path(sys.executable).parent / "deeprl"
    done = subprocess.run([str(script), "--version"], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and done.stdout.strip() == f"deeprl {dist.version}"
    helped = subprocess.run([str(script), "train", "--help"], capture_output=True, text=True, timeout=60)
    assert helped.stdout.startswith("usage: deeprl train") and "mario_ppo: ppo" in helped.stdout


def test_marios_help_lists_its_level_and_its_research_knobs_apart(capsys):
    code, out, _ = run(capsys, "train", "mario_ppo", "ppo", "--help")
    assert code == 0
    main_part, _, rest = out.partition("\nhyperparameters (")[2].partition("\nthe level and its env")
    level_part, _, knobs = rest.partition("\nrestarts, a training curriculum")
    assert "--lr FLOAT" in main_part and "--restart-x" not in main_part and "--world" not in main_part
    assert "--world INT" in level_part and "--frames" in level_part
    assert all(f"--restart-{name}" in knobs for name in ("x", "every", "share", "back-step", "goal-x"))

"""Every bad value is one line naming the flag, exit 2, no run folder, no traceback; and the rough
edges of a first day: seeds apart from evaluation, no silent flags, a quiet console, wandb axes,
publishing that replaces a folder whole."""
import dataclasses
import os
import subprocess
import sys
from pathlib import Path

import pytest

from rlcore.environments.registry import experiment_names, get_experiment
from rlcore.environments.seeding import MAX_EVAL_EPISODES, MAX_RUN_SEED, TRAINING_SEED_SPAN, training_env_seed
from tests.test_cli import ROOT, run

BAD_VALUES = [
    # sizes, widths, counts and budgets
    (["train", "lunar_lander", "dqn", "--hidden", "0"], "--hidden 0 is invalid"),
    (["train", "lunar_lander", "dqn", "--hidden", ","], "--hidden (empty) is invalid"),
    (["train", "cartpole", "a2c", "--num-envs", "0"], "--num-envs 0 is invalid"),
    (["train", "lunar_lander", "dqn", "--batch-size", "0"], "--batch-size 0 is invalid"),
    (["train", "lunar_lander", "dqn", "--batch-size", "512", "--buffer-size", "100"],
     "--batch-size 512 is invalid: it must not exceed --buffer-size 100"),
    (["train", "lunar_lander", "dqn", "--window", "-3"], "--window -3 is invalid"),
    (["train", "lunar_lander", "dqn", "--episodes", "-3"], "argument --episodes: -3 is invalid"),
    (["train", "lunar_lander", "dqn", "--steps", "0"], "argument --steps: 0 is invalid"),
    (["train", "lunar_lander", "dqn", "--final-eval-episodes", "-1"], "argument --final-eval-episodes: -1"),
    (["train", "minitaur", "sac", "--learning-starts", "-5"], "--learning-starts -5 is invalid"),
    (["train", "minitaur", "sac", "--buffer-size", "5000"],
     "--learning-starts 10000 is invalid: it must not exceed --buffer-size 5000"),
    (["train", "lunar_lander", "dqn", "--learning-starts", "200000", "--buffer-size", "100000"],
     "--learning-starts 200000 is invalid: it must not exceed --buffer-size 100000"),
    # probabilities, discount, tau, lambda, clip
    (["train", "lunar_lander", "dqn", "--gamma", "1.5"], "--gamma 1.5 is invalid: allowed is a number from 0 to 1"),
    (["train", "lunar_lander", "dqn", "--tau", "0"], "--tau 0 is invalid: allowed is a number above 0 and at most 1"),
    (["train", "lunar_lander", "dqn", "--eps-end", "-0.1"], "--eps-end -0.1 is invalid"),
    (["train", "mario_ppo", "ppo", "--gae-lambda", "1.2"], "--gae-lambda 1.2 is invalid"),
    (["train", "mario_ppo", "ppo", "--clip", "1"], "--clip 1 is invalid"),
    (["train", "mario_ppo", "ppo", "--stop-success-share", "2"], "--stop-success-share 2 is invalid"),
    # learning rates positive and finite
    (["train", "lunar_lander", "dqn", "--lr", "nan"], "--lr nan is invalid: allowed is a finite number above 0"),
    (["train", "lunar_lander", "a2c", "--actor-lr", "inf"], "--actor-lr inf is invalid"),
    (["train", "minitaur", "sac", "--alpha-lr", "0"], "--alpha-lr 0 is invalid"),
    (["train", "lunar_lander", "dqn", "--stop-score", "nan"], "--stop-score nan is invalid"),
    # choices
    (["train", "lunar_lander", "dqn", "--optimizer", "sgd"], "--optimizer sgd is invalid: allowed is one of adam, adamw"),
    (["train", "cartpole", "a2c", "--vec", "threads"], "--vec threads is invalid"),
    (["train", "mario_ppo", "ppo", "--actions", "fancy"], "--actions fancy is invalid"),
    (["train", "mario_ppo", "ppo", "--world", "9"], "--world 9 is invalid: allowed is a whole number from 1 to 8"),
    # the minibatch divides the rollout; SAC's log-std clip is an interval
    (["train", "mario_ppo", "ppo", "--minibatch", "300"], "--minibatch 300 is invalid: it must divide the rollout"),
    (["train", "minitaur", "sac", "--log-std-min", "3"], "--log-std-min 3 is invalid: it must be below --log-std-max 2"),
    # PPO's start from another model: a wrong folder is refused before any env process starts
    (["train", "mario_ppo", "ppo", "--init-from", "/nonexistent"], "--init-from: /nonexistent: no such model folder"),
    (["train", "mario_ppo", "ppo", "--init-from", "saved_networks/lunar_lander/dqn"],
     "--init-from saved_networks/lunar_lander/dqn holds a lunar_lander dqn model, not mario_ppo ppo"),
    # seeds, and evaluate / render counts
    (["train", "lunar_lander", "dqn", "--seed", "-1"], "argument --seed: -1 is invalid"),
    (["train", "lunar_lander", "dqn", "--seed", str(MAX_RUN_SEED + 1)], "argument --seed:"),
    (["evaluate", "lunar_lander", "dqn", "--episodes", "0"], "argument --episodes: 0 is invalid"),
    (["evaluate", "lunar_lander", "dqn", "--episodes", "-2"], "argument --episodes: -2 is invalid"),
    (["evaluate", "lunar_lander", "dqn", "--seed-base", "-1"], "argument --seed-base: -1 is invalid"),
    (["render", "lunar_lander", "dqn", "--fps", "0"], "argument --fps: 0 is invalid"),
    (["render", "lunar_lander", "dqn", "--episodes", "0"], "argument --episodes: 0 is invalid"),
    # one unseen seed per evaluation episode: no more episodes than that range holds
    (["evaluate", "lunar_lander", "dqn", "--episodes", "1000001"], "argument --episodes: 1000001 is invalid: "
                                                                   "allowed is a whole number from 1 to 1000000"),
    (["render", "lunar_lander", "dqn", "--episodes", str(10**20)], "argument --episodes: "),
    (["train", "lunar_lander", "dqn", "--final-eval-episodes", "2000000"], "argument --final-eval-episodes: "
                                                                          "2000000 is invalid"),
    (["render", "lunar_lander", "dqn", "--seed", "x"], "argument --seed: 'x' is not a whole number"),
    (["train", "minitaur", "sac", "--obs-norm", "maybe"], "argument --obs-norm: 'maybe' is invalid: allowed is true or false"),
    # PPO offers no flag it would ignore
    (["train", "mario_ppo", "ppo", "--keep-best", "true"], "unrecognized arguments: --keep-best"),
    (["train", "mario_ppo", "ppo", "--eval-every-steps", "1000"], "unrecognized arguments: --eval-every-steps"),
    (["train", "mario_ppo", "ppo", "--stop-eval-score", "1"], "unrecognized arguments: --stop-eval-score"),
    (["train", "mario_ppo", "ppo", "--checkpoint-every", "5"], "unrecognized arguments: --checkpoint-every"),
    (["train", "mario_ppo", "ppo", "--target-kl", "-0.1"], "--target-kl -0.1 is invalid"),
    # nor does A2C: its update has no minibatches for a KL guard to stop
    (["train", "cartpole", "a2c", "--target-kl", "0.1"], "unrecognized arguments: --target-kl"),
]


@pytest.mark.parametrize("argv, message", BAD_VALUES)
def test_a_bad_value_is_one_line_exit_2_and_no_run_folder(capsys, tmp_path, argv, message):
    run_dir = tmp_path / "run"
    extra = ["--run-dir", str(run_dir), "--wandb", "off"] if argv[0] == "train" else []
    code, out, err = run(capsys, *argv, *extra)
    assert code == 2, (out, err)
    assert message in err, err
    assert len(err.strip().splitlines()) == 1, err
    assert "Traceback" not in err
    assert not run_dir.exists()


@pytest.mark.parametrize("drop, argv, message", [
    ("actor_critic.h5", [], "--init-from {m} has a meta.json but no actor_critic.h5"),
    (None, ["--actions", "complex"], "--init-from: model {m}/actor_critic.h5 outputs (7,), expected (12,)"),
])
def test_init_from_a_model_that_does_not_fit_is_one_line_and_no_run_folder(tmp_path, drop, argv, message):
    """A model folder with a good meta.json whose network is missing or fits another action set: one
    line, exit 2, the env processes closed without a word of theirs, and no run folder left behind."""
    import shutil

    model, run_dir = tmp_path / "model", tmp_path / "run"
    shutil.copytree(ROOT / "saved_networks/mario_ppo/1-1", model)
    if drop:
        (model / drop).unlink()
    proc = subprocess.run([sys.executable, "main.py", "train", "mario_ppo", "ppo", "--init-from", str(model), *argv,
                           "--num-envs", "2", "--vec", "processes", "--steps", "100", "--run-dir", str(run_dir),
                           "--wandb", "off", "--no-progress"], cwd=ROOT, capture_output=True, text=True, timeout=300)
    err = proc.stderr.strip()
    assert proc.returncode == 2 and message.format(m=model) in err, err
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert not run_dir.exists()


UNWRITABLE = [  # BLOCK is a file, so nothing can be written "inside" it (as root too)
    (["train", "cartpole", "dqn", "--episodes", "1", "--wandb", "off", "--run-dir", "BLOCK/run"], "run folder"),
    (["render", "lunar_lander", "dqn", "--out", "BLOCK/demo.mp4"], "--out"),
    (["plot", "RUN", "--out", "BLOCK/plots"], "--out"),
]


@pytest.mark.parametrize("argv, what", UNWRITABLE)
def test_an_unwritable_output_place_is_one_line_exit_2(capsys, tmp_path, argv, what):
    block = tmp_path / "block"
    block.write_text("a file, not a folder")
    run_dir = tmp_path / "run"
    (run_dir).mkdir()
    (run_dir / "metrics.csv").write_text("episode,total_points\n1,2.0\n")
    (run_dir / "model").mkdir()
    (run_dir / "model" / "meta.json").write_text('{"experiment": "toy", "algo": "dqn"}')
    argv = [a.replace("BLOCK", str(block)).replace("RUN", str(run_dir)) for a in argv]
    code, out, err = run(capsys, *argv)
    assert code == 2, (out, err)
    # "BLOCK/x: cannot write there (Not a directory)", or where the folder asked for is BLOCK itself (render's
    # --out BLOCK/demo.mp4): "BLOCK is a file, not a folder"
    assert f"{what} {block}" in err and ("cannot write there" in err or f"{block} is a file, not a folder" in err), err
    assert len(err.strip().splitlines()) == 1 and block.read_text() == "a file, not a folder"


IS_A_FILE = [  # BLOCK itself is a file where a folder is asked for: said so, before anything is printed
    (["train", "cartpole", "dqn", "--episodes", "1", "--wandb", "off", "--run-dir", "BLOCK"],
     "--run-dir BLOCK is a file, not a folder"),
    (["plot", "RUN", "--out", "BLOCK"], "--out BLOCK is a file, not a folder"),
    (["status", "BLOCK"], "BLOCK: is a file; give a run folder such as runs/<name>"),
]


@pytest.mark.parametrize("argv, message", IS_A_FILE)
def test_a_file_where_a_folder_is_asked_for_is_named_as_one(capsys, tmp_path, argv, message):
    block = tmp_path / "block"
    block.write_text("a file, not a folder")
    run_dir = tmp_path / "run"
    run_dir.mkdir()
    (run_dir / "metrics.csv").write_text("episode,total_points\n1,2.0\n")
    (run_dir / "model").mkdir()
    (run_dir / "model" / "meta.json").write_text('{"experiment": "toy", "algo": "dqn"}')
    argv = [a.replace("BLOCK", str(block)).replace("RUN", str(run_dir)) for a in argv]
    code, out, err = run(capsys, *argv)
    assert code == 2 and out == "", (out, err)
    assert err.strip() == "error: " + message.replace("BLOCK", str(block)), err
    assert block.read_text() == "a file, not a folder"


def test_render_wants_an_mp4_or_gif_name_or_a_folder(capsys, tmp_path):
    code, _, err = run(capsys, "render", "lunar_lander", "dqn", "--out", str(tmp_path / "demo.avi"))
    assert code == 2 and "give a file name ending in .mp4 or .gif, or a folder" in err
    assert list(tmp_path.iterdir()) == []


META = '{"experiment": "cartpole", "algo": "dqn", "preset": "default", "seed": 0, "config": {}}'
DAMAGED_RUNS = [  # (metrics.csv, model/meta.json, what the one line says)
    ("episode,total_points\n1,2.0\n", '{"experiment": "cartpole", "algo": "dqn"}', "lacks preset, seed, config"),
    ("a,b\n1,2\n", META, "metrics.csv is damaged or not one of ours (no column episode"),
    ("", META, "metrics.csv is damaged or not one of ours (EmptyDataError)"),
]


@pytest.mark.parametrize("metrics, meta, message", DAMAGED_RUNS)
def test_plot_of_a_damaged_run_is_one_line_exit_2(capsys, tmp_path, metrics, meta, message):
    (tmp_path / "metrics.csv").write_text(metrics)
    (tmp_path / "model").mkdir()
    (tmp_path / "model" / "meta.json").write_text(meta)
    code, out, err = run(capsys, "plot", str(tmp_path))
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "plots").exists() or not list((tmp_path / "plots").iterdir())


def _configs():
    for name in experiment_names():
        exp = get_experiment(name)
        for algo, spec in exp.algos.items():
            for preset in spec.presets:
                yield f"{name}/{algo}/{preset}", exp.preset(algo, preset)


FREE_FORM = {"init_from"}  # a path: checked when it is read


@pytest.mark.parametrize("name, cfg", list(_configs()))
def test_every_field_declares_what_it_allows(name, cfg):
    for f in dataclasses.fields(cfg):
        if f.type in ("bool", bool) or f.name in FREE_FORM:
            continue
        assert f.metadata.get("allowed") is not None, f"{name}: {f.name} declares no allowed values"


def test_help_shows_what_is_allowed(capsys):
    code, out, _ = run(capsys, "train", "lunar_lander", "dqn", "--help")
    assert code == 0 and "allowed: a number from 0 to 1" in " ".join(out.split())


def test_preset_before_the_names_still_adds_the_hyperparameters(capsys):
    code, out, _ = run(capsys, "train", "--preset=article", "--seed", "3", "lunar_lander", "dqn", "--help")
    assert code == 0 and "--tau FLOAT" in out


def test_hyperparameters_before_the_names_are_read_as_hyperparameters(capsys):
    code, out, _ = run(capsys, "train", "--tau", "0.5", "--preset", "article", "lunar_lander", "dqn", "--help")
    assert code == 0 and "--tau FLOAT" in out
    code, _, err = run(capsys, "train", "--tau", "7", "lunar_lander", "dqn")
    assert code == 2 and "--tau" in err and "7" in err and "unknown experiment" not in err


def test_every_experiment_evaluates_above_the_training_seeds():
    """Training env seeds stay below TRAINING_SEED_SPAN (the seeds trainers really hand their envs:
    tests/rlcore/training/test_training.py); every evaluation and selection seed is above it."""
    lowest = min(min(get_experiment(n).eval_seed_base, get_experiment(n).selection_seed_base)
                 for n in experiment_names())
    assert lowest >= TRAINING_SEED_SPAN
    # the largest allowed evaluation (--episodes) stays below every experiment's selection seeds
    for name in experiment_names():
        experiment = get_experiment(name)
        assert experiment.eval_seed_base + MAX_EVAL_EPISODES <= experiment.selection_seed_base


def test_seed_zero_keeps_the_env_seeds_of_the_shipped_runs():
    # the shipped runs reseeded at resumes up to episode ~73,000 (Mario 1-3)
    assert [training_env_seed(0, i) for i in (0, 1, 2, 3, 4, 73_078, 99_999)] == [0, 1, 2, 3, 4, 73_078, 99_999]


def test_no_two_run_seeds_share_a_training_env_seed():
    """Every run seed's block, over every index a run can reach, is its own and below the evaluation
    seeds (before, --seed 1000 repeated --seed 0, and seed 1 met seed 0's seeds after 1,000 episodes)."""
    from rlcore.environments.seeding import seed_block

    seen = set()
    for run_seed in range(MAX_RUN_SEED + 1):
        block = seed_block(run_seed)
        reached = {training_env_seed(run_seed, i) for i in (0, 1, 999, 1000, 1001, 73_078, 10**9)}
        assert reached <= set(block)
        assert seen.isdisjoint(block), run_seed
        seen.update(block)
    assert max(seen) < TRAINING_SEED_SPAN
    with pytest.raises(ValueError):  # a seed past the blocks would have to share one
        training_env_seed(MAX_RUN_SEED + 1, 0)


NOISE = ("oneDNN", "cuInit", "cuda", "absl", "argv[0]", "pybullet build time", "HDF5", "XDG_RUNTIME_DIR", "XNNPACK")


def _cli(*argv, cwd):
    # as on a machine without a display, where SDL complained (a user's `render cartpole a2c`)
    env = {k: v for k, v in os.environ.items()
           if k not in ("TF_CPP_MIN_LOG_LEVEL", "WANDB_SILENT", "DISPLAY", "WAYLAND_DISPLAY", "SDL_VIDEODRIVER",
                        "XDG_RUNTIME_DIR")}
    done = subprocess.run([sys.executable, str(ROOT / "main.py"), *argv], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=300)
    return done.returncode, done.stdout + done.stderr


@pytest.mark.parametrize("argv", [["list"], ["train", "lunar_lander", "dqn", "--help"]])
def test_list_and_help_print_no_tensorflow_line(argv, tmp_path):
    code, text = _cli(*argv, cwd=tmp_path)
    assert code == 0
    assert not [word for word in NOISE if word in text], text


def test_rendering_a_pygame_env_and_a_tflite_export_print_only_our_lines(tmp_path):
    # --out a folder that is not there yet (its trailing '/' says it is one): made, the video named in it
    code, text = _cli("render", "cartpole", "a2c", "--episodes", "1", "--out", f"{tmp_path / 'vids'}/", cwd=tmp_path)
    assert code == 0 and "video:" in text and (tmp_path / "vids" / "cartpole_a2c.mp4").is_file(), text
    pytest.importorskip("ai_edge_litert", reason="the export extra is not installed")
    code2, text2 = _cli("export", "cartpole", "a2c", "--format", "tflite", "--out", str(tmp_path / "x"), cwd=tmp_path)
    assert code2 == 0 and "parity:" in text2
    assert not [word for word in NOISE if word in text + text2], text + text2


def test_training_and_minitaur_evaluation_print_only_our_lines(tmp_path):
    code, text = _cli("train", "lunar_lander", "dqn", "--episodes", "2", "--wandb", "off", "--no-progress",
                      "--final-eval-episodes", "0", "--run-dir", str(tmp_path / "run"), cwd=tmp_path)
    assert code == 0 and "trained: 2 episodes" in text
    code2, text2 = _cli("evaluate", "minitaur", "sac", "--episodes", "1", cwd=tmp_path)
    assert code2 == 0 and "mean-action return" in text2  # SAC acts by its mean action, not greedily
    assert not [word for word in NOISE if word in text + text2], text + text2


def test_the_console_script_finds_shipped_models_from_elsewhere(tmp_path):
    script = Path(sys.executable).parent / "deeprl"
    if not script.exists():
        pytest.skip("the deeprl console script is installed by `make venv`")
    done = subprocess.run([str(script), "evaluate", "cartpole", "dqn", "--episodes", "2"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    # found and evaluated from another folder (the score is the shipped-model tests' question, held to
    # the bar there on any CPU)
    assert "saved_networks/cartpole/dqn): greedy return " in done.stdout and "over 2 episodes" in done.stdout


def test_wandb_charts_every_table_against_env_steps(tmp_path, monkeypatch):
    import wandb.sdk.wandb_run as wandb_run

    from rlcore.training.tracking import Tracker, wandb_row

    defined = []
    original = wandb_run.Run.define_metric

    def spy(self, name, *args, **kwargs):
        defined.append((name, kwargs.get("step_metric")))
        return original(self, name, *args, **kwargs)
    monkeypatch.setattr(wandb_run.Run, "define_metric", spy)
    tracker = Tracker(tmp_path, "t", {}, "offline")
    tracker.log({"episode": 1, "total_points": 3.0, "env_steps": 10})
    tracker.log({"env_steps": 10, "eval_mean": 1.5}, table="evals")
    tracker.close()
    assert ("env_steps", None) in defined and ("*", "env_steps") in defined
    assert list((tmp_path / "wandb").glob("offline-run-*/run-*.wandb"))
    assert wandb_row({"env_steps": 10, "eval_mean": 1.5, "flag": True}, "evals") == {
        "env_steps": 10, "evals/eval_mean": 1.5}
    assert wandb_row({"episode": 1, "total_points": 3.0, "env_steps": 10}, "metrics") == {
        "episode": 1, "total_points": 3.0, "env_steps": 10}


def test_publish_replaces_the_shipped_folder_whole(tmp_path):
    from rlcore.models.shipping import publish

    model = tmp_path / "run" / "model"
    model.mkdir(parents=True)
    for name in ("q_network.h5", "meta.json", "metrics.csv", "rollouts.csv"):
        (model / name).write_text(f"new {name}")
    target = tmp_path / "saved" / "dqn"
    target.mkdir(parents=True)
    (target / "meta.json").write_text("old")
    (target / "Stale_Train_dqn.png").write_text("old plot")
    publish(model, target)
    assert sorted(p.name for p in target.iterdir()) == ["meta.json", "metrics.csv", "q_network.h5",
                                                        "rollouts.csv"]
    assert (target / "meta.json").read_text() == "new meta.json"
    assert [p.name for p in target.parent.iterdir()] == ["dqn"]  # no temporary folder left


def test_a_model_published_over_another_records_what_it_replaced_and_its_card_says_so(tmp_path):
    """Issue 63: a level's one-command model shows the score of the hand-steered model it replaced."""
    import json

    from rlcore.models.shipping import publish
    from tools.docgen.main import replaced_text

    model, target = tmp_path / "run" / "model", tmp_path / "saved" / "1-2"
    model.mkdir(parents=True)
    target.mkdir(parents=True)
    (model / "meta.json").write_text(json.dumps({"preset": "flag", "commands": ["train"], "env_steps": 9}))
    first = {"preset": "levels", "env_steps": 100, "wall_seconds": 3600, "commands": ["a", "b"]}
    (target / "meta.json").write_text(json.dumps({
        "preset": "default", "env_steps": 50, "wall_seconds": 1800, "commands": ["c", "d", "e"], "init_from": first,
        "evaluation": {"episodes": 30, "success_share": 0.5, "seeds": "1000000..1000029", "per_episode": [{}] * 30}}))
    publish(model, target)
    meta = json.loads((target / "meta.json").read_text())
    assert meta["env_steps"] == 9 and meta["replaces"] == {
        "preset": "default", "commands": 3, "env_steps": 150, "wall_seconds": 5400, "finished": None,
        "evaluation": {"episodes": 30, "success_share": 0.5, "seeds": "1000000..1000029"}}

    class Model:
        experiment, name = "mario_ppo", "1-2"
    assert replaced_text(meta["replaces"], Model) == ("flag in 15 of 30 (seeds 1000000..1000029); trained by 3 commands "
                                                      "(`default` preset), 150 env steps, 1.5 h")
    assert replaced_text(None, Model) is None


def test_a_new_run_into_a_folder_that_holds_a_run_is_refused_and_leaves_it_as_it_was(capsys, tmp_path):
    """Starting again with the first command of a long run (not --resume) must not touch its files."""
    run_dir = tmp_path / "run"
    run_dir.mkdir()
    (run_dir / "metrics.csv").write_text("episode,total_points\n1,2.0\n")
    (run_dir / "checkpoint.npz").write_bytes(b"a checkpoint")
    code, out, err = run(capsys, "train", "cartpole", "dqn", "--episodes", "1", "--wandb", "off",
                         "--run-dir", str(run_dir))
    assert code == 2, (out, err)
    assert err.strip() == (f"error: --run-dir {run_dir} already holds a run (checkpoint.npz); continue it "
                           f"with --resume {run_dir}, or give another --run-dir")
    assert sorted(p.name for p in run_dir.iterdir()) == ["checkpoint.npz", "metrics.csv"]
    assert (run_dir / "checkpoint.npz").read_bytes() == b"a checkpoint"
    assert (run_dir / "metrics.csv").read_text() == "episode,total_points\n1,2.0\n"


def test_publish_refuses_a_model_that_misses_the_bar_of_the_one_it_would_replace(capsys, tmp_path, monkeypatch):
    """A short run with --publish must not replace a shipped model that meets its bar (a new user's
    `train cartpole dqn --episodes 8 --publish` did): one line, exit 2, the shipped folder untouched."""
    shipped = tmp_path / "models" / "cartpole" / "dqn"
    shipped.mkdir(parents=True)
    (shipped / "meta.json").write_text("the shipped model")
    monkeypatch.setenv("DEEPRL_MODELS", str(tmp_path / "models"))
    run_dir = tmp_path / "run"
    code, out, err = run(capsys, "train", "cartpole", "dqn", "--episodes", "3", "--final-eval-episodes", "2",
                         "--wandb", "off", "--no-progress", "--run-dir", str(run_dir), "--publish")
    assert code == 2 and not run_dir.exists(), (out, err)  # refused before training: a bar met on 2 episodes is luck
    assert err.strip() == ("error: --publish needs the evaluation a shipped model has (100 episodes on unseen seeds), "
                           "not --final-eval-episodes 2")
    code, out, err = run(capsys, "train", "cartpole", "dqn", "--episodes", "3", "--wandb", "off", "--no-progress",
                         "--run-dir", str(run_dir), "--publish")
    assert code == 2, (out, err)
    assert err.strip() == (f"error: not published to {shipped}/: its evaluation misses the bar of the shipped dqn "
                           f"(mean return >= 500); the model stays in {run_dir / 'model'}/")
    assert [p.name for p in shipped.iterdir()] == ["meta.json"] and (shipped / "meta.json").read_text() == "the shipped model"
    assert (run_dir / "model" / "meta.json").is_file()


def test_a_finished_run_resumed_with_publish_replaces_the_shipped_model_and_records_it(capsys, tmp_path, monkeypatch):
    """How a Mario level of the queue ships (long_runs/README.md): `train --resume RUN --publish` on a finished
    run evaluates it again and replaces the shipped folder whole, whose score the new meta.json keeps."""
    import json

    from rlcore.environments.experiment import Bar
    from rlcore.environments.registry import get_experiment

    monkeypatch.setitem(get_experiment("cartpole").bars, "dqn", Bar("mean", -1.0, "any score, for this test"))
    shipped = tmp_path / "models" / "cartpole" / "dqn"
    shipped.mkdir(parents=True)
    (shipped / "meta.json").write_text(json.dumps({"preset": "article", "commands": ["a", "b"], "env_steps": 5,
                                                   "evaluation": {"episodes": 100, "mean": 9.5, "std": 0.5}}))
    (shipped / "old_plot.png").write_bytes(b"")
    monkeypatch.setenv("DEEPRL_MODELS", str(tmp_path / "models"))
    run_dir = tmp_path / "run"
    args = ["cartpole", "dqn", "--wandb", "off", "--no-progress"]
    code, out, err = run(capsys, "train", *args, "--episodes", "3", "--run-dir", str(run_dir))
    assert code == 0, (out, err)
    code, out, err = run(capsys, "train", *args, "--resume", str(run_dir), "--publish")
    assert code == 0 and f"published to {shipped}/" in out, (out, err)
    meta = json.loads((shipped / "meta.json").read_text())
    assert meta["evaluation"]["episodes"] == 100 and not (shipped / "old_plot.png").exists()
    assert meta["replaces"] == {"preset": "article", "commands": 2, "env_steps": 5, "wall_seconds": 0, "finished": None,
                                "evaluation": {"episodes": 100, "mean": 9.5, "std": 0.5}}


def test_publish_refusal_reads_the_bar_of_the_folder_it_would_replace():
    from rlcore.environments.registry import get_experiment
    from rlcore.models.shipping import publish_refusal

    lander, mario = get_experiment("lunar_lander"), get_experiment("mario_ppo")
    assert publish_refusal(lander, Path("saved/lunar_lander/dqn"), {"evaluation": {"mean": 231.0, "episodes": 100}}) is None
    assert "misses the bar of the shipped a2c (mean return >= 200)" in publish_refusal(
        lander, Path("saved/lunar_lander/a2c"), {"evaluation": {"mean": 199.0, "episodes": 100}})
    assert "no evaluation on unseen seeds" in publish_refusal(lander, Path("saved/lunar_lander/dqn"), {})
    assert "its evaluation has 10 episodes; a shipped model's has 30" in publish_refusal(
        mario, Path("saved/mario_ppo/1-2"), {"evaluation": {"success_share": 1.0, "episodes": 10}})
    assert publish_refusal(mario, Path("saved/mario_ppo/1-2"), {"evaluation": {"success_share": 0.9, "episodes": 30}}) is None
    flags = {"evaluation": {"success_share": 26 / 30, "episodes": 30}}  # 26 of 30: short of the bar on every level
    assert "2-2 (flag in >= 90% of episodes)" in publish_refusal(mario, Path("saved/mario_ppo/2-2"), flags)


def test_a_run_that_spent_its_presets_budget_replaces_a_model_below_its_bar_and_no_other():
    """Issue 63: a Mario level whose run from one command misses the bar within the budget its preset set before
    the run ships that run, in place of the old model below its bar; never a run cut short, or with its budget
    changed, or over a model that meets its bar."""
    from dataclasses import replace

    from rlcore.environments.registry import get_experiment
    from rlcore.models.shipping import publish_refusal

    mario = get_experiment("mario_ppo")
    budget = mario.preset("ppo", "flag").max_env_steps
    spent = {"algo": "ppo", "preset": "flag", "config": {"max_env_steps": budget}, "stopped_by": f"max_env_steps {budget}",
             "evaluation": {"success_share": 26 / 30, "episodes": 30}}
    assert "1-1" in mario.below_bar
    assert publish_refusal(mario, Path("saved/mario_ppo/1-1"), spent) is None
    short = {**spent, "config": {"max_env_steps": budget // 2}, "stopped_by": f"max_env_steps {budget // 2}"}
    for meta in (short, {**spent, "stopped_by": "interrupted"}, {**spent, "preset": "no-such-preset"}):
        assert "misses the bar of the shipped 1-1" in publish_refusal(mario, Path("saved/mario_ppo/1-1"), meta)
    met = replace(mario, below_bar={})  # the level's model meets its bar: nothing below it replaces it
    assert "misses the bar of the shipped 1-1" in publish_refusal(met, Path("saved/mario_ppo/1-1"), spent)


def test_a_folder_that_takes_no_new_files_is_said_so_not_missing():
    """/proc is there, but a file cannot be made in it: the OS says "No such file or directory", which read as
    if the folder were missing (a new user's `render ... --out /proc/x.mp4`)."""
    from rlcore.errors import UserError
    from rlcore.files.atomic import writable_folder

    if not Path("/proc").is_dir():
        pytest.skip("no /proc here")
    with pytest.raises(UserError, match=r"^--out /proc: cannot write there \(the folder takes no new files\)$"):
        writable_folder("/proc", "--out")

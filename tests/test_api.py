"""The Python API end to end (api.train/resume/load/evaluate/render/export) and the notebook docs/api.ipynb,
executed as a user would run it (nbclient, a real Jupyter kernel)."""
import json
from pathlib import Path

import numpy as np
import pytest

from rlcore import api
from rlcore.errors import UserError

ROOT = Path(__file__).resolve().parents[1]


def test_shipped_model_by_name_predicts_and_evaluates():
    policy = api.load(("lunar_lander", "dqn"))
    assert policy.algo == "dqn" and policy.experiment.name == "lunar_lander"
    assert policy.model_dir == ROOT / "saved_networks" / "lunar_lander" / "dqn"
    env = policy.make_env()
    obs, _ = env.reset(seed=1_000_000)
    action = policy.predict(obs)
    assert isinstance(action, int) and 0 <= action < 4
    assert policy.predict(np.stack([obs] * 5)).shape == (5,)
    env.close()
    result = api.evaluate(policy, episodes=2, seed_base=1_000_000)
    recorded = policy.meta["evaluation"]["per_episode"][:2]  # the same seeds the shipped evaluation played
    assert [r["seed"] for r in result["per_episode"]] == [r["seed"] for r in recorded]
    assert result["episodes"] == 2 and result["line"].startswith("greedy return")
    returns = [r["return"] for r in result["per_episode"]]
    assert (result["min"], result["max"]) == (round(min(returns), 2), round(max(returns), 2))  # as the line


def test_mario_level_by_name():
    pytest.importorskip("nes_py", reason="the mario extra is not installed")
    policy = api.load(("mario_ppo", "1-1"))
    assert policy.model_dir.name == "1-1" and policy.meta["config"]["stage"] == 1
    assert api.load(("mario_ppo", "ppo")).model_dir.name == "1-1"  # the default level


@pytest.mark.parametrize("model, message", [
    (("lunar_lander", "sac"), "unknown algorithm 'sac'"),
    (("moon_lander", "dqn"), "unknown experiment 'moon_lander'"),
    (("mario_ppo", "8-4"), "no shipped model mario_ppo 8-4"),
    ("/nonexistent/model", "/nonexistent/model: no such model folder"),
    # a shipped model's name written as a path: the pair it meant
    ("lunar_lander/dqn", r"^lunar_lander/dqn is not a model folder; a shipped model is named as a pair: "
                         r"\('lunar_lander', 'dqn'\)$"),
    ("mario_ppo", r"a shipped model is named as a pair: \('mario_ppo', '1-1'\)$"),
    (5, r"^a model is a folder's path, a shipped model's \(EXPERIMENT, ALGO or LEVEL\) .*; got 5$"),
])
def test_load_mistakes_are_user_errors(model, message):
    if isinstance(model, tuple) and model[0] == "mario_ppo":
        pytest.importorskip("nes_py", reason="the mario extra is not installed")
    with pytest.raises(UserError, match=message):
        api.load(model)


@pytest.mark.parametrize("kwargs, message", [
    ({"seed": -1}, "seed=-1 is invalid: allowed is a whole number from 0 to 900"),
    ({"seed": 901}, "seed=901 is invalid"), ({"seed": 2.5}, "seed=2.5 is invalid"), ({"seed": "3"}, "seed='3' is invalid"),
    ({"final_eval_episodes": -1}, "final_eval_episodes=-1 is invalid"), ({"episodes": 0}, "episodes=0 is invalid"),
    ({"steps": True}, "steps=True is invalid"), ({"wandb": "bogus"}, "^wandb='bogus' is invalid: choose one of 'auto'"),
    # hyperparameters are named as the call gives them, not as the command line's flags
    ({"lr": -1.0}, "^lr=-1.0 is invalid: allowed is a number above 0$"),
    ({"hidden": 64}, "^hidden=64 is invalid: allowed is a list or tuple, each item a whole number of at least 1$"),
    ({"hidden": (16.5, 8)}, r"^hidden=\(16.5, 8\) is invalid: allowed is a list or tuple, each item a whole number"),
    ({"batch_size": 64.0}, "^batch_size=64.0 is invalid: allowed is a whole number of at least 1$"),
    ({"batch_size": 512, "buffer_size": 100}, "^batch_size=512 is invalid: it must not exceed buffer_size=100$"),
    ({"eps_decay": 0.9}, r"^eps_decay does nothing here: it is the factor of eps_schedule='episode'"),
    ({"lrr": 0.1}, "^unknown hyperparameter.s. lrr for DQNConfig; did you mean lr\\? known: "),
])
def test_train_checks_its_arguments_as_the_command_line_does_before_any_folder_exists(tmp_path, kwargs, message,
                                                                                    capsys):
    from rlcore.cli.parser import RUN_SEEDS
    from rlcore.hyperparams.allowed import check_whole

    check_whole("seed", np.int64(3), RUN_SEEDS)  # numpy's integers are whole numbers too
    with pytest.raises(UserError, match=message):
        api.train("cartpole", "dqn", run_dir=tmp_path / "run", **{"episodes": 2, **kwargs})
    assert not (tmp_path / "run").exists() and "training" not in capsys.readouterr().out  # no header first
    if set(kwargs) <= {"episodes", "steps", "final_eval_episodes", "wandb"}:  # resume takes the budgets too, and
        # checks them before it reads the folder
        with pytest.raises(UserError, match=message):
            api.resume(tmp_path / "run", **kwargs)


def test_train_records_the_call_evaluates_and_renders(tmp_path):
    rows = []
    run = api.train("cartpole", "dqn", run_dir=tmp_path / "run", episodes=4, final_eval_episodes=3, seed=2,
                       progress=False, callback=lambda row, table: rows.append((table, row)), lr=5e-4)
    meta = json.loads((run.model_dir / "meta.json").read_text())
    assert meta["command"] == (f"rlcore.api.train('cartpole', 'dqn', seed=2, run_dir={str(tmp_path / 'run')!r}, "
                               f"episodes=4, final_eval_episodes=3, lr=0.0005)")
    assert meta["config"]["lr"] == 5e-4 and meta["seed"] == 2 and meta["config"]["max_episodes"] == 4
    # the same final evaluation as main.py train: unseen seeds, written into meta.json
    assert meta["evaluation"]["episodes"] == 3 and meta["evaluation"]["seeds"] == "1000000..1000002"
    assert run.evaluation == meta["evaluation"]
    further = api.evaluate(run, episodes=2, record_further=True)  # the next unseen seeds, the evaluation kept
    meta = json.loads((run.model_dir / "meta.json").read_text())
    assert further["seeds"] == "1000003..1000004" and meta["further_evaluations"] == [further]
    assert meta["evaluation"] == run.evaluation
    with pytest.raises(UserError, match=r"meta.json records an evaluation already \(.*, 3 episodes on seeds "
                                        r"1000000..1000002\); record_further=True adds one .* replace=True overwrites it$"):
        api.evaluate(run, episodes=1, record=True)
    assert json.loads((run.model_dir / "meta.json").read_text()) == meta
    assert [table for table, _ in rows] == ["metrics"] * 4 and rows[-1][1]["episode"] == 4
    video = api.render(run, tmp_path / "clip.mp4", episodes=1)
    import imageio.v2 as imageio
    with imageio.get_reader(video) as reader:  # decoded by ffmpeg (imageio-ffmpeg)
        assert video == tmp_path / "clip.mp4" and reader.count_frames() > 1
    # a folder, as the command line's --out takes one: made, the video named after the model
    assert api.render(run, f"{tmp_path / 'clips'}/", episodes=1) == tmp_path / "clips" / "cartpole_dqn.mp4"
    with pytest.raises(UserError, match="already holds a run"):
        api.train("cartpole", "dqn", run_dir=tmp_path / "run", episodes=1)
    with pytest.raises(UserError, match="^episodes and max_episodes set the same budget"):
        api.train("cartpole", "dqn", run_dir=tmp_path / "other", episodes=1, max_episodes=2)
    with pytest.raises(UserError, match=r"^out='.*clip\.avi': give a file name ending in \.mp4 or \.gif"):
        api.render(run, tmp_path / "clip.avi")


@pytest.mark.parametrize("call, kwargs, message", [
    ("evaluate", {"episodes": 2.5}, "^episodes=2.5 is invalid: allowed is a whole number from 1 to 1000000$"),
    ("evaluate", {"episodes": "3"}, "^episodes='3' is invalid"), ("evaluate", {"episodes": 0}, "^episodes=0 is invalid"),
    ("evaluate", {"seed_base": -1}, "^seed_base=-1 is invalid: allowed is a whole number of at least 0$"),
    ("render", {"fps": 0}, "^fps=0 is invalid: allowed is a whole number from 1 to 240$"),
    ("render", {"seed": -2}, "^seed=-2 is invalid"), ("render", {"episodes": 1.0}, "^episodes=1.0 is invalid"),
])
def test_evaluate_and_render_check_their_arguments_as_the_command_line_does(tmp_path, call, kwargs, message):
    with pytest.raises(UserError, match=message):
        if call == "render":
            api.render(("cartpole", "dqn"), tmp_path / "clip.mp4", **kwargs)
        else:
            api.evaluate(("cartpole", "dqn"), **kwargs)
    assert not list(tmp_path.iterdir())


def test_resume_goes_on_from_the_checkpoint_records_the_call_and_what_it_changed(tmp_path):
    """api.resume as `main.py train ... --resume`: a stopped run (here: one whose model folder is not written
    yet) or a finished one given a larger budget goes on from its checkpoint; what the run is may not change."""
    first = api.train("cartpole", "dqn", run_dir=tmp_path / "run", episodes=3, final_eval_episodes=0, seed=1,
                      progress=False, lr=5e-4, checkpoint_every=1)
    rows = []
    run = api.resume(first, episodes=5, final_eval_episodes=2, progress=False, lr=2.5e-4,
                     callback=lambda row, table: rows.append(row))
    assert run.run_dir == first.run_dir and [row["episode"] for row in rows] == [4, 5]
    meta = run.meta
    assert meta["commands"] == [first.command, "rlcore.api.resume(" + repr(str(tmp_path / "run"))
                                + ", episodes=5, final_eval_episodes=2, lr=0.00025)"]
    assert meta["command_starts"][1]["changed"] == {"max_episodes": [3, 5], "lr": [5e-4, 2.5e-4]}
    assert (meta["episodes"], meta["seed"], meta["config"]["lr"], meta["evaluation"]["episodes"]) == (5, 1, 2.5e-4, 2)
    with pytest.raises(UserError, match=r"^hidden=\(8, 8\) cannot change on a resume"):
        api.resume(tmp_path / "run", episodes=6, hidden=(8, 8))  # a network of another size is another run
    with pytest.raises(UserError, match="holds no checkpoint.npz to resume from"):
        api.resume(tmp_path / "nothing")


def test_a_resume_keeps_the_runs_final_evaluation_and_wandb_mode_unless_given(tmp_path):
    """A run started with final_eval_episodes=2 and wandb off is evaluated on 2 episodes after a resume that
    does not say (not the experiment's 100) and makes no wandb folder; given again, they change."""
    from rlcore.files.checkpoint import read_checkpoint_state

    first = api.train("cartpole", "dqn", run_dir=tmp_path / "run", episodes=2, final_eval_episodes=2, progress=False)
    state = read_checkpoint_state(first.run_dir / "checkpoint.npz")
    assert (state["wandb_mode"], state["final_eval_episodes"]) == ("off", 2)
    run = api.resume(first, episodes=3, progress=False)
    assert run.meta["evaluation"]["episodes"] == 2 and not (first.run_dir / "wandb").exists()
    run = api.resume(first, episodes=4, final_eval_episodes=1, progress=False)
    assert run.meta["evaluation"]["episodes"] == 1


def test_a_run_in_progress_loads_from_its_checkpoint(tmp_path):
    """A run folder with a checkpoint and no model yet (stopped, or still running): its last checkpoint."""
    from rlcore.training.run import build_spec, run_training

    spec = build_spec("cartpole", "dqn", overrides={"max_episodes": 2, "checkpoint_every": 1},
                      run_dir=tmp_path / "run", wandb_mode="off", progress=False, command="pytest")
    run_training(spec)
    import shutil
    shutil.rmtree(tmp_path / "run" / "model")  # as if it had not finished
    policy = api.load(tmp_path / "run")
    assert policy.meta["snapshot_of"].endswith("checkpoint.npz")
    assert api.evaluate(policy, episodes=1)["episodes"] == 1
    # its export records where it came from as `main.py export` does: the run folder, its last checkpoint
    record = api.export(policy, "savedmodel", tmp_path / "export", observations=16)
    assert record["source_model"] == f"{tmp_path / 'run'}, last checkpoint"


def test_notebook_runs(tmp_path, monkeypatch):
    nbformat = pytest.importorskip("nbformat", reason="the test extra: pip install -e '.[test]'")
    nbclient = pytest.importorskip("nbclient", reason="the test extra: pip install -e '.[test]'")
    notebook = nbformat.read(ROOT / "docs" / "api.ipynb", as_version=4)
    assert not [cell for cell in notebook.cells if cell.get("outputs")]  # kept without outputs in git
    monkeypatch.setenv("PYTHONPATH", str(ROOT))  # the kernel inherits this environment
    monkeypatch.setenv("WANDB_MODE", "offline")
    client = nbclient.NotebookClient(notebook, timeout=300, kernel_name="python3",
                                     resources={"metadata": {"path": str(tmp_path)}})  # the kernel's cwd
    client.execute()
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    text = "\n".join(o.get("text", "") + json.dumps(o.get("data", {}).get("text/plain", ""))
                     for o in outputs)
    assert "greedy return" in text and "rlcore.api.train('CartPole-v1', 'ppo'" in text
    (made,) = (tmp_path / "runs").glob("*/model/meta.json")  # a folder named by its time: a second run
    assert made.parent.parent.name.startswith("CartPole-v1__ppo__0__")  # of the notebook gets its own
    assert "(6144, {'lr': [0.001, 0.0005], 'max_env_steps': [4096, 6144]})" in text  # the resume's cell
    for noise in ("cuInit", "oneDNN custom operations", "absl::InitializeLog"):
        assert noise not in text  # TensorFlow's start-up noise is kept out

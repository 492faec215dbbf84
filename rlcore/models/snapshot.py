"""A model folder made from a run's last checkpoint, so ``evaluate`` and ``render`` work on a run that
is still training or was stopped (``--model long_runs/mario_ppo/2-2``), as RL Zoo's
``enjoy --load-checkpoint`` does. The folder holds the acting network(s) and a ``meta.json`` that
names the checkpoint it came from; nothing is written into the run folder.
"""
from __future__ import annotations

from pathlib import Path

from rlcore.algorithms.registry import family
from rlcore.environments.registry import get_experiment
from rlcore.errors import UserError
from rlcore.files.atomic import write_json
from rlcore.files.checkpoint import load_checkpoint, read_checkpoint_state
from rlcore.models.policies import config_from_meta
from rlcore.training.spec import CHECKPOINT_FILE


def given_folder(folder: str | Path) -> Path:
    """The folder a ``--model`` (or ``api.load``) path stands for: a finished run's folder stands for its
    ``model/``; a model folder or a run in progress, for itself."""
    folder = Path(folder)
    finished = folder / "model"
    return finished if (finished / "meta.json").is_file() and not (folder / "meta.json").is_file() else folder


def is_run_in_progress(folder: str | Path) -> bool:
    """A run folder with a checkpoint and no finished model of its own."""
    folder = Path(folder)
    return (folder / CHECKPOINT_FILE).is_file() and not (folder / "meta.json").is_file()


def model_from_checkpoint(run_dir: str | Path, out_dir: str | Path, experiment: str, algo: str) -> dict:
    """Write the acting network(s) of ``run_dir``'s checkpoint and a meta.json to ``out_dir``; return
    the meta. The run must be one of ``experiment`` ``algo``."""
    run_dir, out_dir = Path(run_dir), Path(out_dir)
    state = read_checkpoint_state(run_dir / CHECKPOINT_FILE)
    from rlcore.environments.gym_experiment import names_the_env

    if not (names_the_env(experiment, state.get("experiment")) and state.get("algo") == algo):
        raise UserError(f"the run in {run_dir} is {state.get('experiment')} {state.get('algo')}, "
                        f"not {experiment} {algo}")
    exp = get_experiment(state["experiment"], state.get("env"))
    cfg = config_from_meta(exp, state)
    env = exp.env_factory(cfg, max_episode_steps=None)()
    agent = family(exp.algo(state["algo"]).kind).build_agent(env.observation_space, env.action_space, cfg)
    env.close()
    load_checkpoint(run_dir / CHECKPOINT_FILE, agent.models(), {})
    agent.save(out_dir)
    meta = {key: state[key] for key in ("experiment", "algo", "kind", "preset", "seed", "config", "env_steps",
                                        "commands", "env") if key in state}
    meta.update(episodes=len(state.get("returns", [])), snapshot_of=str(run_dir / CHECKPOINT_FILE))
    write_json(out_dir / "meta.json", meta)
    return meta

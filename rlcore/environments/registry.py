"""Which experiments there are: this package's experiment packages by name, and any registered
Gymnasium id, each as an :class:`~rlcore.environments.experiment.Experiment`."""
from __future__ import annotations

import importlib

from rlcore.environments import gym_experiment
from rlcore.environments.experiment import Experiment
from rlcore.errors import UserError
from rlcore.host.extras import experiment_needs, require
from rlcore.host.quiet import filtered_stderr

EXPERIMENT_MODULES = {
    "lunar_lander": "lunar_lander.experiment",
    "cartpole": "cartpole.experiment",
    "cartpole_v0": "cartpole.experiment_v0",
    "mario_ppo": "mario_ppo.experiment",
    "minitaur": "minitaur.experiment",
}


def experiment_names() -> list[str]:
    return list(EXPERIMENT_MODULES)


def eval_episodes_words() -> str:
    """How many episodes each experiment's evaluation on unseen seeds runs, for ``--help``: "default
    100; mario_ppo 10; minitaur 30", read from the experiments (their modules import no TensorFlow)."""
    counts = {name: get_experiment(name).eval_episodes for name in EXPERIMENT_MODULES}
    default = Experiment.eval_episodes
    return "; ".join([f"default {default}"] + [f"{name} {n}" for name, n in counts.items() if n != default])


def get_experiment(name: str, env_record: dict | None = None, env_kwargs: dict | None = None) -> Experiment:
    """The experiment ``name``: a package's (``lunar_lander`` ...), else a registered Gymnasium id
    (``Acrobot-v1``, or ``my_envs:Maze-v0`` to import ``my_envs`` first; :mod:`rlcore.environments.gym_experiment`).
    ``env_record``: a model's recorded env (meta.json's ``env``), registered again if this process
    lacks it, and built with the arguments it records; ``env_kwargs``: a new run's ``--env-kwargs``."""
    if name in EXPERIMENT_MODULES:
        if env_kwargs:
            raise UserError(f"--env-kwargs is for a Gymnasium id; {name}'s env is set by its presets and "
                            f"hyperparameters (`train {name} ALGO --help`)")
        return importlib.import_module(EXPERIMENT_MODULES[name]).EXPERIMENT
    if not gym_experiment.looks_like_gym_id(name):
        raise UserError(f"unknown experiment {name!r}; choose one of {', '.join(EXPERIMENT_MODULES)}, "
                        f"or a registered Gymnasium id such as CartPole-v1")
    if env_record:
        gym_experiment.register_from_record(env_record)
        env_kwargs = env_kwargs or env_record.get("env_kwargs")
    return gym_experiment.gym_experiment(name, env_kwargs)


def require_experiment(experiment: str) -> None:
    """Raise the one-line :class:`UserError` of :func:`rlcore.host.extras.require` if the extra that
    ``experiment`` declared is not installed; unknown names are left to :func:`get_experiment`'s error."""
    get_experiment(experiment)  # imports the experiment package, which declares its needs
    what, extra, modules = experiment_needs(experiment)
    with filtered_stderr():  # pybullet prints its build time on import
        for module in modules:
            require(module, what, extra)

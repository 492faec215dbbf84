"""Rebuild a policy from a saved model folder alone (its ``meta.json`` says what it is)."""
from __future__ import annotations

from pathlib import Path

from rlcore.algorithms.registry import family
from rlcore.environments.registry import get_experiment
from rlcore.errors import UserError
from rlcore.files.model_meta import read_meta  # noqa: F401  (callers read it here too)
from rlcore.host.cpu import bfloat16_refusal, cpu_flags


def config_from_meta(exp, meta: dict):
    """The run's hyperparameters, rebuilt as the algorithm's config class."""
    from rlcore.hyperparams.flags import from_dict

    return from_dict(type(exp.preset(meta["algo"], None)), meta.get("config", {}))


def load_policy(model_dir: str | Path, experiment: str | None = None, algo: str | None = None):
    """Return ``(experiment, meta, policy)``.

    ``policy(obs_batch) -> greedy actions``; ``policy.sample(obs_batch, rng)`` draws from pi for
    the policy-gradient kinds; ``policy.make_env()`` builds the env the model was trained on
    (for Mario, its level and action set). ``experiment``/``algo``, when given, must match the
    folder's meta (a DQN folder cannot be rendered as A2C).
    """
    from rlcore.environments.gym_experiment import names_the_env

    meta = read_meta(model_dir)
    if not (names_the_env(experiment, meta.get("experiment")) and algo in (None, meta.get("algo"))):
        raise UserError(f"model in {model_dir} is {meta.get('experiment')} {meta.get('algo')}, "
                        f"not {experiment} {algo}")
    exp = get_experiment(meta["experiment"], meta.get("env"))
    acting = family(exp.algo(meta["algo"]).kind)  # an unknown kind: one line
    config = config_from_meta(exp, meta)
    if reason := bfloat16_refusal(getattr(config, "precision", "float32"), cpu_flags()):
        raise UserError(f"{model_dir}: {reason}")
    # the registered episode limit, not the training cap: evaluations are comparable across runs
    make_env = exp.env_factory(config, max_episode_steps=None)
    env = make_env()
    obs_shape, action_space = env.observation_space.shape, env.action_space
    env.close()
    policy = acting.load_policy(Path(model_dir) / acting.policy_file, obs_shape, action_space, config)
    policy.make_env = make_env
    return exp, meta, policy

"""Rebuild a greedy policy from a saved model folder alone (its ``meta.json`` says what it is)."""
from __future__ import annotations

import json
from pathlib import Path

from rlcore.errors import UserError
from rlcore.experiment import get_experiment


def read_meta(model_dir: str | Path) -> dict:
    model_dir = Path(model_dir)
    meta_path = model_dir / "meta.json"
    if not meta_path.is_file():
        raise UserError(f"{model_dir} has no meta.json: not a model folder of this package "
                        "(train one with `main.py train`, or pass --model)")
    try:
        return json.loads(meta_path.read_text())
    except json.JSONDecodeError as exc:
        raise UserError(f"{meta_path} is damaged ({exc.msg} at line {exc.lineno})")


def load_policy(model_dir: str | Path, experiment: str | None = None, algo: str | None = None):
    """Return ``(experiment, meta, policy)``; ``policy(obs_batch) -> actions``.

    ``experiment``/``algo``, when given, must match the folder's meta (a DQN folder cannot be
    rendered as A2C).
    """
    meta = read_meta(model_dir)
    for key, wanted in (("experiment", experiment), ("algo", algo)):
        if wanted is not None and meta.get(key) != wanted:
            raise UserError(f"model in {model_dir} is {meta.get('experiment')} {meta.get('algo')}, "
                            f"not {experiment} {algo}")
    exp = get_experiment(meta["experiment"])
    spec = exp.algo(meta["algo"])
    env = exp.make_env()
    obs_dim, n_actions = env.observation_space.shape[0], int(env.action_space.n)
    env.close()
    if spec.kind == "dqn":
        from rlcore.agents.dqn import GreedyQPolicy
        return exp, meta, GreedyQPolicy(model_dir, obs_dim, n_actions)
    if spec.kind == "a2c":
        from rlcore.agents.a2c import GreedyActorPolicy
        return exp, meta, GreedyActorPolicy(model_dir, obs_dim, n_actions)
    raise UserError(f"no policy loader for algorithm kind {spec.kind!r}")

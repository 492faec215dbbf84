"""Any registered Gymnasium id as an experiment: the algorithms that fit its spaces, each with a
``default`` preset made of the algorithm's own defaults.

    get_experiment("Acrobot-v1")            # a Gymnasium id
    get_experiment("my_envs:Maze-v0")       # import my_envs (which calls gymnasium.register), then the id

What fits (the agents read nothing of an env but its spaces):

    dqn, ddqn, dueling_dqn, dueling_ddqn,       Discrete actions, vector observations (a 1-D Box, MLP
    a2c, ppo                                    body) or uint8 images H x W x C (CNN body)
    sac                                         Box actions with finite bounds (rescaled to [-1, 1],
                                                the range of its tanh actor), vector observations

``ALE/*`` ids (the ``atari`` extra) get the DQN papers' preprocessing (:mod:`rlcore.environments.atari`).
A Discrete observation (FrozenLake's cell, Taxi's state number) is given to the networks one-hot, as a
vector of n zeros and a one (Stable-Baselines3 does the same); the exported networks take that vector.

A preset is the algorithm's config dataclass defaults, with episodes capped at the env's registered
time limit, stopping once the last 100 episodes average the env's ``reward_threshold`` (when it has one)
and the env pool in-process. Every field stays a flag (``--lr 3e-4``) or a keyword of
:func:`rlcore.api.train`. TensorFlow-free.
"""
from __future__ import annotations

import importlib
import json
import re
from functools import partial
from typing import TYPE_CHECKING

import numpy as np

from rlcore.algorithms.registry import FAMILIES, family
from rlcore.environments import atari
from rlcore.environments.env_kwargs import check_env_kwargs, env_creator
from rlcore.environments.experiment import AlgoSpec, Experiment
from rlcore.environments.remote import RemoteEnv, draws_with_opengl
from rlcore.errors import UserError
from rlcore.host.extras import missing_extra_message, require
from rlcore.host.quiet import filtered_stderr, route_mujoco_warnings

if TYPE_CHECKING:
    import gymnasium
    from gymnasium.envs.registration import EnvSpec

NO_THRESHOLD_STOP = 1e9  # stop_score of an env without a reward threshold: run the whole budget
# the time limit of an env that registers none (CliffWalking-v1, a user's env), unless --max-episode-steps
# gives one: without it, an episode a policy never ends (walking into a wall) would stall a run or an
# evaluation for good. 1,000: the longest limit Gymnasium's own envs register (LunarLander, MuJoCo's)
ADDED_TIME_LIMIT = 1_000

_GYM_ID = re.compile(r"^([\w.]+:)?([\w.-]+/)?[\w.-]+-v\d+$")


def looks_like_gym_id(name: str) -> bool:
    """``Acrobot-v1``, ``ALE/Pong-v5`` or ``my_envs:Maze-v0`` (a versioned Gymnasium id)."""
    return bool(_GYM_ID.match(name))


def split_module(name: str) -> tuple[str | None, str]:
    """``"my_envs:Maze-v0"`` -> ``("my_envs", "Maze-v0")``; a plain id -> ``(None, id)``."""
    module, _, env_id = name.rpartition(":")
    return module or None, env_id


def gym_spec(name: str) -> EnvSpec:
    """The registered :class:`gymnasium.envs.registration.EnvSpec` of ``name`` (importing its module
    first for ``module:id``), or a one-line :class:`UserError`."""
    import gymnasium as gym

    module, env_id = split_module(name)
    if atari.is_atari(env_id):
        atari.register_atari()
    if module is not None:
        try:
            importlib.import_module(module)
        except ImportError as exc:
            raise UserError(f"cannot import {module!r}, the module before ':' in {name!r} that should "
                            f"register {env_id}: {exc}") from None
    try:
        return gym.spec(env_id)
    except gym.error.Error as exc:
        hint = (f" ({module} did not register it)" if module else " (the games ale-py registers: ALE/Pong-v5, "
                "ALE/Breakout-v5, ...)" if atari.is_atari(env_id) else
                " (import the module that calls gymnasium.register first, or give MODULE:ID)")
        raise UserError(f"{env_id} is not a registered Gymnasium id: {exc}{hint}") from None


def names_the_env(given: str | None, recorded: str | None) -> bool:
    """Whether ``given`` names the env a run recorded: its name, or for a user's ``MODULE:ID`` its id too."""
    if given is None or given == recorded:
        return True
    return isinstance(recorded, str) and ":" in recorded and given == recorded.split(":", 1)[1]


def register_from_record(record: dict) -> None:
    """Register a user's env again from a model's meta.json (``env``: id and a string entry point) in a
    process where the module that registered it was not imported. Nothing when the id is known."""
    import gymnasium as gym

    env_id, entry_point = record.get("gymnasium_id"), record.get("entry_point")
    if env_id and atari.is_atari(env_id):
        atari.register_atari()  # ale-py registers its own
        return
    if not env_id or env_id in gym.registry or not isinstance(entry_point, str):
        return
    gym.register(env_id, entry_point=entry_point, kwargs=record.get("kwargs") or {},
                 max_episode_steps=record.get("max_episode_steps"),
                 reward_threshold=record.get("reward_threshold"))


def make_gym_env(render_mode: str | None = None, max_episode_steps: int | None = None, *, name: str,
                 rescale_actions: bool = False, env_kwargs: dict | None = None,
                 in_worker: bool = False, added_time_limit: int | None = None) -> gymnasium.Env:
    """The env ``name`` (``module:id`` imports the module first) with its registered time limit unless
    ``max_episode_steps`` is given (``added_time_limit`` where it registers none), built with ``env_kwargs``
    (``--env-kwargs``); SAC's envs get their Box actions rescaled from [-1, 1]. A MuJoCo env asked for frames
    runs in a worker process (:mod:`rlcore.environments.remote`)."""
    import gymnasium as gym

    max_episode_steps = max_episode_steps or added_time_limit
    module, env_id = split_module(name)
    if module is not None:
        importlib.import_module(module)  # a spawned pool worker registers the user's env here
    if render_mode and not in_worker and draws_with_opengl(gym_spec(name).entry_point):
        return RemoteEnv(partial(make_gym_env, render_mode, max_episode_steps, name=name, in_worker=True,
                                 rescale_actions=rescale_actions, env_kwargs=env_kwargs), env_id)
    env = _make(env_id, render_mode, max_episode_steps, env_kwargs or {})
    if isinstance(env.observation_space, gym.spaces.Discrete):
        env = OneHotObservation(env)
    if rescale_actions:
        env = gym.wrappers.RescaleAction(env, np.float32(-1.0), np.float32(1.0))
    return env


def _make(env_id: str, render_mode: str | None, max_episode_steps: int | None, env_kwargs: dict) -> gymnasium.Env:
    """``gym.make``, given ``render_mode`` only when frames are wanted (an env class may take no such
    argument, as many tutorials write them), and only a mode the env declares; else one line."""
    if atari.is_atari(env_id):
        atari.register_atari()  # in a spawned pool worker too
    make = atari.make_atari if atari.is_atari(env_id) else _gym_make
    if render_mode is None:
        return make(env_id, None, max_episode_steps, env_kwargs)
    modes = _declared_modes(env_id)
    if modes is not None and render_mode not in modes:
        raise UserError(f"{env_id} cannot render {render_mode} frames: its env declares "
                        f"{', '.join(modes) or 'no render mode'} (metadata['render_modes']), so there is no "
                        "video or GIF of it; evaluate works without frames")
    try:
        return make(env_id, render_mode, max_episode_steps, env_kwargs)
    except TypeError as exc:
        raise UserError(f"{env_id} cannot render: its env class takes no render_mode argument ({exc})") from None


def _gym_make(env_id: str, render_mode: str | None, max_episode_steps: int | None, env_kwargs: dict) -> gymnasium.Env:
    """``gym.make``, with what an env's C library prints on every build dropped (:data:`quiet.NOISE`)."""
    import gymnasium as gym

    if draws_with_opengl(gym.spec(env_id).entry_point):
        require("mujoco", f"{env_id} (MuJoCo)")
        route_mujoco_warnings()
    arguments: dict = {**({"render_mode": render_mode} if render_mode else {}), **env_kwargs}
    with filtered_stderr():
        return gym.make(env_id, max_episode_steps=max_episode_steps, **arguments)


def _declared_modes(env_id: str) -> list[str] | None:
    """The render modes the env's class declares (its ``metadata``), read without building it; None when
    its entry point is a function that declares nothing (then only trying tells)."""
    metadata = getattr(env_creator(env_id), "metadata", None)
    return list(metadata.get("render_modes", [])) if isinstance(metadata, dict) else None


def one_hot(observation: int, space: gymnasium.spaces.Discrete) -> np.ndarray:
    """The observation ``observation`` of a Discrete ``space`` (which may start at a value other than 0)
    as a float32 vector of ``space.n`` zeros with a one at its index."""
    vector = np.zeros(int(space.n), np.float32)
    vector[int(observation) - int(space.start)] = 1.0
    return vector


def OneHotObservation(env: gymnasium.Env) -> gymnasium.Env:  # noqa: N802 (a wrapper, named as one)
    """``env`` with its Discrete observations given one-hot, as a Box of n values in [0, 1]."""
    import gymnasium as gym

    space = env.observation_space
    if not isinstance(space, gym.spaces.Discrete):
        raise TypeError(f"one-hot needs a Discrete observation space, not {space}")
    return gym.wrappers.TransformObservation(env, partial(one_hot, space=space),
                                             gym.spaces.Box(0.0, 1.0, (int(space.n),), np.float32))


def algorithms() -> dict[str, tuple[str, str, dict]]:
    """Algorithm name -> (family kind, description, config switches): every variant of every family."""
    return {name: (kind, description, switches) for kind, fam in FAMILIES.items()
            for name, (description, switches) in fam.variants.items()}


def default_preset(kind: str, switches: dict, reward_threshold: float | None) -> object:
    """The algorithm's config defaults, for an env this package knows nothing of."""
    fields = dict(max_episode_steps=0, stop_score=(NO_THRESHOLD_STOP if reward_threshold is None
                                                    else float(reward_threshold)), **switches)
    if family(kind).env_pool:
        fields["vec"] = "inline"  # a Gymnasium env is cheap next to a pipe to another process
    return family(kind).config(**fields)


def gym_experiment(name: str, env_kwargs: dict | None = None) -> Experiment:
    """The :class:`Experiment` of the Gymnasium id ``name`` (``module:id`` allowed) built with ``env_kwargs``
    (which may change its spaces, so the algorithms that fit); an unknown id is a :class:`UserError`. Built
    once per process, name and arguments."""
    env_kwargs = dict(env_kwargs or {})
    key = (name, json.dumps(env_kwargs, sort_keys=True, default=repr), tuple(FAMILIES))  # a family registered since is offered too
    if key not in _BUILT:
        _BUILT[key] = _build(name, env_kwargs)
    return _BUILT[key]


_BUILT: dict[tuple[str, str, tuple[str, ...]], Experiment] = {}


def _missing_dependency(spec: EnvSpec, exc: Exception) -> str:
    """Gymnasium's "not installed" as this package's install line where an extra brings it."""
    if draws_with_opengl(spec.entry_point):
        return missing_extra_message(f"{spec.id} (MuJoCo)", "mujoco")
    return f"{spec.id} needs a package that is not installed: {exc}"


def _build(name: str, env_kwargs: dict) -> Experiment:
    spec = gym_spec(name)
    obs_space, act_space, one_hot_obs, fps = _probe(spec, name, env_kwargs)
    algos, unfit = {}, {}
    for algo, (kind, description, switches) in algorithms().items():
        reason = family(kind).misfit(obs_space, act_space)  # why it cannot train on these spaces, or None
        if reason:
            unfit[algo] = reason
            continue
        preset = default_preset(kind, switches, spec.reward_threshold)
        algos[algo] = AlgoSpec(algo, kind, description, {"default": preset})
    rescale = any(not family(algo.kind).discrete for algo in algos.values())
    # ALE's games end themselves (108,000 frames at most)
    added = ADDED_TIME_LIMIT if spec.max_episode_steps is None and not atari.is_atari(spec.id) else None
    entry_point = spec.entry_point if isinstance(spec.entry_point, str) else None
    return Experiment(
        name=name,
        description=f"Gymnasium {spec.id} (observations {obs_space}, actions {act_space})",
        make_env=partial(make_gym_env, name=name, rescale_actions=rescale, env_kwargs=env_kwargs or None,
                         added_time_limit=added),
        algos=algos,
        solved_score=None if spec.reward_threshold is None else float(spec.reward_threshold),
        plot_prefix=re.sub(r"[^\w.-]", "_", spec.id),
        video_fps=fps,
        unfit=unfit,
        env_record={"gymnasium_id": spec.id, "entry_point": entry_point,
                    "kwargs": _jsonable(spec.kwargs), "max_episode_steps": spec.max_episode_steps,
                    **({"time_limit_added": added} if added else {}),
                    "reward_threshold": spec.reward_threshold, "actions_rescaled_to": [-1, 1] if rescale else None,
                    "observations_one_hot": one_hot_obs, **({"env_kwargs": env_kwargs} if env_kwargs else {}),
                    **({"atari_preprocessing": atari.record()} if atari.is_atari(spec.id) else {})},
    )


def _probe(spec: EnvSpec, name: str, env_kwargs: dict) -> tuple:
    """Make the env once: its observation and action spaces, whether its observations come one-hot (a
    Discrete space), its frame rate; what the env's own checks refuse of ``env_kwargs`` is one line."""
    import gymnasium as gym

    if env_kwargs:
        check_env_kwargs(spec.id, env_kwargs)
    try:
        env = make_gym_env(name=name, env_kwargs=env_kwargs)
    except gym.error.DependencyNotInstalled as exc:
        raise UserError(_missing_dependency(spec, exc)) from None
    except UserError:
        raise
    except Exception as exc:  # a value the env's own checks refuse, whatever it raises (ale-py: RuntimeError)
        if not env_kwargs:
            raise
        said = exc if isinstance(exc, (TypeError, ValueError, AssertionError)) else f"{type(exc).__name__}: {exc}"
        raise UserError(f"--env-kwargs: {spec.id} refused {env_kwargs}: {said}") from None
    try:
        obs_space, act_space = env.observation_space, env.action_space
        one_hot_obs = type(env.unwrapped.observation_space).__name__ == "Discrete"  # given one-hot
        fps = int(env.metadata.get("render_fps") or 30)
    finally:
        env.close()
    return obs_space, act_space, one_hot_obs, fps


def _jsonable(kwargs: dict) -> dict:
    out = {}
    for key, value in (kwargs or {}).items():
        try:
            json.dumps(value)
        except TypeError:
            continue  # a callable or an object: the env's own registration supplies it
        out[key] = value
    return out

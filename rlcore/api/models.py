"""The Python API on models: :func:`load` a model folder, a run or a shipped model as a :class:`Policy`, then
:func:`evaluate`, :func:`render` or :func:`export` it, as ``main.py`` does; :class:`Run` is what training
returns. Re-exported by :mod:`rlcore.api`."""
from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, Union

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "2")  # before anything imports TensorFlow, as main.py does
import numpy as np

from rlcore.environments.experiment import Experiment
from rlcore.errors import UserError
from rlcore.hyperparams.allowed import NON_NEGATIVE, check_whole, named_as_python
from rlcore.hyperparams.limits import EVAL_COUNT, FRAME_RATE

if TYPE_CHECKING:
    import gymnasium

#: a model: a folder (a model folder, a finished run's folder, or a run in progress), a finished
#: :class:`Run`, or a shipped model by name: ``("lunar_lander", "dqn")``, ``("mario_ppo", "1-1")``
ModelRef = Union[str, "os.PathLike[str]", tuple[str, str], "Run"]
ExportFormat = Literal["savedmodel", "tflite", "onnx"]


@dataclass(frozen=True)
class Run:
    """A finished training run: its folder, its model folder and the model's meta.json."""
    run_dir: Path
    model_dir: Path
    meta: dict[str, Any] = field(repr=False)

    @property
    def evaluation(self) -> dict[str, Any] | None:
        """The final evaluation on unseen seeds (meta.json's ``evaluation``), None when skipped."""
        return self.meta.get("evaluation")

    @property
    def command(self) -> str:
        """The call that started the run, as meta.json records it (every call since: ``meta["commands"]``)."""
        return str(self.meta["command"])

    def load(self) -> Policy:
        """The trained policy (:func:`rlcore.api.load` of :attr:`model_dir`)."""
        return load(self.model_dir)



class Policy:
    """A saved model, ready to act: ``predict(observation) -> action``.

    ``experiment`` is what the model was trained on (its env factory, evaluation seeds); ``meta`` its
    meta.json; ``make_env()`` builds its env as it was evaluated (time limit, Mario's level, SAC's
    rescaled actions).
    """

    def __init__(self, model_dir: Path, experiment: Experiment, meta: dict[str, Any], network: Any,
                 keep: Any = None):
        self.model_dir, self.experiment, self.meta = model_dir, experiment, meta
        self.algo: str = str(meta["algo"])
        self.kind: str = experiment.algo(self.algo).kind
        self._network = network  # rlcore.networks.acting.Policy / MeanActionPolicy: batched acting
        self._keep = keep  # a run in progress: the temporary folder of its snapshot, kept with the policy

    def __repr__(self) -> str:
        return f"Policy({self.experiment.name} {self.algo}, {self.model_dir})"

    @property
    def observation_shape(self) -> tuple[int, ...]:
        return tuple(self._network.model.input_shape[1:])

    def make_env(self, render_mode: str | None = None) -> gymnasium.Env:
        """The model's env (``render_mode="rgb_array"`` for frames)."""
        return self._network.make_env(render_mode=render_mode)

    def predict(self, observation: Any, deterministic: bool = True,
                rng: np.random.Generator | None = None) -> Any:
        """The action for one observation (an int, or for SAC an array in [-1, 1] that the env rescales),
        or an array of actions for a batch of observations.

        ``deterministic``: the greedy action (argmax of Q or pi; SAC's mean action), as ``evaluate``
        plays (Mario's evaluation samples from pi: pass ``deterministic=False``); else a draw from pi
        with ``rng`` (the DQN family has no distribution to draw from).
        """
        obs = np.asarray(observation)
        single = obs.shape == self.observation_shape
        batch = obs[None] if single else obs
        if batch.shape[1:] != self.observation_shape:
            raise UserError(f"observation of shape {obs.shape} given; this model takes "
                            f"{self.observation_shape} (or a batch of them)")
        network = self._network
        actions = network(batch) if deterministic else network.sample(batch, rng or np.random.default_rng())
        return actions[0].item() if single and actions.ndim == 1 else (actions[0] if single else actions)

    def __call__(self, observations: np.ndarray) -> np.ndarray:
        """Greedy actions for a batch (the interface rlcore's evaluation and video code call)."""
        return self._network(observations)


# ------------------------------------------------------------------------------- load
def model_folder(model: str | os.PathLike[str] | tuple[str, str]) -> Path:
    """The folder of ``model``: a shipped name (``("lunar_lander", "dqn")``, Mario's ``("mario_ppo",
    "1-1")``), or a path (a finished run's folder stands for its ``model/``). A run in progress is
    returned as it is (:func:`load` reads its last checkpoint)."""
    from rlcore.environments.registry import get_experiment
    from rlcore.models import shipping
    from rlcore.models.snapshot import given_folder

    if isinstance(model, tuple):
        if len(model) != 2 or not all(isinstance(part, str) for part in model):
            raise UserError(f"a shipped model is named (EXPERIMENT, ALGO or LEVEL), e.g. ('lunar_lander', 'dqn'); "
                            f"got {model!r}")
        name, which = model
        exp = get_experiment(name)
        if which in exp.algos or exp.shipped_by is None:
            exp.algo(which)  # an unknown algorithm: one line naming the known ones
            folder = shipping.shipped_dir(name, which)
        else:
            folder = shipping.models_root() / name / which
        return shipping.require_shipped(folder, f"{name} {which}")
    if not isinstance(model, (str, os.PathLike)):
        raise UserError(f"a model is a folder's path, a shipped model's (EXPERIMENT, ALGO or LEVEL) such as "
                        f"('lunar_lander', 'dqn'), a Run or a Policy; got {model!r}")
    folder = given_folder(Path(model))
    if not any((folder / name).is_file() for name in ("meta.json", "checkpoint.npz")):
        if pair := _shipped_name(str(model)):  # "lunar_lander" or "lunar_lander/dqn" meant a shipped model
            raise UserError(f"{model} is not a model folder; a shipped model is named as a pair: {pair}")
    return folder


def _shipped_name(text: str) -> str | None:
    """``('lunar_lander', 'dqn')`` for a text that names an experiment (``lunar_lander``, ``lunar_lander/dqn``,
    ``mario_ppo/1-1``), written as the pair :func:`model_folder` takes; None for any other text."""
    from rlcore.environments.registry import experiment_names, get_experiment

    name, _, which = text.strip("/").partition("/")
    if name not in experiment_names() or "/" in which:
        return None
    exp = get_experiment(name)
    example = exp.shipped_by.default if exp.shipped_by else next(iter(exp.algos))
    return f"({name!r}, {(which or example)!r})"


@named_as_python
def load(model: ModelRef | Policy) -> Policy:
    """The :class:`Policy` of ``model`` (see :data:`ModelRef`), rebuilt from its folder alone: its
    meta.json names the env (a Gymnasium id's registration included) and the network."""
    from rlcore.host.quiet import load_tensorflow
    from rlcore.models.policies import load_policy
    from rlcore.models.snapshot import is_run_in_progress, model_from_checkpoint

    if isinstance(model, Policy):
        return model
    if isinstance(model, Run):
        model = model.model_dir
    folder = model_folder(model)
    load_tensorflow()
    keep = None
    source = folder
    if is_run_in_progress(folder):
        from rlcore.files.checkpoint import read_checkpoint_state
        from rlcore.training.spec import CHECKPOINT_FILE

        state = read_checkpoint_state(folder / CHECKPOINT_FILE)
        keep = tempfile.TemporaryDirectory(prefix="snapshot-")
        model_from_checkpoint(folder, keep.name, state["experiment"], state["algo"])
        source = Path(keep.name)
    exp, meta, network = load_policy(source)
    return Policy(folder, exp, meta, network, keep)


# ---------------------------------------------------------------------- evaluate, render
@named_as_python
def evaluate(model: ModelRef | Policy, episodes: int | None = None, seed_base: int | None = None,
             record: bool = False, record_further: bool = False, replace: bool = False) -> dict[str, Any]:
    """Evaluate on unseen seeds as ``main.py evaluate`` does (episode i seeded ``seed_base + i``,
    default the experiment's evaluation range; ``episodes`` default the experiment's ``eval_episodes``): greedy
    mean/std/min of the return and per-episode records, or for Mario the share of episodes that
    reached the flag. ``line`` holds the one-line report. ``record``: also write it into the model
    folder's meta.json as its evaluation (one recorded already is replaced only with ``replace``).
    ``record_further``: add it to meta.json's ``further_evaluations`` instead, on unseen seeds no
    recorded evaluation played (by default those right after the last ones recorded), the evaluation
    kept."""
    from rlcore.models import shipping

    if record and record_further:
        raise UserError("give record (the model's evaluation) or record_further (one more), not both")
    check_whole("episodes", episodes, EVAL_COUNT, none_ok=True)
    check_whole("seed_base", seed_base, NON_NEGATIVE, none_ok=True)
    policy = load(model)
    count = shipping.eval_episodes(policy.experiment, episodes)
    if record or record_further:
        policy.meta = shipping.record_evaluation(policy.model_dir, count, seed_base, further=record_further,
                                                 replace=replace)
        return dict(policy.meta["further_evaluations"][-1] if record_further else policy.meta["evaluation"])
    summary, line = shipping.run_evaluation(policy.experiment, policy._network, count, seed_base, policy.meta)
    return {**summary, "line": line}


@named_as_python
def render(model: ModelRef | Policy, out: str | os.PathLike[str] = "video.mp4", episodes: int | None = None,
           seed: int | None = None, fps: int | None = None) -> Path:
    """Film ``episodes`` episodes (default the experiment's, 1; Minitaur 3) into ``out``: an ``.mp4``,
    a small looping ``.gif``, or a folder (``EXPERIMENT_ALGO.mp4`` in it). Episode i is seeded ``seed + i`` (default the first evaluation seed).
    Returns the path written."""
    from rlcore.files.atomic import writable_folder
    from rlcore.models.video import video_path
    from rlcore.training.spec import folder_safe

    video_path(out, "video")  # a bad name is refused before the model loads
    check_whole("episodes", episodes, EVAL_COUNT, none_ok=True)
    check_whole("seed", seed, NON_NEGATIVE, none_ok=True)
    check_whole("fps", fps, FRAME_RATE, none_ok=True)
    policy = load(model)
    path = video_path(out, f"{folder_safe(policy.experiment.name)}_{policy.algo}")  # a folder gets the model's name
    writable_folder(path.parent, "out")
    render_policy(policy, path, fps, episodes, seed)
    return path


def render_policy(policy: Policy, out: Path, fps: int | None, episodes: int | None,
                  seed: int | None) -> dict[str, Any]:
    """Write the video; return :func:`rlcore.models.video.record_video`'s record (frames, returns ...)."""
    from rlcore.models.video import record_video

    exp, network = policy.experiment, policy._network
    count = exp.episodes_per_video if episodes is None else episodes
    act = network.sample if exp.goal else None  # Mario plays as it was evaluated
    return record_video(exp, network, out, fps or exp.video_fps, count, seed, make_env=network.make_env, act=act)


@named_as_python
def export(model: ModelRef | Policy, format: ExportFormat, out: str | os.PathLike[str],
           observations: int = 256) -> dict[str, Any]:
    """Export the acting network as a TF SavedModel, a TFLite file or an ONNX file into the folder
    ``out`` and check it against the Keras model (:func:`rlcore.models.export.export_model`); return the
    record written to ``out/export.json``. Needs the export extra for tflite and onnx."""
    from rlcore.host.quiet import load_tensorflow
    from rlcore.models.export import export_model

    policy = load(model)
    load_tensorflow()
    # a run in progress is exported from its last checkpoint, and its record says so, as the CLI's does
    source = f"{policy.model_dir}, last checkpoint" if policy._keep is not None else str(policy.model_dir)
    folder = Path(policy._keep.name) if policy._keep is not None else policy.model_dir  # a run's: its snapshot
    return export_model(folder, format, out, observations=observations, source=source)

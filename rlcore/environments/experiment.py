"""The registry: experiment name -> env factory, algorithms, presets, solved threshold; any other
name that is a Gymnasium id becomes an experiment of its own (:mod:`rlcore.environments.gym_experiment`).

TensorFlow-free, so ``main.py list`` and env-pool workers import it cheaply. Experiment packages
are imported lazily by module path.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import partial
from typing import Callable

from rlcore.errors import UserError


#: experiment name -> module holding ``EXPERIMENT``
@dataclass(frozen=True)
class AlgoSpec:
    """One algorithm of an experiment: which trainer runs it and its named presets."""
    name: str
    kind: str  # trainer / policy family: "dqn" | "a2c" | "ppo" | "sac"
    description: str
    presets: dict  # preset name -> config dataclass instance
    default_preset: str = "default"


@dataclass(frozen=True)
class SeedsBar:
    """What the shipped model's recipe must reach over seeds (its sweep, kept in ``results/sweeps/``), and
    why: over ``seeds`` seeds, the ``statistic`` (``iqm`` or ``median``, as ``main.py report`` computes
    it) of their scores at least ``value``, and, with ``least``, every seed at least that. Scores as the
    model's :class:`Bar` reads them. A sweep of fewer seeds is not judged."""
    statistic: str
    value: float
    seeds: int
    reason: str
    least: float | None = None

    def met_by(self, point: float, scores: list[float]) -> bool | None:
        """Whether a sweep clears it: ``point``, the statistic over its seeds; ``scores``, each seed's.
        None (not judged) for fewer seeds than the bar is set over."""
        if len(scores) < self.seeds:
            return None
        return point >= self.value and (self.least is None or min(scores) >= self.least)

    def describe(self, share: bool) -> str:
        """``IQM over 5 seeds >= 11.3`` or ``median over 3 seeds >= 80%, every seed >= 50%`` (``share``:
        scores are success shares)."""
        show = (lambda v: f"{v:.0%}") if share else (lambda v: f"{v:g}")
        name = "IQM" if self.statistic == "iqm" else self.statistic
        return (f"{name} over {self.seeds} seeds >= {show(self.value)}"
                + ("" if self.least is None else f", every seed >= {show(self.least)}"))


@dataclass(frozen=True)
class Bar:
    """What a shipped model must reach in its evaluation on unseen seeds, and why that number.

    ``metric``: ``mean`` (mean return of the greedy or mean-action policy) or ``success_share``
    (share of episodes reaching the success event, actions sampled from pi). ``full_length_share``:
    the least share of episodes that must last to the time limit (a walk, not a dash and a fall).
    """
    metric: str
    value: float
    reason: str
    full_length_share: float | None = None
    over_seeds: SeedsBar | None = None  # what the recipe must reach over seeds, where a bar is set for it
    published: str | None = None  # what others published for the same task, with the source (the results tables)

    def met_by(self, evaluation: dict) -> bool:
        """Whether a recorded evaluation (meta.json's ``evaluation``) clears the bar."""
        if evaluation.get(self.metric) is None or evaluation[self.metric] < self.value:
            return False
        return self.full_length_share is None or evaluation.get("time_limit_share", 0.0) >= self.full_length_share

    def describe(self, success: str = "success") -> str:
        """``mean return >= 230`` or ``flag in >= 50% of episodes`` (``success``: what a successful episode
        reaches, :func:`rlcore.records.score_words.success_word`), for cards, tables and the console."""
        if self.metric == "success_share":
            text = f"{success} in >= {self.value:.0%} of episodes"
        else:
            text = f"mean return >= {self.value:g}"
        if self.full_length_share is not None:
            text += f", >= {self.full_length_share:.0%} of episodes full length"
        return text


@dataclass(frozen=True)
class Goal:
    """A task scored by an event, not by a return: an info key marks a successful episode.

    With a goal the trainers log success per episode and the stop rule reads the success share;
    evaluation counts successes and plays actions sampled from pi (a greedy policy would play one
    deterministic trajectory), as do render and the export's parity check; videos count successes.
    """
    success_key: str  # an info key, true at the end of a successful episode (Mario: flag_get)
    # an info key that measures how far an episode got (Mario: x_pos): logged per episode and per
    # rollout, evaluated, and plotted (progress and endings plots)
    progress_key: str | None = None
    # an info key that says, as a number, what ended a failed episode (Mario: killed_by, a fall, the
    # clock or an enemy), and the words for a number (Mario: mario_ppo.deaths.cause_name): the
    # evaluation line counts its failures by cause, and a Deaths plot shows the causes' shares
    cause_key: str | None = None
    cause_name: Callable[[float], str] = str

    def __post_init__(self) -> None:
        if not self.success_key:
            raise ValueError("a Goal needs the info key that marks success")


@dataclass(frozen=True)
class Curriculum:
    """What the training env does that evaluation's does not (Mario: restarts further into the level).

    Its fields reach only the trainer's env pool; episodes that start elsewhere train like any other
    but are marked, and what the envs build up over episodes is kept by the checkpoint.
    """
    # config fields that make_env takes in training only (Mario: restart_x, restart_every, ...): the
    # trainer's env pool gets them; evaluations, videos and saved models build the env without them
    env_fields: tuple[str, ...] = ()
    # an info key that marks an episode that did not start where evaluation starts (Mario: restarted):
    # it trains like any other, but its success is left out of the success share the stop rule reads,
    # and its return and progress out of the plots
    partial_key: str | None = None
    partial_start_key: str | None = None  # an info key: where a partial episode started (Mario: start_x)
    # an attribute of the training env that it builds up over episodes, a dict of name -> array, which
    # a checkpoint keeps and a resumed run's env pool gets back (Mario: restart_routes, the buttons that
    # lead to each kept restart point); ignored when the env has no such attribute
    memory: str | None = None
    # share_memory(per_env, config) rewrites the memory a resumed pool hands out, one dict per env
    # (Mario: mario_ppo.curriculum.lend_routes, envs whose restart x never stepped back take the
    # routes of envs whose x did)
    share_memory: Callable[[list[dict], object], list[dict]] | None = None


@dataclass(frozen=True)
class ShippedBy:
    """Models shipped one per value of some config fields (Mario: one per level, world and stage),
    not one per algorithm: saved_networks/EXPERIMENT/<the values joined by '-'>."""
    fields: tuple[str, ...]  # the config fields (Mario: world, stage -> saved_networks/mario_ppo/1-1)
    default: str  # the folder evaluate/render/load take when no value is given (Mario: 1-1)
    noun: str = "model"  # what one such model is, for messages (Mario: level)

    def __post_init__(self) -> None:
        if not self.fields:
            raise ValueError("ShippedBy needs at least one config field")

    def folder(self, values) -> str:
        """The model folder's name for a config (or any object with the fields as attributes)."""
        return "-".join(str(getattr(values, name)) for name in self.fields)

    def default_values(self) -> dict[str, str]:
        """Each field's value in the default folder (Mario: ``{"world": "1", "stage": "1"}``)."""
        return dict(zip(self.fields, self.default.split("-")))

    def folder_from(self, given: dict) -> str:
        """The folder of the values given on a command line (``None``: the default folder's value)."""
        defaults = self.default_values()
        return "-".join(str(defaults[f] if given.get(f) is None else given[f]) for f in self.fields)


@dataclass(frozen=True)
class Experiment:
    """What an experiment declares. Only the first five are required (what a user writes for their
    env); the rest say how it is evaluated, shipped, plotted and filmed when it differs from a
    return-scored gymnasium task, and ``goal``, ``curriculum``, ``shipped_by`` are the typed
    extensions of an experiment scored by an event (Mario's flag)."""
    name: str
    description: str
    make_env: Callable  # make_env(render_mode=None, max_episode_steps=None, **env_fields) -> gymnasium.Env
    algos: dict[str, AlgoSpec]
    solved_score: float | None  # None: no return threshold (Mario's success is the flag)
    eval_seed_base: int = 1_000_000  # final evaluation seeds start here; training never uses them
    selection_seed_base: int = 2_000_000  # periodic evaluations during training (model selection)
    eval_episodes: int = 100  # episodes of the final evaluation on unseen seeds
    # config fields that make_env takes (Mario: world, stage, ...): recorded, so a model rebuilds its env
    env_fields: tuple[str, ...] = ()
    # info keys whose value at an episode's end is kept per episode: in metrics.csv by the PPO and SAC
    # trainers, and in the evaluation's per-episode records (Mario: stalled, 1 when the stall limit
    # ended it; Minitaur: x, metres walked)
    info_keys: tuple[str, ...] = ()
    score_label: str = "return"  # the y label of the returns plot
    plot_prefix: str = ""  # the plot files' name prefix (empty: the experiment's name)
    video_fps: int = 30
    episodes_per_video: int = 1
    # the bar each shipped model must clear, by model folder name (the algorithm, or Mario's level):
    # the one place it is written; tests, cards and the README read it here
    bars: dict[str, Bar] = field(default_factory=dict)
    # shipped models that miss their bar, and why each still ships (a bar raised before the model that meets it
    # is trained): their cards say so, and the tests hold every other shipped model to its bar
    below_bar: dict[str, str] = field(default_factory=dict)
    # algorithms that cannot train on this env -> why, in one clause (a Gymnasium id's spaces:
    # ``sac`` on discrete actions); asking for one is that one line, not "unknown algorithm"
    unfit: dict[str, str] = field(default_factory=dict)
    # what meta.json records of the env beyond the experiment's name, so a model folder rebuilds it in
    # a fresh process (a Gymnasium id: its entry point, kwargs, limits; rlcore.environments.gym_experiment)
    env_record: dict = field(default_factory=dict)
    goal: Goal | None = None  # success is an event an info key marks (Mario: the flag); None: the return
    curriculum: Curriculum | None = None  # training-only env settings (Mario: restarts); None: none
    shipped_by: ShippedBy | None = None  # one shipped model per config value (Mario: level); None: per algorithm

    def training_env_factory(self, config) -> Callable:
        """:meth:`env_factory` plus the curriculum's training-only fields (``Curriculum.env_fields``)."""
        fields = self.curriculum.env_fields if self.curriculum else ()
        return self.env_factory(config, **{name: getattr(config, name) for name in fields})

    def env_factory(self, config=None, **kwargs) -> Callable:
        """A picklable no-argument env constructor for ``config`` (env-pool workers call it).

        Experiments whose env depends on hyperparameters (Mario: world, stage, action set) list
        those fields in ``env_fields``.
        """
        for name in self.env_fields:
            if config is not None:
                kwargs.setdefault(name, getattr(config, name))
        if config is not None:
            kwargs.setdefault("max_episode_steps", config.max_episode_steps or None)
        return partial(self.make_env, **kwargs)

    def bar(self, model: str) -> Bar | None:
        """The bar of the shipped model ``model`` (an algorithm, or Mario's ``1-1``), if it has one."""
        return self.bars.get(model)

    def algo(self, name: str) -> AlgoSpec:
        if name in self.unfit:
            fitting = (f"; algorithms that fit it: {', '.join(self.algos)}" if self.algos
                       else "; no algorithm of this package fits it")
            raise UserError(f"{name} does not fit {self.name}: {self.unfit[name]}{fitting}")
        if name not in self.algos:
            raise UserError(f"unknown algorithm {name!r} for {self.name}; choose one of "
                            f"{', '.join(self.algos)}")
        return self.algos[name]

    def preset(self, algo: str, preset: str | None):
        spec = self.algo(algo)
        preset = preset or spec.default_preset
        if preset not in spec.presets:
            raise UserError(f"unknown preset {preset!r} for {self.name} {algo}; choose one of "
                            f"{', '.join(spec.presets)}")
        return spec.presets[preset]

"""Where shipped models live (saved_networks/), how a finished run is published there, and the
evaluation a model folder records in its meta.json. TensorFlow is imported only to evaluate."""
from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np

from rlcore.errors import UserError
from rlcore.records.score_words import count, return_digits, score_words, success_word

#: the saved_networks/ of the checkout this package runs from (``python main.py`` or an editable install)
SAVED_NETWORKS = Path(__file__).resolve().parents[2] / "saved_networks"
#: where to find the shipped models when the package is installed apart from its checkout
MODELS_ENV = "DEEPRL_MODELS"


def models_root() -> Path:
    """The folder shipped models are read from (and ``--publish`` writes to): ``$DEEPRL_MODELS`` if set;
    else the checkout's saved_networks/; else, for a copy installed into site-packages (``pip install .``,
    which holds the code but not the 79 MB of models), ./saved_networks when the command runs in a clone."""
    given = os.environ.get(MODELS_ENV)
    if given:
        return Path(given).expanduser().resolve()
    if SAVED_NETWORKS.is_dir():
        return SAVED_NETWORKS
    here = Path.cwd() / "saved_networks"
    return here if here.is_dir() else SAVED_NETWORKS


def require_shipped(folder: Path, what: str) -> Path:
    """``folder`` if it holds a shipped model, else one line: where shipped models live when there are
    none at all, or which of its neighbours are shipped (``what`` names the model asked for)."""
    if (folder / "meta.json").is_file():
        return folder
    root = models_root()
    if not root.is_dir():
        raise UserError(f"no shipped models at {root}: they live in the saved_networks/ folder of a clone of the "
                        f"repository; run there, set {MODELS_ENV}=/path/to/saved_networks, or give a model folder")
    shipped = sorted(p.parent.name for p in folder.parent.glob("*/meta.json"))
    raise UserError(f"no shipped model {what} in {folder.parent}; shipped: {', '.join(shipped) or 'none'} "
                    f"(or give a model folder)")


def shipped_dir(experiment: str, algo: str, config=None) -> Path:
    """saved_networks/EXPERIMENT/ALGO, or for Mario saved_networks/mario_ppo/WORLD-STAGE (one
    model per level: the experiment's ``shipped_by`` names the config fields; without a config, its
    ``default`` folder), under :func:`models_root`."""
    from rlcore.environments.registry import get_experiment

    shipped_by = get_experiment(experiment).shipped_by
    root = models_root()
    if shipped_by is None:
        return root / experiment / algo
    if config is None:
        return root / experiment / shipped_by.default
    return root / experiment / shipped_by.folder(config)



def shipped_summary(folder: Path) -> str:
    """``shipped: 20.45 +- 3.99 over 30 episodes`` or ``1-1: flag in 8 of 10 episodes``, as the README
    writes the score (:mod:`rlcore.records.score_words`)."""
    from rlcore.files.model_meta import read_meta

    ev = read_meta(folder).get("evaluation")
    if not ev:
        return f"{folder.name}: shipped (not evaluated)"
    words = score_words(ev, folder.parent.name, folder.name, plus_minus="+-")
    if "success_share" in ev:
        return f"{folder.name}: {words} episodes"
    return f"shipped: {words} over {ev['episodes']} episodes"


def model_name(exp, meta: dict | None) -> str:
    """A model's name as its shipped folder has it (Mario: its level, ``1-4``), from its meta.json's config;
    empty for experiments that ship one model per algorithm, or without a meta."""
    if exp.shipped_by is None or not meta:
        return ""
    config = meta.get("config") or {}
    return "-".join(str(config.get(name, "")) for name in exp.shipped_by.fields)


def eval_episodes(exp, requested: int | None) -> int:
    return exp.eval_episodes if requested is None else requested


def run_evaluation(exp, policy, episodes: int, seed_base: int | None, meta: dict | None = None) -> tuple[dict, str]:
    """Evaluate a loaded policy on unseen seeds: ``(summary for meta.json, one-line report)``.

    Experiments with a success event (Mario's flag) draw actions from pi with a per-episode seed
    (their greedy play is one deterministic trajectory); the others play greedily. ``meta``, the model's,
    names what a success reaches (1-4's axe) as the README does.
    """
    seed_base = exp.eval_seed_base if seed_base is None else seed_base
    seeds = f"{seed_base}..{seed_base + episodes - 1}"
    evaluate = _evaluate_success if exp.goal else _evaluate_returns
    found, line = evaluate(exp, policy, episodes, seed_base, meta)
    summary = {key: value for key, value in found.items() if key not in ("policy", "per_episode")}
    summary.update(seeds=seeds, policy=found["policy"], per_episode=found["per_episode"])  # meta.json's order
    return summary, line + _bar_words(exp, meta, summary, seed_base) + (
        f" (seeds {seeds}, actions sampled from pi)" if exp.goal else "")


def _evaluate_success(exp, policy, episodes: int, seed_base: int, meta: dict | None) -> tuple[dict, str]:
    """The share of episodes reaching the goal, actions drawn from pi."""
    from rlcore.training.evaluation import count_causes, evaluate_success, summarize_success

    goal = exp.goal
    success_key, progress_key = goal.success_key, goal.progress_key
    records = evaluate_success(policy.make_env, policy.sample, episodes, seed_base, success_key,
                               progress_key, info_keys=exp.info_keys)
    summary = {**summarize_success(records, progress_key), "policy": "sampled from pi, numpy RNG seeded per episode",
               "per_episode": records}
    word = success_word(exp.name, model_name(exp, meta), other=success_key)
    line = (f"{word} in {sum(r['success'] for r in records)} of {len(records)} episodes "
            f"({summary['success_share']:.0%}); mean return {summary['mean_return']:.1f}")
    if progress_key:
        line += f"; {progress_key} mean {summary[f'mean_{progress_key}']:.0f}, max {summary[f'max_{progress_key}']:.0f}"
    if goal.cause_key and (causes := count_causes(records, goal.cause_key, goal.cause_name)):
        summary["causes"] = dict(causes)
        line += f"; {goal.cause_key}: " + ", ".join(f"{name} {count}" for name, count in causes)
    return summary, line


def _evaluate_returns(exp, policy, episodes: int, seed_base: int, meta: dict | None) -> tuple[dict, str]:
    """The return of greedy play (SAC: its mean action), with the info keys the experiment reports."""
    from rlcore.networks.acting import MeanActionPolicy
    from rlcore.training.evaluation import play_greedy

    records = play_greedy(exp, policy, episodes, seed_base, make_env=policy.make_env, info_keys=exp.info_keys)
    returns = np.array([r["return"] for r in records])
    full = sum(r["time_limit"] for r in records)
    summary = {"episodes": episodes, "mean": round(float(returns.mean()), 2), "std": round(float(returns.std()), 2),
               "min": round(float(returns.min()), 2), "max": round(float(returns.max()), 2),
               "time_limit_share": round(full / episodes, 3), "policy": "greedy", "per_episode": records}
    digits = return_digits(summary["mean"])  # as score_words, the README and `list` write the recorded one
    acting = "mean-action" if isinstance(policy, MeanActionPolicy) else "greedy"
    line = (f"{acting} return {score_words(summary, exp.name, '', '+-')} over {count(len(returns), 'episode')} "
            f"(min {returns.min():,.{digits}f}, max {returns.max():,.{digits}f}); {full}/{episodes} lasted to "
            f"the time limit")
    for key in exp.info_keys:
        values = [r[key] for r in records if key in r]
        if values:
            summary[f"mean_{key}"] = round(float(np.mean(values)), 2)
            line += f"; {key} at the end: mean {np.mean(values):.2f}, max {np.max(values):.2f}"
    if exp.solved_score is not None:
        line += f"; the task's solved score {exp.solved_score:g}: {'met' if returns.mean() >= exp.solved_score else 'not met'}"
    return summary, line


def _bar_words(exp, meta: dict | None, summary: dict, seed_base: int) -> str:
    """``; the shipped model's bar (mean return >= 230): met``, for a model of an algorithm or level that
    ships one with a bar (the task's solved score is another number: LunarLander's 200, Minitaur's 15).
    The bar is judged on the experiment's evaluation (its episode count, on seeds no part of training
    met): fewer episodes, seeds in training's range, or the seeds of the periodic evaluations that chose
    the model's weights, say so beside the verdict. Seeds past those are as unseen as the unseen range."""
    bar = exp.bar(model_name(exp, meta) or str(meta.get("algo", ""))) if meta else None
    if bar is None:
        return ""
    caveats = []
    if summary["episodes"] < exp.eval_episodes:
        caveats.append(f"on {count(summary['episodes'], 'episode')}, where it is judged on {exp.eval_episodes}")
    seeds = range(seed_base, seed_base + summary["episodes"])
    config = meta.get("config") or {}
    periodic = range(exp.selection_seed_base,
                     exp.selection_seed_base + (int(config.get("eval_episodes") or 0) if config.get("eval_every_steps") else 0))
    if seeds.start < exp.eval_seed_base:
        caveats.append("on seeds in training's range, which training may have met")
    elif seeds.start < periodic.stop and periodic.start < seeds.stop:
        caveats.append("on the seeds of the periodic evaluations that chose the model's weights")
    verdict = "met" if bar.met_by(summary) else "not met"
    name = model_name(exp, meta) or str(meta.get("algo", ""))
    return (f"; the shipped model's bar ({bar.describe(success_word(exp.name, name))}): {verdict}"
            + (f" ({'; '.join(caveats)})" if caveats else ""))


def record_evaluation(model_dir: Path, episodes: int, seed_base: int | None = None, experiment: str | None = None,
                      algo: str | None = None, *, further: bool = False, replace: bool = False) -> dict:
    """Evaluate a model on unseen seeds and write the result into its meta.json: as its ``evaluation`` (refused
    over one recorded already unless ``replace``: a shipped model's 100 episodes are not overwritten by a
    1-episode try), or with ``further`` added to its ``further_evaluations``, its evaluation kept (by default on
    the seeds right after the last ones recorded: a held-out check on seeds nothing chose the model by). Seeds
    another recorded evaluation played are refused: they would no longer be held out. Returns the meta."""
    from rlcore.files.atomic import write_json
    from rlcore.files.model_meta import read_meta
    from rlcore.host.machine import this_machine
    from rlcore.models.policies import load_policy

    def others(meta: dict) -> list[dict]:  # the recorded evaluations the new one's seeds must keep clear of
        return [ev for ev in [meta.get("evaluation") if further else None, *meta.get("further_evaluations", [])] if ev]

    exp, meta = experiment_of(model_dir), read_meta(model_dir)
    if meta.get("evaluation") and not (replace or further):
        raise UserError(_replace_refusal(model_dir, meta["evaluation"], exp, meta))
    if seed_base is None:
        seed_base = max((seed_range(ev).stop for ev in others(meta)), default=exp.eval_seed_base) if further \
            else exp.eval_seed_base
    wanted = range(seed_base, seed_base + episodes)
    if further and (wanted.start < exp.eval_seed_base or wanted.stop > exp.selection_seed_base):
        raise UserError(f"--seed-base {seed_base} with {episodes} episodes plays seeds {wanted.start}..{wanted.stop - 1}, "
                        f"outside {exp.name}'s unseen range {exp.eval_seed_base}..{exp.selection_seed_base - 1}")
    _check_seeds_free(wanted, others(meta), "an evaluation" if further else "a further evaluation")
    exp, loaded, policy = load_policy(model_dir, experiment, algo)
    summary, line = run_evaluation(exp, policy, episodes, seed_base, loaded)
    summary["machine"] = this_machine()  # where these episodes replay exactly (rlcore.host.machine)
    meta = read_meta(model_dir)  # as it is now: another process may have recorded an evaluation meanwhile
    _check_seeds_free(wanted, others(meta), "an evaluation" if further else "a further evaluation")
    if further:
        meta["further_evaluations"] = [*meta.get("further_evaluations", []), summary]
    else:
        meta["evaluation"] = summary
    write_json(model_dir / "meta.json", meta)
    print(f"{'further evaluation' if further else 'evaluation'} (unseen seeds): {line}")
    return meta


def _replace_refusal(model_dir: Path, evaluation: dict, exp, meta: dict) -> str:
    """The line refusing to overwrite a recorded evaluation, naming it and the two ways on."""
    from rlcore.hyperparams.allowed import in_python

    words = score_words(evaluation, exp.name, model_name(exp, meta), plus_minus="+-")
    seeds = f" on seeds {evaluation['seeds']}" if evaluation.get("seeds") else ""
    further, replace = (("record_further=True", "replace=True") if in_python() else
                        ("--record-further", "--replace"))
    return (f"{model_dir / 'meta.json'} records an evaluation already ({words}, {evaluation.get('episodes')} "
            f"episodes{seeds}); {further} adds one on other unseen seeds, {replace} overwrites it")


def seed_range(evaluation: dict) -> range:
    """The seeds a recorded evaluation played (its ``seeds``, ``"1000000..1000009"``)."""
    try:
        first, last = (int(x) for x in evaluation["seeds"].split(".."))
    except (KeyError, ValueError, AttributeError):
        raise UserError(f"a recorded evaluation does not say which seeds it played (seeds: "
                        f"{evaluation.get('seeds')!r}); evaluate the model again with --record") from None
    return range(first, last + 1)


def _check_seeds_free(wanted: range, recorded: list[dict], what: str) -> None:
    for ev in recorded:
        played = seed_range(ev)
        if wanted.start < played.stop and played.start < wanted.stop:
            raise UserError(f"seeds {wanted.start}..{wanted.stop - 1} overlap those of {what} already recorded "
                            f"({ev['seeds']}), which would no longer be held out: choose other seeds with "
                            f"--seed-base (from {max(seed_range(r).stop for r in recorded)})")


def experiment_of(model_dir: Path):
    """The experiment a model folder's meta.json names, without loading the model."""
    from rlcore.environments.registry import get_experiment
    from rlcore.files.model_meta import read_meta

    meta = read_meta(model_dir)
    if not meta.get("experiment"):
        raise UserError(f"{model_dir / 'meta.json'} names no experiment: not a model folder of this package")
    return get_experiment(meta["experiment"], meta.get("env"))


def publish_refusal(experiment, target: Path, meta: dict) -> str | None:
    """Why a finished run's model (its ``meta``) may not become the shipped model at ``target``: it has
    no evaluation on unseen seeds, or that evaluation misses the bar of the model it would replace
    (``experiment.bar``). None: it may."""
    evaluation = meta.get("evaluation")
    if not evaluation:
        return "it has no evaluation on unseen seeds (it was trained with --final-eval-episodes 0)"
    if (evaluation.get("episodes") or 0) < experiment.eval_episodes:  # a bar met on one lucky episode is not met
        return (f"its evaluation has {evaluation.get('episodes') or 0} episodes; a shipped model's has "
                f"{experiment.eval_episodes}")
    bar = experiment.bar(target.name)
    if bar is not None and not bar.met_by(evaluation) and not ships_short_of_bar(experiment, target.name, meta):
        return (f"its evaluation misses the bar of the shipped {target.name} "
                f"({bar.describe(success_word(experiment.name, target.name))})")
    return None


def ships_short_of_bar(experiment, name: str, meta: dict) -> bool:
    """A run that misses its bar still replaces a shipped model that misses it too (the registry's
    ``below_bar``) when it spent its preset's whole env-step budget, set before the run: it is then the best
    run of its recipe (issue 63: a Mario level that cannot reach the bar within its budget ships that run)."""
    config, preset = meta.get("config") or {}, meta.get("preset")
    try:
        budget = experiment.preset(meta.get("algo"), preset).max_env_steps if preset else None
    except (UserError, AttributeError):  # a preset renamed since, or one without an env-step budget
        return False
    return (name in experiment.below_bar and bool(budget) and config.get("max_env_steps") == budget
            and meta.get("stopped_by") == f"max_env_steps {budget}")


def publish(model_dir: Path, target: Path) -> None:
    """Make ``target`` (a saved_networks/ folder) an exact copy of ``model_dir``, replacing it whole
    (:func:`rlcore.files.atomic.replace_folder`: files of an earlier model that the new one lacks do not
    survive, and a crash leaves the old folder or the new one, never a mix)."""
    from rlcore.files.atomic import replace_folder, write_json
    from rlcore.files.model_meta import read_meta

    replaced = replaced_record(target)

    def fill(fresh: Path) -> None:
        for src in sorted(p for p in model_dir.iterdir() if p.is_file()):
            shutil.copyfile(src, fresh / src.name)
        if replaced:  # the card gives the score of the model it replaced beside its own
            write_json(fresh / "meta.json", {**read_meta(fresh), "replaces": replaced})

    replace_folder(target, fill)


def replaced_record(target: Path) -> dict | None:
    """What the shipped model at ``target`` was, for the meta.json of the model that replaces it: its evaluation
    (without its episodes), its number of commands, and the env steps and wall seconds it cost with the runs it
    started from (``--init-from``). None where nothing readable is shipped there."""
    from rlcore.files.model_meta import cost_from_scratch, read_meta

    try:
        meta = read_meta(target)
    except UserError:  # nothing shipped there, or a damaged record the new model repairs
        return None
    (env_steps, wall_seconds), evaluation = cost_from_scratch(meta), meta.get("evaluation") or {}
    return {"preset": meta.get("preset"), "commands": len(meta.get("commands") or []),
            "evaluation": {k: v for k, v in evaluation.items() if k not in ("per_episode", "machine")},
            "env_steps": env_steps, "wall_seconds": wall_seconds, "finished": meta.get("finished")}

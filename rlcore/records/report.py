"""``main.py report``: per-run results of one or more sweeps, aggregated with confidence intervals
(mean, median and IQM with 95 % stratified bootstrap intervals, as rliable has them: :mod:`rlcore.records.bootstrap`),
and what each run's periodic evaluations and critic saw. Keeping runs in ``results/``: :mod:`rlcore.records.keeping`.

A run's final score is the evaluation on unseen seeds in its ``model/meta.json``: the greedy mean
return, or for Mario the share of episodes that reached the flag. TensorFlow-free.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from rlcore.errors import UserError
from rlcore.files.model_meta import read_json
from rlcore.records.bootstrap import AGGREGATES, aggregates, probability_of_improvement, stratified_bootstrap_ci
from rlcore.records.commands import cpus_text
from rlcore.records.eval_history import stability_summary, story, story_text
from rlcore.records.score_words import count


def load_runs(sweep_dir: Path) -> list[dict]:
    """One row per run folder of a sweep: trial, final score, env steps, wall time and the CPU it ran
    on (finished runs only)."""
    sweep_dir = Path(sweep_dir)
    if not sweep_dir.is_dir():
        raise UserError(f"no sweep folder {sweep_dir}")
    rows, unevaluated = [], []
    for meta_path in sorted(sweep_dir.glob("*/model/meta.json")):
        meta = read_json(meta_path, "move that run's folder aside or train it again")
        ev = meta.get("evaluation") or {}
        score = ev.get("success_share", ev.get("mean"))
        if score is None:
            unevaluated.append(meta_path.parent.parent.name)  # trained but not evaluated: no score
            continue
        rows.append({"trial": meta_path.parent.parent.name, "seed": meta["seed"], "score": float(score),
                     "goal": _goal_word(meta) if "success_share" in ev else None,
                     "stop_share": (meta.get("config") or {}).get("stop_success_share") or None,
                     "eval_episodes": ev.get("episodes"), "env_steps": meta["env_steps"],
                     "wall_seconds": meta["wall_seconds"], "run_dir": meta_path.parent.parent,
                     "cpu": cpus_text(meta), "time_limit_share": ev.get("time_limit_share"),
                     "further": [(f["episodes"], f.get("success_share", f.get("mean")))
                                 for f in meta.get("further_evaluations", [])],
                     "story": story(meta_path.parent.parent, meta, _solved_score(meta)),
                     "what": f"{meta.get('experiment')} {meta.get('algo')}"})
    if not rows:
        raise UserError(f"{sweep_dir} holds no finished, evaluated run (model/meta.json with an evaluation)")
    if unevaluated:  # leaving a trained seed out would report the others as if they were all
        raise UserError(f"{sweep_dir}: {', '.join(unevaluated)} trained but has no evaluation on unseen seeds; "
                        f"evaluate it first (a sweep's --resume does, or `python main.py evaluate ... --model "
                        f"RUN_DIR --record`)")
    kinds = sorted({row["what"] for row in rows})
    if len(kinds) > 1:  # one aggregate over unlike scores would mean nothing
        raise UserError(f"{sweep_dir} holds runs of {' and '.join(kinds)}: a report aggregates one experiment "
                        f"and algorithm per folder; give each its own SWEEP_DIR")
    return rows


def _goal_word(meta: dict) -> str:
    """What a run's successful episodes reach (Mario: flag, or axe on x-4), as the cards say it: the model's
    name read from its config as its shipped folder would have it (:func:`rlcore.models.shipping.model_name`)."""
    from rlcore.environments.registry import get_experiment
    from rlcore.models.shipping import model_name
    from rlcore.records.score_words import success_word

    exp = get_experiment(meta["experiment"])
    return success_word(exp.name, model_name(exp, meta), other="goal")


def _solved_score(meta: dict) -> float | None:
    """The solved score of the task a run's meta.json names: a Gymnasium id's recorded
    ``reward_threshold``, else the registry's. None where it has none or it cannot be known here (then
    nothing is claimed, :func:`rlcore.records.eval_history.far_from_solved`): a report never needs the env itself."""
    from rlcore.environments.registry import EXPERIMENT_MODULES, get_experiment

    env = meta.get("env")
    if isinstance(env, dict) and "reward_threshold" in env:
        threshold = env["reward_threshold"]
        return None if threshold is None else float(threshold)
    if meta.get("experiment") not in EXPERIMENT_MODULES:
        return None  # a Gymnasium id without its record: building its env only to learn this is not worth it
    try:
        return get_experiment(meta["experiment"]).solved_score
    except Exception:  # the experiment's extra is missing, or its module fails to import: no claim
        return None


def setting_of(trial: str) -> str:
    """``lr=0.0001__seed=3`` -> ``lr=0.0001``: the grid values, which group runs across seeds."""
    return "__".join(part for part in trial.split("__") if not part.startswith("seed="))


def summarize(sweep_dirs: list[Path], reps: int = 5000) -> dict:
    """Everything ``main.py report`` prints, as numbers: one group per sweep and grid setting."""
    groups = []
    for folder in sweep_dirs:
        runs = load_runs(folder)
        settings = sorted({setting_of(r["trial"]) for r in runs})
        for setting in settings:
            members = [r for r in runs if setting_of(r["trial"]) == setting]
            scores = np.array([[r["score"]] for r in members])
            point, ci = stratified_bootstrap_ci(aggregates, scores, reps=reps)
            label = Path(folder).name + (f" [{setting}]" if setting else "")
            groups.append({"folder": Path(folder), "label": label, "runs": members,
                           "aggregates": {name: (float(point[i]), float(ci[0][i]), float(ci[1][i]))
                                          for i, name in enumerate(AGGREGATES)}})
    result = {"sweeps": groups}
    if len(groups) == 2:
        x, y = (np.array([[r["score"]] for r in g["runs"]]) for g in groups)
        point, ci = stratified_bootstrap_ci(lambda a, b: probability_of_improvement(a, b), x, y, reps=reps)
        result["probability_of_improvement"] = (float(point), float(ci[0]), float(ci[1]))
    return result


def share_text(share: float | None) -> str:
    return "–" if share is None else f"{share:.0%}"


def markdown(result: dict) -> str:
    lines = []
    for s in result["sweeps"]:
        goals = {r["goal"] for r in s["runs"]}
        # a goal's runs are scored by the share of episodes reaching it (Mario: "flag share 0.800 (8 of 10)")
        score = f"{goals.pop()} share" if len(goals) == 1 and None not in goals else "final score"
        lines += [f"## {s['label']} ({s['folder']})", "",
                  f"| run | seed | {score} (unseen seeds) | to time limit | env steps | wall | env steps/s | CPU |",
                  "| --- | ---: | ---: | ---: | ---: | ---: | ---: | --- |"]
        lines += [f"| {r['trial']} | {r['seed']} | {r['score']:.3f}{_of(r)} | {share_text(r.get('time_limit_share'))} "
                  f"| {r['env_steps']:,} | {r['wall_seconds']:.0f} s | {r['env_steps'] / max(r['wall_seconds'], 1e-9):,.0f} "
                  f"| {r.get('cpu') or 'not recorded'} |" for r in s["runs"]]
        lines += ["", f"| over {count(len(s['runs']), 'run')} | point | 95% CI (stratified bootstrap) |",
                  "| --- | ---: | --- |"]
        lines += [f"| {name} | {p:.3f} | [{lo:.3f}, {hi:.3f}] |" for name, (p, lo, hi) in s["aggregates"].items()]
        if any(r.get("further") for r in s["runs"]):
            lines += ["", "Further evaluations on other unseen seeds (`evaluate --record-further`), each run's in order:",
                      ""] + [f"- {r['trial']}: " + ("; ".join(f"{score:.3f} " + (
                                 f"({round(score * episodes)} of {episodes} episodes)" if r.get("goal")
                                 else f"over {episodes} episodes") for episodes, score in r["further"]) or "none")
                             for r in s["runs"]]
        lines += ["", *stability_lines(s["runs"]), ""]
        if critic := critic_lines(s["runs"]):
            lines += [*critic, ""]
    if "probability_of_improvement" in result:
        p, lo, hi = result["probability_of_improvement"]
        first, second = (s["label"] for s in result["sweeps"])
        lines += [f"P({first} > {second}) = {p:.3f} [{lo:.3f}, {hi:.3f}]", ""]
    return "\n".join(lines)


def _of(run: dict) -> str:
    """`` (8 of 10)`` beside a goal's share: the episodes behind it; nothing beside a mean return."""
    if not run.get("goal") or not run.get("eval_episodes"):
        return ""
    return f" ({round(run['score'] * run['eval_episodes'])} of {run['eval_episodes']})"


def stability_lines(runs: list[dict]) -> list[str]:
    """What the runs' periodic evaluations (on selection seeds) say: collapses and the weights kept
    (:mod:`rlcore.records.eval_history` defines a collapse)."""
    stories = [r["story"] for r in runs]
    if not any(st.evaluations for st in stories):
        return ["No periodic evaluations: each model holds its run's last weights."]
    lines = [f"Periodic evaluations (selection seeds): {stability_summary(stories)}", ""]
    lines += [f"- {r['trial']}: {story_text(r['story'])}" for r in runs]
    return lines


def critic_lines(runs: list[dict]) -> list[str]:
    """Each run's critic at its end beside the largest return it was paid (:mod:`rlcore.records.critic_trace`);
    nothing for runs that log no Q."""
    from rlcore.records.critic_trace import WINDOW, critic_cell, critic_trace

    traces = [critic_trace(r["run_dir"]) for r in runs]
    if all(t is None for t in traces):
        return []
    return [f"Critic: the mean Q of its training batches at the end of each run (median of its last {WINDOW} "
            f"episodes), beside the largest return of any of its training episodes (– where a run logs no Q); "
            f"report_critic.png draws that running median over training.", ""] + [
        f"- {r['trial']}: {critic_cell(t)}" for r, t in zip(runs, traces)]

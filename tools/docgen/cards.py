"""Model cards (``saved_networks/.../README.md``), their pages on the docs site (``docs/models/``) and the
results page, filled into templates/ from each model folder's meta.json and the kept sweeps."""
import json

from rlcore.algorithms.registry import FAMILIES
from rlcore.environments.registry import experiment_names, get_experiment
from rlcore.hyperparams.flags import to_dict
from rlcore.records.score_words import hours, score_words
from tools.docgen.data import REPO
from tools.docgen.reference import region_bars
from tools.docgen.regions import OVER_SEEDS_HEADER, experiment_page, region_shipped, region_sweeps
from tools.docgen.sweeps import stop_text
from tools.docgen.words import (
    article_of,
    bar_met,
    bar_text,
    fill,
    link,
    over_seeds,
    ret,
    score_text,
    sweep_score,
    table,
)

#: what a model folder's file is, by its name or extension, or a plot by its kind (PREFIX_KIND_ALGO.png, as
#: rlcore/records/plotting.py names it)
FILE_ROLES = {".h5": "Keras model (the whole network, loadable on its own)", "meta.json":
              "what the run was: preset, every hyperparameter, commands, counters, versions, evaluation",
              "metrics.csv": "one row per training episode", "evals.csv": "the periodic evaluations on selection seeds",
              "rollouts.csv": "one row per PPO rollout (losses, entropy, KL, learning rate)",
              ".png": "training plot", "HOW_TRAINED.md": "the training log, in words", "README.md": "this card"}
PLOT_ROLES = {"Train": "training plot: each episode's return and the 100-episode average",
              "Eval": "the periodic evaluations on selection seeds over training",
              "Progress": "training plot: how far episodes got (x position) and the share reaching the goal",
              "Endings": "training plot: where episodes ended along the level",
              "Deaths": "training plot: what ended the failed episodes, share by cause"}
#: how a card folds away every episode's result: the site's admonition, or HTML details elsewhere
FOLD = {True: '\n??? info "{}"\n    {}\n', False: "\n<details><summary>{}</summary>\n\n{}\n\n</details>\n"}


def model_files(models: list) -> dict[str, str]:
    """Each model's card and its page on the docs site, and the site's index of them."""
    out = {m.card: fill("front_matter.yml", **front_matter(m)) + "\n" + card(m, m.card, docs=False) for m in models}
    out.update({m.page: card(m, m.page, docs=True) for m in models})
    rows = [[f"[{m.slug}]({m.slug}.md)", m.env_id, f"`{m.algo}`", f"**{score_text(m)}**", bar_text(m), bar_met(m),
             over_seeds(m), "yes" if m.gif else "–"] for m in models]
    header = ["model", "env", "algorithm", "score on unseen seeds", "bar", "bar met", OVER_SEEDS_HEADER, "GIF"]
    out["docs/models/index.md"] = fill("models_index.md", table=table(header, rows)) + "\n"
    return out


def front_matter(m) -> dict:
    """The fields of the card's YAML header, which the Hugging Face Hub reads."""
    ev, share = m.evaluation, "success_share" in m.evaluation
    value = ev.get("success_share") if share else f"{ev.get('mean', 0):.2f} +/- {ev.get('std', 0):.2f}"
    return dict(env_id=m.env_id, env_tag=m.env_id.replace("/", "-"), algo=m.algo, experiment=m.experiment,
                metric="flag_share" if share else "mean_reward", value=json.dumps(value),
                metric_name="share of episodes reaching the flag" if share else "mean return",
                episodes=ev.get("episodes"), seeds=json.dumps(ev.get("seeds")), policy=json.dumps(policy_text(m)))


def card(m, page: str, docs: bool) -> str:
    """The card below its front matter, as the file ``page`` (on the docs site or not) shows it."""
    log = f"{m.folder}/HOW_TRAINED.md"
    fields = dict(
        algo_name=m.algo_name, env_id=m.env_id, article=article_of(m.experiment, m.algo),
        readme=link(page, "docs/index.md" if docs else "README.md"), protocol=link(page, "docs/guide/evaluation.md"),
        experiment_page=link(page, experiment_page(m.experiment)),
        gif=f"![{m.slug}]({link(page, m.gif)})\n\n" if m.gif else "", over_seeds=over_seeds_text(m, page),
        per_episode=episodes_fold(m, docs), lineage=lineage_text(m), hyperparameters=hyperparameter_text(m),
        commands=commands_table(m.meta.get("commands") or [m.meta.get("command", "")]),
        log=f"\nThe training log, with what was seen and why each setting changed: [HOW_TRAINED.md]"
            f"({link(page, log)}).\n" if (REPO / log).is_file() else "", files=files_table(m, page, docs))
    return fill("model.md", **fields, **score_fields(m), **usage_fields(m), **training_fields(m)) + "\n"


def usage_fields(m) -> dict:
    """The commands and the Python that evaluate and use the model."""
    exp, acts = get_experiment(m.experiment), FAMILIES.get(m.meta.get("kind"))
    where = zip(exp.shipped_by.fields, m.name.split("-")) if exp.shipped_by else ()
    return dict(experiment=m.experiment, algo=m.algo, name=m.name, slug=m.slug, eval_seed=exp.eval_seed_base,
                where="".join(f" --{field} {value}" for field, value in where),
                eval_episodes=min(exp.eval_episodes, 10), action_comment=(
                    "the mean action, in [-1, 1]: the env rescales it" if acts and not acts.discrete else
                    "greedy; predict(obs, deterministic=False, rng=rng) draws from pi" if acts and acts.stochastic
                    else "greedy"))


def policy_text(m) -> str:
    """How the evaluation chose actions: ``greedy (argmax)``, ``the mean action (deterministic)``, or as recorded."""
    policy, acts = m.evaluation.get("policy", "?"), FAMILIES.get(m.meta.get("kind"))
    if policy != "greedy":
        return policy
    return "the mean action (deterministic)" if acts and not acts.discrete else "greedy (argmax)"


def score_fields(m) -> dict:
    """The evaluation on unseen seeds (by the goal's share, or by the return), the bar, the best selection eval."""
    ev, best, share = m.evaluation, m.meta.get("best_eval") or {}, "success_share" in m.evaluation
    return dict(
        score=score_text(m), evaluation=f"{ev.get('episodes')} episodes on seeds {ev.get('seeds')}, {policy_text(m)}",
        mean_return=f"{ev['mean_return']:,.1f}" if share else None,
        x_position=f"{ev['mean_x_pos']:,.0f} / {ev['max_x_pos']:,.0f}" if share and "mean_x_pos" in ev else None,
        causes=", ".join(f"{k} {v}" for k, v in ev["causes"].items()) if share and ev.get("causes") else None,
        lowest=ret(ev["min"], ev["mean"]) if not share else None,
        time_limit_share=f"{ev['time_limit_share']:.0%}" if "time_limit_share" in ev and not share else None,
        walked=f"{ev['mean_x']:,.1f} m" if "mean_x" in ev and not share else None,
        bar=bar_text(m, met=": "), bar_reason=m.bar.reason if m.bar else None,
        below_bar=get_experiment(m.experiment).below_bar.get(m.name) if bar_met(m) != "met" else None,
        best_eval=f"{ret(best['mean'])} at {best.get('env_steps', 0):,} env steps" if "mean" in best else None,
        replaced=replaced_text(m.meta.get("replaces"), m))


def replaced_text(old: dict | None, m) -> str | None:
    """The shipped model this one replaced (``main.py train --publish``): its score, and what training it cost."""
    if not old:
        return None
    ev, commands = old.get("evaluation") or {}, old.get("commands") or 0
    score = score_words(ev, m.experiment, m.name) if ev else "not evaluated"
    seeds = f" (seeds {ev['seeds']})" if ev.get("seeds") else ""
    return (f"{score}{seeds}; trained by {commands or 'unrecorded'} command{'s' * (commands != 1)} "
            f"(`{old.get('preset')}` preset), {old.get('env_steps', 0):,} env steps, {hours(old.get('wall_seconds', 0))}")


def over_seeds_text(m, page: str) -> str:
    """What the same recipe scored over seeds, where a sweep of it is kept."""
    if not m.sweep:
        return ""
    mean = f", mean {sweep_score(m.sweep.aggregates['mean'][0], m)}" if "mean" in m.sweep.aggregates else ""
    return (f"\nThe same recipe over {len(m.sweep.seeds)} seeds ([report]({link(page, m.sweep.report)}), each run "
            f"scored like this one): {over_seeds(m, bold='')}{mean}; per seed "
            + ", ".join(f"{s}: {sweep_score(v, m)}" for s, v in m.sweep.seeds) + ".\n")


def episodes_fold(m, docs: bool) -> str:
    """Every episode of the evaluation (seed: reached the goal, or its return), folded away."""
    ev, share = m.evaluation, "success_share" in m.evaluation
    cells = ", ".join(f"{r['seed']}: " + (("yes" if r["success"] else "no") if share else ret(r["return"], ev["mean"]))
                      for r in ev.get("per_episode") or [])
    title = f"Every episode of the evaluation (seed: {'reached the flag' if share else 'return'})"
    return FOLD[docs].format(title, cells) if cells else ""


def training_fields(m) -> dict:
    """The run's preset, seed, counters (with the runs it started from), stop, CPU and versions."""
    meta, (steps, seconds), earlier = m.meta, m.from_scratch(), len(m.lineage)
    return dict(
        preset=str(meta.get("preset")), seed=str(meta.get("seed")), env_steps=f"{meta['env_steps']:,}",
        episodes=f"{meta['episodes']:,}", wall=f"{meta['wall_seconds']:,.0f} s ({meta['wall_seconds'] / 3600:.1f} h)",
        earlier_runs=(f"the {earlier} runs" if earlier > 1 else "the run") if earlier else None,
        from_scratch=f"{steps:,} env steps, {seconds:,.0f} s ({seconds / 3600:.1f} h)",
        stopped_by=stop_text(meta, m) if meta.get("stopped_by") else None, weights=meta.get("weights") or None,
        cpu=meta.get("cpu", "not recorded"),
        versions=", ".join(f"{name} {version}" for name, version in (meta.get("versions") or {}).items()),
        finished=meta["finished"][:10] if meta.get("finished") else None)


def commands_table(commands: list) -> str:
    """Each command of a run (a string, or a dict with the counters at which it took effect)."""
    rows = []
    for i, entry in enumerate(commands, 1):
        when = "not recorded" if not isinstance(entry, dict) else ", ".join(
            f"{k.replace('_', ' ')} {entry[k]:,}" for k in ("env_steps", "rollout", "episode")
            if isinstance(entry.get(k), int)) or "–"
        rows.append([str(i), "start" if i == 1 and when == "not recorded" else when,
                     f"`{entry.get('command', '') if isinstance(entry, dict) else entry}`"])
    return table(["#", "took effect at", "command"], rows, "rll")


def lineage_text(m) -> str:
    """A paragraph per run whose weights the model's run started from (``--init-from``), with its commands."""
    text = ""
    for i, parent in enumerate(m.lineage):
        pev = parent.get("evaluation") or {}
        score = (f"{round(pev['success_share'] * pev['episodes'])} of {pev['episodes']}" if "success_share" in pev
                 else ret(pev["mean"]) if "mean" in pev else "not evaluated")
        text += (f"\n{'It' if i == 0 else 'That run in turn'} started from the weights of `{parent.get('path')}` "
                 f"(`--init-from`), a run of {parent.get('env_steps', 0):,} env steps and "
                 f"{parent.get('wall_seconds', 0):,.0f} s (its evaluation: {score}), trained by:\n\n"
                 + commands_table(parent.get("commands") or []) + "\n")
    return text


def hyperparameter_text(m) -> str:
    """Where the model's final settings differ from today's preset of its name."""
    exp = get_experiment(m.experiment)
    name = m.meta.get("preset") or exp.algo(m.algo).default_preset
    try:
        preset = to_dict(exp.preset(m.algo, name))
    except Exception:  # a preset renamed since: compare with nothing
        preset = {}
    rows = [[f"`{k}`", f"`{json.dumps(v)}`", f"`{json.dumps(preset[k])}`" if k in preset else "–"]
            for k, v in (m.meta.get("config") or {}).items() if preset.get(k) != v]
    if not rows:
        return f"None: the model was trained with today's `{name}` preset as it stands."
    return (f"Where the model's final settings differ from today's `{name}` preset (every value is in meta.json's "
            f"`config`):\n\n" + table(["field", "this model", f"`{name}` preset"], rows))


def files_table(m, page: str, docs: bool) -> str:
    """The model folder's files with their size and role; the earlier runs kept in its subfolders."""
    rows = []
    for path in sorted(p for p in (REPO / m.folder).iterdir() if not p.is_dir() and p.name != "README.md"):
        # the docs site serves the plots, logs and meta.json (tools/docgen/hooks.py), not the CSVs or models
        served = not docs or path.suffix == ".png" or path.name in ("HOW_TRAINED.md", "meta.json")
        kind = next((kind for kind in PLOT_ROLES if f"_{kind}_" in path.name and path.suffix == ".png"), None)
        size = path.stat().st_size
        rows.append([f"[`{path.name}`]({link(page, f'{m.folder}/{path.name}')})" if served else f"`{path.name}`",
                     f"{size / 1e6:.1f} MB" if size >= 1e5 else f"{size / 1e3:.0f} kB",
                     PLOT_ROLES[kind] if kind else FILE_ROLES.get(path.name) or FILE_ROLES.get(path.suffix, "")])
    rows += [[f"`{sub.name}/`", "", "an earlier run of this model, kept for its record"]
             for sub in sorted((REPO / m.folder).iterdir()) if sub.is_dir()]
    return table(["file", "size", "what it is"], rows, "lrl")


def results_page(models: list) -> str:
    """Every experiment's shipped models and kept sweeps, and the bars."""
    page, blocks = "docs/results.md", []
    for name in experiment_names():
        if any(m.experiment == name for m in models):
            blocks += [f"## {name}", get_experiment(name).description + ".", region_shipped(page, name)]
            if any(m.experiment == name and m.sweep for m in models):
                blocks += ["Over seeds (the shipped recipe, run again with seeds 0-4 by `main.py sweep`, each run "
                           "scored like the shipped model; IQM with its 95% stratified bootstrap interval):",
                           region_sweeps(page, name)]
    return fill("results.md", experiments="\n\n".join(blocks), bars=region_bars(page, "")) + "\n"

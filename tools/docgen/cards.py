"""Model cards (``saved_networks/.../README.md``), their docs pages (``docs/models/``) and the results
page, all written from each model folder's meta.json and the kept sweeps. Part of :mod:`tools.docgen`."""
from __future__ import annotations

import json

from rlcore.algorithms.registry import FAMILIES
from rlcore.environments.registry import experiment_names, get_experiment
from rlcore.hyperparams.flags import to_dict
from tools.docgen.data import GENERATED_NOTE, REPO, Model
from tools.docgen.reference import region_bars
from tools.docgen.regions import EXPERIMENT_PAGES, region_shipped, region_sweeps
from tools.docgen.sweeps import stop_text
from tools.docgen.words import (
    OVER_SEEDS_HEADER,
    article_of,
    bar_met,
    bar_text,
    eval_text,
    link,
    model_page,
    num,
    over_seeds_bold,
    over_seeds_cell,
    policy_text,
    ret,
    score_text,
    sweep_score,
    table,
)

REPO_NAME = "deeprl-tf2"
# the files a model folder may hold, and what each is
FILE_ROLES = {".h5": "Keras model (the whole network, loadable on its own)", "meta.json":
              "what the run was: preset, every hyperparameter, commands, counters, versions, evaluation",
              "metrics.csv": "one row per training episode", "evals.csv": "the periodic evaluations on selection seeds",
              "rollouts.csv": "one row per PPO rollout (losses, entropy, KL, learning rate)",
              ".png": "training plot", "HOW_TRAINED.md": "the training log, in words", "README.md": "this card"}
# a plot's kind, as rlcore/runs/plotting.py names its file (PREFIX_KIND_ALGO.png), and what it draws
PLOT_ROLES = {"Train": "training plot: each episode's return and the 100-episode average",
              "Eval": "the periodic evaluations on selection seeds over training",
              "Progress": "training plot: how far episodes got (x position) and the share reaching the goal",
              "Endings": "training plot: where episodes ended along the level",
              "Deaths": "training plot: what ended the failed episodes, share by cause"}


def file_role(name: str) -> str:
    """What a model folder's file is, for the card's Files table."""
    if name.endswith(".png"):
        kind = next((kind for kind in PLOT_ROLES if f"_{kind}_" in name), None)
        if kind:
            return PLOT_ROLES[kind]
    return FILE_ROLES.get(name) or FILE_ROLES.get("." + name.rsplit(".", 1)[-1], "")


# ---------------------------------------------------------------------------------- front matter
def front_matter(m: Model) -> str:
    ev = m.evaluation
    success = "success_share" in ev
    value = ev.get("success_share") if success else f"{ev.get('mean', 0):.2f} +/- {ev.get('std', 0):.2f}"
    metric = "flag_share" if success else "mean_reward"
    name = ("share of episodes reaching the flag" if success else "mean return") + " on unseen seeds"
    tags = ["reinforcement-learning", "deep-reinforcement-learning", "tensorflow", "keras", REPO_NAME,
            m.env_id.replace("/", "-"), m.algo, m.experiment]
    lines = ["---", "library_name: keras", "license: mit", "tags:"] + [f"- {t}" for t in tags]
    lines += ["model-index:", f"- name: {m.algo}-{m.env_id.replace('/', '-')}", "  results:",
              "  - task:", "      type: reinforcement-learning", "      name: reinforcement-learning",
              "    dataset:", f"      name: {m.env_id}", f"      type: {m.env_id}",
              "    metrics:", f"    - type: {metric}", f"      value: {json.dumps(value)}",
              f"      name: {name}", "      verified: false", "      args:",
              f"        episodes: {ev.get('episodes')}", f"        seeds: {json.dumps(ev.get('seeds'))}",
              f"        policy: {json.dumps(policy_text(m))}", "---", ""]
    return "\n".join(lines)


# -------------------------------------------------------------------------------------- sections
def score_section(m: Model, page: str, docs: bool) -> str:
    ev, meta = m.evaluation, m.meta
    rows = [["score", f"**{score_text(m)}**"], ["evaluation", eval_text(m)]]
    if "success_share" in ev:
        rows += [["mean return", num(ev["mean_return"])]]
        for key in ("x_pos",):
            if f"mean_{key}" in ev:
                rows += [[f"mean / max {key.replace('_pos', ' position')}", f"{ev[f'mean_{key}']:,.0f} / {ev[f'max_{key}']:,.0f}"]]
        if ev.get("causes"):
            rows += [["what ended the misses", ", ".join(f"{k} {v}" for k, v in ev["causes"].items())]]
    else:
        rows += [["lowest episode", ret(ev["min"], ev["mean"])]]
        if "time_limit_share" in ev:
            rows += [["episodes that lasted to the time limit", f"{ev['time_limit_share']:.0%}"]]
        if "mean_x" in ev:
            rows += [["mean distance walked (x)", f"{num(ev['mean_x'])} m"]]
    rows += [["bar", f"{bar_text(m)}: {bar_met(m)}" if m.bar else "none set"]]
    if m.bar:
        rows += [["why that bar", m.bar.reason]]
    best = meta.get("best_eval") or {}
    if "mean" in best:
        rows += [["best periodic evaluation during training (selection seeds, not unseen)",
                  f"{ret(best['mean'])} at {best.get('env_steps', 0):,} env steps"]]
    text = table(["evaluation", "result"], rows) + "\n"
    if m.sweep:
        agg = m.sweep.aggregates
        text += (f"\nThe same recipe over {len(m.sweep.seeds)} seeds ([report]({link(page, m.sweep.folder + '/report.md')}),"
                 f" each run scored like this one): {over_seeds_bold(m)}")
        if "mean" in agg:
            text += f", mean {sweep_score(agg['mean'][0], m)}"
        text += "; per seed " + ", ".join(f"{s}: {sweep_score(v, m)}" for s, v in m.sweep.seeds) + ".\n"
    per_episode = ev.get("per_episode") or []
    if per_episode:
        key = "success" if "success_share" in ev else "return"
        cells = []
        for r in per_episode:
            value = ("yes" if r["success"] else "no") if key == "success" else ret(r["return"], ev["mean"])
            cells.append(f"{r['seed']}: {value}")
        body = ", ".join(cells)
        title = f"Every episode of the evaluation (seed: {'reached the flag' if key == 'success' else 'return'})"
        if docs:
            text += f'\n??? info "{title}"\n    {body}\n'
        else:
            text += f"\n<details><summary>{title}</summary>\n\n{body}\n\n</details>\n"
    return text


def usage_section(m: Model) -> str:
    exp = get_experiment(m.experiment)
    where = ""
    if exp.shipped_by:
        values = m.name.split("-")
        where = "".join(f" --{f} {v}" for f, v in zip(exp.shipped_by.fields, values))
    cmd = f"python main.py {{}} {m.experiment} {m.algo}{where}"
    return "\n".join([
        "```bash",
        cmd.format("evaluate") + "   # score it again on the unseen seeds",
        cmd.format("render") + f" --out {m.slug}.mp4",
        "```", "",
        "From Python (`rlcore.api`): the model is rebuilt from its folder's meta.json, env included, "
        "from any working folder:", "",
        "```python",
        "from rlcore import api",
        "",
        f'policy = api.load(("{m.experiment}", "{m.name}"))',
        "env = policy.make_env()",
        f"obs, info = env.reset(seed={exp.eval_seed_base})",
        "action = policy.predict(obs)" + _action_comment(m.meta.get("kind")),
        f"print(api.evaluate(policy, episodes={min(exp.eval_episodes, 10)})[\"line\"])   # as `main.py evaluate` prints it",
        "```", ""])


def _action_comment(kind: str | None) -> str:
    acts = FAMILIES.get(kind)
    if acts and not acts.discrete:
        return "   # the mean action, in [-1, 1]: the env rescales it"
    if acts and acts.stochastic:
        return "   # greedy; predict(obs, deterministic=False, rng=rng) draws from pi"
    return "   # greedy"


def _when(entry) -> str:
    if isinstance(entry, dict):
        parts = [f"{k.replace('_', ' ')} {entry[k]:,}" for k in ("env_steps", "rollout", "episode")
                 if isinstance(entry.get(k), int)]
        return ", ".join(parts) or "–"
    return "not recorded"


def _command(entry) -> str:
    return entry.get("command", "") if isinstance(entry, dict) else entry


def commands_table(commands: list) -> str:
    rows = [[str(i), "start" if i == 1 and _when(c) == "not recorded" else _when(c), f"`{_command(c)}`"]
            for i, c in enumerate(commands, 1)]
    return table(["#", "took effect at", "command"], rows, "rll")


def training_section(m: Model, page: str) -> str:
    meta = m.meta
    commands = meta.get("commands") or [meta.get("command", "")]
    rows = [["preset", f"`{meta.get('preset')}`"], ["seed", str(meta.get("seed"))],
            ["env steps", f"{meta['env_steps']:,}"], ["episodes", f"{meta['episodes']:,}"],
            ["wall time of training", f"{meta['wall_seconds']:,.0f} s ({meta['wall_seconds'] / 3600:.1f} h)"]]
    if m.lineage:
        steps, seconds = m.from_scratch()
        rows.append([f"with the {len(m.lineage)} runs it started from" if len(m.lineage) > 1 else "with the run it started from",
                     f"{steps:,} env steps, {seconds:,.0f} s ({seconds / 3600:.1f} h)"])
    if meta.get("stopped_by"):
        rows.append(["stopped by", stop_text(meta, m)])
    if meta.get("weights"):
        rows.append(["weights kept", meta["weights"]])
    rows.append(["CPU", meta.get("cpu", "not recorded")])
    rows.append(["versions", ", ".join(f"{k} {v}" for k, v in (meta.get("versions") or {}).items())])
    if meta.get("finished"):
        rows.append(["finished", meta["finished"][:10]])
    text = table(["training", ""], rows) + "\n\nThe commands of the run, in order (each resume keeps the settings of the " \
                                   "checkpoint, except those it gives again):\n\n" + commands_table(commands) + "\n"
    for i, parent in enumerate(m.lineage):
        pev = parent.get("evaluation") or {}
        score = (f"{round(pev['success_share'] * pev['episodes'])} of {pev['episodes']}" if "success_share" in pev
                 else ret(pev["mean"]) if "mean" in pev else "not evaluated")
        text += (f"\n{'It' if i == 0 else 'That run in turn'} started from the weights of `{parent.get('path')}` "
                 f"(`--init-from`), a run of {parent.get('env_steps', 0):,} env steps and "
                 f"{parent.get('wall_seconds', 0):,.0f} s (its evaluation: {score}), trained by:\n\n"
                 + commands_table(parent.get("commands") or []) + "\n")
    log = REPO / m.folder / "HOW_TRAINED.md"
    if log.is_file():
        text += f"\nThe training log, with what was seen and why each setting changed: [HOW_TRAINED.md]({link(page, m.folder + '/HOW_TRAINED.md')}).\n"
    return text


def hyperparameter_section(m: Model) -> str:
    exp = get_experiment(m.experiment)
    preset_name = m.meta.get("preset") or exp.algo(m.algo).default_preset
    try:
        preset = to_dict(exp.preset(m.algo, preset_name))
    except Exception:  # a preset renamed since: compare with nothing
        preset = {}
    config = m.meta.get("config") or {}
    rows = [[f"`{k}`", f"`{json.dumps(v)}`", f"`{json.dumps(preset[k])}`" if k in preset else "–"]
            for k, v in config.items() if preset.get(k) != v]
    if not rows:
        return f"None: the model was trained with today's `{preset_name}` preset as it stands.\n"
    return (f"Where the model's final settings differ from today's `{preset_name}` preset "
            f"(every value is in meta.json's `config`):\n\n" + table(["field", "this model", f"`{preset_name}` preset"], rows) + "\n")


def files_section(m: Model, page: str, docs: bool) -> str:
    rows = []
    for path in sorted((REPO / m.folder).iterdir()):
        if path.is_dir() or path.name == "README.md":
            continue
        role = file_role(path.name)
        size = path.stat().st_size
        # the docs site serves the plots, logs and meta.json (tools/docgen/hooks.py), not the CSVs or models
        served = not docs or path.suffix == ".png" or path.name in ("HOW_TRAINED.md", "meta.json")
        name = f"[`{path.name}`]({link(page, m.folder + '/' + path.name)})" if served else f"`{path.name}`"
        rows.append([name,
                     f"{size / 1e6:.1f} MB" if size >= 1e5 else f"{size / 1e3:.0f} kB", role])
    for sub in sorted(p for p in (REPO / m.folder).iterdir() if p.is_dir()):
        rows.append([f"`{sub.name}/`", "", "an earlier run of this model, kept for its record"])
    return table(["file", "size", "what it is"], rows, "lrl") + "\n"


def body(m: Model, page: str, docs: bool) -> str:
    exp = get_experiment(m.experiment)
    exp_page = f"docs/experiments/{EXPERIMENT_PAGES[m.experiment]}.md"
    readme = "docs/index.md" if docs else "README.md"
    parts = [f"# {m.title}", "",
             f"A {exp.algos[m.algo].description.split(',')[0]} agent for {m.env_id}, trained with "
             f"[{REPO_NAME}]({link(page, readme)}), which reproduces article {article_of(m.experiment, m.algo)} "
             f"([the experiment]({link(page, exp_page)})) in TensorFlow 2 / Keras.", ""]
    if m.gif:
        parts += [f"![{m.slug}]({link(page, m.gif)})", ""]
    parts += ["## Score on unseen seeds", "",
              "Seeds that neither training nor model selection ever used ([the protocol]"
              f"({link(page, 'docs/guide/evaluation.md')})).", "", score_section(m, page, docs),
              "## Usage", "", usage_section(m),
              "## How it was trained", "", training_section(m, page),
              "## Hyperparameters", "", hyperparameter_section(m),
              "## Files", "", files_section(m, page, docs)]
    return "\n".join(parts)


def cards(models: list[Model]) -> dict[str, str]:
    return {f"{m.folder}/README.md": front_matter(m) + GENERATED_NOTE + "\n\n" + body(m, f"{m.folder}/README.md", False)
            for m in models}


def model_pages(models: list[Model]) -> dict[str, str]:
    out = {model_page(m): GENERATED_NOTE + "\n\n" + body(m, model_page(m), True) for m in models}
    rows = [[f"[{m.slug}]({m.slug}.md)", m.env_id, f"`{m.algo}`", f"**{score_text(m)}**", bar_text(m), bar_met(m),
             over_seeds_cell(m), "yes" if m.gif else "–"] for m in models]
    out["docs/models/index.md"] = "\n".join([
        GENERATED_NOTE, "", "# Models", "",
        f"Every shipped model has a card: its score on unseen seeds, how to use it, every command that trained "
        f"it, and its files. The same card sits beside the model as `saved_networks/.../README.md`, with "
        f"front matter the Hugging Face Hub reads.", "",
        table(["model", "env", "algorithm", "score on unseen seeds", "bar", "bar met", OVER_SEEDS_HEADER, "GIF"], rows),
        ""])
    return out


def results_page(models: list[Model]) -> str:
    page = "docs/results.md"
    parts = [GENERATED_NOTE, "", "# Results", "",
             "Every number here is read from a shipped model's `meta.json` or a sweep kept in "
             "`results/sweeps/`. Scores are on unseen seeds (see [the evaluation protocol](guide/evaluation.md)): "
             "the mean return of the greedy (or mean-action) policy, or for Mario the share of episodes, "
             "actions sampled from pi, that reach the flag. \"best selection eval\" is the best periodic "
             "evaluation during training, on the separate selection seeds whose weights were kept; it is "
             "optimistic by construction and shown only beside the unseen-seed score.", ""]
    for name in experiment_names():
        if not any(m.experiment == name for m in models):
            continue
        exp = get_experiment(name)
        parts += [f"## {name}", "", exp.description + ".", "", region_shipped(page, name), ""]
        if any(m.experiment == name and m.sweep for m in models):
            parts += ["Over seeds (the shipped recipe, run again with seeds 0-4 by `main.py sweep`, each run "
                      "scored like the shipped model; IQM with its 95% stratified bootstrap interval):", "",
                      region_sweeps(page, name), ""]
    parts += ["## Bars", "", "Each bar is declared once, in the experiment registry, with its reason.", "",
              region_bars(page, ""), ""]
    return "\n".join(parts)

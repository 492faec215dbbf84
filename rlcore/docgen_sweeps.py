"""The ``sweep-stability`` region of the docs: what each kept sweep's periodic evaluations say about its
seeds (collapses during training, and whether keep-best kept better weights than the last), read from the
run folders in ``results/sweeps/``. Part of :mod:`rlcore.docgen`; TensorFlow-free."""
from __future__ import annotations

from rlcore.docgen_data import REPO, read_json, shipped_models
from rlcore.eval_history import collapse_text, stability_summary, steps_text, story


def _runs(folder: str) -> list[tuple[dict, object]]:
    """(meta, story) of each finished run of a kept sweep, by seed."""
    runs = []
    for meta_path in (REPO / folder).glob("*/model/meta.json"):
        meta = read_json(meta_path)
        runs.append((meta, story(meta_path.parent.parent, meta)))
    return sorted(runs, key=lambda run: run[0]["seed"])


def sweep_stability(page: str, experiment: str) -> str:
    from rlcore.docgen import link, sweep_score, table

    parts = []
    for m in shipped_models():
        if m.experiment != experiment or m.sweep is None:
            continue
        runs = _runs(m.sweep.folder)
        rows = []
        for meta, st in runs:
            ev = meta.get("evaluation") or {}
            share = ev.get("time_limit_share")
            rows.append([str(meta["seed"]), sweep_score(ev.get("success_share", ev.get("mean")), m),
                         "–" if share is None else f"{share:.0%}", str(st.evaluations),
                         f"{st.best.mean:.2f} at {steps_text(st.best.env_steps)}" if st.best else "–",
                         f"{st.last.mean:.2f}" if st.last else "–",
                         "; ".join(collapse_text(c) for c in st.collapses) or "none",
                         ("best evaluation" if st.kept_best else "last")])
        parts.append(f"**[{m.name}]({link(page, m.sweep.folder + '/report.md')})**: "
                     f"{stability_summary([st for _, st in runs])}\n\n"
                     + table(["seed", "unseen seeds", "to time limit", "periodic evaluations", "best (at)", "last",
                              "collapses (at: mean after the best before it, back by)", "model holds the weights of"],
                             rows, "rrrrrrll"))
    if not parts:
        return "*No sweep over seeds is kept in `results/sweeps/` for this experiment yet.*"
    return "\n\n".join(parts)

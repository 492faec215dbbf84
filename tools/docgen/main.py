"""The docs generator: every number in the README, the docs site and the model cards that comes from an
artefact is written here, from ``saved_networks/*/*/meta.json``, ``results/sweeps/*`` and the registry.

``python -m tools.docgen`` writes; ``python -m tools.docgen --check`` writes nothing and exits 1
listing every file that differs from what it would write (``make test`` runs it through
tests/test_docs.py). TensorFlow-free: it reads JSON and the registry's dataclasses only.

Two kinds of output:

- whole generated files: the model cards ``saved_networks/.../README.md``, ``docs/models/*.md``,
  ``docs/results.md``, ``docs/reference/cli.md`` and ``docs/reference/hyperparameters.md``;
- marked regions inside hand-written pages (README.md and docs/**/*.md): the text between
  ``<!-- generated:NAME ARG -->`` and ``<!-- /generated -->`` is replaced by region NAME with ARG
  (see :data:`REGIONS`); the rest of the page is left as written.
"""
from __future__ import annotations

import argparse
import os

from tools.docgen import cards as docgen_cards
from tools.docgen import reference as docgen_reference
from tools.docgen.data import REPO, shipped_models
from tools.docgen.regions import fill_regions, region_pages


def generate() -> dict[str, str]:
    """Every file the generator owns or fills: repo-relative path -> its text."""
    out = {}
    models = shipped_models()
    out.update(docgen_cards.cards(models))
    out.update(docgen_cards.model_pages(models))
    out["docs/results.md"] = docgen_cards.results_page(models)
    out["docs/reference/cli.md"] = docgen_reference.cli_page()
    out["docs/reference/hyperparameters.md"] = docgen_reference.hyperparameters_page()
    for page in region_pages():
        if page not in out:
            out[page] = fill_regions(page, (REPO / page).read_text())
    return out


def stale_files(out: dict[str, str]) -> list[str]:
    stale = [path for path, text in out.items()
             if not (REPO / path).is_file() or (REPO / path).read_text() != text]
    # a generated model page whose model is gone
    stale += sorted(p.relative_to(REPO).as_posix() for p in (REPO / "docs/models").glob("*.md")
                    if p.relative_to(REPO).as_posix() not in out)
    return stale


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tools.docgen", description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true",
                        help="write nothing; exit 1 listing every file that differs from what would be written")
    args = parser.parse_args(argv)
    out = generate()
    stale = stale_files(out)
    if args.check:
        if stale:
            print("docs out of date (run `python -m tools.docgen`):\n  " + "\n  ".join(stale))
            return 1
        print(f"docs up to date ({len(out)} files)")
        return 0
    for path in stale:
        target = REPO / path
        if path not in out:
            target.unlink()
            print(f"removed {path}")
            continue
        target.parent.mkdir(parents=True, exist_ok=True)
        tmp = target.with_name(target.name + ".tmp")
        tmp.write_text(out[path])
        os.replace(tmp, target)
        print(f"wrote {path}")
    print(f"{len(stale)} of {len(out)} files changed")
    return 0

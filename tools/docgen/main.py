"""The docs generator: every number in the README, the docs site and the model cards that comes from an
artefact, written from ``saved_networks/*/*/meta.json``, ``results/sweeps/*`` and the registry.

``python -m tools.docgen`` writes; ``--check`` writes nothing and exits 1 listing every file that differs
(tests/test_docs.py runs it). TensorFlow-free. It writes whole files (the model cards, ``docs/models/*.md``,
``docs/results.md``, ``docs/reference/{cli,hyperparameters}.md``, each filled into its template in
``templates/``) and the marked regions of hand-written pages (:mod:`tools.docgen.regions`)."""
import argparse
import os

from tools.docgen.cards import model_files, results_page
from tools.docgen.data import REPO, shipped_models
from tools.docgen.reference import cli_page, hyperparameters_page
from tools.docgen.regions import fill_regions, region_pages


def generate() -> dict[str, str]:
    """Every file the generator owns or fills: repo-relative path -> its text."""
    models = shipped_models()
    out = {**model_files(models), "docs/results.md": results_page(models), "docs/reference/cli.md": cli_page(),
           "docs/reference/hyperparameters.md": hyperparameters_page()}
    return out | {page: fill_regions(page, (REPO / page).read_text()) for page in region_pages() if page not in out}


def stale_files(out: dict[str, str]) -> list[str]:
    """The files that differ from ``out``, then the generated model pages whose model is gone."""
    stale = [path for path, text in out.items() if not (REPO / path).is_file() or (REPO / path).read_text() != text]
    gone = (p.relative_to(REPO).as_posix() for p in (REPO / "docs/models").glob("*.md"))
    return stale + sorted(path for path in gone if path not in out)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tools.docgen", description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true",
                        help="write nothing; exit 1 listing every file that differs from what would be written")
    check = parser.parse_args(argv).check
    out = generate()
    stale = stale_files(out)
    if check:
        print("docs out of date (run `python -m tools.docgen`):\n  " + "\n  ".join(stale) if stale
              else f"docs up to date ({len(out)} files)")
        return 1 if stale else 0
    for path in stale:
        target = REPO / path
        if path not in out:
            target.unlink()
            print(f"removed {path}")
            continue
        target.parent.mkdir(parents=True, exist_ok=True)
        target.with_name(target.name + ".tmp").write_text(out[path])
        os.replace(target.with_name(target.name + ".tmp"), target)
        print(f"wrote {path}")
    print(f"{len(stale)} of {len(out)} files changed")
    return 0

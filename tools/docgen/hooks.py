"""MkDocs hook (mkdocs.yml ``hooks:``): serve the shipped models' plots and training logs and the kept
sweeps' reports and curves from where they live, as if they sat under docs/ (``saved_networks/...``,
``results/...``), so the docs link to them without a second copy in the repository.

The pages link to those files by their true place in the repository (``../../saved_networks/...`` from
``docs/models/``), so the links work where the pages are read as files (GitHub, an editor); for the site,
:func:`on_page_markdown` points each such link at the mounted copy."""
from __future__ import annotations

import posixpath
import re
from pathlib import Path

from mkdocs.structure.files import File, Files

REPO = Path(__file__).resolve().parents[2]
MOUNTED = {"saved_networks": ("*.png", "HOW_TRAINED.md", "TRY.md", "meta.json"),
           "results/sweeps": ("*.png", "report.md", "sweep.json")}
DOCS = "docs"
# a markdown link or image target: ](target) or ](target "title"); no spaces inside a target here
LINK = re.compile(r"(\]\()([^)\s]+)((?:\s+\"[^\"]*\")?\))")


def on_files(files: Files, config) -> Files:
    for folder, patterns in MOUNTED.items():
        for pattern in patterns:
            for path in sorted((REPO / folder).rglob(pattern)):
                rel = path.relative_to(REPO).as_posix()
                if files.get_file_from_path(rel) is None:
                    files.append(File(rel, str(REPO), config["site_dir"], config["use_directory_urls"]))
    return files


def on_page_markdown(markdown: str, page, config, files) -> str:
    return site_links(markdown, f"{DOCS}/{page.file.src_uri}")


def site_links(markdown: str, page: str) -> str:
    """``markdown`` of the repository file ``page`` with each link into a mounted folder outside docs/
    pointed at its mounted copy; every other link as it was."""
    here = posixpath.dirname(page)

    def rewrite(match: re.Match) -> str:
        target = match.group(2)
        path, sep, anchor = target.partition("#")
        if not path or "://" in path or path.startswith(("/", "mailto:")):
            return match.group(0)
        in_repo = posixpath.normpath(posixpath.join(here, path))
        if not any(in_repo == folder or in_repo.startswith(folder + "/") for folder in MOUNTED):
            return match.group(0)
        mounted = posixpath.relpath(f"{DOCS}/{in_repo}", here)
        return f"{match.group(1)}{mounted}{sep}{anchor}{match.group(3)}"

    return LINK.sub(rewrite, markdown)


"""MkDocs hook (mkdocs.yml ``hooks:``): serve the shipped models' plots and training logs, the kept sweeps' reports
and curves and the long runs' figure from where they live, as if under docs/, without a second copy. The pages link to
them by their true place (``../../saved_networks/...`` from ``docs/models/``), which works where the pages are read as
files (GitHub, an editor); for the site, :func:`on_page_markdown` points each such link at the mounted copy."""
import posixpath
import re
from pathlib import Path

from mkdocs.structure.files import File, Files

REPO = Path(__file__).resolve().parents[2]
MOUNTED = {"saved_networks": ("*.png", "HOW_TRAINED.md", "TRY.md", "meta.json"),
           "results/sweeps": ("*.png", "report.md", "sweep.json"), "long_runs/mario_ppo": ("flag_share.png",)}
# a markdown link or image target: ](target) or ](target "title"); no spaces inside a target here
LINK = re.compile(r"(\]\()([^)\s]+)((?:\s+\"[^\"]*\")?\))")


def on_files(files: Files, config) -> Files:
    for folder, patterns in MOUNTED.items():
        for path in (path for pattern in patterns for path in sorted((REPO / folder).rglob(pattern))):
            if files.get_file_from_path(rel := path.relative_to(REPO).as_posix()) is None:
                files.append(File(rel, str(REPO), config["site_dir"], config["use_directory_urls"]))
    return files


def on_page_markdown(markdown: str, page, config, files) -> str:
    return site_links(markdown, f"docs/{page.file.src_uri}")


def site_links(markdown: str, page: str) -> str:
    """``markdown`` of the repository file ``page`` with each link into a mounted folder outside docs/
    pointed at its mounted copy; every other link as it was."""
    here = posixpath.dirname(page)

    def rewrite(match: re.Match) -> str:
        path, sep, anchor = match[2].partition("#")
        in_repo = posixpath.normpath(posixpath.join(here, path))
        if not path or "://" in path or path.startswith(("/", "mailto:")) or not any(
                in_repo == folder or in_repo.startswith(folder + "/") for folder in MOUNTED):
            return match[0]
        return f"{match[1]}{posixpath.relpath(f'docs/{in_repo}', here)}{sep}{anchor}{match[3]}"

    return LINK.sub(rewrite, markdown)

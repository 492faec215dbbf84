"""MkDocs hook (mkdocs.yml ``hooks:``): serve the shipped models' plots and training logs and the kept
sweeps' reports and curves from where they live, as if they sat under docs/ (``saved_networks/...``,
``results/...``), so the docs link to them without a second copy in the repository."""
from __future__ import annotations

from pathlib import Path

from mkdocs.structure.files import File, Files

REPO = Path(__file__).resolve().parents[1]
MOUNTED = {"saved_networks": ("*.png", "HOW_TRAINED.md", "TRY.md", "meta.json"),
           "results/sweeps": ("*.png", "report.md", "sweep.json")}


def on_files(files: Files, config) -> Files:
    for folder, patterns in MOUNTED.items():
        for pattern in patterns:
            for path in sorted((REPO / folder).rglob(pattern)):
                rel = path.relative_to(REPO).as_posix()
                if files.get_file_from_path(rel) is None:
                    files.append(File(rel, str(REPO), config["site_dir"], config["use_directory_urls"]))
    return files

"""A finished run's ``model/`` folder: the ``.h5`` files, the plot, every CSV table and ``meta.json``
(what the run was, the commands that made it, its counters, and the package versions)."""
from __future__ import annotations

from datetime import datetime, timezone
from pathlib import Path

from rlcore.files.atomic import writable_folder, write_atomic, write_json
from rlcore.host.cpu import cpu_description
from rlcore.host.machine import package_versions
from rlcore.records.plotting import plot_run


def write_model_folder(run_dir: Path, experiment, describe: dict, save_models, record: dict) -> Path:
    """``save_models(folder)`` writes the model files; ``record`` (commands, counters, ...) goes into
    meta.json after ``describe`` (what the run is). Returns the folder."""
    model_dir = writable_folder(run_dir / "model", "model folder")
    files = [p.name for p in save_models(model_dir)]
    plot_name = plot_run(run_dir, model_dir, experiment, describe)[0].name
    for table in sorted(run_dir.glob("*.csv")):  # metrics, evals, rollouts: all ship
        write_atomic(model_dir / table.name, lambda p, data=table.read_bytes(): p.write_bytes(data))
    meta = {**describe, "command": record["commands"][0], **record, "model_files": files,
            "plot": plot_name, "versions": package_versions(),
            "cpu": cpu_description(),
            "finished": datetime.now(timezone.utc).isoformat(timespec="seconds")}
    write_json(model_dir / "meta.json", meta)
    return model_dir

"""A model folder's ``meta.json`` read back, every way it can be wrong named in one line."""
from __future__ import annotations

import json
from pathlib import Path

from rlcore.errors import UserError


def read_meta(model_dir: str | Path) -> dict:
    model_dir = Path(model_dir)
    meta_path = model_dir / "meta.json"
    if not model_dir.exists():
        raise UserError(f"{model_dir}: no such model folder")
    if not model_dir.is_dir():
        raise UserError(f"{model_dir} is a file; give the model folder that holds it ({model_dir.parent})"
                        if model_dir.name == "meta.json" else f"{model_dir} is a file, not a model folder")
    if not meta_path.is_file():
        raise UserError(f"{model_dir} has no meta.json: not a model folder of this package (a run's model/ "
                        "folder, or a shipped one under saved_networks/)")
    try:
        return json.loads(meta_path.read_text())
    except json.JSONDecodeError as exc:
        raise UserError(f"{meta_path} is damaged ({exc.msg} at line {exc.lineno})")

"""The JSON records a run keeps (a model folder's ``meta.json``, ``sweep.json``) read back, every way one can
be wrong (missing, a folder, binary, cut short, not a record) named in one line."""
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
    return read_json(meta_path, "put back a good copy of the model folder (or train it again)")


def read_json(path: Path, fix: str) -> dict:
    """The JSON object in ``path``; a :class:`UserError` naming the file, what is wrong and ``fix``."""
    path = Path(path)
    try:
        data = json.loads(path.read_bytes().decode("utf-8"))
    except IsADirectoryError:
        raise UserError(f"{path} is a folder where a JSON record should be; {fix}") from None
    except FileNotFoundError:
        raise UserError(f"{path} is missing; {fix}") from None
    except UnicodeDecodeError:
        raise UserError(f"{path} is damaged (not text: binary bytes); {fix}") from None
    except json.JSONDecodeError as exc:
        raise UserError(f"{path} is damaged ({exc.msg} at line {exc.lineno}); {fix}") from None
    if not isinstance(data, dict):
        raise UserError(f"{path} is damaged (it holds no JSON object); {fix}")
    return data


def lineage(meta: dict) -> list[dict]:
    """The runs whose weights a model's run started from (``--init-from``), nearest first, as its meta.json
    records them; empty for a model trained from scratch."""
    chain, parent = [], meta.get("init_from")
    while isinstance(parent, dict):
        chain.append(parent)
        parent = parent.get("init_from")
    return chain


def cost_from_scratch(meta: dict) -> tuple[int, float]:
    """Env steps and wall seconds of a model's run and of every run it started from: what the model cost."""
    runs = [meta, *lineage(meta)]
    return sum(r.get("env_steps", 0) for r in runs), sum(r.get("wall_seconds", 0.0) for r in runs)

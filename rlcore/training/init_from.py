"""``--init-from``: the model folder a run starts its weights from, checked before any env starts."""
from __future__ import annotations

from pathlib import Path

from rlcore.errors import UserError
from rlcore.files.model_meta import read_meta
from rlcore.hyperparams.allowed import flag, setting


def init_from_meta(folder: str | Path, experiment: str, algo: str, network_file: str) -> dict:
    """The meta.json of the model folder a run starts from (PPO's ``init_from``), which must hold a model
    of the same experiment and algorithm, and its ``network_file``: a :class:`UserError` naming it otherwise."""
    try:
        meta = read_meta(folder)
    except UserError as exc:
        raise UserError(f"{flag('init_from')}: {exc}") from None
    if not (meta.get("experiment") and meta.get("algo")):
        raise UserError(f"{setting('init_from', str(folder))}: its meta.json does not say which experiment and "
                        f"algorithm its model is for (a {experiment} {algo} model is needed)")
    if (meta["experiment"], meta["algo"]) != (experiment, algo):
        raise UserError(f"{setting('init_from', str(folder))} holds a {meta['experiment']} {meta['algo']} model, "
                        f"not {experiment} {algo}")
    network = Path(folder) / network_file
    if not network.is_file():
        raise UserError(f"{setting('init_from', str(folder))} has a meta.json but no {network.name}: copy the "
                        "whole model folder")
    return meta

"""A run's CSV tables read back for a resume, whatever a disk error or a bad copy left in them.

A row that is not UTF-8 text, has the wrong number of cells, or an ``env_steps`` cell that is not a
number is damaged: the resume drops it and says how many (docs/guide/resume.md). A table whose header
itself is damaged, or a folder where the table should be, is one line naming it and what to do.
"""
from __future__ import annotations

import csv
import io
from pathlib import Path

from rlcore.errors import UserError


def read_table(path: Path) -> tuple[list[list[str]], int]:
    """(the header and the sound rows of the CSV table at ``path``, how many damaged rows were left out).
    An empty file is a table with no rows."""
    if path.is_dir():
        raise UserError(f"{path} is a folder where the run's CSV table should be: move it aside and resume again")
    raw = path.read_bytes()
    if not raw.strip():
        return [], 0
    lines = raw.split(b"\n")
    try:
        header = next(csv.reader([lines[0].decode("utf-8").rstrip("\r")]))
    except (UnicodeDecodeError, StopIteration):
        header = []
    if not header or not all(name.strip() for name in header):
        raise UserError(f"{path}: its header line is damaged (not the column names this package writes); move "
                        "the file aside (the resume starts the table again) or put back a good copy")
    rows, damaged = [header], 0
    for line in lines[1:]:
        if not line.strip():
            continue
        row = _sound_row(line, header)
        if row is None:
            damaged += 1
        else:
            rows.append(row)
    return rows, damaged


def _sound_row(line: bytes, header: list[str]) -> list[str] | None:
    try:
        row = next(csv.reader(io.StringIO(line.decode("utf-8").rstrip("\r"))))
    except (UnicodeDecodeError, StopIteration, csv.Error):
        return None
    if len(row) > len(header):
        return None
    if "env_steps" in header:
        col = header.index("env_steps")
        try:
            float(row[col])
        except (IndexError, ValueError):
            return None
    return row

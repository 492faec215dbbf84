"""One interface for run metrics: wandb (online / offline / off), a CSV, and a PNG plot.

wandb mode ``auto`` follows ``WANDB_MODE`` when the user set it, else means online when the user is
logged in (``WANDB_API_KEY`` or a netrc entry), offline otherwise. Never a prompt; with no network,
``online`` fails fast with one clear line.
"""
from __future__ import annotations

import csv
import io
import math
import netrc
import os
import sys
from pathlib import Path

from rlcore.errors import UserError, WriteFailed
from rlcore.files.atomic import atomic_path
from rlcore.files.csv_tables import read_table
from rlcore.hyperparams.allowed import setting

WANDB_MODES = ("auto", "online", "offline", "off")
WANDB_PROJECT = "deep-rl-tf2"


def wandb_logged_in() -> bool:
    if os.environ.get("WANDB_API_KEY"):
        return True
    try:
        return netrc.netrc().authenticators("api.wandb.ai") is not None
    except (FileNotFoundError, netrc.NetrcParseError, OSError):
        return False


# wandb's own variable, as its users set it (``dryrun`` is its old name for offline)
WANDB_MODE_ENV = {"online": "online", "offline": "offline", "dryrun": "offline", "disabled": "disabled"}


def resolve_wandb_mode(requested: str) -> str:
    """'auto' -> ``$WANDB_MODE`` if set, else 'online' if logged in, else 'offline'; 'off' -> 'disabled'."""
    if requested not in WANDB_MODES:
        raise UserError(f"unknown wandb mode {requested!r}; choose one of {', '.join(WANDB_MODES)}")
    if requested == "auto":
        from_env = WANDB_MODE_ENV.get(os.environ.get("WANDB_MODE", "").strip().lower())
        return from_env or ("online" if wandb_logged_in() else "offline")
    return "disabled" if requested == "off" else requested


STEP_KEY = "env_steps"  # the x axis of every wandb chart


def wandb_row(row: dict, table: str) -> dict:
    """The numbers of one CSV row as wandb keys: ``metrics`` keys as they are (the article's
    ``total_points`` ...), other tables' under ``<table>/``; ``env_steps`` is the shared axis."""
    numbers = {k: v for k, v in row.items()
               if isinstance(v, (int, float)) and not isinstance(v, bool) and not math.isnan(v)}
    if table == "metrics":
        return numbers
    return {(k if k == STEP_KEY else f"{table}/{k}"): v for k, v in numbers.items()}


def _widen_header(path: Path, names: list[str]) -> list[str]:
    """The header of the CSV table at ``path``, with any of ``names`` it lacks appended (the file is
    rewritten atomically; older rows get empty cells there)."""
    rows, damaged = read_table(path)
    header = rows[0]
    new = [name for name in names if name not in header]
    if new or damaged:
        with atomic_path(path) as tmp, open(tmp, "w", newline="") as f:
            csv.writer(f).writerows([header + new] + [r + [""] * len(new) for r in rows[1:]])
    return header + new


class Tracker:
    """Logs one row of numbers at a time to wandb and ``<run_dir>/metrics.csv``.

    The CSV columns come from the first row; resuming appends to the same file, and a column that a
    newer version of the code logs is added to the header (older rows leave it empty).
    """

    def __init__(self, run_dir: str | Path, run_name: str, config: dict, wandb_mode: str = "auto",
                 wandb_id: str | None = None, on_row=None):
        self.run_dir = Path(run_dir)
        self.on_row = on_row  # on_row(row, table): also hand every row to a caller (a Ray trial)
        self.run_dir.mkdir(parents=True, exist_ok=True)
        self.csv_path = self.run_dir / "metrics.csv"
        self._tables: dict[str, tuple] = {}  # table name -> (binary file, its column names)
        self.damaged_rows: dict[str, int] = {}  # table -> damaged rows the last resume left out
        self.wandb_run = None
        mode = resolve_wandb_mode(wandb_mode)
        if mode != "disabled":
            try:
                self.wandb_run = self._start_wandb(mode, run_name, config, wandb_id)
            except UserError as exc:
                if wandb_mode != "auto":
                    raise
                print(f"warning: {exc}; logging offline instead", file=sys.stderr)
                self.wandb_run = self._start_wandb("offline", run_name, config, wandb_id)
        self.wandb_id = self.wandb_run.id if self.wandb_run else None
        if self.wandb_run is not None:
            self._define_axes()

    def _start_wandb(self, mode: str, run_name: str, config: dict, wandb_id: str | None):
        os.environ.setdefault("WANDB_SILENT", "true")
        import wandb

        timeout = float(os.environ.get("WANDB_INIT_TIMEOUT", 30))
        settings = wandb.Settings(silent=True, init_timeout=timeout, x_disable_stats=True, disable_git=True,
                                  console="off")
        try:
            return wandb.init(project=WANDB_PROJECT, name=run_name, config=config, mode=mode,
                              dir=str(self.run_dir), id=wandb_id, resume="allow" if wandb_id else None,
                              settings=settings)
        except Exception as exc:  # no network, bad key, service failure
            reason = str(exc).splitlines()[0][:200] if str(exc) else type(exc).__name__
            raise UserError(f"wandb could not start in {mode} mode ({reason}); "
                            f"use {setting('wandb', 'offline')} (sync later with `wandb sync`) or "
                            f"{setting('wandb', 'off')}")

    def _define_axes(self) -> None:
        """Every chart of every table against env steps, not wandb's own call counter."""
        self.wandb_run.define_metric(STEP_KEY)
        self.wandb_run.define_metric("*", step_metric=STEP_KEY)

    def drop_rows_after(self, env_steps: int) -> dict[str, int]:
        """Remove the rows logged after a checkpoint taken at ``env_steps``.

        A run killed between two checkpoints has logged episodes its checkpoint does not hold;
        the resumed run plays them again, so their first rows go. Every CSV table of the run with an
        ``env_steps`` column is rewritten atomically, its damaged rows left out too (counted in
        ``damaged_rows``). Returns {file name: rows dropped}.
        """
        dropped, damaged_rows = {}, {}
        for path in sorted(self.run_dir.glob("*.csv")):
            rows, damaged = read_table(path)
            if not rows or "env_steps" not in rows[0]:
                continue
            col = rows[0].index("env_steps")
            kept = [rows[0]] + [r for r in rows[1:] if float(r[col]) <= env_steps]
            if len(kept) < len(rows):
                dropped[path.name] = len(rows) - len(kept)
            if damaged:
                damaged_rows[path.name] = damaged
            if len(kept) < len(rows) or damaged:
                with atomic_path(path) as tmp, open(tmp, "w", newline="") as f:
                    csv.writer(f).writerows(kept)
        self.damaged_rows = damaged_rows
        return dropped

    def table_path(self, table: str) -> Path:
        return self.run_dir / f"{table}.csv"

    def log(self, row: dict, table: str = "metrics") -> None:
        """Append ``row`` to ``<run_dir>/<table>.csv`` and send its numbers to wandb.

        A row is written whole or not at all: on a full disk the table is cut back to its last
        complete row and :class:`WriteFailed` names it.
        """
        path = self.table_path(table)
        try:
            if table not in self._tables:
                exists = path.exists() and path.stat().st_size > 0
                fieldnames = _widen_header(path, list(row)) if exists else list(row)
                handle = open(path, "ab", buffering=0)  # unbuffered: a failed write leaves nothing pending
                self._tables[table] = (handle, fieldnames)
                if not exists:
                    self._append(handle, dict(zip(fieldnames, fieldnames)), fieldnames)
            handle, fieldnames = self._tables[table]
            self._append(handle, row, fieldnames)
        except OSError as exc:
            raise WriteFailed(path, exc) from None
        if self.wandb_run is not None:
            self.wandb_run.log(wandb_row(row, table))
        if self.on_row is not None:
            self.on_row(row, table)

    @staticmethod
    def _append(handle, row: dict, fieldnames: list[str]) -> None:
        text = io.StringIO()
        csv.DictWriter(text, fieldnames=fieldnames, extrasaction="ignore").writerow(row)
        data, end = text.getvalue().encode(), handle.seek(0, os.SEEK_END)
        try:
            while data:
                data = data[handle.write(data):]
        except OSError:
            handle.truncate(end)  # no half-written row for a resume to trip on
            raise

    def close(self) -> None:
        for handle, _ in self._tables.values():
            handle.close()
        self._tables.clear()
        if self.wandb_run is not None:
            self.wandb_run.finish()
            self.wandb_run = None

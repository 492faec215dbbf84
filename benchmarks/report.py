#!/usr/bin/env python3
"""How long `main.py report` takes on a kept sweep, and its IQM bands alone.

  python benchmarks/report.py [--sweep results/sweeps/minitaur__sac] [--reps 5000] [--repeat 3]

Two JSON lines: the wall seconds of the whole report (the table's bootstrap, the learning-curve and
periodic-evaluation figures with their IQM bands) written into a temporary folder, best of --repeat; and
of the bands alone (one figure's: 5 runs x 40 points, at the figures' 1,000 resamples). TensorFlow-free.
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from common import emit  # noqa: E402


def best_of(repeat: int, work) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        work()
        times.append(time.perf_counter() - start)
    return round(min(times), 3)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sweep", default=str(ROOT / "results" / "sweeps" / "minitaur__sac"))
    parser.add_argument("--reps", type=int, default=5000, help="the table's resamples (report's --reps)")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()

    import contextlib
    import io

    import numpy as np

    from rlcore.cli.main import main as cli_main
    from rlcore.records.report_plots import _iqm_band

    def report() -> None:
        with tempfile.TemporaryDirectory() as out, contextlib.redirect_stdout(io.StringIO()):
            code = cli_main(["report", args.sweep, "--reps", str(args.reps), "--out", out])
            assert code == 0, code

    emit(measure="report", sweep=Path(args.sweep).name, reps=args.reps, seconds=best_of(args.repeat, report))
    curves = np.random.default_rng(0).normal(100.0, 30.0, (5, 40))
    emit(measure="iqm_bands", runs=5, points=40, reps=1000,
         seconds=best_of(args.repeat, lambda: _iqm_band(curves, 1000)))


if __name__ == "__main__":
    main()

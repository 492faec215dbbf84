"""How long a fresh venv takes to install, with pip and with uv, cold (no cache) and warm (cached).

    python benchmarks/install.py                  # the core, both tools, cold then warm
    python benchmarks/install.py --extras all     # every extra (a cold run builds pybullet and nes-py)

One JSON line per measurement: tool, what was installed, cold or warm, seconds. Each measurement gets a
venv of its own in a temporary folder, installs this checkout editable through constraints.txt (as
`make` does), and is deleted afterwards. "cold" runs without the tool's cache (pip --no-cache-dir,
uv --no-cache); "warm" runs right after a cached install of the same set. Needs uv on PATH or in the
venv of the Python running this script (`pip install uv`).
"""
from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def uv_binary() -> str:
    found = shutil.which("uv") or str(Path(sys.executable).parent / "uv")
    if not Path(found).exists():
        sys.exit("error: uv not found; pip install uv")
    return found


def install(tool: str, target: str, cache: bool, python: str) -> float:
    with tempfile.TemporaryDirectory(prefix="install-bench-") as tmp:
        venv = Path(tmp) / "venv"
        subprocess.run([python, "-m", "venv", str(venv)], check=True)
        py = str(venv / "bin" / "python")
        if tool == "pip":
            command = [py, "-m", "pip", "install", "--quiet", "-c", "constraints.txt", "-e", target]
            command += [] if cache else ["--no-cache-dir"]
        else:
            command = [uv_binary(), "pip", "install", "--quiet", "--python", py, "-c", "constraints.txt",
                       "-e", target] + ([] if cache else ["--no-cache"])
        started = time.perf_counter()
        subprocess.run(command, cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
        return time.perf_counter() - started


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--extras", default="", help="e.g. all, or mario,sweep (default: the core only)")
    parser.add_argument("--tools", default="pip,uv", help="the installers to time, comma-separated (default pip,uv)")
    parser.add_argument("--python", default="python3.13", help="the Python each fresh venv is made with")
    args = parser.parse_args()
    target = f".[{args.extras}]" if args.extras else "."
    for tool in args.tools.split(","):
        for label, cache in (("cold", False), ("warm", True)):
            if label == "warm":
                install(tool, target, True, args.python)  # fill the cache first
            seconds = install(tool, target, cache, args.python)
            print(json.dumps({"tool": tool, "install": target, "cache": label, "seconds": round(seconds, 1)}),
                  flush=True)


if __name__ == "__main__":
    main()

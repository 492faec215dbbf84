"""How long a fresh venv takes to install, with pip and with uv, cold (no cache) and warm (cached).

    python benchmarks/install.py                  # the core, both tools, cold then warm
    python benchmarks/install.py --extras all     # every extra (a cold run builds pybullet and nes-py)

One JSON line per measurement: tool, what was installed, cold or warm, whether it compiled every module
to bytecode, seconds; and how long the new venv then takes to import TensorFlow with
PYTHONDONTWRITEBYTECODE=1 (an environment that sets it, as this project's machines and CI do, never writes
a module's .pyc, so a venv installed without them compiles TensorFlow's modules from source in every
process). Each measurement gets a venv of its own in a temporary folder, installs this checkout editable
through constraints.txt, and is deleted afterwards. "cold" runs without the tool's cache (pip
--no-cache-dir, uv --no-cache); "warm" runs right after a cached install of the same set. uv runs as
`make` runs it (--compile-bytecode) and, with --bytecode both, also without it. Needs uv on PATH or in
the venv of the Python running this script (`pip install uv`).
"""
from __future__ import annotations

import argparse
import json
import os
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


def install(tool: str, target: str, cache: bool, python: str, compile_bytecode: bool) -> tuple[float, float]:
    """(seconds to install, seconds to import TensorFlow in the new venv afterwards, second try)."""
    with tempfile.TemporaryDirectory(prefix="install-bench-") as tmp:
        venv = Path(tmp) / "venv"
        subprocess.run([python, "-m", "venv", str(venv)], check=True)
        py = str(venv / "bin" / "python")
        if tool == "pip":
            command = [py, "-m", "pip", "install", "--quiet", "-c", "constraints.txt", "-e", target]
            command += ([] if cache else ["--no-cache-dir"]) + (["--compile"] if compile_bytecode else ["--no-compile"])
        else:
            command = [uv_binary(), "pip", "install", "--quiet", "--python", py, "-c", "constraints.txt",
                       "-e", target] + ([] if cache else ["--no-cache"])
            command += ["--compile-bytecode"] if compile_bytecode else []
        started = time.perf_counter()
        subprocess.run(command, cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
        installed = time.perf_counter() - started
        env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1", "TF_CPP_MIN_LOG_LEVEL": "3"}
        for _ in range(2):  # the second: the files are in the OS's page cache, as in a test suite
            started = time.perf_counter()
            subprocess.run([py, "-c", "import tensorflow"], check=True, env=env, cwd=tmp, stderr=subprocess.DEVNULL)
            imported = time.perf_counter() - started
        return installed, imported


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--extras", default="", help="e.g. all, or mario,sweep (default: the core only)")
    parser.add_argument("--tools", default="pip,uv", help="the installers to time, comma-separated (default pip,uv)")
    parser.add_argument("--python", default="python3.13", help="the Python each fresh venv is made with")
    parser.add_argument("--bytecode", choices=("make", "both"), default="make",
                        help="make: compile to bytecode as `make` does (uv --compile-bytecode; pip's default); "
                             "both: each install also without it")
    args = parser.parse_args()
    target = f".[{args.extras}]" if args.extras else "."
    compiles = (True, False) if args.bytecode == "both" else (True,)
    for tool in args.tools.split(","):
        for label, cache in (("cold", False), ("warm", True)):
            for compile_bytecode in compiles:
                if label == "warm":
                    install(tool, target, True, args.python, compile_bytecode)  # fill the cache first
                seconds, imported = install(tool, target, cache, args.python, compile_bytecode)
                print(json.dumps({"tool": tool, "install": target, "cache": label, "bytecode": compile_bytecode,
                                  "seconds": round(seconds, 1), "import_tensorflow_seconds": round(imported, 2)}),
                      flush=True)


if __name__ == "__main__":
    main()

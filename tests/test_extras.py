"""Missing extras: the core commands work without them, the commands that need one say so in one line.

Each case runs main.py in a subprocess where the optional modules cannot be imported
(``sys.modules[name] = None`` makes ``import name`` fail as if it were not installed).
"""
import subprocess
import sys
from pathlib import Path

import pytest

from rlcore.errors import UserError
from rlcore.host.extras import install_command, require

ROOT = Path(__file__).resolve().parents[1]
OPTIONAL = ["nes_py", "gym_super_mario_bros", "cv2", "pybullet", "pybullet_data", "pybullet_utils", "ray",
            "rliable", "tf2onnx", "onnx", "onnxruntime", "ale_py", "mujoco"]


def run_without_extras(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    code = (f"import sys, runpy\nfor name in {OPTIONAL!r}:\n    sys.modules[name] = None\n"
            f"sys.path.insert(0, {str(ROOT)!r})\nsys.argv = ['main.py', *{list(args)!r}]\n"
            f"runpy.run_path({str(ROOT / 'main.py')!r}, run_name='__main__')\n")
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=cwd, timeout=240)


@pytest.mark.parametrize("args", [["list"], ["--help"], ["train", "lunar_lander", "dqn", "--help"]])
def test_core_commands_work_without_any_extra(args, tmp_path):
    done = run_without_extras(*args, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr


@pytest.mark.parametrize("args,line", [
    (["train", "mario_ppo", "ppo", "--steps", "10"], "Mario needs the mario extra: pip install -e '.[mario]'"),
    (["train", "minitaur", "sac", "--steps", "10"],
     "Minitaur needs the minitaur extra: pip install -e '.[minitaur]'"),
    (["train", "ALE/Pong-v5", "dqn", "--steps", "10"], "Atari (ALE/* ids) needs the atari extra: pip install -e '.[atari]'"),
    (["train", "HalfCheetah-v5", "sac", "--steps", "10"],
     "HalfCheetah-v5 (MuJoCo) needs the mujoco extra: pip install -e '.[mujoco]'"),
    (["sweep", "lunar_lander", "dqn", "--seeds", "0", "--steps", "10"],
     "The sweep command needs the sweep extra: pip install -e '.[sweep]'"),
    (["report", "no_such_sweep"], "The report command needs the sweep extra: pip install -e '.[sweep]'"),
    (["export", "lunar_lander", "dqn", "--format", "onnx"],
     "ONNX export needs the export extra: pip install -e '.[export]'"),
])
def test_a_command_that_needs_a_missing_extra_says_so_in_one_line(args, line, tmp_path):
    done = run_without_extras(*args, cwd=tmp_path)
    assert done.returncode == 2
    assert done.stderr.strip() == f"error: {line}"
    assert list(tmp_path.iterdir()) == []  # no run, sweep or export folder


def test_require_returns_the_module_or_names_the_extra(monkeypatch):
    assert require("json", "JSON", "core").dumps([]) == "[]"
    # Another test in this worker may have imported rliable.metrics already; import_module would then
    # return it from sys.modules without looking at its parent, so hide the whole package.
    for name in [n for n in sys.modules if n == "rliable" or n.startswith("rliable.")] + ["rliable"]:
        monkeypatch.setitem(sys.modules, name, None)
    with pytest.raises(UserError) as err:
        require("rliable.metrics", "A sweep report")
    assert str(err.value) == f"A sweep report needs the sweep extra: {install_command('sweep')}"

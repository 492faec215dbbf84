"""The public API type-checks (mypy), and a user's typed code is checked against it: a wrong call is
caught, a right one passes. Public names are listed in ``__all__`` and ``py.typed`` ships."""
import subprocess
import sys
import tempfile
from pathlib import Path

import rlcore
import rlcore.api

ROOT = Path(__file__).resolve().parents[1]

USER_CODE = '''\
import numpy as np
import rlcore

run: rlcore.Run = rlcore.train("Acrobot-v1", "dqn", episodes=10, lr=5e-4)
policy: rlcore.Policy = rlcore.load(("lunar_lander", "dqn"))
action = policy.predict(np.zeros(8, np.float32))
result: dict = rlcore.evaluate(run, episodes=5, seed_base=10)
video = rlcore.render(policy, "x.gif").with_suffix(".mp4")
record = rlcore.export(run.model_dir, "onnx", "exports/x")
'''
WRONG_CODE = '''\
import rlcore

rlcore.train("Acrobot-v1", "dqn", episodes="ten")
rlcore.export("saved_networks/lunar_lander/dqn", "pickle", "out")
rlcore.render(rlcore.load(("lunar_lander", "dqn")), episodes=1.5)
rlcore.load(42)
'''


def test_public_names_are_listed_and_typed():
    assert set(rlcore.__all__) == set(rlcore.api.__all__)
    for name in rlcore.api.__all__:
        assert getattr(rlcore, name) is getattr(rlcore.api, name)
    for function in (rlcore.train, rlcore.load, rlcore.evaluate, rlcore.render, rlcore.export):
        assert "return" in function.__annotations__ and function.__doc__
    assert (ROOT / "rlcore" / "py.typed").is_file()
    assert "rlcore = py.typed" in (ROOT / "setup.cfg").read_text()  # shipped in the wheel


def test_mypy_over_the_public_api_and_user_code(tmp_path):
    (tmp_path / "user_ok.py").write_text(USER_CODE)
    (tmp_path / "user_wrong.py").write_text(WRONG_CODE)
    done = subprocess.run(
        [sys.executable, "-m", "mypy", "--config-file", str(ROOT / "tests" / "mypy_api.ini"),
         "--cache-dir", str(Path(tempfile.gettempdir()) / "deeprl-mypy-cache"), "--no-error-summary",
         "rlcore/api.py", "rlcore/gym_experiment.py", str(tmp_path / "user_ok.py"), str(tmp_path / "user_wrong.py")],
        cwd=ROOT, capture_output=True, text=True, timeout=300)
    errors = [line for line in done.stdout.splitlines() if ": error:" in line]
    outside = [line for line in errors if "user_wrong.py" not in line]
    assert not outside, "\n".join(outside)
    wrong_lines = sorted({int(line.split(":")[1]) for line in errors if "user_wrong.py" in line})
    assert wrong_lines == [3, 4, 5, 6], done.stdout  # each wrong call caught, on its own line

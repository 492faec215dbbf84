"""The public API type-checks (mypy), and a user's typed code is checked against it: a wrong call is
caught, a right one passes. Public names are listed in ``__all__`` and ``py.typed`` ships."""
import subprocess
import sys
import tempfile
from pathlib import Path

from rlcore import api

ROOT = Path(__file__).resolve().parents[1]

USER_CODE = '''\
import numpy as np
from rlcore import api

run: api.Run = api.train("Acrobot-v1", "dqn", episodes=10, lr=5e-4)
policy: api.Policy = api.load(("lunar_lander", "dqn"))
action = policy.predict(np.zeros(8, np.float32))
result: dict = api.evaluate(run, episodes=5, seed_base=10)
video = api.render(policy, "x.gif").with_suffix(".mp4")
record = api.export(run.model_dir, "onnx", "exports/x")
again: api.Run = api.resume(run, episodes=20, lr=1e-4)
'''
WRONG_CODE = '''\
from rlcore import api

api.train("Acrobot-v1", "dqn", episodes="ten")
api.export("saved_networks/lunar_lander/dqn", "pickle", "out")
api.render(api.load(("lunar_lander", "dqn")), episodes=1.5)
api.load(42)
api.resume(42)
'''


def test_public_names_are_listed_and_typed():
    for name in api.__all__:
        assert getattr(api, name).__module__ in ("rlcore.api", "rlcore.api.models", "rlcore.api.training", "rlcore.environments.experiment", "rlcore.errors",
                                                  "rlcore.training.stopping", "typing")
    import rlcore.models.export  # the export code keeps its module name: the API is rlcore.api, not rlcore itself
    assert callable(rlcore.models.export.export_model) and callable(api.export)
    for function in (api.train, api.resume, api.load, api.evaluate, api.render, api.export):
        assert "return" in function.__annotations__ and function.__doc__
    assert (ROOT / "rlcore" / "py.typed").is_file()
    assert "rlcore = py.typed" in (ROOT / "setup.cfg").read_text()  # shipped in the wheel


def test_mypy_over_the_public_api_and_user_code(tmp_path):
    (tmp_path / "user_ok.py").write_text(USER_CODE)
    (tmp_path / "user_wrong.py").write_text(WRONG_CODE)
    done = subprocess.run(
        [sys.executable, "-m", "mypy", "--config-file", str(ROOT / "tests" / "mypy_api.ini"),
         "--cache-dir", str(Path(tempfile.gettempdir()) / "deeprl-mypy-cache"), "--no-error-summary",
         "rlcore/api/__init__.py", "rlcore/api/models.py", "rlcore/api/training.py",
         "rlcore/environments/gym_experiment.py", str(tmp_path / "user_ok.py"), str(tmp_path / "user_wrong.py")],
        cwd=ROOT, capture_output=True, text=True, timeout=300)
    errors = [line for line in done.stdout.splitlines() if ": error:" in line]
    outside = [line for line in errors if "user_wrong.py" not in line]
    assert not outside, "\n".join(outside)
    wrong_lines = sorted({int(line.split(":")[1]) for line in errors if "user_wrong.py" in line})
    assert wrong_lines == [3, 4, 5, 6, 7], done.stdout  # each wrong call caught, on its own line

"""The package runs on Keras's TensorFlow backend whatever the user chose for other work: KERAS_BACKEND
set to jax or torch (as Keras 3 users do) is overridden for this process before Keras loads, and a
process that loaded Keras with another backend first is told so in one line."""
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def python(code: str, **env: str) -> subprocess.CompletedProcess:
    """A fresh interpreter (Keras not yet loaded), so the order of imports is the one under test."""
    return subprocess.run([sys.executable, "-c", code], cwd=ROOT, env={**os.environ, **env},
                          capture_output=True, text=True, timeout=60)


def test_another_backend_in_the_environment_is_overridden_before_keras_loads():
    done = python("import os, rlcore; print(os.environ['KERAS_BACKEND'])", KERAS_BACKEND="jax")
    assert done.returncode == 0 and done.stdout.strip() == "tensorflow", done.stderr


def test_keras_loaded_first_with_another_backend_is_one_clear_error():
    code = ("import sys, types\n"
            "keras = types.ModuleType('keras'); keras.backend = types.SimpleNamespace(backend=lambda: 'jax')\n"
            "sys.modules['keras'] = keras\n"
            "import rlcore")
    done = python(code)
    assert done.returncode != 0
    assert "rlcore runs on Keras's TensorFlow backend" in done.stderr and "'jax'" in done.stderr, done.stderr


def test_this_process_runs_keras_on_tensorflow():
    import keras

    import rlcore  # noqa: F401

    assert keras.backend.backend() == "tensorflow"

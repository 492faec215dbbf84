import os

import pytest

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")
os.environ.setdefault("WANDB_SILENT", "true")
os.environ.setdefault("WANDB_MODE", "offline")  # never reach for the network from a test


@pytest.fixture
def toy_experiments(monkeypatch):
    """The toy experiments of tests/toy*.py in the registry, so model folders of toy runs load."""
    from rlcore import experiment as registry

    for name in ("toy", "toy_image", "toy_reach"):
        monkeypatch.setitem(registry.EXPERIMENT_MODULES, name, f"tests.{name}")

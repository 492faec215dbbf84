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


# The files that take longest (about a minute each on 2 cores), run first: `make test` hands whole files
# to its workers in collection order, and a long file handed out last would keep one worker busy
# while the others sit idle. Only the order changes; every file still runs.
LONGEST_FIRST = ("test_sweep.py", "test_end_to_end.py", "test_training.py", "test_resume.py",
                 "test_full_disk.py", "test_stop_signals.py", "test_shipped_models.py")


def pytest_collection_modifyitems(items):
    rank = {name: i for i, name in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))  # stable: the rest keep their order

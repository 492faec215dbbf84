import os

import pytest

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")
os.environ.setdefault("WANDB_SILENT", "true")
# never reach for the network from a test, even where the user is logged in to wandb or set WANDB_MODE
# (a run's default wandb mode, auto, follows WANDB_MODE); nor read the user's own shipped-model folder
os.environ["WANDB_MODE"] = "offline"
os.environ.pop("DEEPRL_MODELS", None)
# Under `make test` each xdist worker (and the processes its tests start) gets its share of the cores for
# TensorFlow's op threads, instead of every worker sizing its pools for the whole machine: two workers on
# 2 cores ran two test files 5-8 % faster so (2026-11-27). Results do not depend on it (the shipped models
# replay their records exactly on one thread too).
if os.environ.get("PYTEST_XDIST_WORKER_COUNT"):
    _share = max(1, (os.cpu_count() or 1) // int(os.environ["PYTEST_XDIST_WORKER_COUNT"]))
    os.environ.setdefault("TF_NUM_INTRAOP_THREADS", str(_share))
    os.environ.setdefault("TF_NUM_INTEROP_THREADS", str(_share))


@pytest.fixture(autouse=True)
def registry_as_it_was():
    """Every test leaves the experiment registry as it found it: a test that registers a toy experiment
    and keeps it (a sweep trial run in-process registers what its driver hands it) would change what a
    later test on the same worker sees, and which one that is depends on how the files fall to workers
    (seen: `test_every_experiment_evaluates_above_the_training_seeds` met the toy's seeds, 2026-11-27)."""
    from rlcore.environments import registry

    before = dict(registry.EXPERIMENT_MODULES)
    yield
    registry.EXPERIMENT_MODULES.clear()
    registry.EXPERIMENT_MODULES.update(before)


@pytest.fixture
def sac_without_xla(monkeypatch):
    """SAC agents built without XLA: ~2 s less CPU for each of the many short-lived agents of the tests
    of a trainer's bookkeeping (resume, counters, logging). tests/rlcore/algorithms/test_sac.py and the end-to-end
    Minitaur run keep the compiled update that training uses."""
    from rlcore.algorithms.sac import agent as sac

    monkeypatch.setattr(sac, "XLA", False)


@pytest.fixture
def toy_experiments(monkeypatch):
    """The toy experiments of tests/toy*.py in the registry, so model folders of toy runs load."""
    from rlcore.environments import registry

    for name in ("toy", "toy_image", "toy_reach"):
        monkeypatch.setitem(registry.EXPERIMENT_MODULES, name, f"tests.{name}")


# The files that take longest, first: `make test` hands whole files to its workers in collection order
# (`--dist loadfile --no-loadscope-reorder`; xdist's own order, by number of tests, would leave the
# few-but-long files such as the end-to-end runs for last, one worker busy while the other idles).
# Ranked by their time on a worker of `make test` (2026-11-27, after the suite was made to do less); only
# the order changes, every file still runs.
LONGEST_FIRST = ("test_sweep.py", "test_end_to_end.py", "test_training.py", "test_atari_mujoco.py", "test_docs_examples.py",
                 "test_stop_signals.py",
                 "test_shipped_models.py", "test_sweep_without_ray.py", "test_resume.py", "test_gym_envs.py",
                 "test_cli.py", "test_obs_norm.py", "test_sac.py", "test_bad_values.py", "test_export.py",
                 "test_ppo.py", "test_api.py", "test_partial_episodes.py", "test_restarts.py")


def pytest_collection_modifyitems(items):
    rank = {name: i for i, name in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))  # stable: the rest keep their order

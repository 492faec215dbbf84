"""Every file the package reads back, damaged each way a disk error or a bad copy leaves it (binary
garbage, cut short, empty, a folder in its place): one line naming the file and what to do, a non-zero
exit and no traceback, or the recovery the docs describe (a run's CSV tables: the damaged rows dropped,
docs/guide/resume.md; a table cut short keeps its whole rows)."""
import json
import os
import shutil

import pytest

from rlcore.sweeps.sweep import Sweep
from tests.test_cli import run as cli

QUIET = ["--wandb", "off", "--no-progress", "--final-eval-episodes", "0"]


def binary(path):
    path.write_bytes(b"\xff\xd8" + os.urandom(298))


def cut_short(path):
    path.write_bytes(path.read_bytes()[: max(1, path.stat().st_size // 2)])


def empty(path):
    path.write_bytes(b"")


def folder(path):
    path.unlink()
    path.mkdir()


DAMAGES = {"binary": binary, "cut short": cut_short, "empty": empty, "a folder": folder}
# file in the run folder -> the command that reads it back ({run}: the damaged run's folder)
READERS = {
    "model/meta.json": ["evaluate", "CartPole-v1", "dqn", "--model", "{run}/model", "--episodes", "1"],
    "model/q_network.h5": ["evaluate", "CartPole-v1", "dqn", "--model", "{run}/model", "--episodes", "1"],
    "checkpoint.npz": ["train", "CartPole-v1", "dqn", "--resume", "{run}", "--episodes", "5", *QUIET],
    "metrics.csv": ["status", "{run}"],
}


@pytest.fixture(scope="module")
def finished_run(tmp_path_factory):
    run_dir = tmp_path_factory.mktemp("base") / "run"
    from rlcore.cli.main import main

    assert main(["train", "CartPole-v1", "dqn", "--episodes", "3", "--hidden", "8", "--run-dir", str(run_dir),
                 *QUIET]) == 0
    return run_dir


@pytest.mark.parametrize("damage", sorted(DAMAGES))
@pytest.mark.parametrize("name", sorted(READERS))
def test_a_damaged_file_is_one_line_naming_it(finished_run, tmp_path, capsys, name, damage):
    run_dir = tmp_path / "run"
    shutil.copytree(finished_run, run_dir)
    DAMAGES[damage](run_dir / name)
    code, out, err = cli(capsys, *[part.replace("{run}", str(run_dir)) for part in READERS[name]])
    lines = err.strip().splitlines()
    if code == 0:  # a recovery: only a table cut short, whose whole rows are read
        assert (name, damage) == ("metrics.csv", "cut short"), (name, damage, lines)
        return
    assert "Traceback" not in err and lines[-1].startswith("error: "), lines
    assert str(run_dir) in lines[-1], lines  # it names the file (or its folder)


@pytest.mark.parametrize("damage", sorted(DAMAGES))
def test_a_damaged_sweep_record_is_one_line(tmp_path, capsys, damage):
    folder_ = tmp_path / "sweep"
    folder_.mkdir()
    Sweep("CartPole-v1", "dqn", "sweep", str(folder_), [0]).save()
    DAMAGES[damage](folder_ / "sweep.json")
    with pytest.raises(Exception) as caught:
        Sweep.load(folder_)
    assert "sweep.json" in str(caught.value) and type(caught.value).__name__ == "UserError"


def test_an_export_json_damaged_does_not_stop_a_new_export_there(tmp_path, capsys):
    out = tmp_path / "export"
    assert cli(capsys, "export", "lunar_lander", "dqn", "--format", "savedmodel", "--out", str(out))[0] == 0
    binary(out / "export.json")
    code, _, err = cli(capsys, "export", "lunar_lander", "dqn", "--format", "savedmodel", "--out", str(out))
    assert code == 0, err
    assert json.loads((out / "export.json").read_text())["format"] == "savedmodel"

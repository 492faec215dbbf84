"""A run's CSV tables damaged by a disk error or a bad copy (issue 65): a resume drops the damaged rows and
says how many; a damaged header, or a folder in a table's place, is one line naming the file."""
import shutil
from pathlib import Path

import pytest

from rlcore.errors import UserError
from rlcore.files.csv_tables import read_table
from tests.test_cli import run as cli

OLD = Path(__file__).resolve().parents[2] / "data" / "runs_before_relayout" / "dqn"
QUIET = ["--wandb", "off", "--no-progress", "--final-eval-episodes", "0"]


def test_damaged_rows_are_left_out_and_counted(tmp_path):
    table = tmp_path / "metrics.csv"
    table.write_bytes(b"episode,env_steps,x\n1,10,0.5\n\xff\xfe2,20,0.1\n3,30\n4,abc,1\n5,50,1,extra\n6,60,2\n")
    rows, damaged = read_table(table)
    assert rows == [["episode", "env_steps", "x"], ["1", "10", "0.5"], ["3", "30"], ["6", "60", "2"]]
    assert damaged == 3  # not text, env_steps not a number, a cell too many (a row cut short is kept: old rows lack new columns)
    table.write_bytes(b"")
    assert read_table(table) == ([], 0)


@pytest.mark.parametrize("damage, words", [(b"\xff\xd8\xff\xe0binary", "header line is damaged"),
                                            (None, "is a folder")])
def test_a_damaged_header_or_a_folder_is_one_line(tmp_path, damage, words):
    table = tmp_path / "metrics.csv"
    if damage is None:
        table.mkdir()
    else:
        table.write_bytes(damage)
    with pytest.raises(UserError, match=words):
        read_table(table)


def test_a_resume_drops_the_damaged_rows_and_says_how_many(tmp_path, capsys):
    run_dir = tmp_path / "dqn"
    shutil.copytree(OLD, run_dir)
    with open(run_dir / "metrics.csv", "ab") as f:
        f.write(b"\xff\xfe\x00garbage\n")
    code, out, err = cli(capsys, "train", "CartPole-v1", "dqn", "--resume", str(run_dir), "--episodes", "5", *QUIET)
    assert code == 0, err
    assert "dropped damaged rows" in err and "1 from metrics.csv" in err
    assert b"\xff" not in (run_dir / "metrics.csv").read_bytes()


def test_a_resume_with_a_damaged_header_is_one_line_and_exit_1(tmp_path, capsys):
    run_dir = tmp_path / "dqn"
    shutil.copytree(OLD, run_dir)
    (run_dir / "metrics.csv").write_bytes(b"\x00\x01\x02\xff" * 50)
    code, out, err = cli(capsys, "train", "CartPole-v1", "dqn", "--resume", str(run_dir), "--episodes", "5", *QUIET)
    assert code != 0 and "Traceback" not in err and "metrics.csv: its header line is damaged" in err, err
    (run_dir / "metrics.csv").rename(tmp_path / "metrics.csv.damaged")  # as the line says: moved aside
    code, out, err = cli(capsys, "train", "CartPole-v1", "dqn", "--resume", str(run_dir), "--episodes", "5", *QUIET)
    assert code == 0, err
    assert (run_dir / "metrics.csv").read_text().startswith("episode,")

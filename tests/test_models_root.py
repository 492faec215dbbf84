"""Where the shipped models are read from when the package is not run from its checkout: a copy installed
into site-packages holds the code but not saved_networks/ (79 MB), so `$DEEPRL_MODELS` or a clone's
./saved_networks is used, and a name that cannot be found there is one line saying where to look."""
import shutil
from pathlib import Path

import pytest

from rlcore import api
from rlcore.cli import main as cli
from rlcore.errors import UserError
from rlcore.models import shipping

CHECKOUT_MODELS = Path(shipping.__file__).resolve().parents[2] / "saved_networks"


@pytest.fixture
def installed_apart(monkeypatch, tmp_path):
    """As in a non-editable install: the package's own saved_networks/ does not exist."""
    monkeypatch.setattr(shipping, "SAVED_NETWORKS", tmp_path / "site-packages" / "saved_networks")
    monkeypatch.delenv(shipping.MODELS_ENV, raising=False)
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_deeprl_models_names_the_folder(installed_apart, monkeypatch, capsys):
    models = installed_apart / "models"
    shutil.copytree(CHECKOUT_MODELS / "cartpole", models / "cartpole")
    monkeypatch.setenv(shipping.MODELS_ENV, str(models))
    assert api.load(("cartpole", "dqn")).model_dir == models / "cartpole" / "dqn"
    assert cli.main(["evaluate", "cartpole", "dqn", "--episodes", "1"]) == 0
    # the model evaluated is the one in $DEEPRL_MODELS (its score is not the question here, and a score
    # recorded on one CPU need not repeat exactly on another)
    assert f"cartpole dqn ({models / 'cartpole' / 'dqn'}): greedy return " in capsys.readouterr().out


def test_a_clone_s_saved_networks_is_found_from_where_the_command_runs(installed_apart):
    here = installed_apart / "saved_networks"
    shutil.copytree(CHECKOUT_MODELS / "lunar_lander" / "dqn", here / "lunar_lander" / "dqn")
    assert shipping.models_root() == here
    assert api.load(("lunar_lander", "dqn")).model_dir == here / "lunar_lander" / "dqn"


def test_no_models_anywhere_is_one_line_saying_where_they_live(installed_apart, capsys):
    with pytest.raises(UserError) as err:
        api.load(("cartpole", "dqn"))
    assert str(err.value).startswith(f"no shipped models at {shipping.SAVED_NETWORKS}: they live in the "
                                     f"saved_networks/ folder of a clone")
    assert shipping.MODELS_ENV in str(err.value)
    assert cli.main(["evaluate", "cartpole", "dqn"]) == 2
    err_lines = capsys.readouterr().err.strip().splitlines()
    assert err_lines == [f"error: {err.value}"]

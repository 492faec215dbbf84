"""The pages' examples as one chain, run in order in a fresh folder as a new user runs them (issue 65, item 6):
the README's quickstart, then quickstart, export and resume pages, their ``python main.py`` lines and the
export page's Python blocks. Each example's inputs must come from an earlier one (a run folder, an export),
so a page that reads what no example made fails here.

The Python blocks run as written, ``my_envs`` being the tests' Chase env and ``api.train`` / ``api.evaluate``
given the same small budgets. Budgets shrink (a train gets ``--episodes 2``, an evaluate ``--episodes 2``: a flag given last wins; a
``--resume``, which the pages give after a Ctrl-C, one episode more than the run before it has) and the
``RUN_NAME`` placeholder becomes the newest folder under ``runs/``. Left out, each for its CPU minutes:
commands of the ``mario_ppo`` experiment or on its run folders, renders and evaluations of ``minitaur`` (the shipped models of
both are played by ``tests/test_shipped_models.py``), ``--help`` lines (parsed by ``tests/test_docs.py``)
and ``sweep`` / ``report`` (``tests/test_sweep.py``).
"""
import re
import shlex
import sys
from pathlib import Path

import pytest

from rlcore import api
from tests.test_cli import run as cli

REPO = Path(__file__).resolve().parents[1]
CHAIN = ["README.md", "docs/get-started/quickstart.md", "docs/export.md", "docs/guide/resume.md"]
SHRINK = {"train": ["--episodes", "2", "--final-eval-episodes", "1", "--wandb", "off", "--no-progress"],
          "evaluate": ["--episodes", "2"]}
BLOCK = re.compile(r"^```(\w+)\n(.*?)^```", re.S | re.M)


def examples(page: str):
    """(kind, text) in page order: ("command", one ``python main.py`` line) or ("python", a block)."""
    for language, body in BLOCK.findall((REPO / page).read_text()):
        if language == "python":
            yield "python", body
        elif language == "bash":
            for line in body.splitlines():
                if line.startswith("python main.py "):
                    yield "command", line.split(" # ")[0].split("  #")[0].strip()


def left_out(argv: list[str]) -> bool:
    command, experiment = argv[0], (argv[1] if len(argv) > 1 else "")
    return ("--help" in argv or command in ("sweep", "report") or any("mario_ppo" in a for a in argv)
            or (experiment == "minitaur" and command in ("render", "evaluate", "train")))


def newest_run(folder: Path) -> str:
    runs = sorted((folder / "runs").iterdir(), key=lambda p: p.stat().st_mtime)
    return runs[-1].name


def small_budgets(monkeypatch):
    """``api.train`` and ``api.evaluate`` as the pages call them, with the chain's budgets."""
    train, evaluate = api.train, api.evaluate

    def small_train(*args, **kwargs):
        kwargs.update(steps=None, episodes=2, final_eval_episodes=1, progress=False)
        return train(*args, **kwargs)

    monkeypatch.setattr(api, "train", small_train)
    monkeypatch.setattr(api, "evaluate", lambda model, *args, **kwargs: evaluate(model, **{**kwargs, "episodes": 2}))


@pytest.fixture
def users_folder(tmp_path, monkeypatch):
    """A fresh working folder holding the user's ``my_envs`` module of the README; afterwards Gymnasium's
    registry as it was (the README registers ``Chase-v0`` from ``my_envs``) with the experiments built from
    it, and the modules that register ids on import forgotten if they were first imported here."""
    import gymnasium as gym

    from rlcore.environments import gym_experiment

    env_class = (Path(__file__).parent / "user_env.py").read_text().split("\ngym.register(")[0]
    (tmp_path / "my_envs.py").write_text(f"{env_class}\nChase = ChaseEnv\n")  # the class; the README registers it
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.chdir(tmp_path)
    before, modules, built = dict(gym.registry), set(sys.modules), dict(gym_experiment._BUILT)
    gym.registry.pop("Chase-v0", None)  # a user's fresh session has not registered it (a test before may have)
    yield tmp_path
    gym.registry.clear()
    gym.registry.update(before)
    gym_experiment._BUILT.clear()  # the experiments built from those registrations, too
    gym_experiment._BUILT.update(built)
    for name in {"my_envs"} - modules:  # imported here: another folder's my_envs is another module
        sys.modules.pop(name, None)


def test_the_pages_examples_run_in_order_each_on_what_an_earlier_one_made(users_folder, capsys, monkeypatch):
    tmp_path = users_folder
    small_budgets(monkeypatch)
    ran, resumes = [], 0
    for page in CHAIN:
        for kind, text in examples(page):
            if kind == "python":
                exec(compile(text, f"{page} (python block)", "exec"), {})  # noqa: S102 (the page's own code)
                ran.append(f"{page}: a python block")
                continue
            if "RUN_NAME" in text:
                text = text.replace("RUN_NAME", newest_run(tmp_path))
            argv = shlex.split(text)[2:]
            if left_out(argv):
                continue
            shrink = SHRINK.get(argv[0], [])
            if "--resume" in argv:
                resumes += 1
                shrink = [*shrink, "--episodes", str(2 + resumes)]
            code, out, err = cli(capsys, *argv, *shrink)
            assert code == 0, f"{page}: `{text}` exited {code}: {err.strip()[-600:]}"
            ran.append(f"{page}: {text}")
    assert len(ran) >= 20, ran

# Two commands for a new machine:  `make demo`  and  `make test`.
PYTHON ?= python3.13
VENV   := .venv
PY     := $(VENV)/bin/python
UV     := $(VENV)/bin/uv
# Installs are locked: constraints.txt pins every package to the version the tests and the shipped
# models last ran with. `make lock` refreshes it from a fresh install (a deliberate step: run the
# tests after it, commit it with what it changed).
LOCK   := constraints.txt
CORE   := $(VENV)/.installed-core
ALL    := $(VENV)/.installed-all

.PHONY: venv demo test lock benchmark save-long-runs clean docs docs-check

$(PY):
	@command -v $(PYTHON) >/dev/null 2>&1 || { echo "error: $(PYTHON) not found; install Python 3.13 (pyenv install 3.13) or run make PYTHON=/path/to/python3.13"; exit 1; }
	$(PYTHON) -m venv $(VENV)

$(UV): | $(PY)
	$(PY) -m pip install --quiet -c $(LOCK) uv

# What `make demo` needs: the core (LunarLander, CartPole, any Gymnasium env). Redone when setup.cfg or
# the lock changes. uv installs (pip would too: `pip install -c constraints.txt -e .`).
# --compile-bytecode writes every module's .pyc at install, as pip does by default: where the environment
# sets PYTHONDONTWRITEBYTECODE (this project's machines and CI do), Python never writes them itself, and
# every process compiled TensorFlow from source: its import took 10 s instead of 3.5 s, and `make test`,
# which starts a process for every command-line test, 885 s instead of 685 s (benchmarks/install.py and
# side-by-side suites beside a training, Intel Xeon, 2026-11-29; docs: speed notes).
$(CORE): setup.cfg pyproject.toml $(LOCK) | $(UV)
	$(UV) pip install --quiet --compile-bytecode --python $(PY) -c $(LOCK) -e .
	touch $@

# What `make test` needs: every extra (mario, minitaur, sweep, docs, export, test).
$(ALL): setup.cfg pyproject.toml $(LOCK) | $(UV)
	$(UV) pip install --quiet --compile-bytecode --python $(PY) -c $(LOCK) -e '.[all]'
	touch $@ $(CORE)

# Install only (every extra), no training and no tests.
venv: $(ALL)

# Train the default experiment (LunarLander DQN, default preset) until solved, evaluate it,
# then write its plot and an MP4 of the trained agent. wandb: online if logged in, else offline.
demo: $(CORE)
	$(PY) main.py train lunar_lander dqn --video

# The suite on the CPU's cores (pytest-xdist; a test file stays on one worker, so its module fixtures, a
# local Ray among them, are its own; the longest files first, ranked in tests/conftest.py). It is
# CPU-bound, and the machine's speed moves by up to 2x from hour to hour. On 2 cores of one machine, fresh
# clones, quiet, 2026-11-27, the suite before and after it was made to do ~20 % less, side by side:
# 9 min 34 s -> 7 min 57 s and 8 min 04 s at 11:00; 7 min 36 s -> 5 min 59 s at 12:15 (the old suite took
# up to 10 min 56 s earlier that day). Three workers on 2 cores were slower (8 min 18 s).
test: $(ALL)
	$(PY) -m pytest -q -n auto --maxprocesses 4 --dist loadfile --no-loadscope-reorder

# Refresh the lock: every package at the newest version setup.cfg allows, installed into a fresh venv,
# frozen into constraints.txt. Then `make test`, and commit the lock with what it changed.
lock:
	rm -rf .venv-lock
	$(PYTHON) -m venv .venv-lock
	.venv-lock/bin/python -m pip install --quiet --upgrade pip uv
	.venv-lock/bin/uv pip install --quiet --python .venv-lock/bin/python -e '.[all]'
	.venv-lock/bin/python -m pip freeze --all --exclude-editable > $(LOCK)
	rm -rf .venv-lock

# Speed measurements, one JSON line each (several minutes: they train to solved).
benchmark: $(ALL)
	$(PY) benchmarks/lunar_lander.py dqn
	$(PY) benchmarks/cartpole.py --train a2c
	$(PY) benchmarks/mario.py
	$(PY) benchmarks/minitaur.py
	$(PY) benchmarks/sweep.py
	$(PY) benchmarks/report.py

# The docs: regenerate every generated page, card and README region from the artefacts, then build the
# site into build/site/. docs-check changes nothing: it fails on drift or on a broken link (make test
# runs the same checks in tests/test_docs.py).
# mkdocs-material prints a banner about MkDocs 2 on every build; the site builds with MkDocs 1 (the lock)
docs docs-check: export NO_MKDOCS_2_WARNING = 1

docs: $(ALL)
	$(PY) -m tools.docgen
	$(VENV)/bin/mkdocs build --strict --quiet

docs-check: $(ALL)
	$(PY) -m tools.docgen --check
	$(VENV)/bin/mkdocs build --strict --quiet --site-dir build/site-check

# The README's and the model cards' GIFs, one per shipped model, each on a stated evaluation seed: the first
# of its recorded evaluation, or for Mario the first on which that evaluation reached the flag, played as it
# is evaluated (tools/gifs.py; `render` prints whether it reached it again). `python -m tools.gifs --missing`
# makes only the cards' missing ones.
.PHONY: gifs
gifs: $(ALL)
	$(PY) -m tools.gifs

# Commit the checkpoints and CSV tables of the runs under long_runs/ (before every stop of a session), with
# the figure of their flag share against env steps.
save-long-runs:
	$(PY) long_runs/queue.py --plot long_runs/mario_ppo/flag_share.png
	git add -A long_runs
	git diff --cached --quiet -- long_runs || git commit -q -m "long_runs: checkpoints and CSV tables" -- long_runs

clean:
	rm -rf runs wandb videos .pytest_cache

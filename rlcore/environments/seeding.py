"""Which env seeds a training run uses: never one of the evaluation or model-selection seeds, and never
one that another run seed uses.

Final evaluations use seeds from ``Experiment.eval_seed_base`` (1,000,000) up and periodic
evaluations from ``selection_seed_base`` (2,000,000) up, so every training env seed lies in
[0, TRAINING_SEED_SPAN). A run hands its envs seeds only when it starts and when it resumes: env
``i`` gets the seed at index ``episodes so far + i``. Each run seed owns a block of that span, and
an index wraps inside its own block, so two run seeds never share an env seed:

- seed 0 owns [0, 100,000): index ``i`` -> ``i`` (below 100,000), the seeds every shipped model was
  trained with (the largest index any of them used is about 73,000), so those runs still reproduce;
- seed ``s`` from 1 to ``MAX_RUN_SEED`` owns the 1,000 seeds from ``100,000 + (s - 1) * 1,000``.

A wrapped index repeats a seed within one run only, after 1,000 (or 100,000) episodes; that repeats
a start state the run has already met, nothing an evaluation sees.
"""
from __future__ import annotations

TRAINING_SEED_SPAN = 1_000_000
SEED_ZERO_BLOCK = 100_000  # seed 0: today's seeds, as the shipped runs used them
BLOCK = 1_000  # every other run seed
MAX_RUN_SEED = (TRAINING_SEED_SPAN - SEED_ZERO_BLOCK) // BLOCK  # 900
# a final evaluation plays one seed per episode, from eval_seed_base up to where the selection seeds begin
MAX_EVAL_EPISODES = 1_000_000  # = Experiment.selection_seed_base - Experiment.eval_seed_base


def training_env_seed(run_seed: int, index: int) -> int:
    """The env seed of episode (or env) ``index`` of the run seeded ``run_seed`` (0 to MAX_RUN_SEED)."""
    if not 0 <= run_seed <= MAX_RUN_SEED:
        raise ValueError(f"run seed {run_seed} is outside 0-{MAX_RUN_SEED}")
    if run_seed == 0:
        return index % SEED_ZERO_BLOCK
    return SEED_ZERO_BLOCK + (run_seed - 1) * BLOCK + index % BLOCK


def seed_block(run_seed: int) -> range:
    """Every env seed the run seeded ``run_seed`` can hand its envs."""
    first = training_env_seed(run_seed, 0)
    return range(first, first + (SEED_ZERO_BLOCK if run_seed == 0 else BLOCK))

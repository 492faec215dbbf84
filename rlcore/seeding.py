"""Which env seeds a training run uses: never one of the evaluation or model-selection seeds.

Final evaluations use seeds from ``Experiment.eval_seed_base`` (1,000,000) up and periodic
evaluations from ``selection_seed_base`` (2,000,000) up. Training env seeds are folded into
[0, 1,000,000), so no ``--seed`` and no number of episodes can reach either range.
"""
from __future__ import annotations

TRAINING_SEED_SPAN = 1_000_000
MAX_RUN_SEED = 2**32 - 1  # numpy and TensorFlow take seeds below 2**32
# a final evaluation plays one seed per episode, from eval_seed_base up to where the selection seeds begin
MAX_EVAL_EPISODES = 1_000_000  # = Experiment.selection_seed_base - Experiment.eval_seed_base


def training_env_seed(run_seed: int, index: int) -> int:
    """The env seed of episode (or env) ``index`` of the run seeded ``run_seed``."""
    return (run_seed * 1000 + index) % TRAINING_SEED_SPAN

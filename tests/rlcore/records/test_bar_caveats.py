"""`evaluate`'s verdict on the shipped model's bar says when it was not judged as the bar is: on fewer
episodes, on seeds in training's range, or on the periodic evaluations' seeds that chose the weights.
Seeds past those (the quickstart's --seed-base 3000000) are as unseen as the unseen range."""
import pytest

from rlcore.environments.registry import get_experiment
from rlcore.models.shipping import _bar_words

META = {"experiment": "minitaur", "algo": "sac", "config": {"eval_every_steps": 50_000, "eval_episodes": 5}}
SUMMARY = {"episodes": 30, "mean": 20.0, "time_limit_share": 1.0}


@pytest.mark.parametrize("seed_base, caveat", [
    (1_000_000, None),  # the unseen range
    (3_000_000, None),  # past the selection seeds the run used: never met
    (2_000_005, None),  # right after the 5 periodic evaluation seeds
    (5, "on seeds in training's range, which training may have met"),
    (999_990, "on seeds in training's range, which training may have met"),
    (2_000_000, "on the seeds of the periodic evaluations that chose the model's weights"),
    (1_999_990, "on the seeds of the periodic evaluations that chose the model's weights"),  # runs into them
])
def test_the_bar_verdict_names_seeds_training_or_selection_met(seed_base, caveat):
    words = _bar_words(get_experiment("minitaur"), META, SUMMARY, seed_base)
    assert words.startswith("; the shipped model's bar (") and ": met" in words
    assert (caveat in words) if caveat else not words.endswith(")"), words


def test_a_run_without_periodic_evaluations_met_no_selection_seeds():
    meta = {**META, "config": {"eval_every_steps": 0, "eval_episodes": 5}}
    assert "periodic" not in _bar_words(get_experiment("minitaur"), meta, SUMMARY, 2_000_000)

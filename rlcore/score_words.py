"""A shipped model's recorded evaluation in words, one rule for the README, the model cards and the
console (``main.py list``): ``270.7 ± 21.4``, ``20.45 ± 3.99`` or ``flag in 8 of 10``. Plain Python: it
reads a meta.json's ``evaluation`` and names only."""
from __future__ import annotations


def success_word(experiment: str, name: str, other: str = "success") -> str:
    """What a successful episode reaches: Mario's flag, or the axe that ends a castle (x-4); ``other``
    for any other experiment (the console gives its goal's info key)."""
    if experiment == "mario_ppo":
        return "axe" if name.endswith("-4") else "flag"
    return other


def score_words(evaluation: dict, experiment: str, name: str, plus_minus: str = "±") -> str:
    """The score on unseen seeds: successes out of episodes, or mean and spread of the return with one
    decimal from 100 up and two below (270.7 ± 21.4, but 20.45 ± 3.99)."""
    if "success_share" in evaluation:
        won = round(evaluation["success_share"] * evaluation["episodes"])
        return f"{success_word(experiment, name)} in {won} of {evaluation['episodes']}"
    digits = return_digits(evaluation["mean"])
    return f"{evaluation['mean']:,.{digits}f} {plus_minus} {evaluation['std']:,.{digits}f}"


def return_digits(mean: float) -> int:
    """Decimals of a return near ``mean``: one from 100 up, two below (Minitaur's 20.45)."""
    return 1 if abs(mean) >= 100 else 2

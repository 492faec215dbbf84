"""A run's records in words, one rule for the README, the model cards and the console (``main.py list``,
``status``): a recorded evaluation (``270.7 ± 21.4``, ``20.45 ± 3.99`` or ``flag in 8 of 10``), what
stopped a run, a wall time. Plain Python: it reads a meta.json's fields and names only."""
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


def count(number: int, noun: str) -> str:
    """``1 episode``, ``30 episodes``, ``1,000 runs``: a count with its noun, singular for one."""
    return f"{number:,} {noun}" + ("" if number == 1 else "s")


def hours(seconds: float) -> str:
    """A wall time as the tables write it: ``3.1 h`` from an hour up, else ``725 s``."""
    return f"{seconds / 3600:.1f} h" if seconds >= 3600 else f"{seconds:,.0f} s"


def stop_words(recorded: str, experiment: str, name: str, window: int = 100) -> str:
    """What ended a run, in words (meta.json's ``stopped_by`` names the rule and its value: ``max_env_steps
    1000000`` -> ``its budget of 1,000,000 env steps``); a rule not known here, as recorded. ``name``: the
    model's (Mario's level, for what its success reaches); ``window``: the run's averaging window."""
    rule, _, value = (recorded or "").partition(" ")
    try:
        number = float(value)
    except ValueError:
        return recorded or "–"
    texts = {"max_env_steps": f"its budget of {number:,.0f} env steps",
             "max_episodes": f"its budget of {number:,.0f} episodes",
             "stop_eval_score": f"a periodic evaluation of {number:,.1f} or more",
             "stop_score": f"a {window}-episode average of {number:,.1f} or more",
             "stop_success_share": f"the {success_word(experiment, name)} reached in {number * 100:g}% or more of the "
                                   f"last {window} training episodes from the start"}
    return texts.get(rule, recorded)

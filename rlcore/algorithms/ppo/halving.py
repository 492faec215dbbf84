"""``--lr-halve-at`` and ``--entropy-halve-at``: halve a PPO setting as the success share passes marks.

Mario 2-1 held at a 30-36 % flag share for 280 rollouts at Adam 1e-4, with approx KL ~0.022 per update;
a resume at 5e-5 took it to 45 % within 20 rollouts, another at 2.5e-5 to 58 %. 1-3, 1-4, 2-1, 2-2 and 2-3
each lowered the entropy weight by hand too (0.01 -> 0.003 -> 0.001 -> 0) once the flag came, so that
a policy sampled from pi stops trying other buttons where one wrong press kills. Each was a manual stop
and resume. This does the same by rule: the value is its base x 0.5^k, where k counts the marks that the
best success share so far has reached. The share is the stop rule's,
:attr:`~rlcore.training.episodes.EpisodeBook.settled_success_share` (none until the window is full).

The best share is kept in the checkpoint (one key, shared by every halved setting), so a resume comes
back at the same values; a resume's ``--lr`` or ``--entropy-coef`` is the value before any halving.
"""
from __future__ import annotations


class HalvingAtShares:
    """One setting (``name``), halved once for each mark the best success share so far has reached."""
    STATE_KEY = "best_success_share"

    def __init__(self, name: str, base: float, marks: tuple[float, ...], state: dict | None = None):
        self.name, self.base, self.marks = name, base, tuple(sorted(marks))
        self.best = float((state or {}).get(self.STATE_KEY, 0.0))

    def halvings(self) -> int:
        return sum(self.best >= mark for mark in self.marks)

    def rate(self) -> float:
        return self.base * 0.5 ** self.halvings()

    def observe(self, share: float | None) -> str | None:
        """After a rollout: note the share (``book.settled_success_share``; None before the window is
        full); return a line for the console when the value changed, else None."""
        if not self.marks or share is None or share <= self.best:
            return None
        before = self.rate()
        self.best = share
        if self.rate() == before:
            return None
        return (f"success share {share:.0%} reached {max(m for m in self.marks if m <= share):g}: "
                f"{self.name} {before:.3g} -> {self.rate():.3g}")

    def state(self) -> dict:
        return {self.STATE_KEY: self.best} if self.marks else {}


def LearningRateHalving(lr: float, marks: tuple[float, ...], state: dict | None = None) -> HalvingAtShares:
    """The learning rate's halving (``--lr-halve-at``)."""
    return HalvingAtShares("learning rate", lr, marks, state)

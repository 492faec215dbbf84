"""Training loops, one per algorithm family, sharing :mod:`rlcore.trainers.session`."""

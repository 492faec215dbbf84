"""Sweeps: one run folder per (seed, grid value) trial, on Ray Tune or one after another, their status.

May import: records, models, training and below; never api or cli.
"""

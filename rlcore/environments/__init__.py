"""Environments: the experiment registry (name -> env factory, presets, bars), any Gymnasium id as an experiment, the env pool, env seeds.

May import: rlcore.errors, rlcore.host, rlcore.hyperparams, rlcore.algorithms (its registry of families).
"""

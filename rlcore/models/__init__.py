"""Saved models: a policy rebuilt from a folder, a model from a run's last checkpoint, video and GIF, export with parity, the shipped models.

May import: training, algorithms, environments, networks and below; never records, sweeps, api or cli.
"""

"""Reading a run back: status, pace, commands, evaluation history, critic trace, plots, report with bootstrap intervals, keeping finished runs.

May import: models, training and below; never sweeps, api or cli.
"""

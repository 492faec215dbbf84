"""One training run: its spec, session, checkpoints, stop rules, episode book, periodic evaluation, tracking and the run function.

May import: everything below it (files, host, hyperparams, environments, networks, algorithms' shared parts); never
models, records, sweeps, api or cli, except training.run, which asks the registry of families for the loop, and
training.session, which draws the model folder's plot (records.plotting).
"""

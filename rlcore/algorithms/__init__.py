"""The algorithms: a folder per family (config, Keras agent with its GradientTape step, training loop) and
the parts they share (replay, GAE, the off-policy loop, sampling, the agent protocol).

May import: rlcore.errors, files, host, hyperparams, networks, environments.vector, training; never models, records, sweeps, api or cli.
"""

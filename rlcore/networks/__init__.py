"""Keras networks as files: custom layers, saving and loading whole .h5 models with checks, a model's forward pass in numpy.

May import: rlcore.errors, rlcore.files, rlcore.host.
"""

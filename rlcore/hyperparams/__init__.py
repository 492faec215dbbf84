"""Hyperparameters declared once: allowed values beside each field, the fields every config shares, and their command-line flags.

May import: rlcore.errors, rlcore.files.
"""

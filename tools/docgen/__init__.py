"""The docs generator: every number in the README, the docs site and the model cards that comes from an
artefact, written from the checkout (``python -m tools.docgen``; ``--check`` fails on drift)."""

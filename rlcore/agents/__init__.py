"""Agents: one file per algorithm, Keras models and a compiled GradientTape train step."""

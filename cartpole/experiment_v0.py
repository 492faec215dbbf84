"""Registry entry for CartPole-v0 (see :mod:`cartpole.experiment`)."""
from cartpole.experiment import EXPERIMENT_V0 as EXPERIMENT  # noqa: F401

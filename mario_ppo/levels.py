"""The levels of Super Mario Bros (worlds 1-8, stages 1-4): what ``--world`` and ``--stage`` allow,
for training and for choosing a shipped model. Imports nothing heavy, so the CLI parser can use it."""
from rlcore.hyperparams.allowed import Allowed

WORLD = Allowed(low=1, high=8)
STAGE = Allowed(low=1, high=4)

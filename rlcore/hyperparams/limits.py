"""The values the settings of a command (not of a config) may take: a run's seed, the episodes of an
evaluation, a video's frame rate. Declared once, checked the same by the command line and the API."""
from rlcore.environments.seeding import MAX_EVAL_EPISODES, MAX_RUN_SEED
from rlcore.hyperparams.allowed import Allowed

RUN_SEEDS = Allowed(low=0, high=MAX_RUN_SEED)
FINAL_EVALUATION = Allowed(low=0, high=MAX_EVAL_EPISODES)  # one unseen seed per episode; 0 = none
EVAL_COUNT = Allowed(low=1, high=MAX_EVAL_EPISODES)  # evaluate's and render's --episodes
FRAME_RATE = Allowed(low=1, high=240)  # render's --fps

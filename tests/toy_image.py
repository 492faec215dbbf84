"""Registry module of the picture version of the toy task (PPO tests)."""
from tests.toy import IMAGE_EXPERIMENT as EXPERIMENT  # noqa: F401

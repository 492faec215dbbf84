"""Registry module of the continuous toy task (SAC tests)."""
from tests.toy import REACH_EXPERIMENT as EXPERIMENT  # noqa: F401

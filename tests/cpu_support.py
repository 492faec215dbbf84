"""What this process's CPU settings let a test run: a bfloat16 network cannot run under a oneDNN capped
below AVX-512 on an AVX-512 CPU (``ONEDNN_MAX_CPU_ISA=AVX2 make test``, the developer guide's way to take
the float32 kernels of an older CPU), so the tests that build one skip there, saying why."""
import pytest

from rlcore.host.cpu import bfloat16_refusal, cpu_flags

BFLOAT16_BLOCKED = bfloat16_refusal("bfloat16", cpu_flags())
needs_bfloat16 = pytest.mark.skipif(BFLOAT16_BLOCKED is not None, reason=BFLOAT16_BLOCKED or "")


def skip_where_its_precision_cannot_run(meta: dict) -> None:
    """Skip the test of a model trained in bfloat16 (``meta``: its meta.json) where this process cannot
    build one, saying why: the shipped models' tests and the kept sweeps' replays (Mario 1-1's seeds) alike."""
    if (meta.get("config") or {}).get("precision") == "bfloat16" and BFLOAT16_BLOCKED:
        pytest.skip(BFLOAT16_BLOCKED)

"""The CPU a run trains on, read from /proc/cpuinfo (Linux): its name and vector units for meta.json,
and whether ``--precision bfloat16`` was ever measured faster on such a CPU."""
from __future__ import annotations

import os
import platform
from pathlib import Path

CPUINFO = Path("/proc/cpuinfo")
SIMD_FLAGS = ("avx2", "fma", "avx512f", "avx512_bf16", "amx_tile")  # what oneDNN picks its code paths by
# the CPU flags bfloat16 was measured faster with (README, Speed): Intel's AMX tiles, and AMD's
# AVX-512 bfloat16 dot products (an EPYC without AMX, 2026-11-26: update 11.6 -> 6.6 s)
BFLOAT16_MATMUL = ("amx_bf16", "avx512_bf16")
# the CPU flags with which TensorFlow hands bfloat16 work to oneDNN (its IsBF16SupportedByOneDNNOnThisCPU)
ONEDNN_BFLOAT16 = ("avx512f", "avx_ne_convert")


def first_cpu_fields(cpuinfo: str | Path = CPUINFO) -> dict[str, str]:
    """The first core's ``key: value`` fields; empty where the file cannot be read."""
    try:
        text = Path(cpuinfo).read_text()
    except OSError:
        return {}
    first = {}
    for line in text.splitlines():
        if ":" in line:
            key, value = (part.strip() for part in line.split(":", 1))
            first.setdefault(key, value)
    return first


def cpu_flags(cpuinfo: str | Path = CPUINFO) -> set[str] | None:
    """The first core's flags, or None where they cannot be read (no claim either way then)."""
    return _flags(first_cpu_fields(cpuinfo))


def _flags(fields: dict[str, str]) -> set[str] | None:
    return set(fields["flags"].split()) if "flags" in fields else None


def cpu_description(cpuinfo: str | Path = CPUINFO) -> str:
    """The CPU a run trained on, e.g. ``AMD EPYC (avx2 fma avx512f)``. A seed repeats a run bit for bit
    on one machine, but TensorFlow's oneDNN kernels order float sums by the CPU's vector units, so the
    same seed on another CPU can drift (seen on LunarLander's dueling runs); meta.json says which."""
    first = first_cpu_fields(cpuinfo)
    name = first.get("model name") or platform.processor() or platform.machine() or "unknown"
    flags = _flags(first) or set()
    simd = [f for f in SIMD_FLAGS if f in flags]
    return f"{name} ({' '.join(simd)})" if simd else name


def bfloat16_note(precision: str, flags: set[str] | None) -> str | None:
    """One console line when a run computes in bfloat16 on a CPU where that was never measured faster."""
    if precision != "bfloat16" or flags is None or flags.intersection(BFLOAT16_MATMUL):
        return None
    return (f"note: --precision bfloat16 was measured faster only on CPUs with "
            f"{' or '.join(BFLOAT16_MATMUL)}, which this one lacks; `python benchmarks/mario.py --skip-env "
            "--skip-pool` compares both precisions here, and a resume with --precision float32 switches back")


def bfloat16_refusal(precision: str, flags: set[str] | None, environ=os.environ) -> str | None:
    """Why a bfloat16 network cannot run in this process, or None. TensorFlow sends bfloat16 convolutions
    to oneDNN on any CPU with AVX-512F or AVX-NE-CONVERT; a oneDNN capped below AVX-512
    (``ONEDNN_MAX_CPU_ISA=AVX2``, as when imitating an older CPU) has no kernel for them, and the first
    forward pass would fail deep in TensorFlow. Other CPUs never hit this: TensorFlow runs bfloat16 on
    its own kernels there."""
    if precision != "bfloat16" or flags is None or not flags.intersection(ONEDNN_BFLOAT16):
        return None
    if environ.get("TF_ENABLE_ONEDNN_OPTS", "1").strip().lower() in ("0", "false"):
        return None  # TensorFlow's own kernels, not oneDNN's
    # oneDNN reads its cap from ONEDNN_MAX_CPU_ISA, else from the old name; a name it does not know caps nothing
    name = next((n for n in ("ONEDNN_MAX_CPU_ISA", "DNNL_MAX_CPU_ISA") if environ.get(n, "").strip()), None)
    cap = environ.get(name, "").strip().upper() if name else ""
    no_bfloat16 = {"SSE41", "AVX", "AVX2", "AVX2_VNNI"} | ({"AVX2_VNNI_2"} if "avx_ne_convert" not in flags else set())
    if cap in no_bfloat16:
        return (f"a bfloat16 network cannot run with {name}={cap}: on this CPU TensorFlow hands bfloat16 "
                f"convolutions to oneDNN, which has none for that instruction set; unset {name}, or set "
                f"TF_ENABLE_ONEDNN_OPTS=0 to use TensorFlow's own kernels")
    return None

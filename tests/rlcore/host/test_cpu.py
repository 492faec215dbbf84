"""What /proc/cpuinfo tells: meta.json's CPU line, and the bfloat16 note (said once where bfloat16 was
never measured faster, and nowhere else)."""
from rlcore.host.cpu import bfloat16_note, cpu_description, cpu_flags

CORE = """processor\t: {n}
vendor_id\t: GenuineIntel
model name\t: Intel(R) Xeon(R) Platinum 8375C CPU @ 2.90GHz
flags\t\t: fpu sse2 avx {extra} fma avx512f avx512_vnni
"""


def test_the_cpu_line_names_the_model_and_the_vector_units_onednn_picks_by(tmp_path):
    info = tmp_path / "cpuinfo"
    info.write_text(CORE.format(n=0, extra="avx2") + "\n" + CORE.format(n=1, extra=""))
    # the first core's fields; the SIMD flags in SIMD_FLAGS order, others (avx, sse2, vnni) left out
    assert cpu_description(info) == "Intel(R) Xeon(R) Platinum 8375C CPU @ 2.90GHz (avx2 fma avx512f)"


def test_a_cpu_without_the_listed_flags_is_named_alone(tmp_path):
    info = tmp_path / "cpuinfo"
    info.write_text("processor : 0\nmodel name : ARM Neoverse-N1\nFeatures : fp asimd\n")
    assert cpu_description(info) == "ARM Neoverse-N1"


def test_no_cpuinfo_falls_back_to_the_platform(tmp_path, monkeypatch):
    monkeypatch.setattr("platform.processor", lambda: "arm")
    assert cpu_description(tmp_path / "missing") == "arm"
    monkeypatch.setattr("platform.processor", lambda: "")  # Linux often says nothing here
    monkeypatch.setattr("platform.machine", lambda: "aarch64")
    assert cpu_description(tmp_path / "missing") == "aarch64"


CPUINFO = """processor\t: 0
vendor_id\t: GenuineIntel
flags\t\t: fpu sse2 avx2 avx512f amx_tile amx_bf16
bugs\t\t: spectre_v1
processor\t: 1
flags\t\t: fpu
"""


def test_flags_come_from_the_first_processor(tmp_path):
    (tmp_path / "cpuinfo").write_text(CPUINFO)
    assert cpu_flags(tmp_path / "cpuinfo") == {"fpu", "sse2", "avx2", "avx512f", "amx_tile", "amx_bf16"}
    (tmp_path / "bare").write_text("processor\t: 0\n")
    assert cpu_flags(tmp_path / "bare") is None
    assert cpu_flags(tmp_path / "missing") is None


def test_the_note_appears_only_for_bfloat16_without_bfloat16_dot_products():
    assert bfloat16_note("bfloat16", {"avx2", "avx512f"}).startswith("note: --precision bfloat16")
    assert bfloat16_note("bfloat16", {"avx2", "amx_bf16"}) is None
    assert bfloat16_note("bfloat16", {"avx512f", "avx512_bf16"}) is None  # measured faster on an EPYC
    assert bfloat16_note("float32", {"avx2"}) is None
    assert bfloat16_note("bfloat16", None) is None  # flags unknown (not Linux): no claim either way

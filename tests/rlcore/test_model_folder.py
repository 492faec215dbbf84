"""meta.json's record of the machine: the CPU line read from /proc/cpuinfo."""
from rlcore.trainers.model_folder import cpu_description

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

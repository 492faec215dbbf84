"""The docs generator left the installed package (issue 64): the old command says where it went."""

def test_the_old_docgen_command_points_to_the_new_one():
    import subprocess
    import sys
    from pathlib import Path

    done = subprocess.run([sys.executable, "-m", "rlcore.docgen"], cwd=Path(__file__).resolve().parents[2],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 1 and done.stdout == ""
    assert done.stderr.strip() == ("rlcore.docgen moved: run `python -m tools.docgen` (or `make docs`) from a "
                                   "checkout of the repository")

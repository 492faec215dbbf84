"""The README and the docs site: no generated number has drifted from its artefact, the site builds
with no broken link, every documented command parses, and the README stays short."""
from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from rlcore.cli.parser import build_parser

REPO = Path(__file__).resolve().parents[1]
DOC_FILES = [REPO / "README.md"] + sorted((REPO / "docs").rglob("*.md"))
# placeholders that documented commands use, and what stands in for them when the line is parsed
PLACEHOLDERS = {"RUN_NAME": "run", "RUN_DIR": "run", "<repository URL>": "url", "<run>": "run",
                "<name>": "name", "<algo>": "dqn", "ALGO": "dqn", "<experiment>": "lunar_lander",
                "EXPERIMENT": "lunar_lander"}
# the shape of a command rather than a command: not parsed
SCHEMATIC = {"python main.py ...", "python main.py COMMAND ...",
             "python main.py train EXPERIMENT ALGO --preset NAME --flag VALUE"}


def test_generated_docs_have_not_drifted():
    result = subprocess.run([sys.executable, "-m", "tools.docgen", "--check"], cwd=REPO,
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stdout + result.stderr


def test_docgen_imports_no_tensorflow():
    code = "import sys, tools.docgen.main as d; d.generate(); print('tensorflow' in sys.modules)"
    result = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, timeout=120)
    assert result.stdout.strip() == "False", result.stdout + result.stderr


def test_site_builds_strict(tmp_path):
    pytest.importorskip("mkdocs", reason="mkdocs is not installed (the docs extra: pip install -e '.[docs]')")
    pytest.importorskip("material", reason="mkdocs-material is not installed (the docs extra)")
    result = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
                            cwd=REPO, capture_output=True, text=True, timeout=600,
                            env={**os.environ, "NO_MKDOCS_2_WARNING": "1"})
    assert result.returncode == 0, result.stderr[-4000:]
    assert (tmp_path / "site" / "index.html").is_file()
    assert (tmp_path / "site" / "models" / "mario_ppo_1-1" / "index.html").is_file()


def documented_commands() -> list[tuple[str, str]]:
    """Every ``python main.py ...`` command in the README and the docs: lines of code blocks that start
    with it, and inline `python main.py ...` spans. The dated notes are history and left out."""
    found = []
    for path in DOC_FILES:
        if "notes" in path.relative_to(REPO).parts:
            continue
        text = path.read_text()
        spans = re.findall(r"`(python main\.py [^`]+)`", text)
        spans += [line.strip() for line in text.splitlines() if line.strip().startswith("python main.py ")]
        for span in spans:
            if span not in SCHEMATIC:
                found.append((path.relative_to(REPO).as_posix(), span))
    return found


def test_there_are_documented_commands():
    assert len(documented_commands()) > 50


@pytest.mark.parametrize("where,command", documented_commands())
def test_documented_command_parses(where, command):
    line = command.split("  #")[0].split(" # ")[0].strip()
    for placeholder, value in PLACEHOLDERS.items():
        line = line.replace(placeholder, value)
    argv = shlex.split(line)[2:]  # drop "python main.py"
    if "--help" in argv or "-h" in argv:
        argv = [a for a in argv if a not in ("--help", "-h")]
    try:
        build_parser(argv).parse_args(argv)
    except SystemExit as stop:
        pytest.fail(f"{where}: `{command}` does not parse (exit {stop.code})")


def test_readme_is_short_and_says_no_session():
    text = (REPO / "README.md").read_text()
    assert len(text.splitlines()) <= 220
    assert "session" not in text.lower()
    assert "make demo" in text and "make test" in text


def test_every_shipped_model_has_a_card():
    for meta in (REPO / "saved_networks").glob("*/*/meta.json"):
        card = meta.parent / "README.md"
        assert card.is_file(), f"{meta.parent} has no model card"
        head = card.read_text().split("---")[1]
        assert "library_name: keras" in head and "model-index:" in head


def test_the_layout_page_names_every_module():
    """docs/developer/layout.md is where a newcomer finds what each file holds: a module added without a
    line there is a module they cannot find."""
    layout = (REPO / "docs" / "developer" / "layout.md").read_text()
    packages = ["rlcore", "lunar_lander", "cartpole", "mario_ppo", "minitaur"]
    modules = [path for name in packages for path in sorted((REPO / name).rglob("*.py")) if path.name != "__init__.py"]
    assert len(modules) > 60
    def named(path: Path) -> bool:
        """The file's name on the page, not inside another name (status.py in sweep_status.py)."""
        name = re.escape(path.name)
        return re.search(rf"(?<![\w/]){name}|{path.parent.name}/{name}", layout) is not None

    missing = [str(path.relative_to(REPO)) for path in modules if not named(path)]
    assert not missing, f"docs/developer/layout.md names no line for {missing}"


def test_no_page_shows_a_doubled_percent_sign():
    """argparse expands ``%%`` in a flag's help but not in a description, and a field's help reaches the
    hyperparameter page unexpanded: each would show ``%%`` to the reader (the report command's description did)."""
    shown = [str(path.relative_to(REPO)) for path in DOC_FILES if "%%" in path.read_text()]
    assert not shown, shown


def test_the_reproducibility_page_names_every_setting_a_record_replays_on():
    from rlcore.host import machine

    page = (REPO / "docs" / "guide" / "reproducibility.md").read_text()
    for name in ("TF_ENABLE_ONEDNN_OPTS", *machine.NUMERIC_VARIABLES):
        assert re.search(rf"`{name}[`=]", page), name


def test_every_relative_link_holds_in_the_repository():
    """Pages are read as files too (GitHub, an editor): each relative link of the README, the docs, the
    model cards and the kept reports points at a file that exists where the page sits. (The site's hook
    points links into saved_networks/ and results/ at its mounted copies; the strict build checks those.)"""
    import posixpath

    link = re.compile(r"\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
    pages = DOC_FILES + sorted((REPO / "saved_networks").rglob("README.md")) + sorted((REPO / "results").rglob("*.md"))
    broken, seen = [], 0
    for path in pages:
        page = path.relative_to(REPO).as_posix()
        text = re.sub(r"```.*?```", "", path.read_text(), flags=re.S)  # code blocks hold no links
        for target in link.findall(text):
            file = target.partition("#")[0]
            if not file or "://" in file or file.startswith(("/", "mailto:")):
                continue
            seen += 1
            if not (REPO / posixpath.normpath(posixpath.join(posixpath.dirname(page), file))).exists():
                broken.append(f"{page}: {target}")
    assert seen > 100 and not broken, broken[:20]


def test_the_site_hook_points_repository_links_at_the_mounted_copies():
    pytest.importorskip("mkdocs", reason="mkdocs is not installed (the docs extra: pip install -e '.[docs]')")
    from tools.docgen.hooks import site_links

    page = "docs/models/mario_ppo_1-1.md"
    text = ("![plot](../../saved_networks/mario_ppo/1-1/a.png) [report](../../results/sweeps/x/report.md#iqm) "
            "[api](../api.md) [web](https://example.org/saved_networks/a.png)")
    assert site_links(text, page) == ("![plot](../saved_networks/mario_ppo/1-1/a.png) "
                                      "[report](../results/sweeps/x/report.md#iqm) [api](../api.md) "
                                      "[web](https://example.org/saved_networks/a.png)")


def test_no_wrapped_line_starts_a_numbered_list_by_accident():
    """A paragraph whose wrapped line begins "10. " starts a new list item on the site (Python-Markdown reads
    it so; GitHub does not): the Mario page's reward item broke off at "all divided by" that way. Every
    numbered line of a page continues the list above it at its indent (1 after nothing, n after n-1)."""
    pages = DOC_FILES + sorted((REPO / "saved_networks").rglob("*.md")) + sorted((REPO / "results").rglob("*.md"))
    item = re.compile(r"^( *)(\d+)\. ")
    bad = []
    for path in pages:
        text = re.sub(r"```.*?```", lambda m: "\n" * m.group().count("\n"), path.read_text(), flags=re.S)
        last: dict[str, int] = {}  # indent -> the number of the last item at that indent
        for number, line in enumerate(text.splitlines(), 1):
            match = item.match(line)
            if match:
                indent, n = match.group(1), int(match.group(2))
                if n != 1 and last.get(indent) != n - 1:
                    bad.append(f"{path.relative_to(REPO)}:{number}: {line.strip()[:60]}")
                last[indent] = n
    assert not bad, bad


def test_every_list_stands_apart_from_the_paragraph_above_it():
    """A list right under a paragraph line, with no blank line between, is a list on GitHub but run-on text
    on the site (Python-Markdown): "Why:" then "- 1-3 is the treetop level ..." read as one paragraph with
    dashes in it on five pages of notes and training logs."""
    pages = DOC_FILES + sorted((REPO / "saved_networks").rglob("*.md")) + sorted((REPO / "results").rglob("*.md"))
    item = re.compile(r"^\s*([-*+]|\d+\.)\s")
    not_a_paragraph = re.compile(r"^\s*([-*+]\s|\d+\.\s|#|\||<|!!!|\?\?\?|>)")
    bad = []
    for path in pages:
        text = re.sub(r"\A---\n.*?\n---\n", lambda m: "\n" * m.group().count("\n"), path.read_text(), flags=re.S)
        lines = re.sub(r"```.*?```", lambda m: "\n" * m.group().count("\n"), text, flags=re.S).splitlines()
        start = None  # the first line of the block the line belongs to
        for number, line in enumerate(lines):
            if not line.strip():
                start = None
                continue
            start = number if start is None else start
            if (item.match(line) and number != start and not not_a_paragraph.match(lines[start])
                    and not any(item.match(lines[above]) for above in range(start, number))):
                bad.append(f"{path.relative_to(REPO)}:{number + 1}: {line.strip()[:60]}")
    assert not bad, bad

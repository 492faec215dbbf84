"""No import cycle in rlcore or the docs generator: not at module level, and not through an import inside
a function either (which hides a cycle from Python but not from a reader). Imports under
``if TYPE_CHECKING:`` are for annotations only and are left out."""
import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGES = ("rlcore", "tools")


def module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def modules() -> dict[str, Path]:
    return {module_name(p): p for package in PACKAGES for p in (ROOT / package).rglob("*.py")
            if p.name != "__main__.py"}


def _type_checking_only(node: ast.AST) -> bool:
    test = getattr(node, "test", None)
    return isinstance(node, ast.If) and isinstance(test, ast.Name) and test.id == "TYPE_CHECKING"


def imported(path: Path, known: set[str]) -> set[str]:
    """The package modules ``path`` imports anywhere in it (the longest known name of each import)."""
    out: set[str] = set()

    def resolve(name: str) -> None:
        while name and name not in known:
            name = name.rpartition(".")[0]
        if name:
            out.add(name)

    def visit(node: ast.AST) -> None:
        if _type_checking_only(node):
            return
        if isinstance(node, ast.Import):
            for alias in node.names:
                resolve(alias.name)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            for alias in node.names:
                full = f"{node.module}.{alias.name}"
                resolve(full if full in known else node.module)
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(ast.parse(path.read_text()))
    return out


def import_graph() -> dict[str, set[str]]:
    mods = modules()
    known = set(mods)
    return {name: imported(path, known) - {name} for name, path in mods.items()}


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []
    counter = [0]

    def connect(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                connect(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            connect(v)
    return found


def test_no_module_imports_itself_back():
    assert cycles(import_graph()) == []


def test_the_check_finds_a_cycle_hidden_in_a_function(tmp_path):
    late = tmp_path / "late.py"
    late.write_text("import os\n\ndef later():\n    from rlcore.b import thing\n\n"
                    "if TYPE_CHECKING:\n    from rlcore.c import Only\n")
    assert imported(late, {"rlcore.b", "rlcore.c"}) == {"rlcore.b"}  # the annotation-only import is no edge
    graph = {"rlcore.a": {"rlcore.b"}, "rlcore.b": {"rlcore.c"}, "rlcore.c": {"rlcore.a"}, "rlcore.d": {"rlcore.a"}}
    assert cycles(graph) == [["rlcore.a", "rlcore.b", "rlcore.c"]]


def test_every_folder_of_code_is_a_package_the_wheel_finds():
    """setup.cfg's `packages = find:` takes only folders with an __init__.py: one without (rlcore/runs/, now records/,
    was once ignored by a `runs/` line meant for the top-level run folders) would be left out of a wheel."""
    from setuptools import find_packages

    found = set(find_packages(str(ROOT), include=["rlcore", "rlcore.*"]))
    folders = {".".join(p.parent.relative_to(ROOT).parts) for p in (ROOT / "rlcore").rglob("*.py")}
    assert folders <= found, sorted(folders - found)

"""The host package's layers (host/README.md, "Layers"): every import of an
orfa module, at the top of a module or inside a function, goes to the
importer's own layer or one below it, and no modules import each other in a
circle. Read from the source (ast), so an import that only runs on some
path counts as well."""

import ast
import re
from pathlib import Path
from typing import Dict, List, Set, Tuple

import pytest

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "host" / "orfa"
README = ROOT / "host" / "README.md"


def module_names() -> Dict[str, Path]:
    """orfa's modules by dotted name (a package by its own name)."""
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = ("orfa",) + path.relative_to(PACKAGE).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


MODULES = module_names()


def _resolve(target: str) -> str:
    """The module an import of `target` loads last: itself, or (a name
    inside a module) the nearest module above it."""
    while target not in MODULES:
        target = target.rpartition(".")[0]
    return target


def imports_of(name: str, source: str) -> Set[str]:
    """The orfa modules `name` imports, anywhere in its source: `import
    orfa.x`, `from .x import y` (y itself when it is a module),
    importlib.import_module("orfa.x")."""
    is_package = MODULES[name].name == "__init__.py"
    found: Set[str] = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parts = name.split(".")
                base = parts[:len(parts) - node.level + (1 if is_package else 0)]
                base = ".".join(base + ([node.module] if node.module else []))
            else:
                base = node.module or ""
            targets = [base + "." + a.name for a in node.names]
        elif isinstance(node, ast.Call) and getattr(node.func, "attr", "") == "import_module" \
                and node.args and isinstance(node.args[0], ast.Constant):
            targets = [node.args[0].value]
        else:
            continue
        found |= {_resolve(t) for t in targets if t == "orfa" or t.startswith("orfa.")}
    found.discard(name)
    return found


def graph() -> Dict[str, Set[str]]:
    return {name: imports_of(name, path.read_text()) for name, path in MODULES.items()}


def layers(text: str) -> List[Tuple[str, List[str]]]:
    """The README's "Layers" table: per row (lowest first), its title and
    its module patterns (`orfa.cli.*` is the package and every module below
    it)."""
    section = text.split("\n## Layers", 1)[1].split("\n## ", 1)[0]
    rows = [line for line in section.splitlines() if line.startswith("| ") and "`orfa" in line]
    return [(row.split("|")[1].strip(), re.findall(r"`(orfa[\w.*]*)`", row)) for row in rows]


def layer_of(name: str, table) -> int:
    for rank, (_, patterns) in enumerate(table):
        for pattern in patterns:
            if name == pattern or (pattern.endswith(".*") and
                                   (name + ".").startswith(pattern[:-1])):
                return rank
    raise AssertionError("%s is in no layer: add it to the Layers table of host/README.md"
                         % name)


def cycles(edges: Dict[str, Set[str]]) -> List[List[str]]:
    """Every strongly connected group of more than one module (Tarjan)."""
    index: Dict[str, int] = {}
    low: Dict[str, int] = {}
    stack: List[str] = []
    out: List[List[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in sorted(edges.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                out.append(sorted(group))

    for v in sorted(edges):
        if v not in index:
            visit(v)
    return out


def test_the_package_has_no_import_cycle():
    assert cycles(graph()) == []


def test_every_import_goes_down_the_layers():
    table = layers(README.read_text())
    wrong = ["%s (%s) imports %s (%s)" % (a, table[layer_of(a, table)][0],
                                          b, table[layer_of(b, table)][0])
             for a, targets in graph().items() for b in sorted(targets)
             if layer_of(b, table) > layer_of(a, table)]
    assert wrong == []


def test_every_module_has_a_layer():
    table = layers(README.read_text())
    for name in MODULES:
        layer_of(name, table)


# --- the checker itself: it finds what it must --------------------------------------

def test_imports_are_read_wherever_they_stand():
    src = ("from . import protocol as p\nfrom .errors import OrfaError\n"
           "import orfa.flow\nimport os\n"
           "def f():\n    from .board import Board\n"
           "    import importlib\n    importlib.import_module('orfa.flash')\n")
    assert imports_of("orfa.gateway", src) == {
        "orfa.protocol", "orfa.errors", "orfa.flow", "orfa.board", "orfa.flash"}
    # relative to a package's __init__, and a name that is not a module
    assert imports_of("orfa.cli", "from .. import __version__\nfrom . import plot\n"
                      "from .common import UsageError\n") == {
        "orfa", "orfa.cli.plot", "orfa.cli.common"}
    assert imports_of("orfa.cli.plot", "from . import main\nfrom ..sim import SimError\n") \
        == {"orfa.cli", "orfa.sim"}


def test_a_cycle_is_found():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert cycles({"a": {"b"}, "b": set()}) == []


@pytest.mark.parametrize("name, rank", [("orfa.errors", 0), ("orfa.gateway", 1),
                                        ("orfa.board", 2), ("orfa.clients.servo", 3),
                                        ("orfa.cli", 4), ("orfa.cli.plot", 4)])
def test_the_layers_are_read_from_the_readme(name, rank):
    table = layers(README.read_text())
    assert len(table) == 5
    assert layer_of(name, table) == rank


def test_an_upward_import_is_caught():
    table = layers(README.read_text())
    # gateway.py making Boards by importing orfa.board: what it did before
    assert layer_of("orfa.board", table) > layer_of("orfa.gateway", table)
    with pytest.raises(AssertionError, match="no layer"):
        layer_of("orfa.nowhere", table)

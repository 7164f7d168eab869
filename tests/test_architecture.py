"""The layout keeps its promises: no import cycles, a pure core, small modules.

Read from the source with :mod:`ast` (module-level imports only: an import
inside a function runs later and cannot form an import-time cycle).
"""

from __future__ import annotations

import ast
from pathlib import Path
from typing import Dict, List, Set

import pytest

SRC = Path(__file__).resolve().parents[1] / "src"
PKG = SRC / "rangebearing"
MAX_LINES = 300
# Cohesive modules allowed to be longer, each with its reason.
LONGER = {
    "rangebearing.net.protocol": "wire format v1: encoder, decoder and their shared field table in one place",
}


def module_name(path: Path) -> str:
    parts = list(path.relative_to(SRC).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES: Dict[str, Path] = {module_name(p): p for p in PKG.rglob("*.py")}


def top_level_imports(name: str) -> Set[str]:
    path = MODULES[name]
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found: Set[str] = set()
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        if isinstance(node, ast.If):  # e.g. "if TYPE_CHECKING:" blocks are not run
            continue
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            submodules = {f"{target}.{a.name}" for a in node.names} & MODULES.keys()  # "from . import checks"
            found.update(submodules)
            if len(submodules) < len(node.names):
                found.add(target)
    return {m for m in found if m in MODULES and m != name}


GRAPH = {name: top_level_imports(name) for name in MODULES}


def test_the_graph_was_read() -> None:
    assert "rangebearing.core.params" in GRAPH["rangebearing.core.pipeline"]
    assert "rangebearing.config.checks" in GRAPH["rangebearing.config.schema"]


def test_no_import_cycles() -> None:
    state: Dict[str, int] = {}
    cycles: List[List[str]] = []

    def visit(node: str, stack: List[str]) -> None:
        state[node] = 1
        for nxt in sorted(GRAPH[node]):
            if state.get(nxt) == 1:
                cycles.append([*stack[stack.index(nxt):], nxt])
            elif nxt not in state:
                visit(nxt, [*stack, nxt])
        state[node] = 2

    for name in sorted(GRAPH):
        if name not in state:
            visit(name, [name])
    assert cycles == []


@pytest.mark.parametrize("name", sorted(m for m in MODULES if m.startswith("rangebearing.core")))
def test_the_core_imports_nothing_of_the_shell(name: str) -> None:
    allowed = ("rangebearing.core", "rangebearing.errors", "rangebearing._compat")
    outside = [m for m in GRAPH[name] if not (m == allowed[0] or m.startswith(allowed[0] + ".") or m in allowed)]
    assert outside == []


def test_interfaces_do_not_import_their_implementations() -> None:
    assert not {m for m in GRAPH["rangebearing.sources.base"] if m.startswith("rangebearing.sources.")}


@pytest.mark.parametrize("name", sorted(MODULES))
def test_modules_stay_small(name: str) -> None:
    lines = len(MODULES[name].read_text(encoding="utf-8").splitlines())
    limit = 450 if name in LONGER else MAX_LINES
    assert lines <= limit, f"{MODULES[name]} has {lines} lines"

"""core.tracking has no import cycle: the result types and the input validation live in their
own modules, imported by both the readable tracker and the compiled kernel."""

from __future__ import annotations

import ast
from pathlib import Path

import core.tracking

PACKAGE = "core.tracking"
ROOT = Path(core.tracking.__file__).parent


def _imports(path: Path) -> set[str]:
    """Modules of the package a file imports, at module level or inside functions."""
    names: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module)
            # `from core.tracking import ekf` imports the submodule core.tracking.ekf
            names |= {f"{node.module}.{a.name}" for a in node.names}
    modules = {f"{PACKAGE}.{p.stem}" for p in ROOT.glob("*.py") if p.stem != "__init__"}
    return {n for n in names if n in modules}


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Every module that can reach itself, with the path (depth-first search)."""
    found = []
    for start in sorted(graph):
        stack = [(start, [start])]
        seen = set()
        while stack:
            node, path = stack.pop()
            for nxt in graph.get(node, ()):
                if nxt == start:
                    found.append([*path, start])
                elif nxt not in seen:
                    seen.add(nxt)
                    stack.append((nxt, [*path, nxt]))
    return found


def test_cycle_finder_finds_a_cycle() -> None:
    assert _cycles({"a": {"b"}, "b": {"a"}, "c": {"a"}}) == [["a", "b", "a"], ["b", "a", "b"]]
    assert _cycles({"a": {"b"}, "b": set()}) == []


def test_no_import_cycle_in_tracking() -> None:
    graph = {f"{PACKAGE}.{p.stem}": _imports(p) for p in ROOT.glob("*.py") if p.stem != "__init__"}
    assert _cycles(graph) == []
    assert graph[f"{PACKAGE}.kernel"] >= {f"{PACKAGE}.results", f"{PACKAGE}.inputs"}

"""Architecture rules: ``core`` never imports Qt or ``app``; no import cycle in ``core`` or ``app``.

The layer contracts (which package may import which) are import-linter contracts in
``pyproject.toml``, checked by ``lint-imports`` in ``make test``.
"""

from __future__ import annotations

import ast
import pkgutil
import subprocess
import sys
from collections.abc import Iterable, Mapping
from pathlib import Path

import grimp
import pytest

import core

ROOT = Path(__file__).resolve().parents[1]
QT_MODULES = ("PySide6", "shiboken6", "pyqtgraph", "PyQt5", "PyQt6")


def core_modules() -> list[str]:
    return sorted(
        m.name
        for m in pkgutil.walk_packages(core.__path__, prefix="core.")
        if "__main__" not in m.name
    )


def test_core_has_modules() -> None:
    assert "core.config" in core_modules()


def test_importing_any_core_module_loads_no_qt() -> None:
    mods = core_modules()
    code = (
        "import importlib, sys\n"
        f"for m in {mods!r}:\n"
        "    importlib.import_module(m)\n"
        f"bad = sorted(k for k in sys.modules if k.split('.')[0] in {QT_MODULES!r})\n"
        "print(','.join(bad))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True
    )
    assert out.stdout.strip() == "", f"core imported Qt modules: {out.stdout.strip()}"


def test_importing_core_and_building_the_cli_loads_no_app_and_no_qt() -> None:
    """``radartune``'s parser, ``gui`` included, is built without the app (found at run time)."""
    code = (
        "import importlib, sys\n"
        f"for m in {core_modules()!r}:\n"
        "    importlib.import_module(m)\n"
        "import core.cli\n"
        "core.cli.build_parser().parse_args(['gui', '--scene', 'x.json', '--paused'])\n"
        f"bad = sorted(k for k in sys.modules if k.split('.')[0] in {('app', *QT_MODULES)!r})\n"
        "print(','.join(bad))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True
    )
    assert out.stdout.strip() == "", f"core loaded app or Qt modules: {out.stdout.strip()}"


def test_no_app_import_statement_in_core_sources() -> None:
    offenders = []
    for path in (ROOT / "core").rglob("*.py"):
        for line in path.read_text().splitlines():
            s = line.strip()
            if s.startswith(("import ", "from ")) and s.split()[1].split(".")[0] == "app":
                offenders.append(f"{path.relative_to(ROOT)}: {s}")
    assert offenders == []


def test_gui_options_belong_to_the_app_and_reach_it_through_the_cli() -> None:
    """``radartune gui --help`` prints the app's own option table, and the app's command-line
    module (imported by the CLI when ``gui`` runs) loads no Qt until the window is made."""
    code = (
        "import sys, app.main\n"
        f"bad = sorted(k for k in sys.modules if k.split('.')[0] in {QT_MODULES!r})\n"
        "print(','.join(bad))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True
    )
    assert out.stdout.strip() == "", f"app.main imported Qt at load: {out.stdout.strip()}"
    from app.main import build_parser

    out = subprocess.run(
        [sys.executable, "-m", "core.cli", "gui", "--help"],
        cwd=ROOT, capture_output=True, text=True, check=True,
    )  # fmt: skip
    assert out.stdout == build_parser().format_help()
    assert "--scene FILE" in out.stdout
    bad = subprocess.run(
        [sys.executable, "-m", "core.cli", "gui", "--quit-after", "soon"],
        cwd=ROOT, capture_output=True, text=True,
    )  # fmt: skip
    assert bad.returncode == 2
    assert bad.stderr.splitlines()[-1].startswith("radartune gui: error: argument --quit-after")


def test_no_qt_import_statement_in_core_sources() -> None:
    offenders = []
    for path in (ROOT / "core").rglob("*.py"):
        for line in path.read_text().splitlines():
            s = line.strip()
            if s.startswith(("import ", "from ")) and any(q in s.split()[1] for q in QT_MODULES):
                offenders.append(f"{path.relative_to(ROOT)}: {s}")
    assert offenders == []


def import_cycles(imports: Mapping[str, Iterable[str]]) -> list[frozenset[str]]:
    """Every import cycle: the strongly connected components with more than one module, and
    single modules that import themselves (Tarjan's algorithm, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    cycles: list[frozenset[str]] = []
    for root in sorted(imports):
        if root in index:
            continue
        work = [(root, iter(sorted(imports.get(root, ()))))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            v, children = work[-1]
            w = next(children, None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(imports.get(w, ())))))
                elif w in on_stack:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                component = set()
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    component.add(w)
                    if w == v:
                        break
                if len(component) > 1 or v in imports.get(v, ()):
                    cycles.append(frozenset(component))
    return cycles


def project_imports() -> dict[str, set[str]]:
    """Module -> modules of core and app it imports (at load or inside a function)."""
    graph = grimp.build_graph("core", "app", cache_dir=None)
    return {m: set(graph.find_modules_directly_imported_by(m)) for m in graph.modules}


@pytest.fixture(scope="module")
def cycles() -> list[frozenset[str]]:
    return import_cycles(project_imports())


def test_cycle_finder_finds_cycles_and_only_cycles() -> None:
    imports = {
        "a": {"b"},
        "b": {"c"},
        "c": {"a", "d"},  # a -> b -> c -> a
        "d": {"e"},
        "e": set(),  # d -> e: no cycle
        "f": {"f"},  # a module importing itself
        "g": {"h"},
        "h": {"g"},  # g <-> h
    }
    assert sorted(map(sorted, import_cycles(imports))) == [["a", "b", "c"], ["f"], ["g", "h"]]
    assert import_cycles({"a": {"b"}, "b": {"c"}, "c": set()}) == []


def test_graph_sees_lazy_imports_and_namespace_free_packages() -> None:
    imports = project_imports()
    # a function-level import is an import too (core/cli/worker.py imports the study only
    # inside its `run`); app/views must be a package for the contracts to see it
    assert "core.optimization.study" in imports["core.cli.worker"]
    assert "app.data" in imports["app.views.top_view"]


def test_no_import_cycle_in_core_or_app(cycles: list[frozenset[str]]) -> None:
    assert [sorted(c) for c in cycles] == [], "import cycles"


def private_imports() -> set[tuple[str, str, str]]:
    """(file, module, name) of every `from core|app... import _name` in core/ and app/."""
    found = set()
    for top in ("core", "app"):
        for path in sorted((ROOT / top).rglob("*.py")):
            for node in ast.walk(ast.parse(path.read_text(), str(path))):
                if not isinstance(node, ast.ImportFrom) or node.level or not node.module:
                    continue
                if node.module.split(".")[0] not in ("core", "app"):
                    continue
                for alias in node.names:
                    if alias.name.startswith("_") and not alias.name.startswith("__"):
                        rel = path.relative_to(ROOT).as_posix()
                        found.add((rel, node.module, alias.name))
    return found


def test_no_private_name_imported_across_modules() -> None:
    assert sorted(private_imports()) == [], "private names imported from another module"


def test_every_kernel_module_imports_the_jit_guard() -> None:
    """A module that compiles numba kernels imports core.jit_guard first, or its compiled code
    could depend on what else was compiled in the process (docs/decisions/simulation-13)."""
    missing = []
    for path in sorted((ROOT / "core").rglob("*.py")):
        tree = ast.parse(path.read_text(), str(path))
        uses_numba = any(
            (isinstance(n, ast.Import) and any(a.name.split(".")[0] == "numba" for a in n.names))
            or (isinstance(n, ast.ImportFrom) and (n.module or "").split(".")[0] == "numba")
            for n in ast.walk(tree)
        )
        guarded = any(
            isinstance(n, ast.ImportFrom)
            and n.module == "core"
            and any(a.name == "jit_guard" for a in n.names)
            for n in tree.body
        )
        if uses_numba and not guarded and path.name != "jit_guard.py":
            missing.append(path.relative_to(ROOT).as_posix())
    assert missing == [], f"kernel modules without `from core import jit_guard`: {missing}"

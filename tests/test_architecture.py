"""Architecture rules: ``core`` never imports Qt."""

from __future__ import annotations

import pkgutil
import subprocess
import sys
from pathlib import Path

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


def test_no_qt_import_statement_in_core_sources() -> None:
    offenders = []
    for path in (ROOT / "core").rglob("*.py"):
        for line in path.read_text().splitlines():
            s = line.strip()
            if s.startswith(("import ", "from ")) and any(q in s.split()[1] for q in QT_MODULES):
                offenders.append(f"{path.relative_to(ROOT)}: {s}")
    assert offenders == []

"""Architecture rules: ``core`` never imports Qt or ``app``."""

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

"""Start the application: ``radartune gui`` / ``python -m app`` / ``make run``.

The app owns its command line: :func:`add_arguments` is the one table of the GUI's options and
:func:`main` parses them. ``radartune gui`` (:mod:`core.cli.gui`) passes its arguments through to
:func:`main`, finding this module by name only when it runs. Importing this module loads no Qt.
"""

from __future__ import annotations

import argparse
import sys


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The app's options (``radartune gui``, ``python -m app``)."""
    p.add_argument("--scene", metavar="FILE", help="scene JSON to open (default: the paper scene)")
    p.add_argument(
        "--quit-after",
        metavar="SECONDS",
        type=float,
        default=None,
        help="close the window after this many seconds (smoke tests)",
    )
    p.add_argument("--paused", action="store_true", help="open without playing")
    p.add_argument(
        "--replay",
        metavar="FILE",
        help="play a recording instead of simulating: a data set .npz or a file radartune "
        "import reads (TI UART log, visualizer replay)",
    )
    p.add_argument("--cfg", metavar="CFG", help="with --replay: the TI .cfg of the recording")
    p.add_argument(
        "--settings",
        metavar="FILE",
        default=None,
        help="settings file (INI); default: the user's RadarTune settings",
    )
    p.add_argument(
        "--debug",
        action="store_true",
        help="also print the traceback of an unexpected error on stderr (always in the log)",
    )


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="radartune gui", description="Start the RadarTune window.")
    add_arguments(p)
    return p


def missing_platform_libraries() -> list[str]:
    """System libraries Qt's X11 platform plugin needs but cannot find (empty when fine).

    Qt aborts the whole process with a long message when its ``xcb`` plugin cannot load, so this
    is checked before Qt starts: ``ldd`` of the plugin and its XCB library, plus
    ``libxcb-cursor``, which Qt >= 6.5 opens at run time. Only on Linux with X11.
    """
    import ctypes.util
    import os
    import subprocess
    from pathlib import Path

    platform = os.environ.get("QT_QPA_PLATFORM", "")
    if not sys.platform.startswith("linux") or platform not in ("", "xcb"):
        return []
    if not os.environ.get("DISPLAY"):
        return []  # Wayland or no display at all: Qt says so itself
    try:
        import PySide6
    except ImportError:
        return []
    qt = Path(PySide6.__file__).parent / "Qt"
    missing: list[str] = []
    for lib in (qt / "plugins/platforms/libqxcb.so", qt / "lib/libQt6XcbQpa.so.6"):
        try:
            out = subprocess.run(["ldd", str(lib)], capture_output=True, text=True, timeout=10)
        except (OSError, subprocess.SubprocessError):
            return []  # cannot tell: let Qt try
        for line in out.stdout.splitlines():
            if "not found" in line:
                name = line.split("=>")[0].strip()
                if name not in missing:
                    missing.append(name)
    if ctypes.util.find_library("xcb-cursor") is None:
        missing.append("libxcb-cursor.so.0")
    return missing


def debian_package(soname: str) -> str:
    """Debian package of a shared library: ``libxcb-icccm.so.4`` -> ``libxcb-icccm4``."""
    name, _, version = soname.partition(".so.")
    return f"{name}-{version}" if name[-1].isdigit() else f"{name}{version}"


def settings_error(path: str) -> str | None:
    """Why a ``--settings`` file cannot be used, as one line naming it (and the key); None when
    it can. Its JSON-valued settings are read as the window reads them (before any window
    exists, so nothing is written back), so that a bad value is exit 2, never a traceback."""
    from PySide6 import QtCore

    from app.window import JSON_SETTINGS, stored_json
    from core.errors import InputError

    settings = QtCore.QSettings(path, QtCore.QSettings.IniFormat)
    for key in JSON_SETTINGS:
        try:
            stored_json(settings, key)
        except InputError as exc:
            return str(exc)
    return None


def scene_error(path: str) -> str | None:
    """Why the scene file cannot be opened, as one line naming it; None when it can.

    Read and validated exactly as the window will (before any window exists), so that a bad
    ``--scene`` is one line on stderr and exit 2 rather than a window or a traceback.
    """
    from app.engine import Engine
    from app.errors import log_exception, one_line
    from app.models import SceneModel

    try:
        SceneModel(Engine()).load(path)
    except Exception as exc:
        log_exception(f"cannot load scene {path}", exc)
        return one_line(exc, path)
    return None


def run(
    scene: str | None = None,
    quit_after: float | None = None,
    paused: bool = False,
    settings_file: str | None = None,
    replay: str | None = None,
    cfg: str | None = None,
) -> int:
    """Create the QApplication and the main window, play, and run the event loop."""
    engine = None
    if replay is not None:
        from app.engine import Engine
        from app.errors import log_exception, one_line
        from app.replay import ReplayEngine, attach_recording, load_recording

        try:
            engine = Engine()  # simulating again after File → Close recording
            attach_recording(engine, ReplayEngine(load_recording(replay, cfg), path=replay))
        except Exception as exc:
            log_exception(f"cannot replay {replay}", exc)
            print(f"radartune gui: error: {one_line(exc, replay)}", file=sys.stderr)
            return 2
    if settings_file:
        problem = settings_error(settings_file)
        if problem is not None:
            print(f"radartune gui: error: {problem}", file=sys.stderr)
            return 2
    if scene is not None:
        problem = scene_error(scene)
        if problem is not None:
            print(f"radartune gui: error: {problem}", file=sys.stderr)
            return 2
    missing = missing_platform_libraries()
    if missing:
        packages = " ".join(debian_package(m) for m in missing)
        print(
            "radartune gui: error: Qt's X11 platform plugin cannot load; missing system "
            f"libraries {', '.join(missing)} (Debian/Ubuntu: sudo apt-get install {packages})",
            file=sys.stderr,
        )
        return 2
    import pyqtgraph as pg
    from PySide6 import QtCore, QtWidgets

    from app.errors import install_excepthooks
    from app.window import MainWindow

    # one OpenGL share group: pyqtgraph keeps a shader per item class, which a floated (new
    # context) 3-D view could not use otherwise
    QtCore.QCoreApplication.setAttribute(QtCore.Qt.AA_ShareOpenGLContexts)
    app = QtWidgets.QApplication.instance() or QtWidgets.QApplication(sys.argv[:1])
    app.setOrganizationName("RadarTune")
    app.setApplicationName("RadarTune")
    pg.setConfigOptions(antialias=False, imageAxisOrder="row-major")
    if settings_file:
        settings = QtCore.QSettings(settings_file, QtCore.QSettings.IniFormat)
    else:
        settings = QtCore.QSettings(
            QtCore.QSettings.IniFormat, QtCore.QSettings.UserScope, "RadarTune", "RadarTune"
        )
    window = MainWindow(settings, engine, scene_path=scene)
    restore_hooks = install_excepthooks(window.show_error)  # a message box, never a crash
    window.show()
    if not paused:
        window.playback.set_playing(True)
    if quit_after is not None:
        QtCore.QTimer.singleShot(int(quit_after * 1000), window.close)
    code = app.exec()
    window.shutdown()  # joins the workers before the window (their parent) is destroyed
    restore_hooks()
    return code


def main(argv: list[str] | None = None) -> int:
    """Parse the app's arguments and run it; an unexpected error before the window exists (or
    after it closed) is one line on stderr and exit 2, its traceback in the log."""
    from app.errors import LOG_FILE, log_exception, one_line, setup_logging

    args = build_parser().parse_args(argv)
    setup_logging(debug=args.debug)
    try:
        return run(args.scene, args.quit_after, args.paused, args.settings, args.replay, args.cfg)
    except Exception as exc:
        log_exception("the app failed", exc)
        print(
            f"radartune gui: error: internal error: {one_line(exc)} (details in {LOG_FILE})",
            file=sys.stderr,
        )
        return 2


if __name__ == "__main__":
    sys.exit(main())

"""Start the application: ``radartune gui`` / ``python -m app`` / ``make run``."""

from __future__ import annotations

import argparse
import sys
import traceback

from core.cli.gui import add_arguments


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="radartune gui", description="Start the RadarTune window.")
    add_arguments(p)
    return p


def run(
    scene: str | None = None,
    quit_after: float | None = None,
    paused: bool = False,
    settings_file: str | None = None,
) -> int:
    """Create the QApplication and the main window, play, and run the event loop."""
    import pyqtgraph as pg
    from PySide6 import QtCore, QtWidgets

    from app.window import MainWindow

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
    window = MainWindow(settings, scene_path=scene)

    def excepthook(exc_type, exc, tb):  # an unexpected error becomes a message, not a crash
        traceback.print_exception(exc_type, exc, tb)
        window.show_error(f"internal error: {exc_type.__name__}: {exc}")

    sys.excepthook = excepthook
    window.show()
    if not paused:
        window.playback.set_playing(True)
    if quit_after is not None:
        QtCore.QTimer.singleShot(int(quit_after * 1000), window.close)
    return app.exec()


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return run(args.scene, args.quit_after, args.paused, args.settings)


if __name__ == "__main__":
    sys.exit(main())

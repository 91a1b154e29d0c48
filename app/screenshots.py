"""Screenshots of the running app for the user guide, one per view.

    QT_QPA_PLATFORM=offscreen python -m app.screenshots --out docs/screenshots
    QT_QPA_PLATFORM=xcb xvfb-run -a -s "-screen 0 1920x1080x24" python -m app.screenshots

The second form (Xvfb, Qt's real xcb platform) made the committed ones.

Runs the real window on the paper scene (simulated through the radar chain, tracked with the
default parameters), optionally runs a short study on the scene's point clouds (``--study N``)
and grabs each view with ``QWidget.grab()``. Settings go to a temporary file, never the user's.
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
import time
from pathlib import Path

import app  # noqa: F401  (thread settings before numpy)


def wait_until(qa, cond, timeout_s: float) -> bool:
    """Process Qt events until ``cond()`` is true or ``timeout_s`` passed; ``cond()``."""
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        qa.processEvents()
        if cond():
            return True
        time.sleep(0.01)
    return cond()


class Shots:
    """The screenshot scripts' grab-and-save: :meth:`save` grabs a widget (after the pending
    events, so that it shows its last state) into ``out/NAME`` and remembers the name;
    :meth:`listing` is the paths written, one a line."""

    def __init__(self, qa, out: Path) -> None:
        self.qa, self.out = qa, out
        self.names: list[str] = []

    def save(self, widget, name: str) -> None:
        self.qa.processEvents()
        widget.grab().save(str(self.out / name))
        self.names.append(name)

    def listing(self) -> str:
        return "\n".join(str(self.out / s) for s in self.names)


def open_window(out: Path, scene_path: str | None = None):
    """The application, a main window on fresh settings (in a temporary folder, also returned)
    and the output folder ``out`` created: what both screenshot scripts start from."""
    import pyqtgraph as pg
    from PySide6 import QtCore, QtWidgets

    from app.window import MainWindow

    # as app.main: the 3-D view's GL items survive its dock being floated (a new top level)
    QtCore.QCoreApplication.setAttribute(QtCore.Qt.AA_ShareOpenGLContexts)
    qa = QtWidgets.QApplication.instance() or QtWidgets.QApplication(sys.argv[:1])
    pg.setConfigOptions(imageAxisOrder="row-major")
    out.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix="radartune-shots-"))
    settings = QtCore.QSettings(str(tmp / "settings.ini"), QtCore.QSettings.IniFormat)
    kwargs = {} if scene_path is None else {"scene_path": scene_path}
    return qa, MainWindow(settings, restore=False, **kwargs), tmp


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m app.screenshots", description=__doc__)
    parser.add_argument("--out", default="docs/screenshots", help="output folder")
    parser.add_argument("--frame", type=int, default=60, help="frame shown (0-based)")
    parser.add_argument(
        "--study", type=int, default=12, metavar="N", help="trials of the demo study (0: none)"
    )
    parser.add_argument("--width", type=int, default=1600)
    parser.add_argument("--height", type=int, default=1000)
    args = parser.parse_args(argv)

    out = Path(args.out)
    qa, w, tmp = open_window(out)
    w.resize(args.width, args.height)
    w.show()
    if not wait_until(qa, lambda: w.cache.complete, 300):
        print("simulation did not finish", file=sys.stderr)
        return 1
    wait_until(qa, lambda: w.tracking_model.result is not None, 120)
    wait_until(qa, lambda: w.tracker.idle, 60)
    shots = Shots(qa, out)
    save = shots.save

    if args.study > 0:
        w.study_model.set_form(n_trials=args.study, storage=str(tmp / "study.db"))
        w.start_study()
        ok = wait_until(qa, lambda: not w.study_model.running, 600)
        if not ok or not w.study_model.progress.best_params:
            print(f"demo study: no completed trial ({w.errors})", file=sys.stderr)
    frame = min(args.frame, len(w.cache) - 1)
    w.playback.set_frame(frame)
    w.redraw()
    w.docks["Tracker"].raise_()
    w.docks["Scene"].raise_()
    qa.processEvents()
    w.redraw()
    save(w, "main_window.png")
    save(w.top_view, "top_view_snr.png")
    w.colour_combo.setCurrentIndex(w.colour_combo.findData("label"))
    w.redraw()
    save(w.top_view, "top_view_label.png")
    save(w.rd_view, "range_doppler.png")
    save(w.psi_view, "psi_and_metrics.png")
    save(w.playback_bar, "playback_bar.png")
    for title, name in (
        ("Scene", "scene_panel.png"),
        ("Radar", "radar_panel.png"),
        ("Tracker", "tracker_panel.png"),
        ("Study", "study_panel.png"),
        ("Processing", "processing_panel.png"),
    ):
        w.docks[title].raise_()
        save(w.docks[title], name)
    # a drawn trajectory: waypoints in the table and on the top view
    w.docks["Scene"].raise_()
    w.scene_panel.add_wp_button.click()
    w.scene_panel.append_waypoint(2.5, 4.0)
    w.scene_panel.draw_button.setChecked(True)
    w.redraw()
    save(w.scene_panel, "scene_waypoints.png")
    save(w.top_view, "top_view_waypoints.png")
    w.shutdown()
    shutil.rmtree(tmp, ignore_errors=True)
    print(shots.listing())
    return 0


if __name__ == "__main__":
    sys.exit(main())

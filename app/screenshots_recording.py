"""Screenshots of a recording replayed in the app (the user guide's recording pictures).

    QT_QPA_PLATFORM=xcb xvfb-run -a -s "-screen 0 1920x1080x24" \\
        python -m app.screenshots_recording [--recording FILE] --out docs/screenshots

Default recording: TI's people-counting CSV ``pc3_iwr6843/pc3_2023-06-21-12-27-01.csv`` of the
public recordings folder (:func:`core.benchmarks.clouds.real_data_dir`). The window opens on the
paper scene, File → Open recording reads the file (in its worker thread), and the frame shown is
grabbed with ``QWidget.grab()``: the main window (TI's tracks beside RadarTune's, the
statistics panel) and the recording panel. Settings go to a temporary file.
"""

from __future__ import annotations

import argparse
import shutil
import sys
from pathlib import Path

import app  # noqa: F401  (thread settings before numpy)
from app.screenshots import Shots, open_window, wait_until

DEFAULT_RECORDING = "pc3_iwr6843/pc3_2023-06-21-12-27-01.csv"


def compare(w) -> None:
    """Each tracker with its default parameters on the replayed frames: the mean number of
    confirmed tracks a frame and the share of frames where it equals TI's track count."""
    import numpy as np

    from app.engine import track

    frames = w.cache.frames
    ti = np.array([w.recording.frame_stats(k, f, None).ti_count for k, f in enumerate(frames)])
    print(f"TI's tracks: {ti.mean():.2f} a frame (max {ti.max()}), {len(frames)} frames")
    for tracker in ("paper", "room", "gtrack"):
        w.params_model.set_tracker(tracker)
        w.params_model.reset()
        res = track(frames, w.params_model.params(), w.playback_control.frame_period_s)
        n = np.array([int(f.confirmed.sum()) for f in res.frames])
        print(
            f"{tracker:7s} confirmed {n.mean():5.2f} a frame (max {n.max()}), "
            f"equal to TI's count in {np.mean(n == ti):.0%} of the frames"
        )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m app.screenshots_recording", description=__doc__
    )
    parser.add_argument("--recording", default=None, help="recording file (default: see above)")
    parser.add_argument("--out", default="docs/screenshots", help="output folder")
    parser.add_argument("--frame", type=int, default=56, help="frame shown (0-based)")
    parser.add_argument("--colour", default="doppler", help="colour the points by this")
    parser.add_argument(
        "--tracker", default="room", choices=("paper", "room", "gtrack"), help="tracker shown"
    )
    parser.add_argument(
        "--zoom", type=float, default=3.0, help="top view: ±ZOOM m across, 0: the whole area"
    )
    parser.add_argument(
        "--compare",
        action="store_true",
        help="also print each tracker's mean confirmed-track count against TI's track count",
    )
    parser.add_argument("--width", type=int, default=1600)
    parser.add_argument("--height", type=int, default=1000)
    args = parser.parse_args(argv)
    if args.recording is None:
        from core.benchmarks.clouds import real_data_dir

        args.recording = str(real_data_dir() / DEFAULT_RECORDING)

    out = Path(args.out)
    qa, w, tmp = open_window(out)
    w.resize(args.width, args.height)
    w.show()
    w.params_model.set_tracker(args.tracker)
    w.recording.load(args.recording)
    if not wait_until(qa, lambda: w.recording.replaying or bool(w.errors), 300) or w.errors:
        print(f"cannot open {args.recording}: {w.errors}", file=sys.stderr)
        return 1
    wait_until(qa, lambda: w.cache.complete, 300)
    wait_until(qa, lambda: w.tracking_model.result is not None, 120)
    wait_until(qa, lambda: w.tracker.idle, 60)
    shots = Shots(qa, out)

    w.colour_combo.setCurrentIndex(w.colour_combo.findData(args.colour))
    w.playback.set_frame(min(args.frame, len(w.cache) - 1))
    w.recording.stats_dock.raise_()
    qa.processEvents()
    view = w.top_view
    if args.zoom > 0:  # the person in this recording stays within 1 m of the sensor
        view._stop_auto_fit()
        view.getPlotItem().vb.setRange(xRange=(-args.zoom, args.zoom), yRange=(-0.3, args.zoom))
    w.redraw()
    shots.save(w, "recording_window.png")
    shots.save(w.recording.dock, "recording_panel.png")
    if args.compare:
        compare(w)
    w.shutdown()
    shutil.rmtree(tmp, ignore_errors=True)
    print(shots.listing())
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Screenshots of the radar views, the track table and the label legend for the user guide.

    QT_QPA_PLATFORM=offscreen python -m app.screenshots_views --out docs/screenshots

Runs the real window on a scene (default: the two-person scene, simulated through the radar
chain and tracked with the default parameters) and grabs each view at one frame with
``QWidget.grab()``. Settings go to a temporary file, never the user's.
"""

from __future__ import annotations

import argparse
import shutil
import sys
from pathlib import Path

import app  # noqa: F401  (thread settings before numpy)
from app.engine import ROOT
from app.screenshots import Shots, open_window, wait_until

SHOTS = (
    ("ra_view", "views_range_azimuth.png"),
    ("profile_view", "views_range_profile.png"),
    ("spectrogram_view", "views_micro_doppler.png"),
    ("elevation_view", "views_elevation.png"),
    ("track_table", "views_track_table.png"),
    ("people_table", "views_people_table.png"),
)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m app.screenshots_views", description=__doc__)
    parser.add_argument("--out", default="docs/screenshots", help="output folder")
    parser.add_argument(
        "--scene", default=str(ROOT / "resources" / "scenes" / "two_persons.json"), help="scene"
    )
    parser.add_argument("--frame", type=int, default=60, help="frame shown (0-based)")
    args = parser.parse_args(argv)

    out = Path(args.out)
    qa, w, tmp = open_window(out, args.scene)
    w.resize(1600, 1000)
    w.show()
    if not wait_until(qa, lambda: w.cache.complete, 600):
        print("simulation did not finish", file=sys.stderr)
        return 1
    wait_until(qa, lambda: w.tracking_model.result is not None and w.tracker.idle, 300)
    w.playback.set_frame(min(args.frame, len(w.cache) - 1))
    w.colour_combo.setCurrentIndex(w.colour_combo.findData("label"))
    w.redraw()
    index = w.playback.frame
    w.views_control.draw_all(index, w.cache.frames[index], w.tracking_model.result)
    shots = Shots(qa, out)
    for attr, name in SHOTS:
        widget = getattr(w.views_control, attr)
        widget.resize(900, 300)
        shots.save(widget, name)
    shots.save(w.top_view, "views_top_view_identities.png")
    w.shutdown()
    shutil.rmtree(tmp, ignore_errors=True)
    print(shots.listing())
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""The GUI benchmark behind ``radartune bench gui``: the real window on the paper scene, with a
timer probe in the event loop.

    python -m app.bench_gui --json OUT.json [--quick] [--soak SECONDS]

Measures (medians over repetitions, this machine is shared):

* **slider → overlay drawn**: a tracker slider moved, until the views have drawn the re-tracked
  overlay (the first redraw after the new tracking result reached the GUI thread);
* **playback redraws/s** at 4× and 8× while playing the cached scene;
* **a live sensor at 20 frames/s** (the sensor emulator on pseudo-terminals streaming the scene's
  clouds): from a frame's last byte read on the data port to the redraw showing it tracked, and
  frames sent against frames received;
* **the 3-D view's redraws/s** with 2 000 points, docked and floated at 1280 x 800 px;
* **event-loop gaps while a study runs**: a 5 ms ``QTimer`` probe records its ticks; a gap is
  the time between two ticks (the longest, and how many exceed 100 ms).

``--soak SECONDS``: the live link alone for that long (frames sent, received, dropped, damaged,
latency, the process's memory before and after).

Also the probe's gaps while idle (the reference of the same run). Settings go to a temporary
file; the study to a temporary storage.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

import app  # noqa: F401  (thread settings before numpy)

PROBE_MS = 5


def _wait(qa, cond, timeout_s: float) -> bool:
    """Run the real event loop (``QEventLoop.exec``) until ``cond()`` or the time-out; ``cond``
    is checked by a 2 ms timer in that loop, as any other timer of the app."""
    from PySide6 import QtCore

    if cond():
        return True
    loop = QtCore.QEventLoop()
    poll = QtCore.QTimer()
    poll.setInterval(2)
    poll.timeout.connect(lambda: cond() and loop.quit())
    deadline = QtCore.QTimer()
    deadline.setSingleShot(True)
    deadline.timeout.connect(loop.quit)
    poll.start()
    deadline.start(int(timeout_s * 1000))
    loop.exec()
    poll.stop()
    deadline.stop()
    return bool(cond())


class Probe:
    """A 5 ms timer in the GUI's event loop: the gaps between its ticks."""

    def __init__(self) -> None:
        from PySide6 import QtCore

        self.ticks: list[float] = []
        self.timer = QtCore.QTimer()
        self.timer.setTimerType(QtCore.Qt.PreciseTimer)
        self.timer.setInterval(PROBE_MS)
        self.timer.timeout.connect(lambda: self.ticks.append(time.perf_counter()))

    def start(self) -> None:
        self.ticks = []
        self.timer.start()

    def stop(self) -> dict:
        self.timer.stop()
        gaps = [1e3 * (b - a) for a, b in zip(self.ticks, self.ticks[1:])]
        return {
            "n_ticks": len(self.ticks),
            "max_gap_ms": round(max(gaps), 1) if gaps else None,
            "n_gaps_over_100_ms": sum(g > 100 for g in gaps),
            "n_gaps_over_50_ms": sum(g > 50 for g in gaps),
            "median_gap_ms": round(statistics.median(gaps), 2) if gaps else None,
        }


def _rss_bytes() -> int | None:
    """The process's resident set size now (Linux ``/proc/self/statm``; None elsewhere)."""
    try:
        pages = int(Path("/proc/self/statm").read_text().split()[1])
    except (OSError, ValueError, IndexError):
        return None
    return pages * os.sysconf("SC_PAGE_SIZE")


def run(quick: bool = False, soak_s: float | None = None) -> dict:
    import pyqtgraph as pg
    from PySide6 import QtCore, QtWidgets

    from app.window import MainWindow

    QtCore.QCoreApplication.setAttribute(QtCore.Qt.AA_ShareOpenGLContexts)  # as app.main
    qa = QtWidgets.QApplication.instance() or QtWidgets.QApplication(sys.argv[:1])
    pg.setConfigOptions(imageAxisOrder="row-major")
    tmp = Path(tempfile.mkdtemp(prefix="radartune-bench-gui-"))
    settings = QtCore.QSettings(str(tmp / "settings.ini"), QtCore.QSettings.IniFormat)
    t0 = time.perf_counter()
    w = MainWindow(settings, restore=False)
    w.resize(1600, 1000)
    w.show()
    out: dict = {"platform": qa.platformName()}
    try:
        if not _wait(qa, lambda: w.cache.complete, 600):
            raise RuntimeError("the scene was not simulated within 10 minutes")
        _wait(qa, lambda: w.tracking_model.result is not None and w.tracker.idle, 600)
        out["first_track_s"] = round(time.perf_counter() - t0, 2)
        out["scene_frames"] = len(w.cache)
        _wait(qa, lambda: False, 1.0)  # settle
        if soak_s is not None:  # the live link alone, for as long as asked
            out["soak"] = _live(qa, w, tmp, seconds=soak_s)
            return out

        # ---- idle probe (reference) ----
        probe = Probe()
        probe.start()
        _wait(qa, lambda: False, 2.0)
        out["idle"] = probe.stop()

        # ---- slider → overlay drawn ----
        row = w.tracker_panel.rows["q_coeff"]
        state = {"changed": None, "drawn": None}
        w.tracking_model.changed.connect(lambda _r: state.__setitem__("changed", True))
        real_redraw = w.redraw

        def redraw() -> None:
            real_redraw()
            if state["changed"] and state["drawn"] is None:
                state["drawn"] = time.perf_counter()

        w.redraw = redraw
        latencies = []
        n = 5 if quick else 15
        for i in range(n):
            state["changed"], state["drawn"] = None, None
            position = 200 + (i * 37) % 600
            t_move = time.perf_counter()
            row.slider.setValue(position)
            if not _wait(qa, lambda: state["drawn"] is not None, 60):
                continue
            latencies.append(1e3 * (state["drawn"] - t_move))
            _wait(qa, lambda: w.tracker.idle, 30)
            _wait(qa, lambda: False, 0.1)
        w.redraw = real_redraw
        out["slider_to_overlay_ms"] = {
            "median": round(statistics.median(latencies), 1),
            "min": round(min(latencies), 1),
            "max": round(max(latencies), 1),
            "n": len(latencies),
        }

        # ---- playback ----
        out["playback"] = {}
        seconds = 2.0 if quick else 4.0
        for speed in (4.0, 8.0):
            w.playback.set_speed(speed)
            w.playback.set_frame(0)
            w.playback.loop = True
            probe.start()
            n0 = w.n_draws
            w.playback.set_playing(True)
            t_start = time.perf_counter()
            _wait(qa, lambda: False, seconds)
            elapsed = time.perf_counter() - t_start
            w.playback.set_playing(False)
            gaps = probe.stop()
            out["playback"][f"{speed:g}x"] = {
                "redraws_per_s": round((w.n_draws - n0) / elapsed, 1),
                "max_gap_ms": gaps["max_gap_ms"],
            }

        # ---- the 3-D view ----
        out["cloud3d"] = _cloud3d(qa, w, seconds=2.0 if quick else 5.0)

        # ---- study ----
        n_trials = 4 if quick else 12
        w.study_model.set_form(n_trials=n_trials, n_jobs=1, storage=str(tmp / "study.db"))
        probe.start()
        t_start = time.perf_counter()
        w.start_study()
        _wait(qa, lambda: w.study_model.running, 10)
        _wait(qa, lambda: not w.study_model.running, 300)
        study = probe.stop()
        p = w.study_model.progress
        study.update(
            n_trials=n_trials,
            n_complete=p.n_complete,
            n_pruned=p.n_pruned,
            n_failed=p.n_failed,
            wall_s=round(time.perf_counter() - t_start, 1),
            errors=list(w.errors),
        )
        out["study"] = study

        # ---- live sensor (last: its frames replace the scene's, on which the study runs) ----
        out["live"] = _live(qa, w, tmp, seconds=10.0 if quick else 60.0)
    finally:
        w.shutdown()
        w.close()
        shutil.rmtree(tmp, ignore_errors=True)
    return out


def _cloud3d(qa, w, seconds: float, n_points: int = 2000) -> dict:
    """The 3-D view (View → 3-D view) redrawing 2 000-point frames as fast as it can: each
    redraw sets the points, colours and tracks of another frame (the scene's tracks), and the
    next one starts when the last is on the screen (the widget's ``frameSwapped``). Offscreen
    there is no OpenGL: the reason is reported instead."""
    import numpy as np

    from app.data import FrameData
    from core.pointcloud import PointCloud

    vc = w.views_control
    view = vc.cloud3d
    if view.reason is not None:
        return {"not_run": view.reason}
    vc.cloud3d_dock.show()
    _wait(qa, lambda: False, 0.3)
    if view.gl is None:
        return {"not_run": "the 3-D view was not shown"}
    rng = np.random.default_rng(0)
    frames = []
    for k in range(len(w.cache)):
        x, y, z = (
            rng.uniform(-4, 4, n_points),
            rng.uniform(0.5, 9, n_points),
            rng.uniform(-1, 1, n_points),
        )
        r = np.sqrt(x**2 + y**2 + z**2)
        cloud = PointCloud(
            range_m=r, azimuth_rad=np.arctan2(x, y), elevation_rad=np.arcsin(z / r),
            radial_velocity_mps=rng.uniform(-3, 3, n_points), snr_db=rng.uniform(10, 50, n_points),
            x_m=x, y_m=y, z_m=z, source=np.zeros(n_points, dtype=np.int64),
        )  # fmt: skip
        frames.append(FrameData(index=k, t_s=0.0, cloud=cloud, truth_xy_m=np.zeros((0, 2))))
    view.persistence = 1
    result = w.tracking_model.result
    dock = vc.cloud3d_dock
    out: dict = {"points": n_points, **_redraw_rate(qa, view, frames, result, seconds)}
    # the view at a full window's size: the dock floated and resized to FULL_3D_PX
    dock.setFloating(True)
    dock.resize(*FULL_3D_PX)
    _wait(qa, lambda: False, 0.5)
    out["full"] = _redraw_rate(qa, view, frames, result, seconds)
    dock.setFloating(False)
    view.colour_by = "snr"
    dock.hide()
    return out


#: The floating 3-D view's size in the benchmark's second case (the dock, title bar included)
FULL_3D_PX = (1280, 800)


def _redraw_rate(qa, view, frames, result, seconds: float) -> dict:
    """Redraws a second of ``view`` at its present size, coloured by SNR and by track."""
    from PySide6 import QtCore

    size = view.gl.size() * view.gl.devicePixelRatioF()
    out: dict = {"gl_px": [int(size.width()), int(size.height())]}
    for mode in ("snr", "track"):
        view.colour_by = mode
        state = {"n": 0}

        def next_frame(state: dict = state) -> None:  # each frame on screen asks for the next
            state["n"] += 1
            view.show_frame(state["n"] % len(frames), frames, result)

        view.gl.frameSwapped.connect(next_frame)
        t0, c0 = time.perf_counter(), time.process_time()
        next_frame()
        loop = QtCore.QEventLoop()
        QtCore.QTimer.singleShot(int(seconds * 1000), loop.quit)
        loop.exec()
        view.gl.frameSwapped.disconnect(next_frame)
        n = state["n"] - 1
        out[f"{mode}_redraws_per_s"] = round(n / (time.perf_counter() - t0), 1)
        # CPU of the whole process (Mesa's llvmpipe renders in threads of its own): what a
        # redraw costs, whatever the machine's load
        out[f"{mode}_cpu_ms_per_redraw"] = round(1e3 * (time.process_time() - c0) / max(n, 1), 1)
    return out


def _live(qa, w, tmp: Path, seconds: float, frame_period_s: float = 0.05) -> dict:
    """A live link at 20 frames/s: the cached scene's clouds written as a UART capture (SDK 3
    packets, as ``radartune export --format uart``), streamed by the sensor emulator on
    pseudo-terminals, looped, for ``seconds``; the window connected to it as File → Connect
    sensor does. Latency: from a frame's last byte written to the data port read by the link to
    the end of the redraw showing that frame tracked, for every frame drawn so."""
    from dataclasses import replace

    from core.formats.ti_cfg import write_ti_cfg
    from core.formats.ti_uart import encode_frame
    from core.live import LinkSettings
    from core.live.emulator import Faults, SensorEmulator

    radar = replace(w.scene_model.scene.radar, frame_period_s=frame_period_s)
    cfg = tmp / "live.cfg"
    write_ti_cfg(radar, cfg)
    capture = b"".join(encode_frame(f.cloud, k + 1) for k, f in enumerate(w.cache.frames))
    probe = Probe()
    latencies: list[float] = []
    real_redraw = w.redraw

    def redraw() -> None:
        real_redraw()
        received = w.live.received_s.pop(w.playback.frame, None)
        tracked = w.tracking_model.result
        if received is not None and tracked is not None and tracked.n_frames > w.playback.frame:
            latencies.append(time.perf_counter() - received)

    w.redraw = redraw
    rss_start = _rss_bytes()
    with SensorEmulator(capture, faults=Faults(), loop=True) as em:
        settings = LinkSettings(cli_port=em.cli_port, data_port=em.data_port, cfg=str(cfg))
        probe.start()
        w.live.start(settings, str(tmp / "live.dat"))
        _wait(qa, lambda: w.live.n_frames > 0, 30)
        t_start = time.perf_counter()
        n0 = w.live.n_frames
        _wait(qa, lambda: False, seconds)
        elapsed = time.perf_counter() - t_start
        n_received = w.live.n_frames - n0
        w.live.stop()
        _wait(qa, lambda: not w.live.running and w.live.act_connect.isEnabled(), 30)
        gaps = probe.stop()
        n_sent = em.n_packets_sent
    w.redraw = real_redraw
    rss_end = _rss_bytes()
    lat = sorted(1e3 * x for x in latencies)
    record = tmp / "live.dat"
    growth = None if rss_start is None or rss_end is None else rss_end - rss_start
    return {
        "seconds": round(elapsed, 1),
        "frame_period_ms": frame_period_s * 1e3,
        "frames_sent": n_sent,
        "frames_received": w.live.n_frames,
        "frames_received_per_s": round(n_received / elapsed, 2),
        "frames_in_cache": len(w.cache),
        "dropped": w.live.n_dropped,
        "damaged": w.live.n_damaged,
        "frames_drawn_tracked": len(lat),
        "latency_ms": {
            "median": round(statistics.median(lat), 1) if lat else None,
            "p90": round(lat[int(0.9 * (len(lat) - 1))], 1) if lat else None,
            "max": round(lat[-1], 1) if lat else None,
        },
        "record_bytes": record.stat().st_size if record.exists() else 0,
        "max_gap_ms": gaps["max_gap_ms"],
        # the whole process's memory before the link and after it closed; the window keeps
        # every frame received in its cache, so some growth a frame is expected
        "rss_start_mb": None if rss_start is None else round(rss_start / 2**20, 1),
        "rss_end_mb": None if rss_end is None else round(rss_end / 2**20, 1),
        "rss_growth_kb_per_frame": (
            None if growth is None else round(growth / 1024 / max(n_received, 1), 2)
        ),
        "errors": list(w.errors),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m app.bench_gui", description=__doc__)
    parser.add_argument("--json", required=True, help="write the figures here")
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--soak", type=float, metavar="SECONDS", help="the live link alone")
    args = parser.parse_args(argv)
    result = run(quick=args.quick, soak_s=args.soak)
    result["qpa_platform"] = os.environ.get("QT_QPA_PLATFORM", "")
    Path(args.json).write_text(json.dumps(result, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())

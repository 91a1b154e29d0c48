"""A live sensor in the app: File → Connect sensor … / Stop sensor.

:class:`LiveWorker` runs :class:`core.live.LiveLink` in its own thread (the cfg dialogue, the
data port, the recording, ``sensorStop`` on the way out), so the GUI never waits on a port. Each
frame is handed to the GUI thread, which appends it to the window's frame cache as a simulation
worker does; the cache is re-tracked with the tracker panel's parameters and drawn by the same
playback path as a simulation or a replay, the view following the newest tracked frame. Stop
ends the link (``sensorStop``); an error (a rejected cfg line, a port that vanished) is one line
in the window's message box; Connect again reconnects.
"""

from __future__ import annotations

import threading
import time
from collections import OrderedDict

import numpy as np
from PySide6 import QtCore, QtGui

from app.data import FrameData, TrackFrame, TrackingResult
from app.errors import log_exception, one_line
from core.live import LinkSettings, LiveLink
from core.pointcloud import PointCloud
from core.tracking.history import TrackHistory

#: Arrival times kept for the latency measurement: the newest frames'. The view follows the
#: newest frame, so a frame not drawn by the time this many newer ones arrived never will be.
MAX_ARRIVALS = 256


class ArrivalTimes:
    """``time.perf_counter()`` of each frame's last byte, by frame index, for the newest
    :data:`MAX_ARRIVALS` frames (``radartune bench gui`` pops a frame's time when it is drawn).

    Bounded: the oldest time is let go when a new one would exceed the capacity, counted in
    ``n_evicted``, so a long session keeps a constant few kB however many frames are never
    drawn (the draw timer skips frames that arrive faster than it draws).
    """

    def __init__(self, capacity: int = MAX_ARRIVALS) -> None:
        if capacity < 1:
            raise ValueError(f"capacity must be >= 1, got {capacity}")
        self.capacity = int(capacity)
        self._times: OrderedDict[int, float] = OrderedDict()
        self.n_evicted = 0

    def add(self, index: int, t_s: float) -> None:
        self._times[index] = t_s
        while len(self._times) > self.capacity:
            self._times.popitem(last=False)
            self.n_evicted += 1

    def pop(self, index: int, default: float | None = None) -> float | None:
        return self._times.pop(index, default)

    def clear(self) -> None:
        self._times.clear()
        self.n_evicted = 0

    def __len__(self) -> int:
        return len(self._times)


class LiveTracks:
    """The link's own tracks, frame by frame, as the overlay draws a tracking result.

    The live link tracks each frame once as it arrives
    (:class:`core.tracking.tracker.StreamTracker`, a constant cost per frame), where re-tracking
    the whole cache for every frame costs in proportion to the session's length (0.08 s for 200
    frames, 0.33 s for 1 200, measured on a loaded 2-core machine). :meth:`result` builds the
    :class:`~app.data.TrackingResult` of the frames so far: their tracks, the estimate (the
    confirmed track of highest ψ), trails and ψ curves; loss, RMSE and OSPA are NaN (a sensor
    has no ground truth).
    """

    def __init__(self, velocity_col: int = 2) -> None:
        #: the first velocity column of the tracker's state (2: the IPDA's; gtrack's: its dims)
        self.velocity_col = velocity_col
        self.frames: list[TrackFrame] = []
        self._est: list[tuple[float, float]] = []
        self._history = TrackHistory()

    def add(self, index: int, tracks) -> None:
        """The tracks (:class:`core.tracking.results.FrameTracks`) of frame ``index``; frames
        before it that never arrived get no tracks."""
        from app.engine import track_frame

        while len(self.frames) < index:
            self.frames.append(TrackFrame.empty())
            self._est.append((np.nan, np.nan))
        tf = track_frame(tracks, velocity_col=self.velocity_col)
        self.frames.append(tf)
        e = tracks.estimate
        self._est.append(tuple(tf.xy_m[e]) if e >= 0 else (np.nan, np.nan))
        self._history.add(index, tracks)

    def result(self, frame_period_s: float) -> TrackingResult:
        from app.engine.tracking import curve_fields

        t0 = time.perf_counter()
        n_f = len(self.frames)
        est = np.array(self._est, dtype=float).reshape(n_f, 2)
        nan = np.full(n_f, np.nan)
        return TrackingResult(
            frames=tuple(self.frames),
            estimate_xy_m=est,
            truth_xy_m=np.full((n_f, 2), np.nan),
            running_loss=nan,
            running_rmse_m=nan,
            ospa_m=nan,
            **curve_fields(self._history.curves(frame_period_s)),
            params_key="live",
            elapsed_s=time.perf_counter() - t0,
            engine="numpy",
            people=None,
        )


class LiveWorker(QtCore.QThread):
    """One link from connect to close; every frame emitted as it arrives."""

    connected = QtCore.Signal(object)  # core.config.RadarConfig of the cfg
    frame_ready = QtCore.Signal(object)  # core.live.LiveFrame
    failed = QtCore.Signal(str)
    closed = QtCore.Signal(str)  # a one-line summary

    def __init__(self, settings: LinkSettings, params, record: str | None, parent=None) -> None:
        super().__init__(parent)
        self.settings = settings
        self.params = params
        self.record = record
        self._lock = threading.Lock()
        self._stop = False
        self._link: LiveLink | None = None

    def stop(self) -> None:
        """End the link at its next read (thread-safe); the worker then sends sensorStop."""
        with self._lock:
            self._stop = True
            if self._link is not None:
                self._link.stop()

    def run(self) -> None:  # worker thread
        link = None
        n = 0
        try:
            link = LiveLink(self.settings, self.params, record=self.record)
            with self._lock:
                self._link = link
                if self._stop:
                    link.stop()
            link.start()
            self.connected.emit(link.radar)
            for frame in link.frames():
                n += 1
                self.frame_ready.emit(frame)
        except Exception as exc:  # any failure becomes a message, never a crash
            log_exception("live link failed", exc)
            self.failed.emit(one_line(exc))
        finally:
            if link is not None:
                recorded = link.recorded_bytes
                path = link.close()
                kept = f"; recorded {recorded} bytes to {path}" if path is not None else ""
                self.closed.emit(f"sensor stopped after {n} frames{kept}")


class LiveController(QtCore.QObject):
    """File → Connect sensor …, Stop sensor; feeds the window's cache from a :class:`LiveWorker`.

    While the link runs, the overlay shows the link's own tracks (:class:`LiveTracks`: the
    parameters of the Tracker panel when Connect was pressed); when it ends, the session is
    re-tracked with the panel's parameters, as a finished simulation is.
    """

    def __init__(self, window) -> None:
        super().__init__(window)
        self._w = window
        self._worker: LiveWorker | None = None
        self.last_summary = ""
        self._edge = 0
        self._generation = -1
        #: frame index -> time.perf_counter() of its last byte (``radartune bench gui``)
        self.received_s = ArrivalTimes()
        self._tracks = LiveTracks()
        self._result: TrackingResult | None = None
        self.n_frames = self.n_dropped = self.n_damaged = 0
        self.frame_period_s = float("nan")
        menu = next(a.menu() for a in window.menuBar().actions() if a.text() == "&File")
        quit_action = next((a for a in menu.actions() if a.text() == "&Quit"), None)
        self.act_connect = QtGui.QAction("&Connect sensor …", window)
        self.act_stop = QtGui.QAction("S&top sensor", window)
        self.act_stop.setEnabled(False)
        self.act_connect.triggered.connect(self.connect_dialog)
        self.act_stop.triggered.connect(self.stop)
        for action in (self.act_connect, self.act_stop):
            menu.insertAction(quit_action, action)
        menu.insertSeparator(quit_action)
        window.tracking_model.changed.connect(self._on_tracked)
        window.scene_control.info_changed.connect(self._on_scene_info)

    @property
    def running(self) -> bool:
        return self._worker is not None and self._worker.isRunning()

    @property
    def owns_frames(self) -> bool:
        """The window's frames are this link's (live or stopped), not the scene's simulation."""
        return self._generation >= 0 and self._w.cache.generation == self._generation

    # ---- connect ----
    def connect_dialog(self) -> None:
        from app.connect_dialog import ConnectDialog

        cfg = str(self._w.settings.value("live/cfg", "") or "")
        dialog = ConnectDialog(self._w, cfg=cfg)
        self.dialog = dialog

        def accepted() -> None:
            self._w.settings.setValue("live/cfg", dialog.cfg_edit.text())
            self.start(dialog.settings(), dialog.record_path)

        dialog.accepted.connect(accepted)
        dialog.open()

    def start(self, settings: LinkSettings, record: str | None = None) -> None:
        """Connect: the simulation stops, the cache is cleared for the sensor's frames."""
        w = self._w
        if self.running:
            w.show_error("live sensor: a sensor is connected; stop it before connecting again")
            return
        if w.params_model.tracker == "room":  # core.live.stream_tracker: no room mode yet
            w.show_error(
                "live sensor: the live link tracks with the paper tracker or gtrack, not the "
                "room mode (it has no frame-by-frame form yet); choose 'paper' or 'gtrack' in "
                "the tracker panel, and re-track the recording in the room mode afterwards"
            )
            return
        try:
            params = w.params_model.params()
        except Exception as exc:  # noqa: BLE001 - bad parameters are a message
            w.show_error(one_line(exc))
            return
        w.sim.stop()
        w.tracker.invalidate()
        w.cache.clear(expected=0, truth_paths=())
        self._generation = w.cache.generation
        self._set_live_face(True)
        self.received_s.clear()
        self._tracks = LiveTracks(velocity_col=getattr(params, "dims", 2))
        self._result = None
        self._edge = 0  # the newest frame the view was moved to: following while it is there
        self.n_frames = self.n_dropped = self.n_damaged = 0
        worker = LiveWorker(settings, params, record, self)
        worker.connected.connect(self._on_connected)
        worker.frame_ready.connect(self._on_frame)
        worker.failed.connect(lambda m: w.show_error(f"live sensor: {m}"))
        worker.closed.connect(self._on_closed)
        worker.finished.connect(lambda: self._on_finished(worker))
        self._worker = worker
        self.act_stop.setEnabled(True)
        self.act_connect.setEnabled(False)
        w.statusBar().showMessage(f"connecting to {settings.cli_port} …", 5000)
        worker.start()

    def _set_live_face(self, live: bool) -> None:
        """A sensor has no ground truth and no radar cube: no truth paths, loss, RMSE or OSPA
        (the track counts instead) and the cube's views say why, until the scene is simulated
        again."""
        w = self._w
        from app.recording_control import LIVE_SOURCE

        truth = not live and w.engine.has_truth
        w.psi_view.has_truth = truth
        w.psi_view.set_recording_counts(None, None)
        w.top_view.set_has_truth(truth)
        if live:
            w.top_view.set_truth_paths([])
        w.recording._set_views_unavailable(live, LIVE_SOURCE)

    def _on_scene_info(self, _info) -> None:
        """The scene adopted again (its simulation replaces the sensor's frames)."""
        if self._generation >= 0 and not self.running and not self._w.recording.replaying:
            self._generation = -1
            self._set_live_face(False)

    def stop(self) -> None:
        """Stop the sensor (``sensorStop``, sent by the worker as the link closes)."""
        if self._worker is not None:
            self._worker.stop()

    def wait(self, timeout_ms: int = 10000) -> bool:
        if self._worker is None:
            return True
        self.stop()
        return self._worker.wait(timeout_ms)

    def shutdown(self) -> None:
        self.wait()

    # ---- worker -> window ----
    def _on_connected(self, radar) -> None:
        w = self._w
        self.frame_period_s = radar.frame_period_s
        w.playback_control.set_frame_period(radar.frame_period_s)
        w.tracker.frame_period_s = radar.frame_period_s
        w.playback.set_playing(False)
        w.statusBar().showMessage(
            f"sensor configured ({self._worker.settings.cfg if self._worker else ''}); "
            "frames arriving",
            5000,
        )

    def _on_frame(self, frame) -> None:
        w = self._w
        if w.cache.generation != self._generation:
            self.stop()  # the scene was changed: the cache is no longer the sensor's
            return
        empty = np.zeros((0, 2))
        # frames lost on the way keep their place: empty frames, as the importer inserts
        while len(w.cache) < frame.index:
            k = len(w.cache)
            w.cache.append(
                FrameData(
                    index=k, t_s=k * self.frame_period_s, cloud=PointCloud.empty(), truth_xy_m=empty
                )
            )
        w.cache.append(
            FrameData(index=frame.index, t_s=frame.t_s, cloud=frame.cloud, truth_xy_m=empty)
        )
        self.received_s.add(frame.index, frame.received_s)
        self.n_frames += 1
        self.n_dropped, self.n_damaged = frame.n_dropped, frame.n_damaged
        self._tracks.add(frame.index, frame.tracks)
        self._result = self._tracks.result(self.frame_period_s)
        w.tracking_model.set_result(self._result)

    def _on_tracked(self, result) -> None:
        """Follow the newest frame while the playback bar is at the end."""
        if result is None or result is not self._result:
            return
        index = result.n_frames - 1
        if self._w.playback.frame < self._edge:
            return  # the user went back to an earlier frame: stay there
        self._edge = index
        self._w.playback.set_frame(index)

    def _on_closed(self, summary: str) -> None:
        self.act_stop.setEnabled(False)
        self.act_connect.setEnabled(True)
        if self._w.cache.generation == self._generation and len(self._w.cache):
            self._w.cache.mark_complete()  # re-tracked with the panel's parameters
        self._w.statusBar().showMessage(summary, 10000)
        self.last_summary = summary

    def _on_finished(self, worker: LiveWorker) -> None:
        if self._worker is worker:
            self._worker = None
        worker.deleteLater()

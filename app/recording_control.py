"""Recordings in the window: File → Open recording …, drag and drop, recent files, and the
window's face while a recording plays (its facts instead of the scene editor, TI's tracks as a
layer, views that need a radar cube saying so, the people count and frame statistics).

Loading runs in a worker thread (a CSV of a few MB takes seconds); a file that cannot be read is
one line in a message box and the window keeps what it showed. The window's engine is switched to
the recording (:func:`app.replay.attach_recording`) only once the file has loaded.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
from PySide6 import QtCore, QtGui, QtWidgets

from app.errors import log_exception, one_line
from app.panels.recording_panel import RecordingPanel, slow_radar_warning
from app.panels.stats_panel import FrameStats, StatsPanel
from app.replay import (
    RECORDING_FILTER,
    ReferenceLayer,
    ReplayEngine,
    attach_recording,
    detach_recording,
    recording_facts,
    replay_of,
)
from app.views.unavailable import set_unavailable

#: Recent recordings kept in the File menu.
MAX_RECENT = 8
RECENT_KEY = "recording/recent"
#: Suffixes a dropped file is taken as a recording by (a .json is a scene unless it is a replay).
RECORDING_SUFFIXES = (".dat", ".bin", ".csv", ".txt", ".npz", ".json")
NO_CUBE = (
    "{source} has no {what}: the sensor sent its point cloud, not the "
    "radar cube. Simulate a scene, or import a DCA1000 capture of raw ADC samples, to see it."
)
RECORDING_SOURCE = "A recording of detected points"
LIVE_SOURCE = "A live sensor's stream of detected points"


def sibling_cfg(path: Path) -> Path | None:
    """The TI ``.cfg`` beside a recording with the same stem (``cap.bin`` → ``cap.cfg``)."""
    cfg = path.with_suffix(".cfg")
    return cfg if cfg.is_file() and path.suffix.lower() != ".cfg" else None


def is_scene_file(path: Path) -> bool:
    """A scene JSON (has ``persons``), not a visualizer replay."""
    if path.suffix.lower() != ".json":
        return False
    try:
        with open(path, "rb") as fh:
            head = fh.read(1 << 16)
    except OSError:
        return False
    return b'"persons"' in head and b'"data"' not in head


class RecordingLoader(QtCore.QThread):
    """Reads one recording (:func:`app.replay.load_recording`) off the GUI thread."""

    loaded = QtCore.Signal(object, str)  # Dataset, path
    failed = QtCore.Signal(str, str)  # one line, path

    def __init__(self, path: str, cfg: str | None, parent=None) -> None:
        super().__init__(parent)
        self.path, self.cfg = path, cfg

    def run(self) -> None:
        from app.replay import load_recording

        try:
            ds = load_recording(self.path, self.cfg)
        except Exception as exc:  # InputError or a reader fault: one line, the file named
            log_exception(f"cannot open recording {self.path}", exc)
            self.failed.emit(one_line(exc, self.path), self.path)
            return
        self.loaded.emit(ds, self.path)


class RecordingController(QtCore.QObject):
    """Recording files and the replay face of a :class:`~app.window.MainWindow`."""

    opened = QtCore.Signal(str)  # path of the recording now playing
    failed = QtCore.Signal(str)  # the one line shown for a file that cannot be read

    def __init__(self, window) -> None:
        super().__init__(window)
        self._w = window
        self.loader: RecordingLoader | None = None
        self.path: str | None = None
        self.facts = None
        self._reference: ReferenceLayer | None = None
        self._head_count = np.zeros(0, dtype=np.int64)
        self._scene_dock_was_visible = True
        self._link_t: tuple[float, int] | None = None
        self._link_fps = float("nan")
        self._mean_points = float("nan")
        self._radar = None
        self._build_menu()
        self._build_docks()
        self._build_view_bar()
        window.setAcceptDrops(True)
        window.installEventFilter(self)
        window.scene_control.info_changed.connect(self._on_scene_info)
        window.scene_model.changed.connect(self.update_title)
        window.cache.finished.connect(self._on_cache_finished)
        if replay_of(window.engine) is not None:  # radartune gui --replay FILE
            replay = replay_of(window.engine)
            assert replay is not None
            self._enter(replay, replay.path)

    # ---- construction ----
    def _build_menu(self) -> None:
        w = self._w
        file_menu = next(a.menu() for a in w.menuBar().actions() if a.text() == "&File")
        first_separator = next(a for a in file_menu.actions() if a.isSeparator())
        self.act_open = QtGui.QAction("Open &recording …", w)
        self.act_open.setShortcut(QtGui.QKeySequence("Ctrl+R"))
        self.act_open.triggered.connect(self.open_dialog)
        self.recent_menu = QtWidgets.QMenu("Recent recordings", w)
        self.recent_menu.setObjectName("recentMenu")
        self.act_close = QtGui.QAction("Close recording (simulate the scene)", w)
        self.act_close.triggered.connect(self.close_recording)
        self.act_close.setEnabled(False)
        file_menu.insertSeparator(first_separator)
        file_menu.insertAction(first_separator, self.act_open)
        file_menu.insertMenu(first_separator, self.recent_menu)
        file_menu.insertAction(first_separator, self.act_close)
        self._fill_recent_menu()

    def _build_docks(self) -> None:
        w = self._w
        self.panel = RecordingPanel()
        self.panel.close_requested.connect(self.close_recording)
        # not one of the window's arranged panels (w.docks): hidden until a recording plays,
        # then put where the scene editor is
        scroll = QtWidgets.QScrollArea()
        scroll.setWidget(self.panel)
        scroll.setWidgetResizable(True)
        scroll.setFrameShape(QtWidgets.QFrame.NoFrame)
        self.dock = QtWidgets.QDockWidget("Recording", w)
        self.dock.setObjectName("dockRecording")
        self.dock.setWidget(scroll)
        self.dock.setMinimumWidth(300)
        self.dock.hide()
        self.stats_panel = StatsPanel()
        # a tab beside the track table (bottom): in the panels' tab group on the right it made
        # the first start's window taller than a 1366x768 screen at 150 %
        scroll = QtWidgets.QScrollArea()
        scroll.setWidget(self.stats_panel)
        scroll.setWidgetResizable(True)
        scroll.setFrameShape(QtWidgets.QFrame.NoFrame)
        self.stats_dock = QtWidgets.QDockWidget("Statistics", w)
        self.stats_dock.setObjectName("dockStatistics")
        self.stats_dock.setWidget(scroll)
        tracks = w.views_control.tracks_dock
        w.addDockWidget(QtCore.Qt.BottomDockWidgetArea, self.stats_dock)
        w.tabifyDockWidget(tracks, self.stats_dock)
        tracks.raise_()
        if tracks.isHidden():  # a small screen: the bottom docks start closed
            self.stats_dock.hide()
        view_menu = next(a.menu() for a in w.menuBar().actions() if a.text() == "&View")
        view_menu.addAction(self.dock.toggleViewAction())
        view_menu.addAction(self.stats_dock.toggleViewAction())

    def _build_view_bar(self) -> None:
        bar = self._w.findChild(QtWidgets.QToolBar, "viewBar")
        self.reference_check = QtWidgets.QCheckBox("TI's tracks")
        self.reference_check.setObjectName("referenceCheck")
        self.reference_check.setToolTip("draw the sensor's own tracks (a recording's reference)")
        self.reference_check.setChecked(True)
        self.reference_check.setEnabled(False)
        self.reference_check.toggled.connect(self._on_reference_toggled)
        bar.addSeparator()
        bar.addWidget(self.reference_check)

    # ---- recent files ----
    def recent(self) -> list[str]:
        text = self._w.settings.value(RECENT_KEY, "[]", type=str) or "[]"
        try:
            items = json.loads(text)
        except ValueError:
            return []
        return (
            [str(p) for p in items if isinstance(p, str)][:MAX_RECENT]
            if isinstance(items, list)
            else []
        )

    def _set_recent(self, items: list[str]) -> None:
        self._w.settings.setValue(RECENT_KEY, json.dumps(items[:MAX_RECENT]))
        self._fill_recent_menu()

    def _remember(self, path: str) -> None:
        p = str(Path(path).resolve())
        self._set_recent([p, *(q for q in self.recent() if q != p)])
        self._w.settings.setValue("recording/last_dir", str(Path(p).parent))

    def _fill_recent_menu(self) -> None:
        self.recent_menu.clear()
        items = self.recent()
        for path in items:
            act = self.recent_menu.addAction(Path(path).name)
            act.setToolTip(path)
            act.setData(path)
            act.triggered.connect(lambda _c=False, p=path: self.open_recent(p))
        self.recent_menu.setEnabled(bool(items))

    def open_recent(self, path: str) -> None:
        if not Path(path).exists():
            self._set_recent([p for p in self.recent() if p != path])
            self._w.show_error(f"{path}: no longer exists; removed from the recent recordings")
            return
        self.load(path)

    # ---- opening ----
    def open_dialog(self) -> None:
        start = self._w.settings.value("recording/last_dir", str(Path.cwd()), type=str)
        path, _ = QtWidgets.QFileDialog.getOpenFileName(
            self._w, "Open recording", start, RECORDING_FILTER
        )
        if path:
            self.load(path)

    def load(self, path: str | Path, cfg: str | Path | None = None) -> None:
        """Read ``path`` in the background (its ``.cfg`` beside it is used when ``cfg`` is None);
        on success the window replays it, on failure one line and nothing changes."""
        path = Path(path)
        if cfg is None:
            cfg = sibling_cfg(path)
        if self.loader is not None and self.loader.isRunning():
            self._w.statusBar().showMessage("still reading the previous recording …", 5000)
            return
        self.loader = RecordingLoader(str(path), None if cfg is None else str(cfg), self)
        self.loader.loaded.connect(self._on_loaded)
        self.loader.failed.connect(self._on_failed)
        self._w.statusBar().showMessage(f"reading {path.name} …")
        self.loader.start()

    def _on_failed(self, message: str, path: str) -> None:
        self._w.show_error(message)
        self.failed.emit(message)

    def _on_loaded(self, ds, path: str) -> None:
        try:
            replay = ReplayEngine(ds, path=path)
        except Exception as exc:
            log_exception(f"cannot replay {path}", exc)
            self._w.show_error(one_line(exc, path))
            return
        self._remember(path)
        w = self._w
        w.playback.set_playing(False)
        attach_recording(w.engine, replay)
        self._enter(replay, path)
        w.scene_model.changed.emit()  # new scene facts, then the frames: the replay's
        w.playback.set_frame(0)
        w.statusBar().showMessage(f"replaying {Path(path).name}: {ds.n_frames} frames", 8000)
        self.opened.emit(path)

    def _enter(self, replay: ReplayEngine, path: str) -> None:
        """The window's replay face for ``replay`` (also for ``radartune gui --replay``)."""
        w = self._w
        self.path = path
        ds = replay.dataset
        self.facts = recording_facts(ds, Path(path).name if path else "", source=path)
        self.panel.show_facts(self.facts)
        self._reference = ReferenceLayer.of(ds) if ds.has_reference else None
        self._head_count = np.asarray(ds.people_count, dtype=np.int64)
        counts = np.diff(ds.frame_offsets)
        self._mean_points = float(counts.mean()) if len(counts) else float("nan")
        w.top_view.set_reference(self._reference)
        self.reference_check.setEnabled(self._reference is not None)
        if not self.facts.has_snr and w.top_view.colour_by == "snr":
            i = w.colour_combo.findData("doppler")
            w.colour_combo.setCurrentIndex(i)  # its signal recolours the view
        w.psi_view.has_truth = replay.has_truth
        w.top_view.set_has_truth(replay.has_truth)
        w.psi_view.set_recording_counts(
            counts, self._reference.counts() if self._reference is not None else None
        )
        scene_dock, rec_dock = w.docks["Scene"], self.dock
        if w.dockWidgetArea(rec_dock) == QtCore.Qt.NoDockWidgetArea:
            w.addDockWidget(w.dockWidgetArea(scene_dock), rec_dock)
            w.tabifyDockWidget(scene_dock, rec_dock)
        if rec_dock.isHidden():  # not when one recording follows another
            self._scene_dock_was_visible = not scene_dock.isHidden()
        rec_dock.show()
        rec_dock.raise_()
        scene_dock.hide()
        self._set_views_unavailable(True)
        self._align_scene_radar(replay.radar)
        self.act_close.setEnabled("replay" in w.engine.__dict__)
        self.panel.close_button.setEnabled(self.act_close.isEnabled())
        self.update_title()

    def _align_scene_radar(self, radar) -> None:
        """The scene takes the recording's radar quietly (its area shrunk to the radar's range
        when it reaches further), so that adopting the recording asks nothing."""
        model = self._w.scene_model
        scene = model.scene
        if scene is None or scene.radar == radar:
            return
        doc = model.document
        aoi = dict(doc.get("aoi") or {})
        if aoi.get("max_range_m", 0.0) > radar.max_range_m:
            aoi["max_range_m"] = int(radar.max_range_m * 100.0) / 100.0
        try:
            doc.update(radar=radar.to_dict(), aoi=aoi)
            model.set_document(doc)
        except Exception as exc:  # the scene keeps its radar: the views still draw the points
            log_exception("the recording's radar does not fit the scene", exc)

    def _set_views_unavailable(self, replay: bool, source: str = RECORDING_SOURCE) -> None:
        w = self._w
        views = w.views_control
        for view, what in (
            (w.rd_view, "range-Doppler map"),
            (views.ra_view, "range-azimuth map"),
            (views.profile_view, "range profile"),
            (views.spectrogram_view, "micro-Doppler spectrogram (it is cut from the range-Doppler "
                                     "map at each person's range)"),
        ):  # fmt: skip
            set_unavailable(view, NO_CUBE.format(source=source, what=what) if replay else None)

    def close_recording(self) -> None:
        """Back to simulating the scene."""
        w = self._w
        if "replay" not in w.engine.__dict__:  # simulating, or an engine that only replays
            return
        w.playback.set_playing(False)
        detach_recording(w.engine)
        self.path = self.facts = None
        self._reference = None
        self._head_count = np.zeros(0, dtype=np.int64)
        w.top_view.set_reference(None)
        self.reference_check.setEnabled(False)
        w.psi_view.has_truth = w.engine.has_truth
        w.top_view.set_has_truth(w.engine.has_truth)
        w.psi_view.set_recording_counts(None, None)
        if self._scene_dock_was_visible:
            w.docks["Scene"].show()
            w.docks["Scene"].raise_()
        self.dock.hide()
        self._set_views_unavailable(False)
        self.act_close.setEnabled(False)
        w.scene_model.changed.emit()
        self.update_title()

    @property
    def replaying(self) -> bool:
        return replay_of(self._w.engine) is not None

    # ---- drag and drop ----
    def eventFilter(self, obj, event) -> bool:
        kind = event.type()
        if kind in (QtCore.QEvent.DragEnter, QtCore.QEvent.DragMove):
            if self._dropped_path(event.mimeData()) is not None:
                event.acceptProposedAction()
                return True
        elif kind == QtCore.QEvent.Drop:
            path = self._dropped_path(event.mimeData())
            if path is not None:
                event.acceptProposedAction()
                self.open_any(path)
                return True
        return False

    @staticmethod
    def _dropped_path(mime: QtCore.QMimeData) -> Path | None:
        if not mime.hasUrls():
            return None
        for url in mime.urls():
            if url.isLocalFile():
                return Path(url.toLocalFile())
        return None

    def open_any(self, path: Path) -> None:
        """A dropped file: a scene JSON opens as the scene, a ``.cfg`` re-reads the recording
        with it (or sets the simulated radar), anything else opens as a recording."""
        w = self._w
        suffix = path.suffix.lower()
        if is_scene_file(path):
            self.close_recording()
            w.load_scene(path)
        elif suffix == ".cfg":
            if self.replaying and self.path:
                self.load(self.path, cfg=path)
            else:
                w.load_cfg(path)
        else:
            self.load(path)

    # ---- the face ----
    def update_title(self, *_args) -> None:
        w = self._w
        if self.replaying:
            name = Path(self.path).name if self.path else "recording"
            w.setWindowTitle(f"{name} (recording) — RadarTune")
            return
        path = w.scene_model.path
        w.setWindowTitle(f"{path.name if path else 'paper scene'} — RadarTune")

    def _on_reference_toggled(self, on: bool) -> None:
        self._w.top_view.set_show_reference(on)
        self._w._mark_dirty()

    def _on_scene_info(self, info) -> None:
        self._radar = info.radar
        warning = slow_radar_warning(info.radar.max_velocity_mps)
        self.stats_panel.set_warning(warning)
        if warning:
            self._w.statusBar().showMessage(warning, 10000)

    def _on_cache_finished(self) -> None:
        frames = self._w.cache.frames
        if not self.replaying and frames:
            self._mean_points = float(np.mean([len(f.cloud) for f in frames]))

    def frame_stats(self, index: int, frame, result) -> FrameStats:
        """The statistics of frame ``index`` (the frame shown)."""
        w = self._w
        tf = result.frames[index] if result is not None and 0 <= index < result.n_frames else None
        live = w.live
        if live.running:
            now = time.perf_counter()
            if self._link_t is None or now - self._link_t[0] > 1.0:
                if self._link_t is not None:
                    dt = now - self._link_t[0]
                    self._link_fps = (live.n_frames - self._link_t[1]) / dt
                self._link_t = (now, live.n_frames)
            dropped = int(live.n_dropped)
        else:
            self._link_t, self._link_fps = None, float("nan")
            dropped = -1
            if self.facts is not None and self.facts.dropped_frames is not None:
                dropped = self.facts.dropped_frames
        hc = int(self._head_count[index]) if 0 <= index < len(self._head_count) else -1
        radar = self._radar
        return FrameStats(
            index=index,
            n_frames=len(w.cache),
            t_s=float(frame.t_s) if frame is not None else float("nan"),
            frame_period_s=w.playback_control.frame_period_s,
            n_points=len(frame.cloud) if frame is not None else 0,
            mean_points=self._mean_points,
            n_confirmed=int(np.count_nonzero(tf.confirmed)) if tf is not None else 0,
            n_tracks=len(tf) if tf is not None else 0,
            ti_count=self._reference.count(index) if self._reference is not None else -1,
            head_count=hc,
            truth_count=(
                int(np.isfinite(frame.truth_xy_m).all(axis=1).sum())
                if frame is not None and w.psi_view.has_truth
                else -1
            ),
            dropped_frames=dropped,
            link_fps=self._link_fps,
            max_velocity_mps=radar.max_velocity_mps if radar is not None else float("nan"),
        )

    def redraw(self, index: int, frame, result) -> None:
        """The people count on the top view and the statistics panel (the window's draw)."""
        stats = self.frame_stats(index, frame, result)
        self._w.top_view.set_count(stats.count_html() if frame is not None else None)
        dock = self.stats_dock
        if dock.isVisible() and not dock.visibleRegion().isEmpty():
            self.stats_panel.show_stats(stats)

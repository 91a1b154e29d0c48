"""The main window: live views in the centre, editor panels in docks, persistence of settings
and layout (QSettings). It composes the controllers: :class:`~app.playback.PlaybackController`
(play timer, playback bar, frame index), :class:`~app.scene_control.SceneController` (scene
files and edits, TI .cfg, re-simulation), the simulation / re-tracking workers and the study."""

from __future__ import annotations

import json
import time
from collections import deque
from pathlib import Path

from PySide6 import QtCore, QtGui, QtWidgets

from app.engine import Engine
from app.errors import log_exception, one_line
from app.models import (
    FrameCache,
    PlaybackModel,
    RadarModel,
    SceneModel,
    TrackerParamsModel,
    TrackingModel,
)
from app.panels.processing_panel import ProcessingPanel
from app.panels.radar_panel import RadarPanel
from app.panels.scene_panel import ScenePanel
from app.panels.study_panel import StudyPanel
from app.panels.tracker_panel import TrackerPanel
from app.playback import PlaybackController
from app.scene_control import SceneController
from app.study import StudyController, StudyModel
from app.views.psi_view import PsiView
from app.views.rd_view import RangeDopplerView
from app.views.top_view import TopView
from app.workers import SimulationController, TrackingController, freeze_heap
from core.config import PAPER_RADAR
from core.errors import InputError

#: Settings stored as JSON text (the tracker panel's state).
JSON_SETTINGS = ("tracker/values", "tracker/extra")
DRAW_INTERVAL_MS = 15  # GUI draw timer: at most ~66 redraws per second, stale frames dropped
RETRACK_EVERY_N_FRAMES = 20  # while the simulation fills the cache


def stored_json(settings: QtCore.QSettings, key: str):
    """A setting stored as JSON text, parsed by core's strict reader (nesting limited):
    :class:`InputError` naming the settings file and the key; ``{}`` when it is not stored."""
    from core.files import parse_json

    text = settings.value(key, "", type=str) or "{}"
    return parse_json(text, f"{settings.fileName()} [{key}]", what="setting")


class MainWindow(QtWidgets.QMainWindow):
    """RadarTune main window. ``settings`` must be given (tests pass a temporary one)."""

    def __init__(
        self,
        settings: QtCore.QSettings,
        engine: Engine | None = None,
        *,
        load_scene: bool = True,
        scene_path: str | None = None,
        restore: bool = True,
    ) -> None:
        super().__init__()
        self.setObjectName("mainWindow")
        self.setWindowTitle("RadarTune")
        self.settings = settings
        self.engine = engine or Engine()
        self.errors: list[str] = []
        self._error_box: QtWidgets.QMessageBox | None = None

        # ---- models ----------------------------------------------------------------------------
        self.scene_model = SceneModel(self.engine, self)
        self.radar_model = RadarModel(PAPER_RADAR, self)
        self.params_model = TrackerParamsModel(self.engine, self)
        self.cache = FrameCache(self)
        self.tracking_model = TrackingModel(self)
        self.playback = PlaybackModel(self)
        self.study_model = StudyModel(self)

        # ---- controllers -----------------------------------------------------------------------
        self.sim = SimulationController(self.engine, self.cache, self)
        self.tracker = TrackingController(
            self.engine, self.cache, self.params_model, self.tracking_model, parent=self
        )
        self.study = StudyController(self.engine, self.study_model, parent=self)

        self._build_central()

        self._build_docks()

        self.playback_control = PlaybackController(self.playback, self.cache, self)
        pc = self.playback_control  # the bar's widgets, as attributes of the window
        self.playback_bar, self._play_timer = pc.bar, pc.timer
        self.act_back, self.act_play, self.act_fwd = pc.act_back, pc.act_play, pc.act_fwd
        self.speed_combo, self.timeline = pc.speed_combo, pc.timeline
        self.frame_label, self.fps_label = pc.frame_label, pc.fps_label
        self.scene_control = SceneController(
            self.engine,
            self.settings,
            self.scene_model,
            self.radar_model,
            self.sim,
            self.tracker,
            self,
        )
        self._scene_timer = self.scene_control.timer
        self._build_view_bar()
        self._build_menus()
        self._build_status()
        # ---- radar views, track table, record and export (app/views_control.py,
        # app/record.py): docks and File-menu entries of their own, drawn from redraw()
        from app.record import RecordController
        from app.views_control import ViewsController

        self.views_control = ViewsController(self)
        self.record = RecordController(self)
        from app.live import LiveController  # File → Connect sensor … (a live TI sensor)

        self.live = LiveController(self)
        from app.recording_control import RecordingController  # File → Open recording …

        self.recording = RecordingController(self)

        self._wire()

        self._draw_timer = QtCore.QTimer(self)
        self._draw_timer.setInterval(DRAW_INTERVAL_MS)
        self._draw_timer.timeout.connect(self._draw)
        self._draw_timer.start()
        self._dirty = True
        self._draw_times: deque[float] = deque(maxlen=60)
        self._draw_costs_s: deque[float] = deque(maxlen=60)
        self._track_ms_per_frame = float("nan")
        self._t_timing_shown = 0.0
        self.n_draws = 0

        if restore:
            self.restore_settings()
        else:
            self.fit_screen()
        if load_scene:
            self.scene_control.load_initial(scene_path)
        freeze_heap()

    # ---- construction helpers ----
    def _build_central(self) -> None:
        """The top view beside the range-Doppler and ψ views (the central splitters)."""
        self.top_view = TopView()
        self.rd_view = RangeDopplerView()
        self.psi_view = PsiView()
        self.psi_view.has_truth = self.engine.has_truth
        right = QtWidgets.QSplitter(QtCore.Qt.Vertical)
        right.setObjectName("rightSplitter")
        right.addWidget(self.rd_view)
        right.addWidget(self.psi_view)
        right.setSizes([350, 350])
        central = QtWidgets.QSplitter(QtCore.Qt.Horizontal)
        central.setObjectName("centralSplitter")
        central.addWidget(self.top_view)
        central.addWidget(right)
        central.setSizes([620, 480])
        self.central_splitter, self.right_splitter = central, right
        self.compact = False
        self.setCentralWidget(central)

    def _build_docks(self) -> None:
        """The scene, radar, tracker, study and processing panels, each in a dock."""
        self.scene_panel = ScenePanel(self.scene_model, self.engine)
        self.radar_panel = RadarPanel(self.radar_model)
        self.tracker_panel = TrackerPanel(self.params_model)
        self.study_panel = StudyPanel(self.study_model)
        self.docks: dict[str, QtWidgets.QDockWidget] = {}
        self._dock("Scene", self.scene_panel, QtCore.Qt.LeftDockWidgetArea)
        self._dock("Radar", self.radar_panel, QtCore.Qt.LeftDockWidgetArea)
        self._dock("Tracker", self.tracker_panel, QtCore.Qt.RightDockWidgetArea)
        self._dock("Study", self.study_panel, QtCore.Qt.RightDockWidgetArea)
        # fidelity level, processing settings and timing (app/panels/processing_panel)
        self.processing_panel = ProcessingPanel(self.engine.fidelity_levels())
        self._dock("Processing", self.processing_panel, QtCore.Qt.LeftDockWidgetArea)
        self.tabifyDockWidget(self.docks["Radar"], self.docks["Processing"])
        self.tabifyDockWidget(self.docks["Scene"], self.docks["Radar"])
        self.tabifyDockWidget(self.docks["Tracker"], self.docks["Study"])
        self.docks["Scene"].raise_()
        self.docks["Tracker"].raise_()

    def _wire(self) -> None:
        """Connect the models, controllers, panels and views."""
        self.scene_control.info_changed.connect(self._on_scene_info)
        self.processing_panel.fidelity_changed.connect(self.set_fidelity)
        self.radar_model.chain_changed.connect(self.set_chain)
        self.scene_control.error.connect(self.show_error)
        self.scene_control.message.connect(lambda m: self.statusBar().showMessage(m, 5000))
        self.cache.reset.connect(self._on_cache_reset)
        self.cache.frames_added.connect(self._on_frames_added)
        self.cache.finished.connect(self._on_cache_finished)
        self.sim.failed.connect(lambda m: self.show_error(f"simulation failed: {m}"))
        self.tracker.failed.connect(lambda m: self.show_error(f"tracking failed: {m}"))
        self.tracker.finished.connect(self._on_tracked)
        self.tracker.compiled.connect(
            lambda t: self.statusBar().showMessage(f"compiled tracker ready ({t:.1f} s)", 5000)
        )
        self.tracking_model.changed.connect(self._on_tracking_changed)
        self.params_model.changed.connect(self._on_params_changed)
        self.playback.frame_changed.connect(self._mark_dirty)
        for panel in (self.scene_panel, self.radar_panel, self.tracker_panel, self.study_panel):
            panel.error.connect(self.show_error)
        self.radar_panel.load_cfg_requested.connect(self.scene_control.load_cfg_dialog)
        self.scene_panel.draw_mode_changed.connect(self.top_view.set_draw_mode)
        self.top_view.waypoint_added.connect(self.scene_panel.append_waypoint)
        self.top_view.waypoints_moved.connect(self._on_waypoints_dragged)
        self.scene_model.selection_changed.connect(self._show_selected_waypoints)
        self.scene_model.selection_changed.connect(self.top_view.set_selected_person)
        self.tracker_panel.apply_best_requested.connect(self.apply_best)
        self.study_panel.apply_best_requested.connect(self.apply_best)
        self.study_panel.start_requested.connect(self.start_study)
        self.study_panel.stop_requested.connect(self.study.stop)
        self.study_panel.enqueue_requested.connect(self.enqueue_current)
        self.study_panel.dashboard_requested.connect(self.open_dashboard)
        self.study_panel.browse_requested.connect(self.browse_storage)
        self.study_model.progress_changed.connect(
            lambda p: self.tracker_panel.apply_best_button.setEnabled(bool(p.best_params))
        )
        self.study_model.message.connect(lambda m: self.statusBar().showMessage(m, 8000))
        self.study_model.form_changed.connect(lambda _f: self.study.refresh())
        # the study tunes the tracker the tracker panel shows (until one is chosen in the
        # study panel; never while a study runs)
        self.params_model.changed.connect(self._study_follows_tracker)

    def _dock(self, title: str, widget: QtWidgets.QWidget, area) -> None:
        scroll = QtWidgets.QScrollArea()
        scroll.setWidget(widget)
        scroll.setWidgetResizable(True)
        scroll.setFrameShape(QtWidgets.QFrame.NoFrame)
        dock = QtWidgets.QDockWidget(title, self)
        dock.setObjectName(f"dock{title}")
        dock.setWidget(scroll)
        dock.setMinimumWidth(300)
        self.addDockWidget(area, dock)
        self.docks[title] = dock

    def _build_view_bar(self) -> None:
        bar = QtWidgets.QToolBar("View", self)
        bar.setObjectName("viewBar")
        self.addToolBar(QtCore.Qt.TopToolBarArea, bar)
        bar.addWidget(QtWidgets.QLabel(" points coloured by "))
        self.colour_combo = QtWidgets.QComboBox()
        self.colour_combo.setObjectName("colourCombo")
        self.colour_combo.addItem("SNR", "snr")
        self.colour_combo.addItem("label (person / clutter / noise)", "label")
        self.colour_combo.addItem("Doppler", "doppler")
        self.colour_combo.addItem("height", "height")
        self.colour_combo.addItem("TI's track", "track")
        bar.addWidget(self.colour_combo)
        bar.addWidget(QtWidgets.QLabel("  persistence "))
        self.persistence_spin = QtWidgets.QSpinBox()
        self.persistence_spin.setObjectName("persistenceSpin")
        self.persistence_spin.setRange(1, 100)
        self.persistence_spin.setSuffix(" frames")
        bar.addWidget(self.persistence_spin)
        bar.addWidget(QtWidgets.QLabel("  trail "))
        self.trail_spin = QtWidgets.QSpinBox()
        self.trail_spin.setObjectName("trailSpin")
        self.trail_spin.setRange(1, 1000)
        self.trail_spin.setSuffix(" frames")
        bar.addWidget(self.trail_spin)
        self.colour_combo.currentIndexChanged.connect(self._on_view_options)
        self.persistence_spin.valueChanged.connect(self._on_view_options)
        self.trail_spin.valueChanged.connect(self._on_view_options)
        self._sync_view_options()

    def _build_menus(self) -> None:
        file_menu = self.menuBar().addMenu("&File")
        scenes = self.scene_control
        file_menu.addAction("&Open scene …", QtGui.QKeySequence.Open, scenes.open_dialog)
        file_menu.addAction("&Save scene as …", QtGui.QKeySequence.SaveAs, scenes.save_dialog)
        file_menu.addAction("Paper scene", scenes.load_paper_scene)
        file_menu.addSeparator()
        file_menu.addAction("Load TI radar .cfg …", scenes.load_cfg_dialog)
        file_menu.addAction("Load tracker parameters …", self.load_params_dialog)
        file_menu.addAction("Save tracker parameters …", self.save_params_dialog)
        file_menu.addSeparator()
        file_menu.addAction("&Quit", QtGui.QKeySequence.Quit, self.close)
        view_menu = self.menuBar().addMenu("&View")
        for dock in self.docks.values():
            view_menu.addAction(dock.toggleViewAction())

    def _build_status(self) -> None:
        # until the first frame: what is happening (a first start compiles the radar chain)
        self.retrack_label = QtWidgets.QLabel(
            "re-track: waiting for the first simulated frame (the first start after an install "
            "compiles the radar chain)"
        )
        self.retrack_label.setObjectName("retrackLabel")
        self.metrics_label = QtWidgets.QLabel()
        self.metrics_label.setObjectName("metricsLabel")
        self.statusBar().addPermanentWidget(self.metrics_label)
        self.statusBar().addPermanentWidget(self.retrack_label)

    # ---- layout ----
    def fit_screen(self, available: QtCore.QRect | None = None) -> None:
        """First start: a window that fits the screen (1366×768 up, at 100 % or 150 %).

        The panels share one tabbed dock on the right, as wide as the widest panel, so that the
        top view keeps the width its locked aspect needs to show the whole area of interest
        (with docks on both sides a 1920-px window showed 29 m for the 10 m area); the central
        splitter gives the top view 60 % of what is left, or, on a very small logical screen
        (1366×768 at 150 %), the top view goes above the two plots.
        """
        if available is None:
            screen = self.screen() or QtWidgets.QApplication.primaryScreen()
            available = screen.availableGeometry()
        width = min(1800, available.width())
        height = min(1000, available.height())
        self.resize(width, height)
        order = tuple(self.docks)
        for title in order:
            self.addDockWidget(QtCore.Qt.RightDockWidgetArea, self.docks[title])
        for title in order[1:]:
            self.tabifyDockWidget(self.docks[order[0]], self.docks[title])
        self.docks["Scene"].raise_()
        # wide enough for every panel's own minimum: no horizontal scroll bar in the dock
        dock_w = max(self.panel_width(d) for d in self.docks.values())
        self.resizeDocks([self.docks["Scene"]], [dock_w], QtCore.Qt.Horizontal)
        centre = max(400, width - dock_w - 20)
        if centre < 700:  # e.g. 1366x768 at 150 %: the plots under the top view
            self.set_compact(True)
            h = max(300, height - 150)
            self.central_splitter.setSizes([h * 3 // 5, h - h * 3 // 5])
            self.right_splitter.setSizes([centre * 11 // 20, centre - centre * 11 // 20])
        else:
            # the top view 60 %: the area of interest is wider (±60°) than deep
            self.central_splitter.setSizes([centre * 3 // 5, centre - centre * 3 // 5])

    def set_compact(self, compact: bool) -> None:
        """Compact layout for small screens: the top view above, range-Doppler and ψ side by
        side below it (the normal layout: top view left, the two plots stacked right)."""
        self.compact = bool(compact)
        vertical, horizontal = QtCore.Qt.Vertical, QtCore.Qt.Horizontal
        self.central_splitter.setOrientation(vertical if compact else horizontal)
        self.right_splitter.setOrientation(horizontal if compact else vertical)

    @staticmethod
    def panel_width(dock: QtWidgets.QDockWidget) -> int:
        """The width a dock needs to show its panel without a horizontal scroll bar."""
        scroll = dock.widget()
        bar_w = scroll.verticalScrollBar().sizeHint().width()
        return max(300, scroll.widget().minimumSizeHint().width() + bar_w + 4)

    # ---- errors ----
    def show_error(self, message: str) -> None:
        """One line naming the problem (and the file); never blocks, never crashes."""
        message = " ".join(part.strip() for part in message.splitlines() if part.strip())
        self.errors.append(message)
        self.statusBar().showMessage(message, 10000)
        if self._error_box is None:
            self._error_box = QtWidgets.QMessageBox(self)
            self._error_box.setObjectName("errorBox")
            self._error_box.setIcon(QtWidgets.QMessageBox.Warning)
            self._error_box.setWindowTitle("RadarTune")
            self._error_box.setModal(False)
        self._error_box.setText(message)
        self._error_box.show()

    # ---- scene (SceneController) ----
    def load_scene(self, path: str | Path) -> bool:
        """Load a scene file; on error show it and keep the current scene."""
        return self.scene_control.load(path)

    def load_cfg(self, path: str | Path) -> bool:
        """Load a TI .cfg into the radar; on error show it, keep the current radar."""
        return self.scene_control.load_cfg(path)

    def _on_scene_info(self, info) -> None:
        self.playback_control.set_frame_period(info.frame_period_s)
        self.top_view.set_aoi(
            info.aoi["min_range_m"], info.aoi["max_range_m"], info.aoi["max_azimuth_deg"]
        )
        self.top_view.set_reflectors(info.reflectors_xy_m)
        self.top_view.set_room(info.room_outline_xy_m)
        self.top_view.set_truth_paths(info.truth_paths)
        self._show_selected_waypoints()
        self.top_view.set_selected_person(self.scene_model.selected_person)
        self.rd_view.set_radar(info.radar)
        if self.scene_model.scene is not None:
            self.processing_panel.show_settings(
                self.engine.processing_settings(self.scene_model.scene)
            )

    def set_chain(self, chain) -> None:
        """Simulate the scene again through another detection chain (``ChainConfig``)."""
        if chain != self.sim.chain:
            self.sim.chain = chain
            self.scene_control.resimulate()

    def set_fidelity(self, name: str) -> None:
        """Simulate the scene again at another fidelity level (a key of the core registry)."""
        if name != self.sim.fidelity:
            self.sim.fidelity = name
            self.processing_panel.set_fidelity(name)
            self.scene_control.resimulate()

    def _show_selected_waypoints(self, *_args) -> None:
        """The top view's handles: the selected person's waypoints (none for classes a–e)."""
        persons = self.scene_model.document.get("persons") or []
        sel = self.scene_model.selected_person
        traj = persons[sel]["trajectory"] if 0 <= sel < len(persons) else {}
        self.top_view.set_waypoints(traj.get("waypoints"))

    def _on_waypoints_dragged(self, rows: list) -> None:
        """A drag the scene refuses (e.g. outside the area of interest) puts the handles back."""
        if not self.scene_panel.set_waypoints(rows):
            self._show_selected_waypoints()

    # ---- tracker parameters ----
    def load_params_dialog(self) -> None:
        path, _ = QtWidgets.QFileDialog.getOpenFileName(
            self, "Load tracker parameters", str(Path.cwd()), "JSON (*.json)"
        )
        if path:
            self.load_params(path)

    def load_params(self, path: str | Path) -> bool:
        try:
            tracker, model, values, extra = self.engine.load_tracker_file(path)
            self.params_model.set_tracker(tracker)
            self.params_model.set_values(values, model=model, extra=extra)
            return True
        except (OSError, json.JSONDecodeError) as exc:
            self.show_error(f"{path}: {exc}")
        except InputError as exc:
            self.show_error(str(exc) if exc.source else f"{path}: {exc}")
        except Exception as exc:  # a reader fault (bad bytes, nesting): one line, the file named
            log_exception(f"cannot load tracker parameters {path}", exc)
            self.show_error(one_line(exc, str(path)))
        return False

    def save_params_dialog(self) -> None:
        path, _ = QtWidgets.QFileDialog.getSaveFileName(
            self, "Save tracker parameters", str(Path.cwd() / "tracker.json"), "JSON (*.json)"
        )
        if path:
            try:
                self.params_model.params().save(path)  # atomic: nothing half-written
            except (InputError, OSError) as exc:
                self.show_error(one_line(exc, path))
            except Exception as exc:
                log_exception(f"cannot save tracker parameters {path}", exc)
                self.show_error(one_line(exc, path))

    def _on_params_changed(self) -> None:
        extra = self.params_model.extra_effective()
        self.psi_view.set_thresholds(extra["confirm_threshold"], extra["delete_threshold"])

    def apply_best(self) -> None:
        p = self.study_model.progress
        if not p.best_params:
            self.show_error("no completed trial yet")
            return
        try:
            form = self.study_model.form
            self.params_model.set_tracker(form.tracker)  # the tracker the study tunes
            model = None if form.tracker == "gtrack" else p.best_model
            self.params_model.set_values(p.best_params, model=model)
            self.statusBar().showMessage(f"applied best trial (loss {p.best_loss:.4g} m²)", 5000)
        except InputError as exc:
            self.show_error(str(exc))

    # ---- cache, tracking ----
    def _on_cache_reset(self) -> None:
        self._dirty = True

    def _on_frames_added(self, n: int) -> None:
        if n == 1:  # the radar chain is compiled: now the tracker kernel (priority order)
            self.tracker.start_warm_up()
        if (n == 1 or n % RETRACK_EVERY_N_FRAMES == 0) and not self.live.running:
            self.tracker.request()  # (a live sensor's frames come tracked: app/live.py)
        if self.playback.frame >= n - 1:
            self._dirty = True

    def _on_cache_finished(self) -> None:
        freeze_heap()  # the cached frames live as long as the scene
        self.tracker.request()

    def _on_tracked(self, elapsed_s: float) -> None:
        n = self.tracking_model.result.n_frames if self.tracking_model.result else len(self.cache)
        result = self.tracking_model.result
        numpy = result is not None and result.engine == "numpy"
        self.retrack_label.setText(
            f"re-track {n} frames: {elapsed_s * 1e3:.0f} ms"
            + (" (readable numpy tracker while the compiled one compiles)" if numpy else "")
        )
        self._track_ms_per_frame = elapsed_s * 1e3 / max(n, 1)
        self.tracker_panel.show_timing(elapsed_s, n)

    def _on_tracking_changed(self, result) -> None:
        self.psi_view.set_result(result, self.playback_control.frame_period_s)
        self._dirty = True

    # ---- drawing ----
    def _mark_dirty(self, *_args) -> None:
        self._dirty = True

    def _on_view_options(self, *_args) -> None:
        self.top_view.set_colour_by(self.colour_combo.currentData())
        self.top_view.persistence = self.persistence_spin.value()
        self.top_view.trail_length = self.trail_spin.value()
        self._dirty = True

    def _sync_view_options(self) -> None:
        for w in (self.colour_combo, self.persistence_spin, self.trail_spin):
            w.blockSignals(True)
        self.colour_combo.setCurrentIndex(self.colour_combo.findData(self.top_view.colour_by))
        self.persistence_spin.setValue(self.top_view.persistence)
        self.trail_spin.setValue(self.top_view.trail_length)
        for w in (self.colour_combo, self.persistence_spin, self.trail_spin):
            w.blockSignals(False)

    def _draw(self) -> None:
        """GUI timer: draw only the latest state (intermediate frames are dropped)."""
        if not self._dirty:
            self._update_fps()
            return
        self._dirty = False
        self.redraw()

    def redraw(self) -> None:
        t0 = time.perf_counter()
        frames = self.cache.frames
        index = self.playback.frame
        result = self.tracking_model.result
        frame = frames[index] if 0 <= index < len(frames) else None
        self.top_view.show_frame(index, frames, result)
        self.rd_view.show_frame(frame)
        self.psi_view.set_frame(index)
        self.views_control.redraw(index, frame, result)  # radar views and track table
        self.recording.redraw(index, frame, result)  # people count and statistics
        self._show_metrics(index, result)
        self.n_draws += 1
        now = time.perf_counter()
        self._draw_times.append(now)
        self._draw_costs_s.append(now - t0)
        self._update_fps()

    def _show_metrics(self, index: int, result) -> None:
        if not self.psi_view.has_truth:  # a recording without truth, or a live sensor
            self.metrics_label.setText("no ground truth: no loss, RMSE or OSPA")
            return
        if result is None or index >= result.n_frames:
            self.metrics_label.setText("loss – · RMSE – · OSPA –")
            return
        loss = result.running_loss[index]
        rmse = result.running_rmse_m[index]
        ospa = result.ospa_m[index]
        rmse_t = "–" if rmse != rmse else f"{rmse:.3f} m"
        self.metrics_label.setText(
            f"running loss {loss:.3g} m² · RMSE {rmse_t} · OSPA {ospa:.3f} m"
        )

    def _update_fps(self) -> None:
        now = time.perf_counter()
        recent = [t for t in self._draw_times if now - t <= 1.0]
        rendered = len(recent)
        source = (
            "received" if self.live.owns_frames
            else "read" if self.recording.replaying
            else "simulated"
        )  # fmt: skip
        text = f" rendered {rendered:d} fps · {source} {self.sim.rate_fps:.1f} fps" + (
            " (done)" if self.cache.complete else ""
        )
        if text != self.fps_label.text():  # a label's setText re-lays out its bar
            self.fps_label.setText(text)
        if now - self._t_timing_shown >= 0.5:  # the timing panel twice a second
            self._t_timing_shown = now
            costs = sorted(self._draw_costs_s)
            self.processing_panel.show_timing(
                frame=self.sim.frame_timing_ms,
                track_ms=self._track_ms_per_frame,
                draw_ms=costs[len(costs) // 2] * 1e3 if costs else float("nan"),
                sim_fps=self.sim.rate_fps,
                draw_fps=rendered,
            )

    # ---- study ----
    def start_study(self) -> None:
        """Start a study on the current scene's point clouds (written as a data set first)."""
        if self.study.running:
            return
        form = self.study_model.form
        try:
            dataset = None
            if form.dataset == "scene":
                shown = (
                    "a recording" if self.recording.replaying
                    else "the live sensor" if self.live.owns_frames
                    else ""
                )  # fmt: skip
                if shown:
                    raise InputError(
                        f"the study tunes on the simulated scene, and the frames shown come from "
                        f"{shown}: open or edit a scene to simulate it, or tune on a recording "
                        "with radartune tune --dataset REC.npz --people N"
                    )
                if not self.cache.complete:
                    raise InputError("the scene is still being simulated; wait until it is done")
                storage = Path(form.storage).expanduser().resolve()
                dataset = storage.with_name(storage.stem + "-scene.npz")
                self.engine.scene_dataset(self.cache.frames, self.scene_model.scene, dataset)
            self.study.start(dataset_path=None if dataset is None else str(dataset))
        except InputError as exc:
            self.show_error(str(exc))
        except Exception as exc:
            log_exception("cannot start study", exc)
            self.show_error(f"cannot start study: {one_line(exc)}")

    def _study_follows_tracker(self) -> None:
        tracker = self.params_model.tracker
        if not self.study.running and self.study_model.form.tracker != tracker:
            self.study_model.set_form(tracker=tracker)

    def enqueue_current(self) -> None:
        tuned = self.study_model.form.tracker
        if self.params_model.tracker != tuned:
            self.show_error(
                f"cannot enqueue: the study tunes the {tuned} tracker; the tracker panel shows "
                f"{self.params_model.tracker}"
            )
            return
        self.study.enqueue(
            self.params_model.values,
            self.params_model.model,
            on_error=lambda m: self.show_error(f"cannot enqueue: {m}"),
        )

    def open_dashboard(self) -> None:
        try:
            url = self.study.open_dashboard()
        except InputError as exc:
            self.show_error(str(exc))
            return
        except Exception as exc:
            log_exception("cannot start the dashboard", exc)
            self.show_error(f"cannot start the dashboard: {one_line(exc)}")
            return
        self.statusBar().showMessage(f"dashboard at {url}", 10000)
        # Qt starts the browser detached: webbrowser.open left its child defunct (never reaped)
        QtCore.QTimer.singleShot(1500, lambda: QtGui.QDesktopServices.openUrl(QtCore.QUrl(url)))

    def browse_storage(self) -> None:
        path, _ = QtWidgets.QFileDialog.getSaveFileName(
            self,
            "Study storage",
            self.study_model.form.storage,
            "SQLite (*.sqlite3 *.db);;Journal (*.log)",
            options=QtWidgets.QFileDialog.DontConfirmOverwrite,
        )
        if path:
            try:
                self.study_model.set_form(storage=path)
            except InputError as exc:
                self.show_error(str(exc))

    # ---- persistence ----
    def save_settings(self) -> None:
        s = self.settings
        s.setValue("window/geometry", self.saveGeometry())
        s.setValue("window/state", self.saveState())
        s.setValue("window/central_splitter", self.central_splitter.saveState())
        s.setValue("window/right_splitter", self.right_splitter.saveState())
        s.setValue("window/compact", bool(self.compact))
        s.setValue("playback/speed", float(self.playback.speed))
        s.setValue("view/colour_by", str(self.top_view.colour_by))
        s.setValue("view/persistence", int(self.top_view.persistence))
        s.setValue("view/trail_length", int(self.top_view.trail_length))
        s.setValue("tracker/model", self.params_model.model)
        s.setValue("tracker/tracker", self.params_model.tracker)
        s.setValue("tracker/values", json.dumps(self.params_model.values))
        s.setValue("tracker/extra", json.dumps(self.params_model.extra))
        f = self.study_model.form
        s.setValue("study/model", f.model)
        s.setValue("study/tracker", f.tracker)
        s.setValue("study/n_trials", int(f.n_trials))
        s.setValue("study/n_jobs", int(f.n_jobs))
        s.setValue("study/storage", f.storage)
        s.setValue("study/dataset", f.dataset)
        s.sync()

    def restore_settings(self) -> None:
        s = self.settings
        geometry = s.value("window/geometry", type=QtCore.QByteArray)
        if geometry is not None and not geometry.isEmpty():
            self.restoreGeometry(geometry)
        else:
            self.fit_screen()
        state = s.value("window/state", type=QtCore.QByteArray)
        if state is not None and not state.isEmpty():
            self.restoreState(state)
        if s.value("window/compact", False, type=bool):
            self.set_compact(True)
        for key, splitter in (
            ("window/central_splitter", self.central_splitter),
            ("window/right_splitter", self.right_splitter),
        ):
            st = s.value(key, type=QtCore.QByteArray)
            if st is not None and not st.isEmpty():
                splitter.restoreState(st)
        try:
            self.playback.set_speed(s.value("playback/speed", 1.0, type=float))
        except InputError:
            pass
        colour = s.value("view/colour_by", "snr", type=str)
        self.top_view.set_colour_by(colour)  # an unknown mode is SNR
        self.top_view.persistence = max(1, min(100, s.value("view/persistence", 5, type=int)))
        self.top_view.trail_length = max(1, min(1000, s.value("view/trail_length", 25, type=int)))
        self._sync_view_options()
        try:
            model = s.value("tracker/model", "cv", type=str)
            self.params_model.set_tracker(s.value("tracker/tracker", "paper", type=str))
            values, extra = (stored_json(s, key) for key in JSON_SETTINGS)
            if values:
                self.params_model.set_values(values, model=model)
            if extra:
                self.params_model.set_extra(**extra)
        except (InputError, ValueError, TypeError) as exc:
            self.statusBar().showMessage(f"stored tracker parameters ignored: {exc}", 8000)
        try:
            self.study_model.set_form(
                model=s.value("study/model", "cv", type=str),
                n_trials=s.value("study/n_trials", 50, type=int),
                n_jobs=s.value("study/n_jobs", 1, type=int),
                storage=s.value("study/storage", self.study_model.form.storage, type=str),
                dataset=s.value("study/dataset", "scene", type=str),
                tracker=s.value("study/tracker", self.params_model.tracker, type=str),
            )
        except InputError as exc:
            self.statusBar().showMessage(f"stored study settings ignored: {exc}", 8000)

    def shutdown(self) -> None:
        """Stop timers and workers (close, tests)."""
        self._draw_timer.stop()
        self.playback_control.stop()
        self.live.shutdown()
        self.scene_control.stop()
        self.sim.wait()
        self.tracker.wait()
        self.study.shutdown()

    def closeEvent(self, event: QtGui.QCloseEvent) -> None:
        self.save_settings()
        self.shutdown()
        super().closeEvent(event)

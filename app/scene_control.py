"""Scene control: open, save and edit the scene, apply a TI ``.cfg`` to its radar, re-simulate.

:class:`SceneController` is the one place that changes which scene the window shows. A file that
cannot be read or validated (whatever the exception) becomes one line naming the file on
``error``, unexpected exceptions are logged with their traceback, and the current scene stays. Every
adopted scene is announced with its :class:`~app.data.SceneInfo` on ``info_changed`` (the window
updates its views) and re-simulated after a short debounce, so a burst of edits simulates once.
"""

from __future__ import annotations

import math
from pathlib import Path

from PySide6 import QtCore, QtWidgets

from app.errors import log_exception, one_line
from app.models import RadarModel, SceneModel
from app.workers import SimulationController, TrackingController
from core.config import PAPER_RADAR
from core.errors import InputError

RESIMULATE_DEBOUNCE_MS = 150  # after the last edit of the scene


class SceneController(QtCore.QObject):
    """Scene files and edits for ``window`` (the parent of its file dialogs)."""

    info_changed = QtCore.Signal(object)  # SceneInfo of the scene just adopted
    error = QtCore.Signal(str)  # one line for the user
    message = QtCore.Signal(str)  # a status-bar note

    def __init__(
        self,
        engine,
        settings: QtCore.QSettings,
        scene_model: SceneModel,
        radar_model: RadarModel,
        sim: SimulationController,
        tracker: TrackingController,
        window: QtWidgets.QWidget,
    ) -> None:
        super().__init__(window)
        self._window = window
        self.engine = engine
        self.settings = settings
        self.scene_model = scene_model
        self.radar_model = radar_model
        self.sim = sim
        self.tracker = tracker
        self.timer = QtCore.QTimer(self)
        self.timer.setSingleShot(True)
        self.timer.setInterval(RESIMULATE_DEBOUNCE_MS)
        self.timer.timeout.connect(self.resimulate)
        scene_model.changed.connect(self._on_scene_changed)
        radar_model.changed.connect(self._on_radar_edited)

    # ---- files ----
    def load_initial(self, path: str | None) -> None:
        """The scene given on the command line, else (or when it is bad) the paper scene."""
        if path and self.load(path):
            return
        self.load_paper_scene()

    def load_paper_scene(self) -> None:
        try:
            self.scene_model.set_document(self.engine.paper_document())
        except Exception as exc:
            self._fail("paper scene", exc)

    def load(self, path: str | Path) -> bool:
        """Load a scene file; on error show it and keep the current scene."""
        try:
            self.scene_model.load(path)
        except Exception as exc:  # InputError, or a reader fault: one line, the file named
            self._fail(f"cannot load scene {path}", exc, str(path))
            return False
        self._remember(str(path))
        return True

    def _fail(self, what: str, exc: Exception, source: str | None = None) -> None:
        log_exception(what, exc)
        self.error.emit(one_line(exc, source))

    def _remember(self, path: str) -> None:
        self.settings.setValue("scene/last_dir", str(Path(path).resolve().parent))

    def open_dialog(self) -> None:
        start = self.settings.value("scene/last_dir", str(Path.cwd()), type=str)
        path, _ = QtWidgets.QFileDialog.getOpenFileName(
            self._window, "Open scene", start, "Scene JSON (*.json);;All files (*)"
        )
        if path:
            self.load(path)

    def save_dialog(self) -> None:
        start = self.settings.value("scene/last_dir", str(Path.cwd()), type=str)
        path, _ = QtWidgets.QFileDialog.getSaveFileName(
            self._window, "Save scene", str(Path(start) / "scene.json"), "Scene JSON (*.json)"
        )
        if path:
            try:
                self.scene_model.save(path)
                self._remember(path)
                self.message.emit(f"scene saved to {path}")
            except Exception as exc:
                self._fail(f"cannot save scene {path}", exc, path)

    # ---- TI radar configuration ----
    def load_cfg(self, path: str | Path) -> bool:
        """Load a TI .cfg into the radar; on error show it, keep the current radar."""
        try:
            radar = self.engine.read_ti_cfg(path)
            chain = self.engine.read_ti_chain(path)
        except Exception as exc:  # InputError, or a reader bug: must not crash the app
            self._fail(f"cannot load TI config {path}", exc, str(path))
            return False
        self.radar_model.set_chain(chain)
        self.radar_model.set_radar(radar)
        if chain.ignored:
            self.message.emit(f"chain {chain.name}; ignored: {', '.join(chain.ignored)}")
        return True

    def load_cfg_dialog(self) -> None:
        start = self.settings.value("radar/last_dir", str(Path.cwd()), type=str)
        path, _ = QtWidgets.QFileDialog.getOpenFileName(
            self._window, "Load TI mmWave .cfg", start, "TI config (*.cfg);;All files (*)"
        )
        if path:
            self.settings.setValue("radar/last_dir", str(Path(path).parent))
            self.load_cfg(path)

    # ---- edits ----
    def _on_scene_changed(self) -> None:
        info = self.engine.scene_info(self.scene_model.scene)
        self.tracker.frame_period_s = info.frame_period_s
        self.info_changed.emit(info)
        self.radar_model.set_radar(info.radar)
        self.timer.start()

    def resimulate(self) -> None:
        """Drop the tracks of the old scene and simulate the current one."""
        scene = self.scene_model.scene
        if scene is None:
            return
        self.tracker.invalidate()
        self.sim.start(scene)

    def _on_radar_edited(self, radar) -> None:
        scene = self.scene_model.scene
        if scene is None or scene.radar == radar:
            return
        spec = "paper" if radar == PAPER_RADAR else radar.to_dict()
        try:
            self.scene_model.edit(radar=spec)
            return
        except InputError as exc:
            refused = exc
        aoi = dict(self.scene_model.document.get("aoi") or {})
        # the area of interest reaches beyond the radar's maximum range: offer to shrink it
        max_range_m = math.floor(radar.max_range_m * 100.0) / 100.0  # 1 cm inside the limit
        if aoi.get("max_range_m", 0.0) > radar.max_range_m and self.ask_shrink_aoi(
            aoi["max_range_m"], max_range_m
        ):
            try:
                self.scene_model.edit(radar=spec, aoi={**aoi, "max_range_m": max_range_m})
                self.message.emit(f"area of interest shrunk to {max_range_m:g} m for this radar")
                return
            except InputError as exc:
                refused = exc
        self.error.emit(str(refused))
        self.radar_model.set_radar(scene.radar)

    def ask_shrink_aoi(self, aoi_max_m: float, radar_max_m: float) -> bool:
        """Ask whether to shrink the area of interest to the radar's maximum range."""
        answer = QtWidgets.QMessageBox.question(
            self._window,
            "Radar range shorter than the area of interest",
            f"This radar sees up to {radar_max_m:g} m, the area of interest reaches "
            f"{aoi_max_m:g} m.\n\nShrink the area of interest to {radar_max_m:g} m?",
            QtWidgets.QMessageBox.Yes | QtWidgets.QMessageBox.No,
            QtWidgets.QMessageBox.Yes,
        )
        return answer == QtWidgets.QMessageBox.Yes

    def stop(self) -> None:
        self.timer.stop()

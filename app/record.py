"""Record and export from the main window: workspaces (save, open), the run's point clouds,
tracks and metrics (CSV, data set, ``.npz``), the plots and the window as PNG. The File menu
entries; the files are written by the Qt-free :mod:`app.export` and :mod:`app.workspace`."""

from __future__ import annotations

from pathlib import Path

from PySide6 import QtCore, QtGui, QtWidgets

from app import export
from app.errors import log_exception, one_line
from app.workspace import Workspace, load_workspace, save_workspace
from core.errors import InputError

#: exported plots are drawn this wide (px), whatever their size on screen
EXPORT_WIDTH_PX = 1600


def plot_image(widget: QtWidgets.QWidget) -> QtGui.QPixmap:
    """A plot drawn anew at :data:`EXPORT_WIDTH_PX` wide (pyqtgraph's image exporter, aspect
    kept: text and lines redrawn, not a screen grab enlarged); other widgets grabbed as shown."""
    import pyqtgraph as pg
    from pyqtgraph.exporters import ImageExporter

    if not isinstance(widget, pg.GraphicsView):
        return widget.grab()
    exporter = ImageExporter(widget.scene())
    exporter.parameters()["width"] = max(EXPORT_WIDTH_PX, widget.width())
    image = exporter.export(toBytes=True)
    return QtGui.QPixmap.fromImage(image)


class RecordController(QtCore.QObject):
    """File → Save workspace …, Open workspace …, Export …, Export plots as PNG …,
    Screenshot …. Errors become one line in a message box naming the file and field."""

    def __init__(self, window) -> None:
        super().__init__(window)
        self._w = window
        menu = next(a.menu() for a in window.menuBar().actions() if a.text() == "&File")
        quit_action = next((a for a in menu.actions() if a.text() == "&Quit"), None)
        entries = (
            ("Open &workspace …", self.open_workspace_dialog),
            ("Save w&orkspace …", self.save_workspace_dialog),
            (None, None),
            ("&Export run (CSV, data set) …", self.export_dialog),
            ("Export plots as &PNG …", self.export_plots_dialog),
            ("Screens&hot …", self.screenshot_dialog),
            (None, None),
        )
        self.actions: dict[str, QtGui.QAction] = {}
        for text, slot in entries:
            if text is None:
                menu.insertSeparator(quit_action)
                continue
            action = QtGui.QAction(text, window)
            action.triggered.connect(slot)
            menu.insertAction(quit_action, action)
            self.actions[text.replace("&", "")] = action

    # ---- workspace ----
    def current_workspace(self) -> Workspace:
        w = self._w
        scene = w.scene_model.scene
        if scene is None:
            raise InputError("no scene loaded")
        return Workspace(
            scene=w.scene_model.document,
            radar=scene.radar,
            tracker_model=w.params_model.model,
            tracker_values=w.params_model.values,
            tracker_extra=w.params_model.extra,
            study=w.study_model.form,
            tracker_kind=w.params_model.tracker,
        )

    def save_workspace(self, path: str | Path) -> bool:
        try:
            save_workspace(path, self.current_workspace())
            self._w.statusBar().showMessage(f"workspace saved: {path}", 5000)
            return True
        except InputError as exc:
            self._w.show_error(str(exc) if exc.source else f"{path}: {exc}")
        except Exception as exc:
            log_exception(f"cannot save workspace {path}", exc)
            self._w.show_error(one_line(exc, str(path)))
        return False

    def open_workspace(self, path: str | Path) -> bool:
        """Read, validate the whole file, then apply it (a bad file changes nothing)."""
        w = self._w
        try:
            ws = load_workspace(path, w.engine)
            w.scene_model.set_document(ws.scene, base_dir=Path(path).parent, source=str(path))
            w.params_model.set_tracker(ws.tracker_kind)
            w.params_model.set_values(ws.tracker_values, model=ws.tracker_model)
            if ws.tracker_extra:
                w.params_model.set_extra(**ws.tracker_extra)
            form = ws.study
            w.study_model.set_form(
                **{k: getattr(form, k) for k in ("model", "n_trials", "n_jobs", "storage",
                                                  "study_name", "seed", "dataset")}
            )  # fmt: skip
            w.statusBar().showMessage(f"workspace opened: {path}", 5000)
            return True
        except InputError as exc:
            w.show_error(str(exc) if exc.source else f"{path}: {exc}")
        except Exception as exc:
            log_exception(f"cannot open workspace {path}", exc)
            w.show_error(one_line(exc, str(path)))
        return False

    def save_workspace_dialog(self) -> None:
        path, _ = QtWidgets.QFileDialog.getSaveFileName(
            self._w, "Save workspace", str(Path.cwd() / "workspace.json"), "Workspace (*.json)"
        )
        if path:
            self.save_workspace(path)

    def open_workspace_dialog(self) -> None:
        path, _ = QtWidgets.QFileDialog.getOpenFileName(
            self._w, "Open workspace", str(Path.cwd()), "Workspace (*.json)"
        )
        if path:
            self.open_workspace(path)

    # ---- export ----
    def export_run(self, folder: str | Path) -> list[Path]:
        w = self._w
        frames = list(w.cache.frames)
        try:
            if not frames:
                raise InputError("nothing to export yet: no simulated frame")
            scene = w.scene_model.scene

            def write_dataset(path: Path) -> Path:
                return w.engine.scene_dataset(frames, scene, path)

            written = export.export_run(
                folder,
                frames,
                w.tracking_model.result,
                w.playback_control.frame_period_s,
                write_dataset,
            )
            w.statusBar().showMessage(f"exported {len(written)} files to {folder}", 8000)
            return written
        except InputError as exc:
            w.show_error(str(exc) if exc.source else f"{folder}: {exc}")
        except Exception as exc:
            log_exception(f"cannot export to {folder}", exc)
            w.show_error(one_line(exc, str(folder)))
        return []

    def plot_widgets(self) -> dict[str, QtWidgets.QWidget]:
        w = self._w
        v = w.views_control
        return {
            "top-view": w.top_view,
            "range-doppler": w.rd_view,
            "psi": w.psi_view,
            "range-azimuth": v.ra_view,
            "range-profile": v.profile_view,
            "micro-doppler": v.spectrogram_view,
            "elevation": v.elevation_view,
            "tracks": v.track_table,
        }

    def export_plots(self, folder: str | Path) -> list[Path]:
        """Every plot as ``<name>.png`` in ``folder`` (drawn at the frame shown first)."""
        w = self._w
        folder = Path(folder)
        index = w.playback.frame
        frames = w.cache.frames
        frame = frames[index] if 0 <= index < len(frames) else None
        w.views_control.draw_all(index, frame, w.tracking_model.result)
        out = []
        try:
            folder.mkdir(parents=True, exist_ok=True)
            for name, widget in self.plot_widgets().items():
                if widget.width() < 50 or widget.height() < 50:
                    widget.resize(900, 600)  # a hidden tab has no size yet
                out.append(self._save_png(plot_image(widget), folder / f"{name}.png"))
        except InputError as exc:
            w.show_error(str(exc))
        except OSError as exc:
            w.show_error(one_line(exc, str(folder)))
        return out

    def screenshot(self, path: str | Path) -> Path | None:
        try:
            return self._save_png(self._w.grab(), Path(path))
        except (InputError, OSError) as exc:
            self._w.show_error(one_line(exc, str(path)))
            return None

    @staticmethod
    def _save_png(pixmap: QtGui.QPixmap, path: Path) -> Path:
        """PNG bytes written atomically (nothing half-written)."""
        from core.files import write_bytes_atomic

        data = QtCore.QByteArray()
        buf = QtCore.QBuffer(data)
        buf.open(QtCore.QIODevice.WriteOnly)
        if not pixmap.save(buf, "PNG"):
            raise InputError("cannot encode the image as PNG", str(path))
        buf.close()
        return write_bytes_atomic(path, bytes(data))

    def export_dialog(self) -> None:
        folder = QtWidgets.QFileDialog.getExistingDirectory(self._w, "Export run to folder")
        if folder:
            self.export_run(folder)

    def export_plots_dialog(self) -> None:
        folder = QtWidgets.QFileDialog.getExistingDirectory(self._w, "Export plots to folder")
        if folder:
            written = self.export_plots(folder)
            self._w.statusBar().showMessage(f"{len(written)} plots written to {folder}", 8000)

    def screenshot_dialog(self) -> None:
        path, _ = QtWidgets.QFileDialog.getSaveFileName(
            self._w, "Screenshot", str(Path.cwd() / "radartune.png"), "PNG (*.png)"
        )
        if path:
            self.screenshot(path)

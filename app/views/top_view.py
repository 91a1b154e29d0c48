"""Top view (x-y): AOI, the radar, ground-truth paths, point cloud with persistence (coloured by
SNR, label, Doppler, height or TI's track association, with a colour bar), tracker overlay, TI's
own tracks as a layer of their own, and the people count.

All pyqtgraph items are created once in ``__init__`` and updated with ``setData``. Point and
track colours come from pre-built brush palettes (per-point brush construction is ~8× slower).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pyqtgraph as pg
from PySide6 import QtCore, QtGui, QtWidgets

from app.colours import IDENTITY_PALETTE, LABEL_COLOURS, identity_colour, identity_index, label_key
from app.data import FrameData, TrackFrame, TrackingResult
from app.geometry import aoi_polyline, ellipse_polyline, trails_polyline
from app.person_colours import person_colour
from app.views.axis_cache import cache_axes
from core.config import PAPER_MAX_AZIMUTH_DEG, PAPER_MAX_RANGE_M, PAPER_MIN_RANGE_M
from core.limits import MAX_PERSONS

SNR_MIN_DB = 10.0
SNR_MAX_DB = 50.0
N_SNR_COLOURS = 32
N_PSI_LEVELS = 11
#: Fixed scales of the other colourings: Doppler (radial velocity, m/s, symmetric) and height z (m)
DOPPLER_SPAN_MPS = 3.0
HEIGHT_MIN_M, HEIGHT_MAX_M = -1.0, 2.5

#: colour-by modes: key -> (title of the plot, colour map name or "" for categories, unit, span)
COLOUR_MODES: dict[str, tuple[str, str, str, tuple[float, float]]] = {
    "snr": ("SNR", "plasma", "dB", (SNR_MIN_DB, SNR_MAX_DB)),
    "label": ("person / clutter / false alarm", "", "", (0.0, 1.0)),
    "doppler": (
        "Doppler (radial velocity)",
        "CET-D1",
        "m/s",
        (-DOPPLER_SPAN_MPS, DOPPLER_SPAN_MPS),
    ),  # noqa: E501
    "height": ("height z", "viridis", "m", (HEIGHT_MIN_M, HEIGHT_MAX_M)),
    "track": ("TI's track of each point (grey: none)", "", "", (0.0, 1.0)),
}
#: TI's tracks (the reference layer): magenta hollow diamonds, dashed trails (a colour of no
#: track identity, no point colouring and no person)
REFERENCE_RGB = (255, 60, 255)


def _snr_palette(name: str = "plasma") -> list[QtGui.QBrush]:
    cmap = pg.colormap.get(name)
    colours = cmap.getLookupTable(0.0, 1.0, N_SNR_COLOURS, alpha=False)
    return [pg.mkBrush(int(r), int(g), int(b), 230) for r, g, b in colours]


def _brush_array(brushes: list[QtGui.QBrush]) -> np.ndarray:
    a = np.empty(len(brushes), dtype=object)
    a[:] = brushes
    return a


def _psi_palette(rgb: tuple[int, int, int]) -> list[QtGui.QBrush]:
    # opacity shows ψ: ψ = 0 → faint, ψ = 1 → opaque
    return [pg.mkBrush(*rgb, int(40 + 215 * k / (N_PSI_LEVELS - 1))) for k in range(N_PSI_LEVELS)]


class TopView(pg.PlotWidget):
    """x-y plot of one frame; call :meth:`show_frame`.

    Also the waypoint editor: in draw mode a click appends a waypoint (``waypoint_added``);
    waypoints are draggable (``waypoints_moved`` with all rows ``[x_m, y_m, speed_mps]``).
    """

    waypoint_added = QtCore.Signal(float, float)
    waypoints_moved = QtCore.Signal(list)

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setObjectName("topView")
        self.setAspectLocked(True)
        self.setLabel("bottom", "x", units="m")
        self.setLabel("left", "y", units="m")
        self.setTitle("Top view · points: SNR")
        self.showGrid(x=True, y=True, alpha=0.2)
        # two columns, translucent: half the height over the plot
        self.addLegend(offset=(5, 5), colCount=2, brush=pg.mkBrush(0, 0, 0, 140))
        self._make_brushes()
        self._add_scene_items()
        self._add_track_items()
        self._labels: list[pg.TextItem] = []
        self._add_reference_items()
        self._add_colour_bar()
        self._stack_items()
        self.waypoint_line = self.plot(
            pen=pg.mkPen((255, 0, 255), width=1, style=QtCore.Qt.DashLine), symbol=None
        )
        self._waypoint_items: list[pg.TargetItem] = []
        self._waypoint_rows: list[list[float]] = []
        self.draw_mode = False
        self.scene().sigMouseClicked.connect(self._on_click)

        #: False for a recording without ground truth (:meth:`set_has_truth`)
        self.has_truth = True
        self.colour_by = "snr"  # a key of COLOUR_MODES
        self.persistence = 5
        self.trail_length = 25
        self.n_draws = 0
        self.last_n_points = 0
        self.last_n_tracks = 0
        self.set_aoi(PAPER_MIN_RANGE_M, PAPER_MAX_RANGE_M, PAPER_MAX_AZIMUTH_DEG)
        cache_axes(self.getPlotItem())
        # once the user pans or zooms, the view stays where they put it
        self.getPlotItem().vb.sigRangeChangedManually.connect(self._stop_auto_fit)
        # the people count, large, in the top right corner (set_count)
        self.count_label = QtWidgets.QLabel(self)
        self.count_label.setObjectName("peopleCount")
        self.count_label.setStyleSheet(
            "background: rgba(0, 0, 0, 150); color: white; padding: 4px 8px; border-radius: 4px"
        )
        self.count_label.hide()
        self._label_samples = {
            k: pg.ScatterPlotItem(brush=self._label_brushes[k], pen=None, size=8)
            for k in ("person", "clutter", "false alarm")
        }
        legend = self.getPlotItem().legend
        self._legend_order = [(sample.item, label.text) for sample, label in legend.items]
        self._refresh_legend()
        self.set_colour_by(self.colour_by)

    def _make_brushes(self) -> None:
        """Brushes made once: SNR colours, labels, identities by ψ."""
        self._snr_brushes = _snr_palette()
        self._label_brushes = {k: pg.mkBrush(*c, 220) for k, c in LABEL_COLOURS.items()}
        self._snr_array = np.empty(N_SNR_COLOURS, dtype=object)
        self._snr_array[:] = self._snr_brushes
        self._label_array = np.empty(3, dtype=object)
        self._label_array[:] = [
            self._label_brushes[k] for k in ("person", "clutter", "false alarm")
        ]
        # per identity (app.colours), opacity by ψ: [identity palette index][ψ level]
        self._identity_brushes = [_psi_palette(rgb) for rgb in IDENTITY_PALETTE]
        # continuous colourings (colour map per mode) and TI's track ids (identity palette)
        self._map_arrays = {
            mode: _brush_array(_snr_palette(cmap))
            for mode, (_t, cmap, _u, _s) in COLOUR_MODES.items()
            if cmap and mode != "snr"
        }
        self._map_arrays["snr"] = self._snr_array
        self._track_array = _brush_array(
            [pg.mkBrush(*rgb, 230) for rgb in IDENTITY_PALETTE] + [pg.mkBrush(130, 130, 130, 160)]
        )

    def _add_scene_items(self) -> None:
        """The scene: area outline, static reflectors, truth paths."""
        self.aoi = self.plot(pen=pg.mkPen((120, 120, 120), width=1, style=QtCore.Qt.DashLine))
        self.room = self.plot(
            pen=pg.mkPen((170, 150, 120), width=2), connect="finite", name="walls"
        )
        self.reflectors = pg.ScatterPlotItem(
            symbol="s",
            size=10,
            brush=pg.mkBrush(*LABEL_COLOURS["static"]),
            pen=None,
            name="static reflector",
        )
        self.addItem(self.reflectors)
        # the legend's entry; the paths themselves are one item per person (person_colour)
        self.truth_path = self.plot(
            pen=pg.mkPen((255, 255, 255, 110), width=1.5), connect="finite", name="truth path"
        )
        self._person_paths: list[pg.PlotDataItem] = []
        self._selected_person = 0
        self._n_persons = 0
        self._truth_brushes = [pg.mkPen(person_colour(k), width=1.5) for k in range(MAX_PERSONS)]

    def _add_reference_items(self) -> None:
        """TI's own tracks (a recording's reference layer), off until :meth:`set_reference`."""
        pen = pg.mkPen(REFERENCE_RGB, width=3)
        self.reference = pg.ScatterPlotItem(
            symbol="d", size=20, pen=pen, brush=None, name="TI's tracks"
        )
        self.addItem(self.reference)
        self.reference_trails = self.plot(
            pen=pg.mkPen((*REFERENCE_RGB, 170), width=1.5, style=QtCore.Qt.DashLine),
            connect="finite",
        )
        self._reference = None  # app.replay.ReferenceLayer
        self._reference_sorted: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self.show_reference = True
        self._reference_labels: list[pg.TextItem] = []
        self._legend_hidden = {"TI's tracks"}

    def legend_entry_visible(self, name: str, visible: bool) -> None:
        """Show or hide one legend row by its name (the legend is rebuilt without the hidden
        rows, so that no gap is left where one was)."""
        if visible:
            self._legend_hidden.discard(name)
        else:
            self._legend_hidden.add(name)
        self._rebuild_legend()

    def _rebuild_legend(self) -> None:
        order = getattr(self, "_legend_order", None)
        if order is None:  # still being built: __init__ rebuilds it at its end
            return
        legend = self.getPlotItem().legend
        legend.clear()
        for item, name in order:
            if name not in self._legend_hidden:
                legend.addItem(item, name)
        if self.colour_by == "label":  # the label colours (app.colours)
            for name, sample in self._label_samples.items():
                legend.addItem(sample, f"point: {name}")

    def _add_colour_bar(self) -> None:
        """The radar (a marker at the origin, boresight along y) and the points' colour bar."""
        self.radar_marker = pg.ScatterPlotItem(
            [0.0], [0.0], symbol="t1", size=16, pen=pg.mkPen("w", width=1),
            brush=pg.mkBrush(40, 200, 255), name="radar",
        )  # fmt: skip
        self.addItem(self.radar_marker)
        self.colour_bar = pg.ColorBarItem(
            values=(SNR_MIN_DB, SNR_MAX_DB),
            colorMap=pg.colormap.get("plasma"),
            width=12,
            interactive=False,
        )
        # the plot's own layout, right of the view box (where setImageItem(insert_in=) puts it)
        self.getPlotItem().layout.addItem(self.colour_bar, 2, 5)

    def _add_track_items(self) -> None:
        """Points, trails, gates, truth now, tracks and the estimate."""
        self.points = pg.ScatterPlotItem(size=6, pen=None, name="points")
        self.addItem(self.points)
        self.trails = self.plot(pen=pg.mkPen((0, 220, 90, 150), width=1.5), connect="finite")
        # trails coloured per identity: one NaN-separated curve per palette colour
        self.identity_trails = [
            self.plot(pen=pg.mkPen((*rgb, 190), width=2), connect="finite")
            for rgb in IDENTITY_PALETTE
        ]
        self.gates_confirmed = self.plot(
            pen=pg.mkPen((0, 220, 90), width=1), connect="finite", name="gate (confirmed)"
        )
        self.gates_tentative = self.plot(
            pen=pg.mkPen((240, 220, 40), width=1, style=QtCore.Qt.DotLine),
            connect="finite",
            name="gate (tentative)",
        )
        self.truth_now = pg.ScatterPlotItem(
            symbol="star",
            size=14,
            brush=None,
            pen=pg.mkPen((255, 255, 255), width=1.5),
            name="truth",
        )
        self.addItem(self.truth_now)
        self.tracks = pg.ScatterPlotItem(size=13, pen=pg.mkPen("k", width=1), name="tracks")
        self.addItem(self.tracks)
        self.estimate = pg.ScatterPlotItem(
            symbol="x", size=16, pen=pg.mkPen((255, 40, 40), width=2), brush=None, name="estimate"
        )
        self.addItem(self.estimate)

    def _stack_items(self) -> None:
        """Drawing order: gates and tracks under the points, truth and estimate on top."""
        for z, item in enumerate(
            (self.aoi, self.room, self.truth_path, self.trails, self.gates_tentative,
             self.gates_confirmed, self.tracks, self.reflectors, self.points,
             self.reference_trails, self.reference, self.truth_now, self.estimate,
             self.radar_marker)
        ):  # fmt: skip
            item.setZValue(z)
        for item in self.identity_trails:
            item.setZValue(self.trails.zValue())

    # ---- static content ---------------------------------------------------------------------
    def set_aoi(self, min_range_m: float, max_range_m: float, max_azimuth_deg: float) -> None:
        line = aoi_polyline(min_range_m, max_range_m, max_azimuth_deg)
        self.aoi.setData(line[:, 0], line[:, 1])
        half = max_range_m * np.sin(np.deg2rad(max_azimuth_deg))
        self._aoi_rect = QtCore.QRectF(-half - 0.5, -0.2, 2 * half + 1.0, max_range_m + 0.7)
        self._auto_fit = True
        self.fit_aoi()

    def fit_aoi(self) -> None:
        """Show the whole AOI (the aspect lock widens whichever axis it must)."""
        self.getPlotItem().vb.setRange(rect=self._aoi_rect, padding=0)

    def resizeEvent(self, event) -> None:
        super().resizeEvent(event)
        if getattr(self, "_auto_fit", False):
            self.fit_aoi()
        if hasattr(self, "count_label"):
            self._place_count()

    def _stop_auto_fit(self, *_args) -> None:
        self._auto_fit = False

    def set_room(self, outline_xy_m: np.ndarray) -> None:
        """The room's walls and furniture footprints, one NaN-separated outline (m)."""
        xy = np.asarray(outline_xy_m, dtype=float).reshape(-1, 2)
        self.room.setData(xy[:, 0], xy[:, 1], connect="finite")
        self._refresh_legend()

    def set_reflectors(self, xy_m: np.ndarray) -> None:
        xy = np.asarray(xy_m, dtype=float).reshape(-1, 2)
        self.reflectors.setData(xy[:, 0], xy[:, 1])
        self._refresh_legend()

    def set_truth_paths(self, paths_m: Sequence[np.ndarray]) -> None:
        """Full ground-truth path of every person, each ``(F_i, 2)`` in m, one colour each."""
        paths = [np.asarray(p, dtype=float).reshape(-1, 2) for p in paths_m]
        while len(self._person_paths) < len(paths):  # items created once, reused
            k = len(self._person_paths)
            item = self.plot(connect="finite")
            item.setZValue(self.truth_path.zValue())
            self._person_paths.append(item)
        for k, item in enumerate(self._person_paths):
            if k < len(paths):
                item.setData(paths[k][:, 0], paths[k][:, 1], connect="finite")
            else:
                item.setData([], [])
        self._n_persons = sum(len(p) > 0 for p in paths)
        self._style_person_paths()
        self._refresh_legend()

    def set_has_truth(self, on: bool) -> None:
        """False for a recording without ground truth: no truth marks, no scene estimate (the
        paper's loss scores it against the truth; the tracks are drawn as ever) and no legend
        rows for them."""
        self.has_truth = bool(on)
        if not self.has_truth:
            self.estimate.setData([], [])
            self.truth_now.setData([], [])
        self._refresh_legend()

    def _refresh_legend(self) -> None:
        """The legend lists only what the data on show can draw: walls, reflectors and truth
        paths of a scene that has them; truth and the estimate only with ground truth."""
        if not hasattr(self, "has_truth"):
            return  # still being built
        walls = self.room.getData()[0]
        rows = {
            "walls": walls is not None and len(walls) > 0,
            "static reflector": len(self.reflectors.data) > 0,
            "truth path": self._n_persons > 0,
            "truth": self.has_truth,
            "estimate": self.has_truth,
        }
        for name, visible in rows.items():
            if visible:
                self._legend_hidden.discard(name)
            else:
                self._legend_hidden.add(name)
        self._rebuild_legend()

    def set_selected_person(self, index: int) -> None:
        """Draw the selected person's path wider (the one the editor edits)."""
        self._selected_person = int(index)
        self._style_person_paths()

    def _style_person_paths(self) -> None:
        for k, item in enumerate(self._person_paths):
            r, g, b = person_colour(k)
            selected = k == self._selected_person and self._n_persons > 1
            item.setPen(pg.mkPen((r, g, b, 200 if selected else 130), width=3 if selected else 1.5))
        self._truth_brushes = [pg.mkPen(person_colour(k), width=1.5) for k in range(MAX_PERSONS)]

    # ---- waypoint editor ---------------------------------------------------------------------
    def set_draw_mode(self, on: bool) -> None:
        self.draw_mode = bool(on)
        self.setCursor(QtCore.Qt.CrossCursor if on else QtCore.Qt.ArrowCursor)

    def set_waypoints(self, rows) -> None:
        """Show the selected person's waypoints (``None``: not a drawn trajectory)."""
        # x, y as numbers; the rest (speed, hold, a seated stop's "sit") kept as given
        rows = [[float(r[0]), float(r[1]), *r[2:]] for r in (rows or [])]
        self._waypoint_rows = rows
        while len(self._waypoint_items) > len(rows):
            self.removeItem(self._waypoint_items.pop())
        while len(self._waypoint_items) < len(rows):
            item = pg.TargetItem(
                pos=(0.0, 0.0), size=12, movable=True, pen=pg.mkPen((255, 0, 255), width=2)
            )
            item.sigPositionChangeFinished.connect(self._on_waypoint_dragged)
            self.addItem(item)
            self._waypoint_items.append(item)
        for item, row in zip(self._waypoint_items, rows):
            item.blockSignals(True)
            item.setPos(row[0], row[1])
            item.blockSignals(False)
        xy = np.array([r[:2] for r in rows]).reshape(-1, 2)
        self.waypoint_line.setData(xy[:, 0], xy[:, 1])

    def _on_waypoint_dragged(self, *_args) -> None:
        rows = []
        for item, row in zip(self._waypoint_items, self._waypoint_rows):
            p = item.pos()
            rows.append([round(p.x(), 3), round(p.y(), 3), *row[2:]])  # speed (and hold)
        self.waypoints_moved.emit(rows)

    def _on_click(self, event) -> None:
        if not self.draw_mode or event.button() != QtCore.Qt.LeftButton:
            return
        p = self.getPlotItem().vb.mapSceneToView(event.scenePos())
        self.waypoint_added.emit(float(p.x()), float(p.y()))

    # ---- per frame ----------------------------------------------------------------------------
    def set_colour_by(self, mode: str) -> None:
        """Colour the points by ``mode`` (a key of :data:`COLOUR_MODES`); the colour bar shows
        the scale of the continuous ones."""
        if mode not in COLOUR_MODES:
            mode = "snr"
        self.colour_by = mode
        title, cmap, unit, span = COLOUR_MODES[mode]
        self.setTitle(f"Top view · points: {title}")
        self.colour_bar.setVisible(bool(cmap))
        if cmap:
            self.colour_bar.setColorMap(pg.colormap.get(cmap))
            self.colour_bar.setLevels(span)
            self.colour_bar.axis.setLabel(f"{title.split(' (')[0]} ({unit})")
        # the label colours' legend rows, shown while points are coloured by label
        self._rebuild_legend()

    def _point_brushes(
        self, frames: Sequence[FrameData]
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        xs, ys, keys = [], [], []
        for f in frames:
            c = f.cloud
            xs.append(c.x_m)
            ys.append(c.y_m)
            mode = self.colour_by
            if mode in self._map_arrays:
                value = {"snr": c.snr_db, "doppler": c.radial_velocity_mps, "height": c.z_m}[mode]
                lo, hi = COLOUR_MODES[mode][3]
                k = (np.asarray(value, dtype=float) - lo) / (hi - lo) * (N_SNR_COLOURS - 1)
                keys.append(np.clip(np.round(k), 0, N_SNR_COLOURS - 1).astype(int))
            elif mode == "track":
                pt = f.point_track
                ids = np.full(len(c), -1) if pt is None else np.asarray(pt)
                keys.append(np.where(ids >= 0, identity_index(np.maximum(ids, 0)), -1))
            else:
                keys.append(np.asarray(c.source))
        if not xs:
            return np.zeros(0), np.zeros(0), np.zeros(0, dtype=object)
        x, y, key = np.concatenate(xs), np.concatenate(ys), np.concatenate(keys)
        if self.colour_by in self._map_arrays:
            brushes = self._map_arrays[self.colour_by][key]
        elif self.colour_by == "track":
            brushes = self._track_array[key]  # -1: the last entry, grey
        else:
            # source >= 0 person, -1 clutter, -2 false alarm  ->  palette index 0, 1, 2
            brushes = self._label_array[label_key(key)]
        return x, y, brushes

    def show_frame(
        self,
        index: int,
        frames: Sequence[FrameData],
        tracking: TrackingResult | None = None,
    ) -> None:
        """Draw frame ``index`` with the points of the last ``persistence`` frames.

        ``frames`` is the cache (``frames[i].index == i``); ``tracking`` may cover fewer frames.
        """
        self.n_draws += 1
        if not frames or index < 0:
            self.points.setData([], [])
            self.truth_now.setData([], [])
            self._show_tracks(TrackFrame.empty(), None, index)
            return
        index = min(index, len(frames) - 1)
        window = frames[max(0, index - self.persistence + 1) : index + 1]
        x, y, brushes = self._point_brushes(window)
        self.points.setData(x=x, y=y, brush=brushes)
        self.last_n_points = len(x)
        truth = frames[index].truth_xy_m
        ok = np.isfinite(truth).all(axis=1) & self.has_truth
        pens = [self._truth_brushes[k % MAX_PERSONS] for k in np.flatnonzero(ok)]
        self.truth_now.setData(truth[ok, 0], truth[ok, 1], pen=pens)
        if tracking is not None and index < tracking.n_frames:
            self._show_tracks(tracking.frames[index], tracking, index)
        else:
            self._show_tracks(TrackFrame.empty(), None, index)
        self._show_reference(index)

    # ---- TI's tracks (reference layer) ---------------------------------------------------------
    def set_reference(self, layer) -> None:
        """TI's own tracks of a recording (:class:`app.replay.ReferenceLayer`), None: none."""
        self._reference = layer
        if layer is not None and len(layer.track_id):
            order = np.lexsort((layer.frame, layer.track_id))
            self._reference_sorted = (layer.track_id[order], layer.frame[order], layer.xy_m[order])
        else:
            self._reference_sorted = None
        self.legend_entry_visible("TI's tracks", self._reference_sorted is not None)
        self._show_reference(-1)

    @property
    def has_reference(self) -> bool:
        return self._reference_sorted is not None

    def set_show_reference(self, on: bool) -> None:
        self.show_reference = bool(on)

    def _show_reference(self, index: int) -> None:
        layer = self._reference
        if layer is None or not self.show_reference or index < 0:
            self.reference.setData([], [])
            self.reference_trails.setData([], [])
            for label in self._reference_labels:
                label.hide()
            return
        ids, xy = layer.at(index)
        self.reference.setData(xy[:, 0], xy[:, 1])
        assert self._reference_sorted is not None
        t = trails_polyline(*self._reference_sorted, index, self.trail_length, ids)
        self.reference_trails.setData(t[:, 0], t[:, 1], connect="finite")
        while len(self._reference_labels) < len(ids):
            label = pg.TextItem(color=REFERENCE_RGB, anchor=(1, 0))
            self.addItem(label)
            self._reference_labels.append(label)
        for k, label in enumerate(self._reference_labels):
            if k < len(ids):
                label.setText(f"TI {ids[k]}")
                label.setPos(float(xy[k, 0]) - 0.1, float(xy[k, 1]) - 0.1)
                label.show()
            else:
                label.hide()

    # ---- people count --------------------------------------------------------------------------
    def set_count(self, html: str | None) -> None:
        """The people count, large, in the top right corner (``None`` hides it)."""
        if not html:
            self.count_label.hide()
            return
        if html == self.count_label.text() and self.count_label.isVisibleTo(self):
            return  # unchanged: no re-layout on every draw
        self.count_label.setText(html)
        self.count_label.adjustSize()
        self._place_count()
        self.count_label.show()
        self.count_label.raise_()

    def _place_count(self) -> None:
        w = self.count_label.sizeHint().width()
        self.count_label.move(max(0, self.width() - w - 70), 30)

    def _show_tracks(self, tf: TrackFrame, tracking: TrackingResult | None, index: int) -> None:
        n = len(tf)
        self.last_n_tracks = n
        if n == 0:
            self.tracks.setData([], [])
            self.gates_confirmed.setData([], [])
            self.gates_tentative.setData([], [])
            self.trails.setData([], [])
            for item in self.identity_trails:
                item.setData([], [])
            self.estimate.setData([], [])
            for label in self._labels:
                label.hide()
            return
        psi = np.nan_to_num(tf.psi, nan=1.0)  # fast stage: ψ not known yet, drawn opaque
        level = np.clip(np.round(psi * (N_PSI_LEVELS - 1)), 0, N_PSI_LEVELS - 1).astype(int)
        colour = identity_index(tf.track_id)
        brushes = [self._identity_brushes[c][k] for c, k in zip(colour, level)]
        symbols = ["o" if c else "t" for c in tf.confirmed]
        self.tracks.setData(x=tf.xy_m[:, 0], y=tf.xy_m[:, 1], brush=brushes, symbol=symbols)
        conf = tf.confirmed
        c, g = tf.gate_center_xy_m, tf.gate_shape_xy_m2
        e = ellipse_polyline(c[conf], g[conf], 1.0)
        self.gates_confirmed.setData(e[:, 0], e[:, 1], connect="finite")
        e = ellipse_polyline(c[~conf], g[~conf], 1.0)
        self.gates_tentative.setData(e[:, 0], e[:, 1], connect="finite")
        if tracking is not None:
            live = tf.track_id[tf.confirmed]
            for c, item in enumerate(self.identity_trails):
                t = trails_polyline(
                    tracking.trail_id,
                    tracking.trail_t_index,
                    tracking.trail_xy_m,
                    index,
                    self.trail_length,
                    live[identity_index(live) == c],
                )
                item.setData(t[:, 0], t[:, 1], connect="finite")
            est = tracking.estimate_xy_m[index]
            if self.has_truth and np.isfinite(est).all():
                self.estimate.setData([est[0]], [est[1]])
            else:
                self.estimate.setData([], [])
        while len(self._labels) < n:
            label = pg.TextItem(color=(230, 230, 230), anchor=(0, 1))
            self.addItem(label)
            self._labels.append(label)
        for k, label in enumerate(self._labels):
            if k < n:
                label.setColor(identity_colour(int(tf.track_id[k])))
                psi = tf.psi[k]  # NaN: a tracker without ψ (gtrack)
                label.setText(f"{tf.track_id[k]}" + ("" if psi != psi else f" ψ={psi:.2f}"))
                label.setPos(float(tf.xy_m[k, 0]) + 0.1, float(tf.xy_m[k, 1]) + 0.1)
                label.show()
            else:
                label.hide()

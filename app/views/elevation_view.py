"""Elevation (side) view: the points of the last frames at their horizontal range and height,
with the scene's static reflectors. A 2-D view: pyqtgraph's 3-D items need PyOpenGL, which the
app does not depend on (docs/decisions/app-07-radar-views.md)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pyqtgraph as pg
from PySide6 import QtCore

from app.colours import LABEL_COLOURS, label_key
from app.data import FrameData


class ElevationView(pg.PlotWidget):
    """Height z against horizontal range ρ = √(x² + y²), points coloured by label."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setObjectName("elevationView")
        self.setLabel("bottom", "horizontal range ρ", units="m")
        self.setLabel("left", "height z", units="m")
        self.showGrid(x=True, y=True, alpha=0.2)
        self.addLegend(offset=(-5, 5))
        self._brushes = np.empty(3, dtype=object)
        self._brushes[:] = [
            pg.mkBrush(*LABEL_COLOURS[k], 220) for k in ("person", "clutter", "false alarm")
        ]
        self.ground = self.plot(pen=pg.mkPen((120, 120, 120), width=1, style=QtCore.Qt.DashLine))
        self.radar = pg.ScatterPlotItem(
            [0.0], [0.0], symbol="t1", size=14, brush=pg.mkBrush(230, 230, 230), name="radar"
        )
        self.addItem(self.radar)
        self.reflectors = pg.ScatterPlotItem(
            symbol="s", size=10, brush=pg.mkBrush(*LABEL_COLOURS["static"]), pen=None,
            name="static reflector",
        )  # fmt: skip
        self.addItem(self.reflectors)
        self.points = pg.ScatterPlotItem(size=6, pen=None)
        self.addItem(self.points)
        for key in ("person", "clutter", "false alarm"):
            sample = pg.ScatterPlotItem(brush=pg.mkBrush(*LABEL_COLOURS[key]), pen=None, size=8)
            self.getPlotItem().legend.addItem(sample, key)
        self.persistence = 5
        self.measures_elevation = False
        self.n_draws = 0
        self.set_scene(10.0, np.zeros((0, 3)), measures_elevation=False)

    def set_scene(
        self, max_range_m: float, reflectors_xyz_m: np.ndarray, *, measures_elevation: bool
    ) -> None:
        """Ground line out to ``max_range_m``; static reflectors ``(n, 3)``; whether the chain
        estimates elevation for this scene (otherwise every point has z = 0)."""
        self.measures_elevation = bool(measures_elevation)
        self.ground.setData([0.0, max_range_m], [0.0, 0.0])
        xyz = np.asarray(reflectors_xyz_m, dtype=float).reshape(-1, 3)
        self.reflectors.setData(np.hypot(xyz[:, 0], xyz[:, 1]), xyz[:, 2])
        self.setTitle(
            "Elevation view (side)"
            if measures_elevation
            else "Elevation view (side) · 2-D scene: no elevation processing, z = 0"
        )
        self.setXRange(0.0, max_range_m, padding=0.03)
        self.setYRange(-2.0, 3.0, padding=0.0)

    def show_frame(self, index: int, frames: Sequence[FrameData]) -> None:
        self.n_draws += 1
        if not frames or index < 0:
            self.points.setData([], [])
            return
        index = min(index, len(frames) - 1)
        window = frames[max(0, index - self.persistence + 1) : index + 1]
        x = np.concatenate([f.cloud.x_m for f in window])
        y = np.concatenate([f.cloud.y_m for f in window])
        z = np.concatenate([f.cloud.z_m for f in window])
        key = label_key(np.concatenate([f.cloud.source for f in window]))
        self.points.setData(x=np.hypot(x, y), y=z, brush=self._brushes[key])

"""Range-azimuth heat map: ``FrameData.ra_map_db`` against sin(azimuth) and range, with the
frame's detections on top. Items are created once; the map is drawn with fixed levels."""

from __future__ import annotations

import numpy as np
import pyqtgraph as pg
from PySide6 import QtCore

from app.data import FrameData
from core.config import RadarConfig

LEVEL_SPAN_DB = 50.0
#: azimuth ticks (degrees) drawn on the sin(azimuth) axis
TICKS_DEG = (-90, -60, -45, -30, -15, 0, 15, 30, 45, 60, 90)


class RangeAzimuthView(pg.GraphicsLayoutWidget):
    """Heat map of the range-azimuth map (angle axis uniform in ``u = sin az``, labelled in
    degrees); detections drawn at their measured azimuth and range."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setObjectName("rangeAzimuthView")
        self.plot = self.addPlot(row=0, col=0)
        self.plot.setLabel("bottom", "azimuth (axis uniform in sin az)", units="°")
        self.plot.setLabel("left", "range", units="m")
        self.plot.setTitle("Range-azimuth map (dB, moving reflectors: clutter removed)")
        ticks = [(float(np.sin(np.deg2rad(d))), f"{d}") for d in TICKS_DEG]
        self.plot.getAxis("bottom").setTicks([ticks])
        self.image = pg.ImageItem(axisOrder="row-major")
        self.plot.addItem(self.image)
        self.colorbar = pg.ColorBarItem(
            values=(0.0, LEVEL_SPAN_DB), colorMap=pg.colormap.get("inferno"), width=12
        )
        self.colorbar.setImageItem(self.image, insert_in=self.plot)
        self.points = pg.ScatterPlotItem(
            size=8, symbol="o", pen=pg.mkPen((120, 255, 120), width=1.2), brush=None
        )
        self.plot.addItem(self.points)
        self.message = pg.TextItem("waiting for frames …", color="w", anchor=(0.5, 0.5))
        self.plot.addItem(self.message)
        self._radar: RadarConfig | None = None
        self._levels: tuple[float, float] | None = None
        self._n_angle = 0
        self._max_range_m = 10.0
        self.n_draws = 0

    def set_radar(self, radar: RadarConfig, max_range_m: float | None = None) -> None:
        self._radar = radar
        self._levels = None
        self._n_angle = 0
        self._max_range_m = float(max_range_m or radar.max_range_m)
        self.plot.setXRange(-1.0, 1.0, padding=0.02)
        self.plot.setYRange(0.0, self._max_range_m, padding=0.02)
        self.message.setPos(0.0, self._max_range_m / 2)

    def _set_rect(self, n_range: int, n_angle: int) -> None:
        dr = self._radar.range_resolution_m
        du = 2.0 / n_angle
        # angle index i at u = 2 (i - N/2) / N; range bin k at k dR; the image spans bin edges
        self.image.setRect(QtCore.QRectF(-1.0 - du / 2, -dr / 2, 2.0, n_range * dr))
        self._n_angle = n_angle

    def show_frame(self, frame: FrameData | None) -> None:
        self.n_draws += 1
        ra = None if frame is None else frame.ra_map_db
        if ra is None or self._radar is None:
            self.image.clear()
            self.points.setData([], [])
            self.message.setText(
                "waiting for frames …"
                if frame is None
                else "no range-azimuth map (this fidelity level has no Doppler cube)"
            )
            self.message.show()
            return
        self.message.hide()
        if self._levels is None:
            floor = float(np.median(ra))
            self._levels = (floor - 3.0, floor - 3.0 + LEVEL_SPAN_DB)
            self.colorbar.setLevels(self._levels)
        self.image.setImage(ra, autoLevels=False, levels=self._levels)
        if ra.shape[1] != self._n_angle:
            self._set_rect(*ra.shape)
        c = frame.cloud
        self.points.setData(np.sin(c.azimuth_rad) * np.cos(c.elevation_rad), c.range_m)

"""Range-azimuth heat map: ``FrameData.ra_map_db`` against range and sin(azimuth), with the
frame's detections on top. Range runs along the horizontal axis (the views sit in a wide,
low dock, and range has the most bins). Items are created once; levels are fixed per radar."""

from __future__ import annotations

import numpy as np
import pyqtgraph as pg
from PySide6 import QtCore

from app.data import FrameData
from core.config import RadarConfig

LEVEL_SPAN_DB = 50.0
#: azimuth ticks (degrees) drawn on the sin(azimuth) axis
TICKS_DEG = (-60, -30, 0, 30, 60)


class RangeAzimuthView(pg.GraphicsLayoutWidget):
    """Heat map of the range-azimuth map (angle axis uniform in ``u = sin az``, labelled in
    degrees); detections drawn at their measured azimuth and range."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setObjectName("rangeAzimuthView")
        self.plot = self.addPlot(row=0, col=0)
        self.plot.setLabel("bottom", "range", units="m")
        self.plot.setLabel("left", "azimuth", units="°")
        self.plot.setTitle("Range-azimuth map (dB; azimuth uniform in sin az; clutter removed)")
        ticks = [(float(np.sin(np.deg2rad(d))), f"{d}") for d in TICKS_DEG]
        self.plot.getAxis("left").setTicks([ticks])
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
        self.plot.setYRange(-1.0, 1.0, padding=0.02)
        self.plot.setXRange(0.0, self._max_range_m, padding=0.02)
        self.message.setPos(self._max_range_m / 2, 0.0)

    def _set_rect(self, n_range: int, n_angle: int) -> None:
        dr = self._radar.range_resolution_m
        du = 2.0 / n_angle
        # range bin k at k dR; angle index i at u = 2 (i - N/2) / N; the image spans bin edges
        self.image.setRect(QtCore.QRectF(-dr / 2, -1.0 - du / 2, n_range * dr, 2.0))
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
        # image rows are the vertical axis: [angle index, range bin]
        self.image.setImage(ra.T, autoLevels=False, levels=self._levels)
        if ra.shape[1] != self._n_angle:
            self._set_rect(*ra.shape)
        c = frame.cloud
        self.points.setData(c.range_m, np.sin(c.azimuth_rad) * np.cos(c.elevation_rad))

"""Range-Doppler heatmap: dB with fixed levels, axes in m and m/s, CFAR detections marked."""

from __future__ import annotations

import numpy as np
import pyqtgraph as pg
from PySide6 import QtCore

from app.data import FrameData
from app.views.axis_cache import cache_axes
from core.config import RadarConfig

#: Fixed colour levels in dB relative to the map's noise floor estimate are not used: the map is
#: drawn in absolute dB with levels fixed per radar (a median-based floor would flicker).
DEFAULT_LEVEL_SPAN_DB = 60.0


class RangeDopplerView(pg.GraphicsLayoutWidget):
    """Heatmap of ``FrameData.rd_map_db`` with detections; items created once."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setObjectName("rangeDopplerView")
        self.plot = self.addPlot(row=0, col=0)
        self.plot.setLabel("bottom", "radial velocity", units="m/s")
        self.plot.setLabel("left", "range", units="m")
        # no title: its width was the plot's minimum width and pushed the colour bar out of a
        # narrow view at 150 %; the axes and the colour bar's "dB" say what it is
        self.setToolTip("range-Doppler map, dB (CFAR detections: red squares)")
        self.image = pg.ImageItem(axisOrder="row-major")
        self.plot.addItem(self.image)
        self.colorbar = pg.ColorBarItem(
            values=(0.0, DEFAULT_LEVEL_SPAN_DB),
            colorMap=pg.colormap.get("viridis"),
            width=12,
            label="dB",
        )
        # its own column of the layout (not inside the plot): its tick labels get their width
        self.colorbar.setImageItem(self.image)
        self.addItem(self.colorbar, row=0, col=1)
        self.detections = pg.ScatterPlotItem(
            size=9, symbol="s", pen=pg.mkPen("r", width=1.5), brush=None, pxMode=True
        )
        self.plot.addItem(self.detections)
        self.message = pg.TextItem("waiting for frames …", color="w", anchor=(0.5, 0.5))
        self.plot.addItem(self.message)
        self._radar: RadarConfig | None = None
        self._levels: tuple[float, float] | None = None
        self.n_draws = 0
        cache_axes(self.plot, self.colorbar)

    def set_radar(self, radar: RadarConfig) -> None:
        """Axes from the radar: range bins → m, Doppler bins → m/s (zero velocity centred)."""
        self._radar = radar
        self._levels = None
        dr = radar.range_resolution_m
        dv = radar.velocity_resolution_mps
        n_d = radar.n_loops
        # bin centres: range k*dr, velocity (j - n_d/2)*dv; the image spans the bin edges
        self._rect = QtCore.QRectF((-n_d / 2 - 0.5) * dv, -0.5 * dr, n_d * dv, radar.n_samples * dr)
        self.image.setRect(self._rect)
        self.plot.setXRange(self._rect.left(), self._rect.right(), padding=0)
        self.plot.setYRange(0.0, radar.n_samples * dr, padding=0)
        self.message.setPos(0.0, radar.n_samples * dr / 2)

    def set_levels(self, low_db: float, high_db: float) -> None:
        self._levels = (float(low_db), float(high_db))
        self.colorbar.setLevels(self._levels)

    def show_frame(self, frame: FrameData | None) -> None:
        """Draw one frame (``None`` clears)."""
        self.n_draws += 1
        if frame is None or frame.rd_map_db is None or self._radar is None:
            self.image.clear()
            self.detections.setData([], [])
            self.message.setText(
                "waiting for frames …" if frame is None else "range-Doppler map not kept"
            )
            self.message.show()
            return
        self.message.hide()
        rd = frame.rd_map_db
        if self._levels is None:
            # fixed levels, chosen once per radar from the first map: noise floor .. +span
            floor = float(np.median(rd))
            self.set_levels(floor - 5.0, floor - 5.0 + DEFAULT_LEVEL_SPAN_DB)
        self.image.setImage(rd, autoLevels=False, levels=self._levels)
        self.image.setRect(self._rect)
        det = np.asarray(frame.detections)
        if det.size:
            radar = self._radar
            r = det[:, 0] * radar.range_resolution_m
            v = (det[:, 1] - radar.n_loops // 2) * radar.velocity_resolution_mps
            self.detections.setData(v, r)
        else:
            self.detections.setData([], [])

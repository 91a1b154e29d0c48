"""Range profile of one Doppler column of the range-Doppler map with the CFAR threshold the
detector applied to it, and the column's detections marked."""

from __future__ import annotations

import numpy as np
import pyqtgraph as pg
from PySide6 import QtCore, QtWidgets

from app.data import FrameData
from core.config import RadarConfig


class RangeProfileView(QtWidgets.QWidget):
    """Power against range at one Doppler bin (chosen, or that of the strongest detection),
    the two-stage CFAR threshold (``FrameData.cfar_threshold_db``) and the detections."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setObjectName("rangeProfileView")
        bar = QtWidgets.QHBoxLayout()
        bar.addWidget(QtWidgets.QLabel("Doppler bin"))
        self.bin_spin = QtWidgets.QSpinBox()
        self.bin_spin.setObjectName("dopplerBinSpin")
        self.bin_spin.setSpecialValueText("strongest detection")
        self.bin_spin.setRange(-17, 15)  # set_radar: -n_loops/2 - 1 (auto) .. n_loops/2 - 1
        self.bin_spin.setValue(-17)
        self.bin_spin.setToolTip(
            "Doppler bin of the column drawn (0 = zero velocity); lowest value: the column of"
            " the frame's strongest detection"
        )
        bar.addWidget(self.bin_spin)
        self.column_label = QtWidgets.QLabel()
        bar.addWidget(self.column_label, 1)
        self.plot = pg.PlotWidget()
        self.plot.setLabel("bottom", "range", units="m")
        self.plot.setLabel("left", "power (dB)")
        self.plot.setTitle("Range profile with the CFAR threshold")
        self.plot.showGrid(x=True, y=True, alpha=0.2)
        self.plot.addLegend(offset=(5, 5))  # top left: below the minimum range, rarely data
        self.profile = self.plot.plot(pen=pg.mkPen((230, 230, 230), width=1.2), name="power")
        self.threshold = self.plot.plot(
            pen=pg.mkPen((255, 80, 80), width=1.5, style=QtCore.Qt.DashLine),
            connect="finite",
            name="CFAR threshold",
        )
        self.detections = pg.ScatterPlotItem(
            size=9, symbol="o", pen=pg.mkPen((80, 255, 120), width=1.5), brush=None,
            name="detections",
        )  # fmt: skip
        self.plot.addItem(self.detections)  # named: the legend lists it
        lay = QtWidgets.QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.addLayout(bar)
        lay.addWidget(self.plot, 1)
        self._radar: RadarConfig | None = None
        self._frame: FrameData | None = None
        self.column = None  # Doppler index drawn last
        self.bin_spin.valueChanged.connect(lambda _v: self.show_frame(self._frame))
        self.n_draws = 0

    def set_radar(self, radar: RadarConfig, max_range_m: float | None = None) -> None:
        self._radar = radar
        half = radar.n_loops // 2
        self.bin_spin.blockSignals(True)
        self.bin_spin.setRange(-half - 1, radar.n_loops - half - 1)
        self.bin_spin.setValue(-half - 1)
        self.bin_spin.blockSignals(False)
        self.plot.setXRange(0.0, float(max_range_m or radar.max_range_m), padding=0.02)

    def _column(self, frame: FrameData) -> int:
        half = self._radar.n_loops // 2
        if self.bin_spin.value() >= -half:
            return self.bin_spin.value() + half
        det = np.asarray(frame.detections)
        if len(det):
            power = frame.rd_map_db[det[:, 0], det[:, 1]]
            return int(det[int(np.argmax(power)), 1])
        return half + 1  # no detection: the first bin beside zero velocity

    def show_frame(self, frame: FrameData | None) -> None:
        self.n_draws += 1
        self._frame = frame
        if frame is None or frame.rd_map_db is None or self._radar is None:
            for item in (self.profile, self.threshold, self.detections):
                item.setData([], [])
            self.column = None
            self.column_label.setText("no range-Doppler map")
            return
        radar = self._radar
        j = self._column(frame)
        self.column = j
        r = np.arange(frame.rd_map_db.shape[0]) * radar.range_resolution_m
        self.profile.setData(r, frame.rd_map_db[:, j])
        if frame.cfar_threshold_db is not None:
            self.threshold.setData(r, frame.cfar_threshold_db[:, j], connect="finite")
        else:
            self.threshold.setData([], [])
        det = np.asarray(frame.detections)
        mine = det[det[:, 1] == j] if len(det) else det
        self.detections.setData(
            mine[:, 0] * radar.range_resolution_m, frame.rd_map_db[mine[:, 0], j]
        )
        d = j - radar.n_loops // 2
        self.column_label.setText(
            f"  column: Doppler bin {d:+d} ({d * radar.velocity_resolution_mps:+.2f} m/s)"
        )

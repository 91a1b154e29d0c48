"""ψ (existence probability) of every track against time, with the thresholds, and the
running metrics (loss, RMSE, OSPA) against time; without ground truth (a recording) the lower
plot shows what a recording has instead: the confirmed tracks a frame against TI's own track
count, and the text line the frame's points."""

from __future__ import annotations

import numpy as np
import pyqtgraph as pg
from PySide6 import QtCore

from app.data import TrackingResult
from app.views.axis_cache import cache_axes


class PsiView(pg.GraphicsLayoutWidget):
    """Top: ψ per track (tentative yellow, confirmed green); bottom: running loss and OSPA."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setObjectName("psiView")
        self._has_truth = True
        self.psi_plot = self.addPlot(row=0, col=0)
        self.psi_plot.setTitle("existence probability ψ", size="9pt")
        self.psi_plot.setLabel("left", "ψ")
        self.psi_plot.setLabel("bottom", "time", units="s")
        self.psi_plot.setYRange(-0.02, 1.08, padding=0)
        self.psi_plot.showGrid(y=True, alpha=0.2)
        self.psi_all = self.psi_plot.plot(pen=pg.mkPen((240, 220, 40, 120), width=1))
        self.psi_confirmed = self.psi_plot.plot(pen=pg.mkPen((0, 220, 90), width=2))
        self.confirm_line = pg.InfiniteLine(
            angle=0,
            pen=pg.mkPen((0, 220, 90), style=QtCore.Qt.DashLine),
            label="confirm {value:.2f}",
            # inside the plot at the left, below its line (between the two thresholds): clear of
            # the axis, the title and the other label
            labelOpts={"position": 0.02, "color": (0, 220, 90), "anchors": [(0, 0), (0, 0)]},
        )
        self.delete_line = pg.InfiniteLine(
            angle=0,
            pen=pg.mkPen((255, 80, 80), style=QtCore.Qt.DashLine),
            label="delete {value:.2f}",
            labelOpts={"position": 0.02, "color": (255, 80, 80), "anchors": [(0, 1), (0, 1)]},
        )
        self.psi_plot.addItem(self.confirm_line)
        self.psi_plot.addItem(self.delete_line)
        self.cursor = pg.InfiniteLine(angle=90, pen=pg.mkPen((200, 200, 200), width=1))
        self.psi_plot.addItem(self.cursor)

        self.metric_plot = self.addPlot(row=1, col=0)
        self.metric_plot.setTitle("running metrics", size="9pt")
        self.metric_plot.setLabel("bottom", "time", units="s")
        self.metric_plot.setLabel("left", "RMSE, OSPA", units="m")
        # one row in the top right corner, translucent: the curves start at the left
        self.metric_plot.addLegend(
            offset=(-5, 5), colCount=2, brush=pg.mkBrush(0, 0, 0, 120), labelTextSize="8pt"
        )
        self.metric_plot.setXLink(self.psi_plot)
        self.rmse_curve = self.metric_plot.plot(pen=pg.mkPen((255, 140, 0), width=2), name="RMSE")
        self.ospa_curve = self.metric_plot.plot(pen=pg.mkPen((60, 140, 255), width=1), name="OSPA")
        # without ground truth: the track counts (step curves)
        self.count_curve = self.metric_plot.plot(
            pen=pg.mkPen((0, 220, 90), width=2), stepMode="right", name="confirmed tracks"
        )
        self.ti_curve = self.metric_plot.plot(
            pen=pg.mkPen((255, 60, 255), width=1.5, style=QtCore.Qt.DashLine),
            stepMode="right",
            name="TI's tracks",
        )
        self._truth_face: bool | None = None
        self._points = np.zeros(0, dtype=np.int64)
        self._ti_count: np.ndarray | None = None
        self._confirmed = np.zeros(0, dtype=np.int64)
        self.cursor2 = pg.InfiniteLine(angle=90, pen=pg.mkPen((200, 200, 200), width=1))
        self.metric_plot.addItem(self.cursor2)
        self.metric_text = pg.LabelItem(justify="left", color=(230, 230, 230), size="9pt")
        self.addItem(self.metric_text, row=2, col=0)
        self.ci.layout.setRowStretchFactor(0, 3)
        self.ci.layout.setRowStretchFactor(1, 2)
        self.set_thresholds(0.9, 0.1)
        self._frame_period_s = 0.08
        self._result: TrackingResult | None = None
        self._metric_text = ""
        self.n_draws = 0
        self._set_face()
        cache_axes(self.psi_plot, self.metric_plot)

    @property
    def has_truth(self) -> bool:
        """False for a recording without ground truth: no loss, RMSE or OSPA drawn, the track
        counts instead."""
        return self._has_truth

    @has_truth.setter
    def has_truth(self, on: bool) -> None:
        self._has_truth = bool(on)
        self._set_face()

    def set_recording_counts(self, points: np.ndarray | None, ti_count: np.ndarray | None) -> None:
        """A recording's points a frame and TI's track count a frame (None: not a recording, or
        no TI tracks), drawn while there is no ground truth."""
        self._points = np.zeros(0, dtype=np.int64) if points is None else np.asarray(points)
        self._ti_count = None if ti_count is None else np.asarray(ti_count)
        self._truth_face = None  # the legend follows whether TI's counts are there
        self._set_face()

    def _set_face(self) -> None:
        """The lower plot's face: running metrics with ground truth, track counts without."""
        truth = bool(self.has_truth)
        if truth == self._truth_face:
            return
        self._truth_face = truth
        legend = self.metric_plot.legend
        legend.clear()
        if truth:
            self.metric_plot.setTitle("running metrics", size="9pt")
            self.metric_plot.setLabel("left", "RMSE, OSPA", units="m")
            legend.addItem(self.rmse_curve, "RMSE")
            legend.addItem(self.ospa_curve, "OSPA")
            self.count_curve.setData([], [])
            self.ti_curve.setData([], [])
        else:
            self.metric_plot.setTitle("tracks a frame (no ground truth)", size="9pt")
            self.metric_plot.setLabel("left", "tracks", units="")
            legend.addItem(self.count_curve, "confirmed tracks")
            if self._ti_count is not None:
                legend.addItem(self.ti_curve, "TI's tracks")
            self.rmse_curve.setData([], [])
            self.ospa_curve.setData([], [])

    def set_thresholds(self, confirm: float, delete: float) -> None:
        self.confirm_line.setValue(confirm)
        self.delete_line.setValue(delete)

    def set_result(self, result: TrackingResult | None, frame_period_s: float) -> None:
        """Redraw the curves of a whole tracker run."""
        self._frame_period_s = frame_period_s
        self._result = result
        self._set_face()
        if result is None or result.n_frames == 0:
            for c in (self.psi_all, self.psi_confirmed, self.rmse_curve, self.ospa_curve,
                      self.count_curve, self.ti_curve):  # fmt: skip
                c.setData([], [])
            self._confirmed = np.zeros(0, dtype=np.int64)
            return
        self.psi_all.setData(result.psi_t_s, result.psi_value, connect="finite")
        self.psi_confirmed.setData(
            result.psi_confirmed_t_s, result.psi_confirmed_value, connect="finite"
        )
        t = np.arange(result.n_frames) * frame_period_s
        if self.has_truth:
            self.rmse_curve.setData(t, result.running_rmse_m, connect="finite")
            self.ospa_curve.setData(t, result.ospa_m, connect="finite")
        else:
            n = result.n_frames
            self._confirmed = np.fromiter(
                (np.count_nonzero(f.confirmed) for f in result.frames), dtype=np.int64, count=n
            )
            edges = np.arange(n) * frame_period_s  # each count from its frame to the next
            self.count_curve.setData(edges, self._confirmed)
            ti = self._ti_count
            if ti is not None and len(ti) >= n:
                self.ti_curve.setData(edges, ti[:n])
            else:
                self.ti_curve.setData([], [])
            top = max(
                int(self._confirmed.max(initial=0)), 0 if ti is None else int(ti.max(initial=0))
            )
            self.metric_plot.setYRange(0.0, max(top, 1) + 0.5, padding=0)
        self.psi_plot.setXRange(0.0, max(t[-1], frame_period_s), padding=0.02)

    def set_frame(self, index: int) -> None:
        self.n_draws += 1
        t = index * self._frame_period_s
        self.cursor.setValue(t)
        self.cursor2.setValue(t)
        r = self._result
        if not self.has_truth:
            text = f"t = {t:.2f} s"
            if 0 <= index < len(self._points):
                text += f" · {int(self._points[index])} points"
            if 0 <= index < len(self._confirmed):
                text += f" · confirmed tracks {int(self._confirmed[index])}"
            if self._ti_count is not None and 0 <= index < len(self._ti_count):
                text += f" · TI {int(self._ti_count[index])}"
            text += "<br>no ground truth: no loss, RMSE or OSPA"
        elif r is None or index >= r.n_frames:
            text = "running loss –<br>RMSE – · OSPA –"
        else:
            rmse = r.running_rmse_m[index]
            rmse_t = "–" if rmse != rmse else f"{rmse:.3f} m"
            text = (
                f"t = {t:.2f} s · running loss L = {r.running_loss[index]:.3g} m²<br>"
                f"RMSE {rmse_t} · OSPA {r.ospa_m[index]:.3f} m"
            )
        if text != self._metric_text:
            self._metric_text = text
            self.metric_text.setText(text)

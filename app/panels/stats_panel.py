"""Statistics panel: the people count (RadarTune's confirmed tracks, TI's tracks and the head
count when the data has them) and per-frame figures: points, tracks, frame time and period,
dropped frames, and the link's frame rate while a sensor is connected."""

from __future__ import annotations

import math
from dataclasses import dataclass

from PySide6 import QtWidgets


@dataclass(frozen=True, slots=True, kw_only=True)
class FrameStats:
    """What the statistics panel shows for one frame (-1 or NaN: not known)."""

    index: int
    n_frames: int
    t_s: float
    frame_period_s: float
    n_points: int
    mean_points: float
    n_confirmed: int
    n_tracks: int
    ti_count: int = -1
    head_count: int = -1
    #: persons present in the frame's ground truth (a simulation), -1 without truth
    truth_count: int = -1
    dropped_frames: int = -1
    link_fps: float = float("nan")
    max_velocity_mps: float = float("nan")

    def count_html(self) -> str:
        """The people count as the top view shows it, large: RadarTune's confirmed tracks, and
        beside it TI's count and the head count where known."""
        noun = "person" if self.n_confirmed == 1 else "people"
        parts = [f"<span style='font-size:28px; font-weight:bold'>{self.n_confirmed}</span>"
                 f"<span style='font-size:13px'> {noun}</span>"]  # fmt: skip
        extra = []
        if self.truth_count >= 0:
            extra.append(f"truth {self.truth_count}")
        if self.ti_count >= 0:
            extra.append(f"TI {self.ti_count}")
        if self.head_count >= 0:
            extra.append(f"head count {self.head_count}")
        if extra:
            parts.append(f"<span style='font-size:14px'> · {' · '.join(extra)}</span>")
        return "".join(parts)

    def rows(self) -> list[tuple[str, str]]:
        def known(v: float, fmt: str) -> str:
            return fmt.format(v) if math.isfinite(v) and v >= 0 else "–"

        return [
            ("people (confirmed tracks)", str(self.n_confirmed)),
            ("TI's tracks", str(self.ti_count) if self.ti_count >= 0 else "–"),
            ("head count", str(self.head_count) if self.head_count >= 0 else "–"),
            ("persons in the truth", str(self.truth_count) if self.truth_count >= 0 else "–"),
            ("frame", f"{self.index + 1} / {self.n_frames}"),
            ("frame time", known(self.t_s, "{:.2f} s")),
            ("frame period", known(self.frame_period_s * 1e3, "{:.1f} ms")),
            ("points this frame", str(self.n_points)),
            ("points a frame (mean)", known(self.mean_points, "{:.1f}")),
            ("tracks (confirmed / all)", f"{self.n_confirmed} / {self.n_tracks}"),
            ("dropped frames", str(self.dropped_frames) if self.dropped_frames >= 0 else "–"),
            ("link rate", known(self.link_fps, "{:.1f} frames/s")),
            ("max velocity", known(self.max_velocity_mps, "{:.2f} m/s")),
        ]


class StatsPanel(QtWidgets.QWidget):
    """The people count and the frame statistics; :meth:`show_stats`."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setObjectName("statsPanel")
        outer = QtWidgets.QVBoxLayout(self)
        self.count = QtWidgets.QLabel()
        self.count.setObjectName("statsCount")
        outer.addWidget(self.count)
        self.warning = QtWidgets.QLabel()
        self.warning.setObjectName("statsWarning")
        self.warning.setWordWrap(True)
        self.warning.setStyleSheet("color: #e0a000; font-weight: bold")
        self.warning.hide()
        outer.addWidget(self.warning)
        box = QtWidgets.QGroupBox("This frame")
        self.form = QtWidgets.QFormLayout(box)
        self.values: dict[str, QtWidgets.QLabel] = {}
        outer.addWidget(box)
        outer.addStretch(1)
        self.stats: FrameStats | None = None

    def show_stats(self, stats: FrameStats) -> None:
        if stats == self.stats:
            return
        self.stats = stats
        self.count.setText(stats.count_html())
        for label, value in stats.rows():
            if label not in self.values:
                widget = QtWidgets.QLabel()
                self.form.addRow(label, widget)
                self.values[label] = widget
            if self.values[label].text() != value:
                self.values[label].setText(value)

    def set_warning(self, text: str) -> None:
        self.warning.setText(text)
        self.warning.setVisible(bool(text))

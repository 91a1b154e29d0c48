"""Micro-Doppler spectrogram of the selected person: the Doppler spectrum at that person's range
(``FrameData.person_doppler_db``) against time, up to the frame shown."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pyqtgraph as pg
from PySide6 import QtCore

from app.colours import hex_colour
from app.data import FrameData
from app.person_colours import person_colour
from core.config import RadarConfig

LEVEL_SPAN_DB = 45.0


class MicroDopplerView(pg.GraphicsLayoutWidget):
    """Image of Doppler (m/s) against time (s) for one person; a line marks the frame shown.

    The columns come ready from the worker (one per frame); the view only copies them into its
    image buffer as frames arrive.
    """

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setObjectName("microDopplerView")
        self.plot = self.addPlot(row=0, col=0)
        self.plot.setLabel("bottom", "time", units="s")
        self.plot.setLabel("left", "radial velocity", units="m/s")
        self.image = pg.ImageItem(axisOrder="row-major")
        self.plot.addItem(self.image)
        self.colorbar = pg.ColorBarItem(
            values=(0.0, LEVEL_SPAN_DB), colorMap=pg.colormap.get("viridis"), width=12
        )
        self.colorbar.setImageItem(self.image, insert_in=self.plot)
        self.cursor = pg.InfiniteLine(angle=90, pen=pg.mkPen((255, 255, 255, 160), width=1))
        self.plot.addItem(self.cursor)
        self.message = pg.TextItem("waiting for frames …", color="w", anchor=(0.5, 0.5))
        self.plot.addItem(self.message)
        self._radar: RadarConfig | None = None
        self._period_s = 0.08
        self.person = 0
        self._buffer = np.zeros((0, 0), dtype=np.float32)  # [Doppler bin, frame]
        self._filled = 0
        self._levels: tuple[float, float] | None = None
        self.n_draws = 0
        self._set_title()

    def _set_title(self) -> None:
        c = hex_colour(person_colour(self.person))
        self.plot.setTitle(
            f"Micro-Doppler at the range of <span style='color:{c}'>person {self.person + 1}</span>"
            " (dB)"
        )

    def set_radar(self, radar: RadarConfig, frame_period_s: float) -> None:
        self._radar = radar
        self._period_s = float(frame_period_s)
        self.reset()

    def set_person(self, person: int) -> None:
        if person != self.person:
            self.person = int(person)
            self._set_title()
            self.reset()

    def reset(self) -> None:
        """Forget the columns (new scene, other person); they are copied again on the next draw."""
        self._buffer = np.zeros((0, 0), dtype=np.float32)
        self._filled = 0
        self._levels = None
        self.image.clear()

    def show_frame(self, index: int, frames: Sequence[FrameData]) -> None:
        self.n_draws += 1
        if self._radar is None or not frames:
            self.message.setText("waiting for frames …")
            self.message.show()
            return
        n_d = self._radar.n_loops
        if self._buffer.shape[1] < len(frames) or self._buffer.shape[0] != n_d:
            grown = np.full((n_d, max(len(frames), 2 * self._buffer.shape[1])), np.nan, np.float32)
            if self._buffer.shape[0] == n_d:
                grown[:, : self._filled] = self._buffer[:, : self._filled]
            else:
                self._filled = 0
            self._buffer = grown
        for k in range(self._filled, len(frames)):
            col = frames[k].person_doppler_db
            if col is not None and self.person < len(col):
                self._buffer[:, k] = col[self.person]
        self._filled = len(frames)
        shown = self._buffer[:, : self._filled]
        if not np.isfinite(shown).any():
            self.message.setText(
                f"no range-Doppler maps, or person {self.person + 1} is not in the scene"
            )
            self.message.show()
            self.image.clear()
            return
        self.message.hide()
        if self._levels is None:
            floor = float(np.nanmedian(shown))
            self._levels = (floor, floor + LEVEL_SPAN_DB)
            self.colorbar.setLevels(self._levels)
        self.image.setImage(np.nan_to_num(shown, nan=self._levels[0]), autoLevels=False,
                            levels=self._levels)  # fmt: skip
        dv = self._radar.velocity_resolution_mps
        t = self._period_s
        # frame k at t = k T, Doppler index j at (j - n_d/2) dv; the image spans bin edges
        self.image.setRect(QtCore.QRectF(-t / 2, (-n_d / 2 - 0.5) * dv, self._filled * t, n_d * dv))
        self.cursor.setPos(index * t)

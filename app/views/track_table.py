"""Track table: every live track of the frame shown, one row each, following the playback."""

from __future__ import annotations

import math

import numpy as np
from PySide6 import QtGui, QtWidgets

from app.colours import identity_colour
from app.data import TrackFrame

COLUMNS = (
    ("ID", "track identity (colour as in the top view)"),
    ("status", "confirmed or tentative"),
    ("ψ", "existence probability"),
    ("x (m)", "estimated position x"),
    ("y (m)", "estimated position y"),
    ("vx (m/s)", "estimated velocity x"),
    ("vy (m/s)", "estimated velocity y"),
    ("σx, σy (m)", "standard deviations of the position estimate, √P_xx and √P_yy"),
    ("age (s)", "time since the track was born"),
    (
        "assoc. points",
        "measurements in the track's gate this frame, those of its (J)IPDA update"
        " (0: born this frame or none gated; – : not reported)",
    ),
    (
        "last NIS",
        "normalised innovation squared of this frame's update, ε = ν̃ᵀ S⁻¹ ν̃ with ν̃ = Σ βᵢ νᵢ"
        " (– : no measurement gated, born this frame, or not reported)",
    ),
)


def _num(v: float, fmt: str) -> str:
    return "–" if v is None or not math.isfinite(v) else format(v, fmt)


def track_rows(tf: TrackFrame, index: int, frame_period_s: float) -> list[list[str]]:
    """The table's text, row by row (tracks in the tracker's order)."""
    n = len(tf)
    vel = tf.velocity_xy_mps if tf.velocity_xy_mps is not None else np.full((n, 2), np.nan)
    sig = tf.sigma_xy_m if tf.sigma_xy_m is not None else np.full((n, 2), np.nan)
    birth = tf.birth_frame if tf.birth_frame is not None else np.full(n, -1)
    assoc = tf.n_associated if tf.n_associated is not None else np.full(n, -1)
    nis = tf.nis if tf.nis is not None else np.full(n, np.nan)
    rows = []
    for k in range(n):
        age = (index - int(birth[k])) * frame_period_s if birth[k] >= 0 else math.nan
        rows.append(
            [
                str(int(tf.track_id[k])),
                "confirmed" if tf.confirmed[k] else "tentative",
                _num(float(tf.psi[k]), ".3f"),
                _num(float(tf.xy_m[k, 0]), ".2f"),
                _num(float(tf.xy_m[k, 1]), ".2f"),
                _num(float(vel[k, 0]), ".2f"),
                _num(float(vel[k, 1]), ".2f"),
                f"{_num(float(sig[k, 0]), '.3f')}, {_num(float(sig[k, 1]), '.3f')}",
                _num(age, ".2f"),
                str(int(assoc[k])) if assoc[k] >= 0 else "–",
                _num(float(nis[k]), ".2f"),
            ]
        )
    return rows


class TrackTable(QtWidgets.QTableWidget):
    """Rows = the tracks of :class:`TrackFrame` at the frame shown; the ID cell carries the
    track's identity colour."""

    def __init__(self, parent=None) -> None:
        super().__init__(0, len(COLUMNS), parent)
        self.setObjectName("trackTable")
        self.setHorizontalHeaderLabels([c for c, _ in COLUMNS])
        for i, (_c, tip) in enumerate(COLUMNS):
            self.horizontalHeaderItem(i).setToolTip(tip)
        self.setEditTriggers(QtWidgets.QAbstractItemView.NoEditTriggers)
        self.setSelectionBehavior(QtWidgets.QAbstractItemView.SelectRows)
        self.verticalHeader().setVisible(False)
        self.horizontalHeader().setSectionResizeMode(QtWidgets.QHeaderView.ResizeToContents)
        self.setAlternatingRowColors(True)
        self.frame_period_s = 0.08
        self.n_draws = 0

    def show_tracks(self, tf: TrackFrame | None, index: int) -> None:
        self.n_draws += 1
        rows = [] if tf is None else track_rows(tf, index, self.frame_period_s)
        self.setUpdatesEnabled(False)
        self.setRowCount(len(rows))
        for r, row in enumerate(rows):
            for c, text in enumerate(row):
                item = self.item(r, c)
                if item is None:
                    item = QtWidgets.QTableWidgetItem()
                    self.setItem(r, c, item)
                item.setText(text)
            swatch = QtGui.QColor(*identity_colour(int(tf.track_id[r])))
            self.item(r, 0).setBackground(swatch)
            self.item(r, 0).setForeground(QtGui.QColor(0, 0, 0))
        self.setUpdatesEnabled(True)

"""People table: the several-person metrics of the run, one row per person, and the frame shown's
GOSPA, its decomposition and the people-count error. Draws what the engine computed
(:class:`core.evaluation.people.PeopleRun` in :class:`app.data.TrackingResult`), never computes."""

from __future__ import annotations

import math
from typing import Any

from PySide6 import QtGui, QtWidgets

from app.person_colours import person_colour

COLUMNS = (
    ("person", "person index (colour as in the scene editor and the top view's truth)"),
    ("loss ×10⁻³", "the paper's loss L_j of the person over the run (eq. 13), 1 m² if never"),
    ("RMSE (m)", "position error of the person's estimate over the frames it has one"),
    ("present", "frames in which the person is in the scene"),
    ("missed", "frames present without a confirmed track within GOSPA's cut-off"),
    ("switches", "identity switches: the person's track id changed (– : no identities)"),
)


def _num(v: float, fmt: str) -> str:
    return "–" if v is None or not math.isfinite(v) else format(v, fmt)


def people_rows(people: Any) -> list[list[str]]:
    """The table's text, one row per person (None: no rows)."""
    if people is None:
        return []
    rows = []
    for m in people.persons:
        rows.append(
            [
                str(m.person + 1),  # 1-based for users, as the scene panel
                _num(m.loss * 1e3, ".4g"),
                _num(m.rmse_m, ".3f"),
                str(m.frames_present),
                str(m.frames_missed),
                str(m.identity_switches) if m.identity_switches >= 0 else "–",
            ]
        )
    return rows


def frame_line(people: Any, index: int) -> str:
    """GOSPA, its terms and the count error of frame ``index``; the run's means beside."""
    if people is None or not 0 <= index < len(people.frames.gospa_m):
        return "GOSPA – · count error –"
    f = people.frames
    mean = f.mean()
    return (
        f"frame: GOSPA {f.gospa_m[index]:.3f} m (localisation {f.localisation[index]:.3f}, "
        f"missed {f.missed[index]:.3f}, false {f.false[index]:.3f} m²) · "
        f"{int(f.n_confirmed[index])} tracks for {int(f.n_present[index])} present "
        f"(count error {int(f.count_error[index]):+d})   run: GOSPA {mean['gospa_m']:.3f} m, "
        f"people counted right in {mean['count_exact_fraction']:.0%} of frames"
    )


def _swatch(rgb: tuple[int, int, int]) -> QtGui.QIcon:
    """A filled square with a dark border (person 0 is white: it must show on a light table)."""
    pm = QtGui.QPixmap(12, 12)
    pm.fill(QtGui.QColor(*rgb))
    painter = QtGui.QPainter(pm)
    painter.setPen(QtGui.QColor(60, 60, 60))
    painter.drawRect(0, 0, 11, 11)
    painter.end()
    return QtGui.QIcon(pm)


class PeopleTable(QtWidgets.QWidget):
    """A line for the frame shown and a row per person."""

    def __init__(self, parent: QtWidgets.QWidget | None = None) -> None:
        super().__init__(parent)
        self.frame_label = QtWidgets.QLabel(frame_line(None, 0))
        self.frame_label.setWordWrap(True)
        self.table = QtWidgets.QTableWidget(0, len(COLUMNS))
        self.table.setEditTriggers(QtWidgets.QAbstractItemView.NoEditTriggers)
        self.table.verticalHeader().setVisible(False)
        for c, (name, tip) in enumerate(COLUMNS):
            item = QtWidgets.QTableWidgetItem(name)
            item.setToolTip(tip)
            self.table.setHorizontalHeaderItem(c, item)
        self.table.horizontalHeader().setSectionResizeMode(QtWidgets.QHeaderView.ResizeToContents)
        layout = QtWidgets.QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.frame_label)
        layout.addWidget(self.table)
        self._shown: Any = None

    def show_people(self, people: Any, index: int) -> None:
        """Draw ``people`` (a PeopleRun or None) at frame ``index``."""
        self.frame_label.setText(frame_line(people, index))
        if people is self._shown:
            return  # the rows are per run: only the frame line follows the playback
        self._shown = people
        rows = people_rows(people)
        self.table.setRowCount(len(rows))
        for r, row in enumerate(rows):
            for c, text in enumerate(row):
                item = QtWidgets.QTableWidgetItem(text)
                if c == 0:
                    item.setIcon(_swatch(person_colour(r)))
                self.table.setItem(r, c, item)

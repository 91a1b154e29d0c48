"""Recording panel: what a replayed recording is and holds (device, format, frames, dropped
frames, frame period, points a frame, SNR, elevation, TI's tracks, head count, truth) in place of
the scene editor, with the reader's notes and a warning when the radar folds walking speed."""

from __future__ import annotations

from PySide6 import QtCore, QtWidgets

from app.replay import WALKING_SPEED_MPS, RecordingFacts


def slow_radar_warning(max_velocity_mps: float) -> str:
    """The warning for a radar whose unambiguous velocity is below walking speed ("" if none)."""
    if max_velocity_mps >= WALKING_SPEED_MPS:
        return ""
    return (
        f"maximum velocity {max_velocity_mps:.2f} m/s is below walking speed "
        f"({WALKING_SPEED_MPS:g} m/s): a walking person's Doppler folds (aliases); "
        "shorten the chirp period in the cfg"
    )


class RecordingPanel(QtWidgets.QWidget):
    """The facts of the recording being replayed; :meth:`show_facts`."""

    close_requested = QtCore.Signal()

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setObjectName("recordingPanel")
        outer = QtWidgets.QVBoxLayout(self)
        box = QtWidgets.QGroupBox("Recording")
        self.form = QtWidgets.QFormLayout(box)
        self.form.setRowWrapPolicy(QtWidgets.QFormLayout.WrapLongRows)
        self.values: dict[str, QtWidgets.QLabel] = {}
        outer.addWidget(box)
        self.warning = QtWidgets.QLabel()
        self.warning.setObjectName("recordingWarning")
        self.warning.setWordWrap(True)
        self.warning.setStyleSheet("color: #e0a000; font-weight: bold")
        self.warning.hide()
        outer.addWidget(self.warning)
        notes_box = QtWidgets.QGroupBox("Reader's notes")
        notes_layout = QtWidgets.QVBoxLayout(notes_box)
        self.notes = QtWidgets.QLabel()
        self.notes.setObjectName("recordingNotes")
        self.notes.setWordWrap(True)
        self.notes.setTextInteractionFlags(QtCore.Qt.TextSelectableByMouse)
        notes_layout.addWidget(self.notes)
        outer.addWidget(notes_box)
        self.close_button = QtWidgets.QPushButton("Close recording (simulate the scene)")
        self.close_button.setObjectName("closeRecordingButton")
        self.close_button.clicked.connect(self.close_requested)
        outer.addWidget(self.close_button)
        outer.addStretch(1)
        self.facts: RecordingFacts | None = None

    def show_facts(self, facts: RecordingFacts) -> None:
        self.facts = facts
        for label, value in facts.rows():
            if label not in self.values:
                widget = QtWidgets.QLabel()
                widget.setObjectName(f"fact_{label.replace(' ', '_')}")
                widget.setWordWrap(True)
                widget.setTextInteractionFlags(QtCore.Qt.TextSelectableByMouse)
                self.form.addRow(label, widget)
                self.values[label] = widget
            self.values[label].setText(value)
        warning = slow_radar_warning(facts.max_velocity_mps)
        self.warning.setText(warning)
        self.warning.setVisible(bool(warning))
        self.notes.setText("\n".join(f"• {n}" for n in facts.notes) or "none")

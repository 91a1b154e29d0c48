"""Processing panel: the simulator's fidelity level (editable: the scene is simulated again),
the processing chain's settings (windows, static clutter removal, the two CFAR stages, the
detection ranges, the angle FFT) as the chain runs them, and a timing table (a simulated frame
and its parts, which add up to it; track and draw per frame; frames per second simulated and
drawn)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from PySide6 import QtCore, QtWidgets

if TYPE_CHECKING:
    from app.workers import FrameTiming

#: What each fidelity level is (docs/fidelity-models.md)
FIDELITY_TEXT = {
    "exact": "exact baseband (the paper's chain)",
    "fast": "fast baseband (grouped kernels)",
    "measurement": "measurement model (no baseband)",
}


def _cfar_text(c: dict) -> str:
    side = "cyclic" if c.get("cyclic") else "one-sided at the edges"
    return (
        f"{c['method'].upper()} · {c['n_train']} train / {c['n_guard']} guard cells each side · "
        f"P_fa {c['pfa']:g} · {side}"
    )


def _ms(value: float) -> str:
    if not math.isfinite(value):
        return "–"
    return f"{value:.2f} ms" if value < 1.0 else f"{value:.1f} ms"


class ProcessingPanel(QtWidgets.QWidget):
    """Fidelity level, processing settings (read from the chain) and per-frame timings."""

    fidelity_changed = QtCore.Signal(str)

    def __init__(self, levels: list[str], parent=None) -> None:
        super().__init__(parent)
        self.setObjectName("processingPanel")
        outer = QtWidgets.QVBoxLayout(self)
        sim_box = QtWidgets.QGroupBox("Simulator")
        sim_form = QtWidgets.QFormLayout(sim_box)
        self.fidelity = QtWidgets.QComboBox()
        self.fidelity.setObjectName("fidelityCombo")
        for name in levels:
            self.fidelity.addItem(f"{name} — {FIDELITY_TEXT.get(name, name)}", name)
        sim_form.addRow("fidelity level", self.fidelity)
        outer.addWidget(sim_box)

        proc_box = QtWidgets.QGroupBox("Processing chain (as it runs)")
        self.proc_form = QtWidgets.QFormLayout(proc_box)
        self.proc_form.setRowWrapPolicy(QtWidgets.QFormLayout.WrapLongRows)
        self.settings_labels: dict[str, QtWidgets.QLabel] = {}
        for key, title in (
            ("windows", "windows (range, Doppler)"),
            ("static_clutter_removal", "static clutter removal"),
            ("range_cfar", "range CFAR"),
            ("doppler_cfar", "Doppler CFAR"),
            ("cfar_noise_model", "CFAR noise model"),
            ("peak_grouping", "peak grouping"),
            ("ranges", "detections between"),
            ("angle_fft_size", "azimuth FFT"),
        ):
            label = QtWidgets.QLabel("–")
            label.setObjectName(f"proc_{key}")
            label.setWordWrap(True)
            label.setTextInteractionFlags(QtCore.Qt.TextSelectableByMouse)
            self.settings_labels[key] = label
            self.proc_form.addRow(title, label)
        outer.addWidget(proc_box)

        time_box = QtWidgets.QGroupBox("Timing per frame")
        time_form = QtWidgets.QFormLayout(time_box)
        self.timing_labels: dict[str, QtWidgets.QLabel] = {}
        for key, title, tip in (
            ("chain", "simulate + process + views", "one frame from the engine, in all: the "
             "three rows below add up to it (mean of the last 50 frames, the first left out)"),
            ("synthesis", "  simulate", "baseband synthesis and receiver noise of one frame "
             "(exact level; the fast and measurement levels do both halves in one kernel: –)"),
            ("processing", "  process", "range and Doppler FFTs, clutter removal, CFAR, angles "
             "and point cloud of one frame (exact level)"),
            ("other", "  views, hand-off", "the rest of the frame's time: the range profile's "
             "CFAR threshold, the micro-Doppler spectra and the frame's snapshot"),
            ("track", "track", "last re-track of the whole scene divided by its frames "
             "(tracker, ψ, gates, metrics)"),
            ("draw", "draw", "last redraw of the views (median of the last 60)"),
            ("sim_fps", "frames/s simulated", "frames simulated per second since the start"),
            ("draw_fps", "redraws/s", "redraws in the last second"),
        ):  # fmt: skip
            label = QtWidgets.QLabel("–")
            label.setObjectName(f"timing_{key}")
            label.setToolTip(tip)
            self.timing_labels[key] = label
            time_form.addRow(title, label)
        outer.addWidget(time_box)
        outer.addStretch(1)
        self.fidelity.currentIndexChanged.connect(
            lambda i: self.fidelity_changed.emit(self.fidelity.itemData(i))
        )

    def set_fidelity(self, name: str) -> None:
        self.fidelity.blockSignals(True)
        self.fidelity.setCurrentIndex(max(0, self.fidelity.findData(name)))
        self.fidelity.blockSignals(False)

    def show_settings(self, s: dict) -> None:
        """``s``: ``ProcessingSettings.to_dict()`` of the chain for the current scene."""
        text = {
            "windows": f"{s['range_window']}, {s['doppler_window']}",
            "static_clutter_removal": "on" if s["static_clutter_removal"] else "off",
            "range_cfar": _cfar_text(s["range_cfar"]),
            "doppler_cfar": _cfar_text(s["doppler_cfar"]),
            "cfar_noise_model": "window-correlated cells and the zero-Doppler notch"
            if s["cfar_noise_model"]
            else "independent cells",
            "peak_grouping": "3 × 3 local maxima" if s["peak_grouping"] else "off",
            "ranges": f"{s['min_range_m']:g} … {s['max_range_m']:g} m",
            "angle_fft_size": f"{s['angle_fft_size']} points",
        }
        for key, value in text.items():
            self.settings_labels[key].setText(value)

    def show_timing(
        self,
        *,
        frame: FrameTiming,
        track_ms: float,
        draw_ms: float,
        sim_fps: float,
        draw_fps: int,
    ) -> None:
        """``frame``: the simulated frames' times (their parts add up to the total)."""
        self.timing_labels["chain"].setText(_ms(frame.total))
        self.timing_labels["synthesis"].setText(_ms(frame.synthesis))
        self.timing_labels["processing"].setText(_ms(frame.processing))
        self.timing_labels["other"].setText(_ms(frame.other))
        self.timing_labels["track"].setText(_ms(track_ms))
        self.timing_labels["draw"].setText(_ms(draw_ms))
        self.timing_labels["sim_fps"].setText("–" if sim_fps <= 0 else f"{sim_fps:.1f}")
        self.timing_labels["draw_fps"].setText(f"{draw_fps:d}")

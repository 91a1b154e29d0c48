"""Tracker sliders: the tracker switch (the paper's IPDA, the room tracker, TI's gtrack), every
parameter of the chosen tracker's search space with its range (log where the search space is
logarithmic), the CV/CA switch, the non-optimised settings, reset and apply-best."""

from __future__ import annotations

import math

from PySide6 import QtCore, QtWidgets

from app.data import ParamSpec
from app.models import TrackerParamsModel
from core.errors import InputError

SLIDER_STEPS = 1000

#: The tracker switch: (key, text, the sliders' group title)
TRACKER_CHOICES = (
    ("paper", "paper (one-point IPDA)", "Optimised parameters (eq. 15 ranges)"),
    ("room", "room mode (groups of points, static, ghosts)",
     "Optimised parameters (eq. 15 ranges + the room tracker's)"),
    ("gtrack", "gtrack (TI's people tracker)",
     "gtrack's parameters (TI's defaults, RadarTune's ranges)"),
)  # fmt: skip


def to_slider(spec: ParamSpec, value: float) -> int:
    """Value → slider position 0…SLIDER_STEPS (log-linear when ``spec.log``)."""
    lo, hi = spec.low, spec.high
    value = min(max(value, lo), hi)
    if spec.log:
        u = (math.log(value) - math.log(lo)) / (math.log(hi) - math.log(lo))
    else:
        u = (value - lo) / (hi - lo)
    return int(round(u * SLIDER_STEPS))


def from_slider(spec: ParamSpec, position: int) -> float:
    """Slider position → value (inverse of :func:`to_slider`)."""
    u = position / SLIDER_STEPS
    if spec.log:
        return math.exp(math.log(spec.low) + u * (math.log(spec.high) - math.log(spec.low)))
    return spec.low + u * (spec.high - spec.low)


def bounds_text(spec: ParamSpec) -> str:
    """The slider's label: ``symbol meaning`` over its bounds and unit (and the scale)."""
    unit = f" {spec.unit}" if spec.unit else " (no unit)"
    scale = ", log" if spec.log else ""
    title = spec.title or spec.label or spec.name
    return (
        f"{title}<br><span style='color:gray; font-size:small'>"
        f"{spec.low:g} … {spec.high:g}{unit}{scale}</span>"
    )


class ParamRow(QtCore.QObject):
    """Slider + spin box of one parameter; both edit the model."""

    def __init__(
        self, spec: ParamSpec, model: TrackerParamsModel, layout, row: int, on_error
    ) -> None:
        super().__init__(layout.parentWidget())
        self.spec = spec
        self._model = model
        self._on_error = on_error
        self.label = QtWidgets.QLabel(bounds_text(spec))
        self.label.setObjectName(f"label_{spec.name}")
        self.slider = QtWidgets.QSlider(QtCore.Qt.Horizontal)
        self.slider.setObjectName(f"slider_{spec.name}")
        self.slider.setRange(0, SLIDER_STEPS)
        self.spin = QtWidgets.QDoubleSpinBox()
        self.spin.setObjectName(f"spin_{spec.name}")
        self.spin.setDecimals(4)
        self.spin.setRange(spec.low, spec.high)
        self.spin.setSingleStep((spec.high - spec.low) / 100)
        self.spin.setKeyboardTracking(False)
        self.spin.setMinimumWidth(80)
        if spec.unit:
            self.spin.setSuffix(f" {spec.unit}")
        unit = f" {spec.unit}" if spec.unit else ""
        tip = f"{spec.name} ∈ [{spec.low:g}, {spec.high:g}]{unit}" + (
            ", log scale" if spec.log else ""
        )
        for w in (self.label, self.slider, self.spin):
            w.setToolTip(tip)
        layout.addWidget(self.label, row, 0)
        layout.addWidget(self.slider, row, 1)
        layout.addWidget(self.spin, row, 2)
        self.slider.valueChanged.connect(self._on_slider)
        self.spin.valueChanged.connect(self._on_spin)

    def _on_slider(self, position: int) -> None:
        self._set(from_slider(self.spec, position))

    def _on_spin(self, value: float) -> None:
        self._set(value)

    def _set(self, value: float) -> None:
        try:
            self._model.set_value(self.spec.name, value)
        except InputError as exc:
            self._on_error(str(exc))
            self.sync()

    def sync(self) -> None:
        """Model → widgets, signals blocked."""
        value = self._model.values.get(self.spec.name)
        if value is None:
            return
        for w in (self.slider, self.spin):
            w.blockSignals(True)
        self.slider.setValue(to_slider(self.spec, value))
        self.spin.setValue(value)
        for w in (self.slider, self.spin):
            w.blockSignals(False)

    def remove(self) -> None:
        for w in (self.label, self.slider, self.spin):
            w.setParent(None)
            w.deleteLater()


class TrackerPanel(QtWidgets.QWidget):
    """Sliders bound both ways to a :class:`TrackerParamsModel`."""

    apply_best_requested = QtCore.Signal()
    error = QtCore.Signal(str)

    def __init__(self, model: TrackerParamsModel, parent=None) -> None:
        super().__init__(parent)
        self.setObjectName("trackerPanel")
        self.model = model
        outer = QtWidgets.QVBoxLayout(self)
        switch = QtWidgets.QHBoxLayout()
        switch.addWidget(QtWidgets.QLabel("Tracker"))
        self.tracker_combo = QtWidgets.QComboBox()
        self.tracker_combo.setObjectName("trackerCombo")
        for key, text, _title in TRACKER_CHOICES:
            self.tracker_combo.addItem(text, key)
        switch.addWidget(self.tracker_combo, 1)
        outer.addLayout(switch)
        top = QtWidgets.QHBoxLayout()
        top.addWidget(QtWidgets.QLabel("Motion model"))
        self.model_combo = QtWidgets.QComboBox()
        self.model_combo.setObjectName("modelCombo")
        self.model_combo.addItem("CV (constant velocity)", "cv")
        self.model_combo.addItem("CA (constant acceleration)", "ca")
        top.addWidget(self.model_combo, 1)
        outer.addLayout(top)

        group = QtWidgets.QGroupBox(TRACKER_CHOICES[0][2])
        self.params_group = group
        self.grid = QtWidgets.QGridLayout(group)
        self.grid.setColumnStretch(1, 1)
        outer.addWidget(group)
        self.rows: dict[str, ParamRow] = {}

        other = QtWidgets.QGroupBox("Fixed settings")
        self.fixed_group = other
        form = QtWidgets.QFormLayout(other)
        self.p_g = self._spin(0.5, 0.9999, 4, "p_g")
        self.confirm = self._spin(0.01, 1.0, 3, "confirm_threshold")
        self.delete = self._spin(0.0, 0.99, 3, "delete_threshold")
        self.rho = self._spin(1e-6, 10.0, 6, "clutter_density")
        self.rho_np = QtWidgets.QCheckBox("non-parametric")
        self.rho_np.setObjectName("rho_nonparametric")
        rho_row = QtWidgets.QHBoxLayout()
        rho_row.addWidget(self.rho, 1)
        rho_row.addWidget(self.rho_np)
        form.addRow("gate probability P_G", self.p_g)
        form.addRow("confirm ψ ≥", self.confirm)
        form.addRow("delete ψ <", self.delete)
        form.addRow("clutter density ρ", rho_row)
        outer.addWidget(other)

        buttons = QtWidgets.QHBoxLayout()
        self.reset_button = QtWidgets.QPushButton("Reset to defaults")
        self.reset_button.setObjectName("resetButton")
        self.apply_best_button = QtWidgets.QPushButton("Apply best of study")
        self.apply_best_button.setObjectName("applyBestButton")
        self.apply_best_button.setEnabled(False)
        buttons.addWidget(self.reset_button)
        buttons.addWidget(self.apply_best_button)
        outer.addLayout(buttons)
        self.timing = QtWidgets.QLabel("re-track: waiting for the first simulated frames")
        self.timing.setObjectName("retrackTiming")
        outer.addWidget(self.timing)
        outer.addStretch(1)

        self.model_combo.currentIndexChanged.connect(self._on_model_combo)
        self.tracker_combo.currentIndexChanged.connect(self._on_tracker_combo)
        self.reset_button.clicked.connect(model.reset)
        self.apply_best_button.clicked.connect(self.apply_best_requested)
        for w in (self.p_g, self.confirm, self.delete, self.rho):
            w.valueChanged.connect(self._on_extra)
        self.rho_np.toggled.connect(self._on_extra)
        model.changed.connect(self.sync)
        self._rows_model = None
        self.sync()

    def _spin(self, lo, hi, decimals, name) -> QtWidgets.QDoubleSpinBox:
        s = QtWidgets.QDoubleSpinBox()
        s.setObjectName(f"spin_{name}")
        s.setRange(lo, hi)
        s.setDecimals(decimals)
        s.setSingleStep(10 ** (-min(decimals, 3)) * 10)
        s.setKeyboardTracking(False)
        return s

    def _rebuild_rows(self) -> None:
        for row in self.rows.values():
            row.remove()
        self.rows = {}
        for k, spec in enumerate(self.model.specs()):
            self.rows[spec.name] = ParamRow(spec, self.model, self.grid, k, self.error.emit)
        self._rows_model = (self.model.tracker, self.model.model)

    def _on_tracker_combo(self, index: int) -> None:
        try:
            self.model.set_tracker(self.tracker_combo.itemData(index))
        except InputError as exc:
            self.error.emit(str(exc))
            self.sync()

    def _on_model_combo(self, index: int) -> None:
        try:
            self.model.set_model(self.model_combo.itemData(index))
        except InputError as exc:
            self.error.emit(str(exc))
            self.sync()

    def _on_extra(self, *_args) -> None:
        extra = {
            "p_g": self.p_g.value(),
            "confirm_threshold": self.confirm.value(),
            "delete_threshold": self.delete.value(),
            "clutter_density": "nonparametric" if self.rho_np.isChecked() else self.rho.value(),
        }
        self.rho.setEnabled(not self.rho_np.isChecked())
        try:
            self.model.set_extra(**extra)
        except InputError as exc:
            self.error.emit(str(exc))
            self.sync()

    def sync(self) -> None:
        """Model → widgets (signals blocked while syncing)."""
        if self._rows_model != (self.model.tracker, self.model.model):
            self._rebuild_rows()
        tracker = self.model.tracker
        for combo, index in (
            (self.model_combo, 0 if self.model.model == "cv" else 1),
            (self.tracker_combo, self.tracker_combo.findData(tracker)),
        ):
            combo.blockSignals(True)
            combo.setCurrentIndex(index)
            combo.blockSignals(False)
        gtrack = tracker == "gtrack"  # its own motion model (3-D constant acceleration)
        self.model_combo.setEnabled(not gtrack)
        self.fixed_group.setVisible(not gtrack)  # the IPDA's ψ thresholds, P_G and ρ
        self.params_group.setTitle(next(t for k, _x, t in TRACKER_CHOICES if k == tracker))
        for row in self.rows.values():
            row.sync()
        extra = self.model.extra_effective()
        widgets = (self.p_g, self.confirm, self.delete, self.rho, self.rho_np)
        for w in widgets:
            w.blockSignals(True)
        self.p_g.setValue(extra["p_g"])
        self.confirm.setValue(extra["confirm_threshold"])
        self.delete.setValue(extra["delete_threshold"])
        rho = extra["clutter_density"]
        self.rho_np.setChecked(rho == "nonparametric")
        if rho != "nonparametric":
            self.rho.setValue(float(rho))
        self.rho.setEnabled(rho != "nonparametric")
        for w in widgets:
            w.blockSignals(False)

    def show_timing(self, elapsed_s: float, n_frames: int) -> None:
        self.timing.setText(
            f"re-track of {n_frames} frames (every track with ψ and gates, metrics): "
            f"{elapsed_s * 1e3:.0f} ms"
        )
        self.timing.setWordWrap(True)

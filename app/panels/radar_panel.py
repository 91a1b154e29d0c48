"""Radar panel: the configuration fields (in engineering units) and the derived values, which
update as the fields change; load a TI mmWave ``.cfg``."""

from __future__ import annotations

from PySide6 import QtCore, QtWidgets

from app.models import RadarModel
from core.config import CHAINS, RadarConfig, default_chain
from core.errors import InputError

#: field, label, display unit, SI per display unit, decimals, min, max (display units)
FIELDS = (
    ("start_frequency_hz", "start frequency Fc", "GHz", 1e9, 3, 1.0, 100.0),
    ("bandwidth_hz", "ramp bandwidth BW", "GHz", 1e9, 4, 0.01, 10.0),
    ("ramp_time_s", "ramp time Tc", "µs", 1e-6, 2, 1.0, 1000.0),
    ("idle_time_s", "idle time Tidle", "µs", 1e-6, 2, 0.0, 1000.0),
    ("sample_rate_hz", "sample rate Fs", "MHz", 1e6, 3, 0.1, 50.0),
    ("n_samples", "ADC samples Nadc", "", 1, 0, 32, 4096),
    ("n_loops", "loops Nc", "", 1, 0, 16, 1024),
    ("n_tx", "TX antennas", "", 1, 0, 1, 3),
    ("n_rx", "RX antennas", "", 1, 0, 1, 4),
    ("frame_period_s", "frame period Δt", "ms", 1e-3, 2, 1.0, 10000.0),
    ("tx_power_dbm", "TX power Pt", "dBm", 1, 1, -40.0, 40.0),
    ("antenna_gain_db", "antenna gain Gmax", "dB", 1, 1, -20.0, 40.0),
    ("receiver_gain_db", "receiver gain Ge", "dB", 1, 1, 0.0, 80.0),
    ("noise_figure_db", "noise figure F", "dB", 1, 1, 0.0, 40.0),
    ("receiver_bandwidth_hz", "noise bandwidth Be", "MHz", 1e6, 3, 0.01, 100.0),
    ("temperature_k", "temperature T", "K", 1, 1, 1.0, 1000.0),
)

#: fields that come with the antenna layout (tx_order, virtual array positions), not edited alone
READ_ONLY = ("n_tx", "n_rx")

#: derived value, label, display unit, SI per display unit, format
DERIVED = (
    ("wavelength_m", "wavelength λ", "mm", 1e-3, ".4f"),
    ("slope_hz_per_s", "slope S", "MHz/µs", 1e12, ".3f"),
    ("chirp_period_s", "chirp period", "µs", 1e-6, ".2f"),
    ("range_resolution_m", "range resolution", "cm", 1e-2, ".3f"),
    ("max_range_m", "max range", "m", 1.0, ".2f"),
    ("velocity_resolution_mps", "velocity resolution", "m/s", 1.0, ".4f"),
    ("max_velocity_mps", "max velocity ±", "m/s", 1.0, ".3f"),
    ("n_virtual", "virtual channels", "", 1, "d"),
)


class RadarPanel(QtWidgets.QWidget):
    """Fields bound both ways to a :class:`RadarModel`."""

    error = QtCore.Signal(str)
    load_cfg_requested = QtCore.Signal()

    def __init__(self, model: RadarModel, parent=None) -> None:
        super().__init__(parent)
        self.setObjectName("radarPanel")
        self.model = model
        outer = QtWidgets.QVBoxLayout(self)
        self.name_label = QtWidgets.QLabel()
        outer.addWidget(self.name_label)
        chain_row = QtWidgets.QFormLayout()
        self.chain_combo = QtWidgets.QComboBox()
        self.chain_combo.setObjectName("chainCombo")
        self.chain_combo.addItems(list(CHAINS))
        self.chain_combo.setToolTip(
            "detection chain: the paper's, TI's out-of-box demo or TI's 3-D people counting "
            "(TI's default settings; a loaded TI .cfg sets the chain with its own)"
        )
        self.chain_combo.currentTextChanged.connect(self._on_chain)
        chain_row.addRow("detection chain", self.chain_combo)
        outer.addLayout(chain_row)
        fields = QtWidgets.QGroupBox("Configuration")
        form = QtWidgets.QFormLayout(fields)
        self.spins: dict[str, QtWidgets.QAbstractSpinBox] = {}
        for name, label, unit, scale, decimals, lo, hi in FIELDS:
            if decimals == 0:
                spin = QtWidgets.QSpinBox()
                spin.setRange(int(lo), int(hi))
            else:
                spin = QtWidgets.QDoubleSpinBox()
                spin.setDecimals(decimals)
                spin.setRange(lo, hi)
            spin.setObjectName(f"radar_{name}")
            spin.setKeyboardTracking(False)
            if unit:
                spin.setSuffix(f" {unit}")
            spin.valueChanged.connect(lambda v, n=name, s=scale: self._on_field(n, v, s))
            if name in READ_ONLY:
                spin.setEnabled(False)
                spin.setToolTip(
                    "set by the antenna layout (TX order, virtual array): load a TI .cfg to change"
                )
            form.addRow(label, spin)
            self.spins[name] = spin
        outer.addWidget(fields)
        derived = QtWidgets.QGroupBox("Derived")
        dform = QtWidgets.QFormLayout(derived)
        self.derived_labels: dict[str, QtWidgets.QLabel] = {}
        for name, label, _unit, _scale, _fmt in DERIVED:
            lab = QtWidgets.QLabel()
            lab.setObjectName(f"derived_{name}")
            lab.setTextInteractionFlags(QtCore.Qt.TextSelectableByMouse)
            dform.addRow(label, lab)
            self.derived_labels[name] = lab
        outer.addWidget(derived)
        buttons = QtWidgets.QHBoxLayout()
        self.load_button = QtWidgets.QPushButton("Load TI .cfg …")
        self.load_button.setObjectName("loadCfgButton")
        self.load_button.clicked.connect(self.load_cfg_requested)
        self.paper_button = QtWidgets.QPushButton("Paper defaults")
        self.paper_button.clicked.connect(lambda: model.set_radar(RadarConfig()))
        buttons.addWidget(self.load_button)
        buttons.addWidget(self.paper_button)
        outer.addLayout(buttons)
        outer.addStretch(1)
        model.changed.connect(self.sync)
        model.chain_changed.connect(self.sync_chain)
        self.sync()
        self.sync_chain()

    def _on_chain(self, name: str) -> None:
        """A chain picked by name: TI's defaults, unless the model already runs that chain
        (e.g. with a loaded .cfg's settings)."""
        if name != self.model.chain.name:
            self.model.set_chain(default_chain(name))

    def sync_chain(self, *_args) -> None:
        self.chain_combo.blockSignals(True)
        self.chain_combo.setCurrentText(self.model.chain.name)
        self.chain_combo.blockSignals(False)

    def _on_field(self, name: str, value, scale: float) -> None:
        si = int(value) if isinstance(value, int) else value * scale
        try:
            self.model.set_field(name, si)
        except InputError as exc:
            self.error.emit(str(exc))
            self.sync()

    def sync(self, *_args) -> None:
        """Model → widgets (signals blocked) and derived values."""
        radar = self.model.radar
        self.name_label.setText(f"<b>{radar.name}</b>")
        for name, _label, _unit, scale, decimals, _lo, _hi in FIELDS:
            spin = self.spins[name]
            spin.blockSignals(True)
            value = getattr(radar, name)
            spin.setValue(int(value) if decimals == 0 else value / scale)
            spin.blockSignals(False)
        for name, _label, unit, scale, fmt in DERIVED:
            value = getattr(radar, name)
            text = format(value / scale if fmt != "d" else value, fmt)
            self.derived_labels[name].setText(f"{text} {unit}".strip())

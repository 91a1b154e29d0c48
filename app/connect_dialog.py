"""File → Connect sensor …: the serial ports, the ``.cfg``, the baud rates and the recording of a
live link (:class:`core.live.LinkSettings`), chosen in one dialog."""

from __future__ import annotations

from PySide6 import QtCore, QtWidgets

from core.errors import InputError
from core.live import LinkSettings, list_ports
from core.live.dialogue import CLI_BAUD

#: Baud rates offered (TI's CLI port: 115 200; data port: 921 600; the low-power SDK's choices).
BAUDS = (115_200, 230_400, 460_800, 921_600, 1_250_000, 3_125_000)
FROM_CFG = "from the cfg"


class ConnectDialog(QtWidgets.QDialog):
    """Ports listed by pyserial (editable: a pseudo-terminal or a port pyserial does not list can be
    typed), the cfg, the baud rates (the data port's default: the cfg's ``baudRate``, else
    921 600) and an optional recording file. :meth:`settings` validates them."""

    def __init__(self, parent: QtWidgets.QWidget | None = None, cfg: str = "") -> None:
        super().__init__(parent)
        self.setObjectName("connectDialog")
        self.setWindowTitle("Connect sensor")
        form = QtWidgets.QFormLayout(self)
        self.cli_combo = self._port_combo("cliPortCombo")
        self.data_combo = self._port_combo("dataPortCombo")
        refresh = QtWidgets.QPushButton("Refresh ports")
        refresh.clicked.connect(self.refresh_ports)
        self.cfg_edit = QtWidgets.QLineEdit(cfg)
        self.cfg_edit.setObjectName("cfgEdit")
        cfg_row = self._with_browse(self.cfg_edit, self._browse_cfg)
        self.cli_baud = self._baud_combo("cliBaudCombo", [str(b) for b in BAUDS], str(CLI_BAUD))
        self.data_baud = self._baud_combo(
            "dataBaudCombo", [FROM_CFG, *(str(b) for b in BAUDS)], FROM_CFG
        )
        self.record_edit = QtWidgets.QLineEdit()
        self.record_edit.setObjectName("recordEdit")
        self.record_edit.setPlaceholderText("no recording")
        record_row = self._with_browse(self.record_edit, self._browse_record)
        form.addRow("CLI port", self.cli_combo)
        form.addRow("Data port", self.data_combo)
        form.addRow("", refresh)
        form.addRow("Configuration (.cfg)", cfg_row)
        form.addRow("CLI baud", self.cli_baud)
        form.addRow("Data baud", self.data_baud)
        form.addRow("Record data port to", record_row)
        buttons = QtWidgets.QDialogButtonBox(
            QtWidgets.QDialogButtonBox.Ok | QtWidgets.QDialogButtonBox.Cancel
        )
        buttons.button(QtWidgets.QDialogButtonBox.Ok).setText("Connect")
        buttons.accepted.connect(self._on_accept)
        buttons.rejected.connect(self.reject)
        form.addRow(buttons)
        self.error_label = QtWidgets.QLabel()
        self.error_label.setObjectName("connectError")
        self.error_label.setWordWrap(True)
        self.error_label.setStyleSheet("color: #b00020")
        form.addRow(self.error_label)
        self.refresh_ports()

    # ---- building ----
    @staticmethod
    def _port_combo(name: str) -> QtWidgets.QComboBox:
        combo = QtWidgets.QComboBox()
        combo.setObjectName(name)
        combo.setEditable(True)
        combo.setMinimumContentsLength(24)
        return combo

    @staticmethod
    def _baud_combo(name: str, items: list[str], current: str) -> QtWidgets.QComboBox:
        combo = QtWidgets.QComboBox()
        combo.setObjectName(name)
        combo.setEditable(True)
        combo.addItems(items)
        combo.setCurrentText(current)
        return combo

    def _with_browse(self, edit: QtWidgets.QLineEdit, slot) -> QtWidgets.QWidget:
        row = QtWidgets.QWidget()
        lay = QtWidgets.QHBoxLayout(row)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.addWidget(edit)
        button = QtWidgets.QPushButton("…")
        button.setMaximumWidth(32)
        button.clicked.connect(slot)
        lay.addWidget(button)
        return row

    def refresh_ports(self) -> None:
        """Ports as pyserial lists them (TI's XDS110 first: its two ports are the sensor's
        CLI/user and data/auxiliary UARTs, in that order)."""
        try:
            ports = list_ports()
        except Exception as exc:  # noqa: BLE001 - a port scan must never break the dialog
            ports = []
            self.error_label.setText(f"cannot list serial ports: {exc}")
        for i, combo in enumerate((self.cli_combo, self.data_combo)):
            text = combo.currentText()
            combo.clear()
            for device, description in ports:
                combo.addItem(f"{device}", device)
                combo.setItemData(combo.count() - 1, description, QtCore.Qt.ToolTipRole)
            if text:
                combo.setCurrentText(text)
            elif len(ports) > i:
                combo.setCurrentIndex(i)

    def _browse_cfg(self) -> None:
        path, _ = QtWidgets.QFileDialog.getOpenFileName(
            self, "TI configuration", self.cfg_edit.text(), "TI .cfg (*.cfg);;All files (*)"
        )
        if path:
            self.cfg_edit.setText(path)

    def _browse_record(self) -> None:
        path, _ = QtWidgets.QFileDialog.getSaveFileName(
            self, "Record the data port to", self.record_edit.text(), "UART log (*.dat)"
        )
        if path:
            self.record_edit.setText(path)

    # ---- result ----
    def settings(self) -> LinkSettings:
        """The chosen settings; :class:`InputError` naming the field that is wrong."""

        def baud(combo: QtWidgets.QComboBox, what: str) -> int | None:
            text = combo.currentText().strip()
            if text == FROM_CFG:
                return None
            try:
                return int(text)
            except ValueError:
                raise InputError(f"{what} must be a whole number of baud, got {text!r}") from None

        cli_baud = baud(self.cli_baud, "CLI baud")
        return LinkSettings(
            cli_port=self.cli_combo.currentText().strip(),
            data_port=self.data_combo.currentText().strip(),
            cfg=self.cfg_edit.text().strip(),
            cli_baud=CLI_BAUD if cli_baud is None else cli_baud,
            data_baud=baud(self.data_baud, "data baud"),
        )

    @property
    def record_path(self) -> str | None:
        return self.record_edit.text().strip() or None

    def _on_accept(self) -> None:
        try:
            self.settings()
        except InputError as exc:
            self.error_label.setText(str(exc))
            return
        self.accept()

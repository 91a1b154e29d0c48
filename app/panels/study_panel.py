"""Study panel: settings, start/stop, progress, best-so-far curve, best-parameter table,
apply best, enqueue current sliders, open the dashboard."""

from __future__ import annotations

import math

import numpy as np
import pyqtgraph as pg
from PySide6 import QtCore, QtWidgets

from app.study import StudyModel, StudyProgress
from core.errors import InputError

#: what a study minimises (core/optimization/objective.py), said under its curve
LOSS_TEXT = (
    "minimises L_t: the mean over the data set's trajectories of each one's loss "
    "L = MSE / N_c (m², the paper's eq. 13–14)"
)


class StudyPanel(QtWidgets.QWidget):
    start_requested = QtCore.Signal()
    stop_requested = QtCore.Signal()
    apply_best_requested = QtCore.Signal()
    enqueue_requested = QtCore.Signal()
    dashboard_requested = QtCore.Signal()
    browse_requested = QtCore.Signal()
    error = QtCore.Signal(str)

    def __init__(self, model: StudyModel, parent=None) -> None:
        super().__init__(parent)
        self.stopping = False
        self.setObjectName("studyPanel")
        self.model = model
        outer = QtWidgets.QVBoxLayout(self)
        form_box = QtWidgets.QGroupBox("Study")
        form = QtWidgets.QFormLayout(form_box)
        self.tracker_combo = QtWidgets.QComboBox()
        self.tracker_combo.setObjectName("studyTracker")
        self.tracker_combo.addItem("paper (one-point IPDA)", "paper")
        self.tracker_combo.addItem("room mode (groups, static, ghosts)", "room")
        self.tracker_combo.addItem("gtrack (TI's people tracker)", "gtrack")
        self.tracker_combo.setToolTip(
            "the tracker tuned, as radartune tune (--mode room, --tracker gtrack); "
            "follows the tracker panel"
        )
        self.model_combo = QtWidgets.QComboBox()
        self.model_combo.setObjectName("studyModel")
        self.model_combo.addItem("CV", "cv")
        self.model_combo.addItem("CA", "ca")
        self.trials = QtWidgets.QSpinBox()
        self.trials.setObjectName("studyTrials")
        self.trials.setRange(1, 100000)
        self.jobs = QtWidgets.QSpinBox()
        self.jobs.setObjectName("studyJobs")
        self.jobs.setRange(1, 64)
        self.dataset = QtWidgets.QComboBox()
        self.dataset.setObjectName("studyDataset")
        self.dataset.addItem("current scene (cached point clouds)", "scene")
        self.dataset.addItem("paper data set (35 trajectories)", "paper")
        storage_row = QtWidgets.QHBoxLayout()
        self.storage = QtWidgets.QLineEdit()
        self.storage.setObjectName("studyStorage")
        self.storage.setToolTip(
            "SQLite file (default), a .log journal file, or a postgresql:// URL"
        )
        self.browse = QtWidgets.QToolButton()
        self.browse.setText("…")
        storage_row.addWidget(self.storage, 1)
        storage_row.addWidget(self.browse)
        for w in (self.trials, self.jobs):
            w.setKeyboardTracking(False)
        form.addRow("tracker", self.tracker_combo)
        form.addRow("motion model", self.model_combo)
        form.addRow("trials", self.trials)
        form.addRow("processes", self.jobs)
        form.addRow("data set", self.dataset)
        form.addRow("storage", storage_row)
        outer.addWidget(form_box)

        buttons = QtWidgets.QHBoxLayout()
        self.start_button = QtWidgets.QPushButton("Start")
        self.start_button.setObjectName("studyStart")
        self.stop_button = QtWidgets.QPushButton("Stop")
        self.stop_button.setObjectName("studyStop")
        self.dashboard_button = QtWidgets.QPushButton("Open dashboard")
        self.dashboard_button.setObjectName("studyDashboard")
        for b in (self.start_button, self.stop_button, self.dashboard_button):
            buttons.addWidget(b)
        outer.addLayout(buttons)
        self.progress_bar = QtWidgets.QProgressBar()
        self.progress_bar.setObjectName("studyProgress")
        outer.addWidget(self.progress_bar)
        self.counts = QtWidgets.QLabel()
        self.counts.setObjectName("studyCounts")
        outer.addWidget(self.counts)
        self.failures = QtWidgets.QLabel()
        self.failures.setObjectName("studyFailures")
        self.failures.setWordWrap(True)
        self.failures.setTextInteractionFlags(QtCore.Qt.TextSelectableByMouse)
        self.failures.setStyleSheet("color: #c0392b;")
        self.failures.hide()
        outer.addWidget(self.failures)

        self.curve_plot = pg.PlotWidget()
        self.curve_plot.setObjectName("studyCurve")
        self.curve_plot.setTitle("best L_t so far")
        self.curve_plot.setLabel("bottom", "busy time (idle gaps between runs left out)", units="s")
        self.curve_plot.setLabel("left", "loss L_t [m²]")
        self.curve_plot.setLogMode(y=True)
        left = self.curve_plot.getAxis("left")
        left.enableAutoSIPrefix(False)
        left.setStyle(autoExpandTextSpace=True)
        self.curve_plot.setMinimumHeight(140)
        self.curve = self.curve_plot.plot(
            pen=pg.mkPen((255, 140, 0), width=2), symbol="o", symbolSize=4, stepMode=None
        )
        outer.addWidget(self.curve_plot, 1)
        self.loss_label = QtWidgets.QLabel(LOSS_TEXT)
        self.loss_label.setObjectName("studyLoss")
        self.loss_label.setWordWrap(True)
        outer.addWidget(self.loss_label)

        self.table = QtWidgets.QTableWidget(0, 2)
        self.table.setObjectName("bestParams")
        self.table.setHorizontalHeaderLabels(["parameter", "best value"])
        self.table.horizontalHeader().setSectionResizeMode(QtWidgets.QHeaderView.Stretch)
        self.table.verticalHeader().setVisible(False)
        self.table.verticalHeader().setDefaultSectionSize(20)
        self.table.setEditTriggers(QtWidgets.QAbstractItemView.NoEditTriggers)
        outer.addWidget(self.table, 1)
        row = QtWidgets.QHBoxLayout()
        self.apply_button = QtWidgets.QPushButton("Apply best")
        self.apply_button.setObjectName("studyApplyBest")
        self.enqueue_button = QtWidgets.QPushButton("Enqueue current sliders")
        self.enqueue_button.setObjectName("studyEnqueue")
        row.addWidget(self.apply_button)
        row.addWidget(self.enqueue_button)
        outer.addLayout(row)

        self.model_combo.currentIndexChanged.connect(
            lambda i: self._set(model=self.model_combo.itemData(i))
        )
        self.tracker_combo.currentIndexChanged.connect(
            lambda i: self._set(tracker=self.tracker_combo.itemData(i))
        )
        self.trials.valueChanged.connect(lambda v: self._set(n_trials=int(v)))
        self.jobs.valueChanged.connect(lambda v: self._set(n_jobs=int(v)))
        self.dataset.currentIndexChanged.connect(
            lambda i: self._set(dataset=self.dataset.itemData(i))
        )
        self.storage.editingFinished.connect(lambda: self._set(storage=self.storage.text().strip()))
        self.browse.clicked.connect(self.browse_requested)
        self.start_button.clicked.connect(self.start_requested)
        self.stop_button.clicked.connect(self._on_stop)
        self.apply_button.clicked.connect(self.apply_best_requested)
        self.enqueue_button.clicked.connect(self.enqueue_requested)
        self.dashboard_button.clicked.connect(self.dashboard_requested)
        model.form_changed.connect(lambda _f: self.sync())
        model.progress_changed.connect(self.show_progress)
        model.running_changed.connect(lambda _r: self.sync())
        self.sync()
        self.show_progress(model.progress)

    def _on_stop(self) -> None:
        self.stopping = True
        self.sync()
        self.stop_requested.emit()

    def _set(self, **changes) -> None:
        try:
            self.model.set_form(**changes)
        except InputError as exc:
            self.error.emit(str(exc))
            self.sync()

    def sync(self) -> None:
        f = self.model.form
        widgets = (
            self.tracker_combo, self.model_combo, self.trials, self.jobs, self.dataset,
            self.storage,
        )  # fmt: skip
        for w in widgets:
            w.blockSignals(True)
        self.tracker_combo.setCurrentIndex(self.tracker_combo.findData(f.tracker))
        self.model_combo.setCurrentIndex(0 if f.model == "cv" else 1)
        self.trials.setValue(f.n_trials)
        self.jobs.setValue(f.n_jobs)
        self.dataset.setCurrentIndex(self.dataset.findData(f.dataset))
        if self.storage.text() != f.storage:
            self.storage.setText(f.storage)
        for w in widgets:
            w.blockSignals(False)
        running = self.model.running
        for w in widgets:
            w.setEnabled(not running)
        # gtrack has its own table: no motion model to choose
        self.model_combo.setEnabled(not running and f.tracker != "gtrack")
        self.start_button.setEnabled(not running)
        if not running:
            self.stopping = False
        # while the workers finish their current trials: "Stopping …", not clickable again
        self.stop_button.setEnabled(running and not self.stopping)
        self.stop_button.setText("Stopping …" if self.stopping else "Stop")
        self.progress_bar.setMaximum(f.n_trials)

    def _decade_ticks(self, values: np.ndarray) -> None:
        """Tick labels on whole decades only (``1e-5``): pyqtgraph's log axis labelled the 2…9
        minor ticks too when the curve spans less than two decades, and they ran together."""
        lo = math.floor(math.log10(float(values.min())))
        hi = math.ceil(math.log10(float(values.max())))
        if hi == lo:
            hi += 1
        step = max(1, (hi - lo + 5) // 6)  # at most ~6 labels
        major = [(float(k), f"1e{k}") for k in range(lo, hi + 1, step)]
        self.curve_plot.getAxis("left").setTicks([major, []])
        self.curve_plot.setYRange(lo, hi, padding=0.02)

    def show_failures(self, failures) -> None:
        """Why trials failed, one line per distinct reason (hidden when none failed)."""
        if not failures:
            self.failures.hide()
            self.failures.setText("")
            return
        lines = [f"{n} × {reason}" for reason, n in failures]
        self.failures.setText("failed trials:\n" + "\n".join(lines))
        self.failures.setToolTip("\n".join(lines))
        self.failures.show()

    def show_progress(self, p: StudyProgress) -> None:
        self.progress_bar.setMaximum(max(self.model.form.n_trials, p.n_finished))
        self.progress_bar.setValue(p.n_finished)
        best = "–" if not math.isfinite(p.best_loss) else f"{p.best_loss:.4g} m²"
        self.counts.setText(
            f"complete {p.n_complete} · pruned {p.n_pruned} · failed {p.n_failed} · "
            f"running {p.n_running} · best loss {best}"
        )
        self.show_failures(p.failures)
        if len(p.curve_t_s):
            ok = np.isfinite(p.curve_best) & (p.curve_best > 0)
            self.curve.setData(p.curve_t_s[ok], p.curve_best[ok])
            if ok.any():
                self._decade_ticks(p.curve_best[ok])
        else:
            self.curve.setData([], [])
            # no trial yet: two decades labelled, not the log axis' empty default (its labels
            # ran into the title)
            self._decade_ticks(np.array([1e-3, 1e-1]))
        items = sorted(p.best_params.items())
        self.table.setRowCount(len(items))
        for i, (k, v) in enumerate(items):
            self.table.setItem(i, 0, QtWidgets.QTableWidgetItem(k))
            text = f"{v:.5g}" if isinstance(v, float) else str(v)
            self.table.setItem(i, 1, QtWidgets.QTableWidgetItem(text))
        self.apply_button.setEnabled(bool(p.best_params))

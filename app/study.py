"""Study model and controller: Optuna studies run in separate processes (started through
:mod:`core.optimization` via the engine); the GUI polls their progress from a pool thread, so
the window never waits for a study or its storage."""

from __future__ import annotations

import dataclasses
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from PySide6 import QtCore

from app.workers import describe_error
from core.errors import InputError


@dataclass(frozen=True, slots=True, kw_only=True)
class StudyForm:
    """What the study panel edits."""

    model: str = "cv"
    n_trials: int = 50
    n_jobs: int = 1
    storage: str = "radartune-studies.db"
    study_name: str = ""
    seed: int = 0
    #: "scene": the current scene's cached point clouds; "paper": the paper's 35 trajectories
    dataset: str = "scene"

    def __post_init__(self) -> None:
        if self.model not in ("cv", "ca"):
            raise InputError(f"model must be 'cv' or 'ca', got {self.model!r}", "model")
        if self.n_trials < 1:
            raise InputError(f"trials must be >= 1, got {self.n_trials}", "trials")
        if self.n_jobs < 1:
            raise InputError(f"jobs must be >= 1, got {self.n_jobs}", "jobs")
        if not self.storage.strip():
            raise InputError("storage must not be empty", "storage")
        if self.dataset not in ("scene", "paper"):
            raise InputError(
                f"data set must be 'scene' or 'paper', got {self.dataset!r}", "dataset"
            )

    @property
    def effective_name(self) -> str:
        return self.study_name or f"radartune-{self.model}"


@dataclass(frozen=True, slots=True, kw_only=True)
class StudyProgress:
    """A snapshot of a study (from its storage)."""

    n_complete: int = 0
    n_pruned: int = 0
    n_failed: int = 0
    n_running: int = 0
    best_loss: float = float("nan")
    best_params: dict = field(default_factory=dict)
    best_model: str = "cv"
    #: best-so-far loss against wall-clock seconds since the first trial started
    curve_t_s: np.ndarray = field(default_factory=lambda: np.zeros(0))
    curve_best: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def n_finished(self) -> int:
        return self.n_complete + self.n_pruned + self.n_failed


class StudyModel(QtCore.QObject):
    form_changed = QtCore.Signal(object)
    progress_changed = QtCore.Signal(object)
    running_changed = QtCore.Signal(bool)
    message = QtCore.Signal(str)

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.form = StudyForm()
        self.progress = StudyProgress()
        self.running = False

    def set_form(self, **changes) -> None:
        new = dataclasses.replace(self.form, **changes)  # validates (InputError)
        if new != self.form:
            self.form = new
            self.form_changed.emit(new)

    def set_progress(self, progress: StudyProgress) -> None:
        self.progress = progress
        self.progress_changed.emit(progress)

    def set_running(self, running: bool) -> None:
        if running != self.running:
            self.running = running
            self.running_changed.emit(running)


class _PollSignals(QtCore.QObject):
    done = QtCore.Signal(int, object)
    failed = QtCore.Signal(int, str)
    started = QtCore.Signal(object)
    start_failed = QtCore.Signal(str)


class _StartJob(QtCore.QRunnable):
    def __init__(self, engine, form, dataset_path, signals) -> None:
        super().__init__()
        self._engine, self._form, self._path, self._signals = engine, form, dataset_path, signals

    def run(self) -> None:
        try:
            handle = self._engine.start_study(self._form, self._path)
            self._signals.started.emit(handle)
        except Exception as exc:
            traceback.print_exc()
            self._signals.start_failed.emit(describe_error(exc))


class _PollJob(QtCore.QRunnable):
    def __init__(self, engine, form, ticket, signals) -> None:
        super().__init__()
        self._engine, self._form, self._ticket, self._signals = engine, form, ticket, signals

    def run(self) -> None:
        try:
            progress = self._engine.study_progress(self._form)
            self._signals.done.emit(self._ticket, progress)
        except Exception as exc:
            traceback.print_exc()
            self._signals.failed.emit(self._ticket, describe_error(exc))


class StudyController(QtCore.QObject):
    """Starts and stops study processes and polls their progress (never blocking the GUI)."""

    finished = QtCore.Signal()
    start_failed = QtCore.Signal(str)

    def __init__(self, engine, model: StudyModel, poll_ms: int = 500, parent=None) -> None:
        super().__init__(parent)
        self._engine = engine
        self._model = model
        self._handle = None
        self._pool = QtCore.QThreadPool(self)
        self._pool.setMaxThreadCount(1)
        self._signals = _PollSignals()
        self._signals.done.connect(self._on_progress)
        self._signals.failed.connect(self._on_poll_failed)
        self._signals.started.connect(self._on_started)
        self._signals.start_failed.connect(self._on_start_failed)
        self._starting = False
        self._timer = QtCore.QTimer(self)
        self._timer.setInterval(poll_ms)
        self._timer.timeout.connect(self._poll)
        self._ticket = 0
        self._polling = False
        self._final_poll = False
        self.dashboard_url: str | None = None
        self._dashboard = None
        self.t_started = 0.0
        self._stop_requested = False

    @property
    def running(self) -> bool:
        return self._handle is not None or self._starting

    def start(self, dataset_path: str | None = None) -> None:
        """Create the study and start its processes from a pool thread (Optuna's import and
        the study creation take seconds; the window keeps running)."""
        if self.running:
            raise InputError("a study is already running", "study")
        form = self._model.form
        Path(form.storage).expanduser().resolve().parent.mkdir(parents=True, exist_ok=True)
        self._starting = True
        self._stop_requested = False
        self._model.set_running(True)
        self._model.message.emit(f"starting study {form.effective_name} …")
        self._pool.start(_StartJob(self._engine, form, dataset_path, self._signals))

    def _on_started(self, handle) -> None:
        self._starting = False
        self._handle = handle
        self.t_started = time.perf_counter()
        form = self._model.form
        self._model.message.emit(f"study {form.effective_name} started ({form.n_jobs} process(es))")
        if self._stop_requested:
            self._handle.stop()
        self._timer.start()

    def _on_start_failed(self, message: str) -> None:
        self._starting = False
        self._model.set_running(False)
        self._model.message.emit(f"cannot start study: {message}")
        self.start_failed.emit(message)

    def stop(self) -> None:
        if self._handle is not None:
            self._handle.stop()
            self._model.message.emit("stopping study …")
        elif self._starting:
            self._stop_requested = True

    def _poll(self) -> None:
        if self._handle is not None and not self._handle.alive():
            self._handle = None
            self._final_poll = True
        if self._polling:
            return
        self._polling = True
        self._ticket += 1
        self._pool.start(_PollJob(self._engine, self._model.form, self._ticket, self._signals))

    def refresh(self) -> None:
        """Poll once (e.g. to show an existing storage)."""
        self._poll()

    def _on_progress(self, ticket: int, progress: StudyProgress) -> None:
        self._polling = False
        self._model.set_progress(progress)
        if self._final_poll:
            self._final_poll = False
            self._timer.stop()
            self._model.set_running(False)
            self._model.message.emit(
                f"study finished: {progress.n_complete} complete, {progress.n_pruned} pruned, "
                f"{progress.n_failed} failed"
            )
            self.finished.emit()

    def _on_poll_failed(self, ticket: int, message: str) -> None:
        self._polling = False
        self._model.message.emit(f"study progress: {message}")
        if self._final_poll:
            self._final_poll = False
            self._timer.stop()
            self._model.set_running(False)
            self.finished.emit()

    def enqueue(self, values: dict, model: str) -> None:
        self._engine.enqueue_trial(self._model.form, values, model)
        self._model.message.emit("current sliders enqueued as the next trial")

    def open_dashboard(self) -> str:
        if self._dashboard is None:
            self._dashboard = self._engine.serve_dashboard(self._model.form)
        return self._dashboard.url

    def shutdown(self, timeout_ms: int = 10000) -> None:
        self._timer.stop()
        self._pool.waitForDone(timeout_ms)  # a start in flight delivers its handle first
        QtCore.QCoreApplication.sendPostedEvents(self)
        if self._handle is not None:
            self._handle.stop()
            self._handle.join(timeout_ms / 1000)
            self._handle = None
        if self._dashboard is not None:
            self._dashboard.shutdown()
            self._dashboard = None
        self._pool.waitForDone(timeout_ms)

"""Study model and controller. Studies run in separate processes: the study service
(:mod:`app.study_service`, one helper process started with ``QProcess``) creates the study,
starts its worker processes through :mod:`core.optimization`, and answers progress polls; the
GUI only writes and reads JSON lines, so it never waits for a study or its storage, and Optuna
never enters the GUI process."""

from __future__ import annotations

import dataclasses
import json
import os
import sys
import tempfile
import time
from pathlib import Path

from PySide6 import QtCore

from app.data import StudyForm, StudyProgress
from core.errors import InputError

#: stderr of the study service process (tracebacks, worker start-up messages)
SERVICE_LOG = Path(tempfile.gettempdir()) / "radartune-study-service.log"


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


class StudyService(QtCore.QObject):
    """The GUI's end of :mod:`app.study_service`: a ``QProcess`` spoken to in JSON lines.

    Requests never block: :meth:`request` writes a line and returns; the answer arrives as a
    call of the given callback from the event loop.
    """

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self._proc: QtCore.QProcess | None = None
        self._buffer = b""
        self._next_id = 0
        self._callbacks: dict[int, tuple] = {}
        self.n_pending = 0

    def _ensure(self) -> QtCore.QProcess:
        if self._proc is None or self._proc.state() == QtCore.QProcess.NotRunning:
            proc = QtCore.QProcess(self)
            env = QtCore.QProcessEnvironment.systemEnvironment()
            root = str(Path(__file__).resolve().parents[1])
            old = env.value("PYTHONPATH", "")
            env.insert("PYTHONPATH", root + (os.pathsep + old if old else ""))
            proc.setProcessEnvironment(env)
            proc.setWorkingDirectory(str(Path.cwd()))
            proc.setProcessChannelMode(QtCore.QProcess.SeparateChannels)
            proc.setStandardErrorFile(str(SERVICE_LOG))
            proc.readyReadStandardOutput.connect(self._on_output)
            proc.finished.connect(self._on_finished)
            proc.start(sys.executable, ["-m", "app.study_service"])
            self._proc = proc
            self._buffer = b""
        return self._proc

    def request(self, op: str, on_result, on_error, **payload) -> None:
        proc = self._ensure()
        self._next_id += 1
        self._callbacks[self._next_id] = (on_result, on_error)
        self.n_pending += 1
        line = json.dumps({"id": self._next_id, "op": op, **payload}) + "\n"
        proc.write(line.encode())

    def _on_output(self) -> None:
        self._buffer += bytes(self._proc.readAllStandardOutput())
        *lines, self._buffer = self._buffer.split(b"\n")
        for raw in lines:
            if not raw.strip():
                continue
            try:
                msg = json.loads(raw)
            except json.JSONDecodeError:
                continue
            cbs = self._callbacks.pop(msg.get("id"), None)
            if cbs is None:
                continue
            self.n_pending -= 1
            on_result, on_error = cbs
            if msg.get("ok"):
                on_result(msg.get("result"))
            else:
                on_error(str(msg.get("error")))

    def _on_finished(self, *_args) -> None:
        pending, self._callbacks = self._callbacks, {}
        self.n_pending = 0
        for _on_result, on_error in pending.values():
            on_error(f"study service stopped (see {SERVICE_LOG})")

    def shutdown(self, timeout_ms: int = 30000) -> None:
        """Stop the study's workers and the service process (blocks: close, tests only)."""
        if self._proc is None or self._proc.state() == QtCore.QProcess.NotRunning:
            return
        self._proc.write(b'{"id": null, "op": "shutdown"}\n')
        self._proc.closeWriteChannel()
        if not self._proc.waitForFinished(timeout_ms):
            self._proc.kill()
            self._proc.waitForFinished(5000)


class StudyController(QtCore.QObject):
    """Starts, polls and stops studies through the study service (never blocking the GUI)."""

    finished = QtCore.Signal()
    start_failed = QtCore.Signal(str)

    def __init__(self, engine, model: StudyModel, poll_ms: int = 500, parent=None) -> None:
        super().__init__(parent)
        self._engine = engine
        self._model = model
        self.service = StudyService(self)
        self._timer = QtCore.QTimer(self)
        self._timer.setInterval(poll_ms)
        self._timer.timeout.connect(self._poll)
        self._running = False
        self._polling = False
        self._dashboard = None
        self.t_started = 0.0

    @property
    def running(self) -> bool:
        return self._running

    def _form_dict(self) -> dict:
        return dataclasses.asdict(self._model.form)

    def start(self, dataset_path: str | None = None) -> None:
        """Create the study and start its worker processes (in the service process)."""
        if self._running:
            raise InputError("a study is already running", "study")
        form = self._model.form
        Path(form.storage).expanduser().resolve().parent.mkdir(parents=True, exist_ok=True)
        self._running = True
        self._model.set_running(True)
        self._model.message.emit(f"starting study {form.effective_name} …")
        self.service.request(
            "start", self._on_started, self._on_start_failed,
            form=self._form_dict(), dataset=dataset_path,
        )  # fmt: skip

    def _on_started(self, _result) -> None:
        self.t_started = time.perf_counter()
        form = self._model.form
        self._model.message.emit(f"study {form.effective_name} started ({form.n_jobs} process(es))")
        self._timer.start()

    def _on_start_failed(self, message: str) -> None:
        self._running = False
        self._model.set_running(False)
        self._model.message.emit(f"cannot start study: {message}")
        self.start_failed.emit(message)

    def stop(self) -> None:
        if self._running:
            self.service.request("stop", lambda _r: None, self._model.message.emit)
            self._model.message.emit("stopping study (workers finish their current trial) …")

    def _poll(self) -> None:
        if self._polling:
            return
        self._polling = True
        self.service.request(
            "progress", self._on_progress, self._on_poll_failed, form=self._form_dict()
        )

    def refresh(self) -> None:
        """Poll once to show what an existing storage holds (no-op for a missing file)."""
        storage = self._model.form.storage
        if "://" in storage and not storage.startswith(("sqlite", "journal")):
            self._poll()
        elif Path(storage.split(":///")[-1]).expanduser().is_file():
            self._poll()

    def _on_progress(self, result: dict) -> None:
        from app.study_service import progress_from_dict

        self._polling = False
        progress = progress_from_dict(result)
        self._model.set_progress(progress)
        if self._running and not result.get("alive", False) and self._timer.isActive():
            self._timer.stop()
            self._running = False
            self._model.set_running(False)
            self._model.message.emit(
                f"study finished: {progress.n_complete} complete, {progress.n_pruned} pruned, "
                f"{progress.n_failed} failed"
            )
            self.finished.emit()

    def _on_poll_failed(self, message: str) -> None:
        self._polling = False
        self._model.message.emit(f"study progress: {message}")
        if self._running and self._timer.isActive() and "stopped" in message:
            self._timer.stop()
            self._running = False
            self._model.set_running(False)
            self.finished.emit()

    def enqueue(self, values: dict, model: str, on_error=None) -> None:
        self.service.request(
            "enqueue",
            lambda _r: self._model.message.emit("current sliders enqueued as the next trial"),
            on_error or self._model.message.emit,
            form=self._form_dict(), values=values, model=model,
        )  # fmt: skip

    def open_dashboard(self) -> str:
        if self._dashboard is None or not self._dashboard.alive():
            self._dashboard = self._engine.serve_dashboard(self._model.form)
        return self._dashboard.url

    def shutdown(self, timeout_ms: int = 30000) -> None:
        self._timer.stop()
        self.service.shutdown(timeout_ms)
        if self._dashboard is not None:
            self._dashboard.shutdown()
            self._dashboard = None

"""Background work: simulation thread, debounced re-tracking, study polling.

Workers hand frozen snapshots (:mod:`app.data`) to the GUI thread through queued signals; the
GUI thread never waits for them. Stale results (an older scene or parameter vector) are dropped.
"""

from __future__ import annotations

import math
import threading
import time
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from PySide6 import QtCore

from app.data import TrackingResult
from app.errors import log_exception, one_line
from app.models import FrameCache, TrackerParamsModel, TrackingModel
from core.errors import InputError


def freeze_heap() -> None:
    """Move every object alive now into the permanent generation (``gc.freeze``).

    A full (generation-2) collection holds the GIL and stops every thread, the GUI included;
    with Optuna, SQLAlchemy, pyqtgraph and the frame cache loaded it took 0.5–0.9 s on the
    loaded test machine. Long-lived objects frozen at a few quiet points (window built,
    simulation done, study started) keep later full collections short.
    """
    import gc

    gc.freeze()


@dataclass(frozen=True, slots=True, kw_only=True)
class FrameTiming:
    """Mean milliseconds per frame over the same frames: ``total`` = ``synthesis`` +
    ``processing`` + ``other`` (``other``: the rest of the frame's wall time, the views' maps
    and the hand-off). The parts are NaN where the level does not time them apart; all are NaN
    before a frame."""

    total: float = math.nan
    synthesis: float = math.nan
    processing: float = math.nan
    other: float = math.nan
    n_frames: int = 0


def frame_timing(times_s: Sequence[tuple[float, float, float]]) -> FrameTiming:
    """:class:`FrameTiming` of frames' (whole frame, synthesis, processing) seconds; the first
    frame, which may compile kernels, is left out once there are others. Means, not medians,
    so that the parts add up to the total over the same frames."""
    rows = list(times_s)
    if len(rows) > 1:
        rows = rows[1:]
    if not rows:
        return FrameTiming()
    a = np.array(rows, dtype=float) * 1e3
    total = float(a[:, 0].mean())
    if not np.isfinite(a[:, 1:]).all():
        return FrameTiming(total=total, n_frames=len(rows))
    synthesis, processing = float(a[:, 1].mean()), float(a[:, 2].mean())
    return FrameTiming(
        total=total,
        synthesis=synthesis,
        processing=processing,
        other=total - synthesis - processing,
        n_frames=len(rows),
    )


class SimulationWorker(QtCore.QThread):
    """Simulates a scene frame by frame; emits each frame as it is ready."""

    frame_ready = QtCore.Signal(int, object)  # generation, FrameData
    done = QtCore.Signal(int)  # generation
    failed = QtCore.Signal(int, str)

    def __init__(self, engine, scene, generation: int, parent=None) -> None:
        super().__init__(parent)
        self._engine = engine
        self._scene = scene
        self.generation = generation
        self._stop = threading.Event()
        self.fidelity = "exact"
        #: detection chain (core.config.ChainConfig; None: the paper's)
        self.chain = None
        #: (whole frame, synthesis, processing) seconds of each simulated frame, latest last:
        #: the whole frame is the wall time from asking the engine for it to having it (radar
        #: chain and the views' maps); synthesis and processing are its parts the chain timed
        #: (NaN where the level does both in one kernel)
        self.frame_times_s: deque[tuple[float, float, float]] = deque(maxlen=50)

    def stop(self) -> None:
        self._stop.set()

    def run(self) -> None:  # worker thread
        try:
            # the chain only when one was chosen (engines without chains keep working)
            extra = {} if self.chain is None else {"chain": self.chain}
            frames = self._engine.simulate(self._scene, fidelity=self.fidelity, **extra)
            t0 = time.perf_counter()
            for frame in frames:
                t1 = time.perf_counter()
                self.frame_times_s.append((t1 - t0, frame.synthesis_s, frame.processing_s))
                if self._stop.is_set():
                    return
                self.frame_ready.emit(self.generation, frame)
                t0 = time.perf_counter()
            if not self._stop.is_set():
                self.done.emit(self.generation)
        except Exception as exc:  # any failure becomes a message, never a crash
            log_exception("simulation failed", exc)
            self.failed.emit(self.generation, one_line(exc))


class SimulationController(QtCore.QObject):
    """Owns the simulation thread of the current scene and fills the :class:`FrameCache`."""

    failed = QtCore.Signal(str)
    rate_changed = QtCore.Signal(float)  # simulated frames per second

    def __init__(self, engine, cache: FrameCache, parent=None) -> None:
        super().__init__(parent)
        self._engine = engine
        self._cache = cache
        self._worker: SimulationWorker | None = None
        self._old: list[SimulationWorker] = []
        self._t_start = 0.0
        self.rate_fps = 0.0
        #: simulator level of the next start (a key of core.simulation.LEVELS)
        self.fidelity = "exact"
        #: detection chain of the next start (core.config.ChainConfig; None: the paper's)
        self.chain = None

    def start(self, scene) -> None:
        """(Re)simulate ``scene``; a running simulation of an older scene is abandoned."""
        self.stop()
        info = self._engine.scene_info(scene)
        self._cache.clear(expected=info.n_frames, truth_paths=info.truth_paths)
        worker = SimulationWorker(self._engine, scene, self._cache.generation, self)
        worker.fidelity = self.fidelity
        worker.chain = self.chain
        worker.frame_ready.connect(self._on_frame)
        worker.done.connect(self._on_done)
        worker.failed.connect(self._on_failed)
        worker.finished.connect(self._reap)
        self._worker = worker
        self._t_start = time.perf_counter()
        worker.start(QtCore.QThread.LowPriority)

    def stop(self) -> None:
        if self._worker is not None:
            self._worker.stop()
            self._old.append(self._worker)
            self._worker = None

    def _reap(self) -> None:
        for w in self._old:
            if w.isFinished():
                w.deleteLater()  # an abandoned worker that has ended: free its QThread
        self._old = [w for w in self._old if not w.isFinished()]

    def wait(self) -> bool:
        """Stop every worker and join it (close, tests); returns True when all have ended.

        There is no time-out: a worker checks its stop flag between frames, so this waits for at
        most the frame in progress. That frame can take many seconds (the first call compiles the
        numba kernels when their cache is cold, as for a new user, and the machine may be busy);
        giving up earlier let the window, the thread's parent, be destroyed under a running thread,
        which Qt answers with ``QThread: Destroyed while thread is still running`` and an abort.
        """
        self.stop()
        for w in self._old:
            w.wait()  # QDeadlineTimer.Forever
        self._reap()
        return not self._old

    @property
    def running(self) -> bool:
        return self._worker is not None and self._worker.isRunning()

    @property
    def frame_timing_ms(self) -> FrameTiming:
        """Per-frame times of the current simulation's last frames (see :func:`frame_timing`)."""
        w = self._worker or (self._old[-1] if self._old else None)
        return frame_timing(list(w.frame_times_s) if w is not None else [])

    def _on_frame(self, generation: int, frame) -> None:
        if generation != self._cache.generation:
            return  # stale: from an abandoned scene
        self._cache.append(frame)
        elapsed = time.perf_counter() - self._t_start
        if elapsed > 0:
            self.rate_fps = len(self._cache) / elapsed
            self.rate_changed.emit(self.rate_fps)

    def _on_done(self, generation: int) -> None:
        if generation == self._cache.generation:
            self._cache.mark_complete()

    def _on_failed(self, generation: int, message: str) -> None:
        if generation == self._cache.generation:
            self.failed.emit(message)


class _Signals(QtCore.QObject):
    result = QtCore.Signal(int, object)
    failed = QtCore.Signal(int, str)
    done = QtCore.Signal(int)
    compiled = QtCore.Signal()


class _TrackJob(QtCore.QRunnable):
    """One re-track: the compiled kernel recording every track (ids, ψ, status, gates) plus the
    metrics, delivered as one :class:`TrackingResult`; skipped when superseded before it runs."""

    def __init__(self, engine, frames, params, frame_period_s, key, ticket, signals, latest):
        super().__init__()
        self.setAutoDelete(True)
        self._args = (engine, frames, params, frame_period_s, key)
        self._ticket = ticket
        self._signals = signals
        self._latest = latest  # callable: the newest ticket (read across threads, an int)

    def run(self) -> None:  # pool thread
        engine, frames, params, frame_period_s, key = self._args
        try:
            if self._latest() == self._ticket:
                # the readable numpy tracker until the compiled kernel is ready (cold start)
                compiled = getattr(engine, "tracker_compiled", lambda: True)()
                kw = {} if compiled else {"engine": "numpy"}
                result = engine.track(frames, params, frame_period_s, key=key, **kw)
                self._signals.result.emit(self._ticket, result)
        except Exception as exc:
            log_exception("re-tracking failed", exc)
            self._signals.failed.emit(self._ticket, one_line(exc))
        finally:
            self._signals.done.emit(self._ticket)


class TrackingController(QtCore.QObject):
    """Re-tracks the cached point clouds when parameters or the cache change.

    Requests are debounced (``debounce_ms``); one run at a time; when a run finishes and newer
    requests arrived meanwhile, only the latest is run (older ones are dropped).
    """

    failed = QtCore.Signal(str)
    finished = QtCore.Signal(float)  # elapsed s of the re-track (tracker + overlay preparation)
    compiled = QtCore.Signal(float)  # the compiled tracker is ready (seconds it took)

    def __init__(
        self,
        engine,
        cache: FrameCache,
        params: TrackerParamsModel,
        tracking: TrackingModel,
        frame_period_s: float = 0.08,
        debounce_ms: int = 30,
        parent=None,
    ) -> None:
        super().__init__(parent)
        self._engine = engine
        self._cache = cache
        self._params = params
        self._tracking = tracking
        self.frame_period_s = frame_period_s
        self._pool = QtCore.QThreadPool(self)
        self._pool.setMaxThreadCount(1)
        self._signals = _Signals()
        self._signals.result.connect(self._on_result)
        self._signals.failed.connect(self._on_failed)
        self._signals.done.connect(self._on_done)
        self._timer = QtCore.QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setInterval(debounce_ms)
        self._timer.timeout.connect(self._launch)
        self._ticket = 0
        self._busy = False
        self._pending = False
        self.last_elapsed_s = float("nan")
        self.n_runs = 0
        params.changed.connect(self.request)
        self.compile_s = float("nan")  # seconds the compiled tracker took to load or compile
        self._warming = False

    def start_warm_up(self) -> None:
        """Load or compile the tracker kernel in a background thread (a cold start compiles for
        a minute or more); when ready, re-track with it (the numpy tracker's overlay is shown
        meanwhile). The window calls this once the first frame is simulated: two compilations
        at once share the GIL and delayed the first frame from 35 s to 171 s (app-06)."""
        warm = getattr(self._engine, "warm_up_tracker", None)
        if self._warming or warm is None or self._engine.tracker_compiled():
            return
        self._warming = True

        def run() -> None:
            try:
                self.compile_s = warm()
            except Exception as exc:  # the numpy tracker stays in use
                log_exception("compiling the tracker kernel failed", exc)
                return
            self._signals.compiled.emit()

        self._signals.compiled.connect(self._on_compiled)
        threading.Thread(target=run, name="tracker-warm-up", daemon=True).start()

    def _on_compiled(self) -> None:
        self.compiled.emit(self.compile_s)
        if self._cache.frames:
            self.request()

    def request(self) -> None:
        self._timer.start()

    def _launch(self) -> None:
        if self._busy:
            self._pending = True
            return
        frames = list(self._cache.frames)
        if not frames:
            return
        try:
            params = self._params.params()
        except InputError as exc:
            self.failed.emit(str(exc))
            return
        self._ticket += 1
        self._busy = True
        self._pending = False
        job = _TrackJob(
            self._engine,
            frames,
            params,
            self.frame_period_s,
            self._params.key(),
            self._ticket,
            self._signals,
            lambda: self._ticket,
        )
        self._pool.start(job)

    def _on_result(self, ticket: int, result: TrackingResult) -> None:
        self.last_elapsed_s = result.elapsed_s
        if ticket == self._ticket:
            self._tracking.set_result(result)
            self.n_runs += 1
            self.finished.emit(result.elapsed_s)

    def _on_failed(self, ticket: int, message: str) -> None:
        if ticket == self._ticket:
            self.failed.emit(message)

    def _on_done(self, ticket: int) -> None:
        self._busy = False
        if self._pending:
            self._pending = False
            self._launch()

    def invalidate(self) -> None:
        """Drop any run in flight (the cache was reset) and clear the overlay."""
        self._ticket += 1
        self._pending = False
        self._timer.stop()
        self._tracking.set_result(None)

    @property
    def idle(self) -> bool:
        return not self._busy and not self._timer.isActive() and not self._pending

    def wait(self, timeout_ms: int = -1) -> bool:
        """Cancel pending requests and wait for the run in flight (default: without a time-out,
        for the reason given at :meth:`SimulationController.wait`)."""
        self._timer.stop()
        self._pending = False
        return self._pool.waitForDone(timeout_ms)

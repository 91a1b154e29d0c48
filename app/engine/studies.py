"""Studies: worker processes of a study, its progress for the panel, the data set of the scene
on screen, enqueued trials and the optuna-dashboard child process. Optuna is never imported
here (studies go through :mod:`core.optimization`)."""

from __future__ import annotations

import json
import math
import os
import socket
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from app.data import FrameData
from app.engine.scenes import ROOT
from core.errors import InputError
from core.optimization.progress import busy_time_s


class StudyProcesses:
    """Handle of a running study (wraps core's ``StudyHandle``)."""

    def __init__(self, handle) -> None:
        self._handle = handle

    def alive(self) -> bool:
        return self._handle.is_running()

    def stop(self) -> None:
        # SIGTERM: each worker stops after its current trial (core handles the rest)
        import signal

        for p in self._handle.procs:
            if p.poll() is None:
                p.send_signal(signal.SIGTERM)

    def join(self, timeout_s: float) -> bool:
        if self._handle.wait(timeout_s):
            return True
        self._handle.stop(timeout=1.0)
        return not self._handle.is_running()


def storage_url(storage: str) -> str:
    """The storage's canonical URL with a file path made absolute (relative to this process's
    working folder), so that a helper process started elsewhere opens the same file."""
    from core.optimization.storage import absolute_url

    return absolute_url(storage)


def scene_dataset(frames: Sequence[FrameData], scene, path: Path) -> Path:
    """Write the cached frames of ``scene`` as a data set ``.npz`` (atomic) for a study."""
    from core.dataset import Dataset

    t_s, xy, v = scene.truth()
    n = len(frames)
    ds = Dataset.from_frames(
        clouds=[f.cloud for f in frames],
        trajectory=np.zeros(n, dtype=np.int32),
        truth_t_s=t_s[:n],
        truth_xy_m=xy[:n],
        truth_v_mps=v[:n],
        trajectory_class=[scene.trajectory_class],
        scene_json=json.dumps(scene.to_dict()),
        radar_json=json.dumps(scene.radar.to_dict()),
        seed=scene.seed,
    )
    return ds.save(path)


def start_study(form, dataset_path: str | None = None) -> StudyProcesses:
    """Create or resume the study and start its worker processes (never in the GUI thread)."""
    from core.optimization import StudySettings, loss_of_study, resolve_dataset
    from core.optimization import start_study as _start

    if dataset_path is None:
        dataset_path = resolve_dataset(None)
    url = storage_url(form.storage)
    settings = StudySettings(
        model=form.study_model,
        mode=form.mode,
        n_trials=form.n_trials,
        n_jobs=form.n_jobs,
        storage=url,
        study_name=form.effective_name,
        seed=form.seed,
        dataset=str(dataset_path),
        # a study resumed from an older storage keeps the objective it was started with
        loss=loss_of_study(url, form.effective_name),
    )
    log = Path(form.storage).expanduser().with_suffix(".workers.log")
    with open(log, "ab") as fh:
        handle = _start(settings, stdout=fh, stderr=subprocess.STDOUT)
    return StudyProcesses(handle)


def study_progress(form):
    """Read a study's trials into a :class:`app.data.StudyProgress`."""
    from app.data import StudyProgress
    from core.optimization import study_progress as _progress

    url = storage_url(form.storage)
    if url.startswith("sqlite:///") and not Path(url[len("sqlite:///") :]).is_file():
        return StudyProgress()
    summaries, best = _progress(url, form.effective_name)
    states = [s.state for s in summaries]
    done = sorted(
        (s for s in summaries if s.state == "COMPLETE" and s.value is not None),
        key=lambda s: s.datetime_complete,
    )
    if done:
        t = busy_time_s(summaries, [s.datetime_complete for s in done])
        best_curve = np.minimum.accumulate(np.array([s.value for s in done]))
    else:
        t, best_curve = np.zeros(0), np.zeros(0)
    return StudyProgress(
        failures=failure_reasons(summaries),
        n_complete=states.count("COMPLETE"),
        n_pruned=states.count("PRUNED"),
        n_failed=states.count("FAIL"),
        n_running=states.count("RUNNING"),
        best_loss=float(best.value) if best is not None else math.nan,
        best_params=dict(best.params) if best is not None else {},
        best_model=form.model,
        curve_t_s=t,
        curve_best=best_curve,
    )


def failure_reasons(summaries, n_max: int = 5) -> tuple[tuple[str, int], ...]:
    """The distinct reasons of the FAIL trials with how many trials each, most frequent first
    (at most ``n_max``); a trial without a recorded reason counts as "no reason recorded"."""
    counts: dict[str, int] = {}
    for s in summaries:
        if s.state == "FAIL":
            reason = getattr(s, "error", "") or "no reason recorded (see the workers' log)"
            counts[reason] = counts.get(reason, 0) + 1
    return tuple(sorted(counts.items(), key=lambda kv: (-kv[1], kv[0]))[:n_max])


def enqueue_trial(form, values: dict[str, float], model: str) -> None:
    """Queue ``values`` (flat, of the form's tracker with motion model ``model``) as the
    study's next trial."""
    from core.optimization import enqueue_params
    from core.tracking.space import tracker_params_dict

    study_model = "gtrack" if form.tracker == "gtrack" else model
    enqueue_params(
        storage_url(form.storage),
        form.effective_name,
        tracker_params_dict(values, study_model, form.mode),
    )


class Dashboard:
    """optuna-dashboard for a storage: ``radartune dashboard`` (core's server, which creates the
    schema first) in a child process on a free local port, so the GUI never serves HTTP."""

    def __init__(self, storage: str) -> None:
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            self.port = s.getsockname()[1]
        self.url = f"http://127.0.0.1:{self.port}/"
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")]).rstrip(
            os.pathsep
        )
        cmd = [sys.executable, "-m", "core.cli", "dashboard", "--storage", storage]
        cmd += ["--port", str(self.port), "--no-browser"]
        # the storage is an absolute URL (serve_dashboard); the process runs in the temporary
        # folder, never in the install folder, so nothing it may write lands in the checkout
        self._proc = subprocess.Popen(
            cmd,
            cwd=tempfile.gettempdir(),
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )

    def alive(self) -> bool:
        return self._proc.poll() is None

    def shutdown(self) -> None:
        if self._proc.poll() is None:
            self._proc.terminate()
            try:
                self._proc.wait(5)
            except subprocess.TimeoutExpired:
                self._proc.kill()
                self._proc.wait(5)


def serve_dashboard(form) -> Dashboard:
    url = storage_url(form.storage)
    if url.startswith("sqlite:///") and not Path(url[len("sqlite:///") :]).is_file():
        raise InputError("no study in this storage yet (start one first)", form.storage)
    return Dashboard(url)

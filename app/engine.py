"""The app's only door into :mod:`core`: scenes, simulation, tracking, studies.

Qt-free: every function here can run in a worker thread. It adapts core results into the
frozen snapshots of :mod:`app.data`, so that views draw and never compute. Optuna is never
imported here (studies go through :mod:`core.optimization`).
"""

from __future__ import annotations

import json
import math
import os
import socket
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from app.data import FrameData, ParamSpec, TrackFrame, TrackingResult
from core.config import RadarConfig
from core.errors import InputError

ROOT = Path(__file__).resolve().parents[1]
PAPER_SCENE_FILE = ROOT / "resources" / "scenes" / "paper_class_c.json"

#: The paper scene (SPEC §6 example, one person of class c): used when the resource is missing.
PAPER_SCENE_DOCUMENT = {
    "schema_version": 1,
    "radar": "paper",
    "seed": 7,
    "clutter_density_per_m2": 0.02,
    "aoi": {"min_range_m": 0.5, "max_range_m": 10.0, "max_azimuth_deg": 60.0},
    "static_reflectors": [],
    "persons": [{"trajectory": {"class": "c", "seed": 3}}],
}

#: Non-optimised TrackerParams fields the tracker panel edits.
EXTRA_FIELDS = ("p_g", "confirm_threshold", "delete_threshold", "clutter_density")


@dataclass(frozen=True, slots=True, kw_only=True)
class SceneInfo:
    """What the views need of a scene before any frame is simulated."""

    n_frames: int
    frame_period_s: float
    truth_paths: tuple[np.ndarray, ...]  # per person (F_i, 2), m
    reflectors_xy_m: np.ndarray  # (n, 2)
    aoi: dict
    radar: RadarConfig


@dataclass(frozen=True, slots=True, kw_only=True)
class ClassParamSpec:
    """A trajectory-class parameter the scene editor offers (float-valued)."""

    name: str
    label: str
    unit: str
    low: float
    high: float
    step: float
    decimals: int
    help: str = ""


def describe(exc: BaseException) -> str:
    """One line for the user: an InputError as is, anything else with its type."""
    if isinstance(exc, InputError):
        return str(exc)
    return f"{type(exc).__name__}: {exc}"


# ---- scenes -----------------------------------------------------------------------------------
def paper_document() -> dict:
    """The app's default scene: the paper scene (``resources/scenes/paper_class_c.json``) with
    the default person model (a walking body, decision scene-07) where its file names none."""
    from core.scene.scene import DEFAULT_PERSON_MODEL

    if PAPER_SCENE_FILE.is_file():
        doc = json.loads(PAPER_SCENE_FILE.read_text())
    else:
        doc = json.loads(json.dumps(PAPER_SCENE_DOCUMENT))
    for person in doc.get("persons", []):
        person.setdefault("model", DEFAULT_PERSON_MODEL)
    return doc


def scene_from_document(doc: dict, base_dir: Path, source: str | None = None):
    """Validate a scene document with :mod:`core.scene`; raises :class:`InputError` naming
    ``source`` (the file) and the field."""
    from core.scene import Scene

    return Scene.from_dict(doc, source=source, base_dir=base_dir)


def scene_info(scene) -> SceneInfo:
    paths = tuple(np.asarray(p.trajectory.position_m, dtype=float) for p in scene.persons)
    refl = np.array([[r.x_m, r.y_m] for r in scene.static_reflectors], dtype=float).reshape(-1, 2)
    return SceneInfo(
        n_frames=scene.n_frames,
        frame_period_s=scene.radar.frame_period_s,
        truth_paths=paths,
        reflectors_xy_m=refl,
        aoi=scene.aoi.to_dict(),
        radar=scene.radar,
    )


def default_aoi() -> dict:
    from core.scene import AOI

    return AOI().to_dict()


_CLASS_PARAM_UI = {
    # name: label, unit, step, decimals, help
    "speed_mps": ("speed", "m/s", 0.05, 2, "walking speed"),
    "start_x_m": ("start x", "m", 0.1, 2, "start position x (needs start y too)"),
    "start_y_m": ("start y", "m", 0.1, 2, "start position y (needs start x too)"),
    "duration_s": ("duration", "s", 0.5, 1, "length of the walk"),
    "turn_rate_hz": ("turn rate", "1/s", 0.05, 2, "mean number of turns per second (c, d)"),
    "stop_rate_hz": ("stop rate", "1/s", 0.05, 2, "mean number of stops per second (d)"),
    "radius_m": ("circle radius", "m", 0.1, 2, "radius of the circle (e)"),
}


def class_param_specs() -> list[ClassParamSpec]:
    """Float parameters of the trajectory classes (union over a–e), from core's table."""
    from core.scene import CLASS_PARAMETERS

    bounds: dict[str, tuple[float, float]] = {}
    for params in CLASS_PARAMETERS.values():
        for name, (kind, lo, hi) in params.items():
            if kind is float and name in _CLASS_PARAM_UI:
                bounds[name] = (lo, hi)
    out = []
    for name, (label, unit, step, dec, help_) in _CLASS_PARAM_UI.items():
        if name in ("start_x_m", "start_y_m"):
            lo, hi = -100.0, 100.0
        elif name in bounds:
            lo, hi = bounds[name]
        else:
            continue
        out.append(
            ClassParamSpec(
                name=name,
                label=label,
                unit=unit,
                low=lo,
                high=hi,
                step=step,
                decimals=dec,
                help=help_,
            )
        )
    return out


def class_param_names(trajectory_class: str) -> set[str]:
    """Parameters (as the editor names them) that class ``trajectory_class`` accepts."""
    from core.scene import CLASS_PARAMETERS

    names = set(CLASS_PARAMETERS.get(trajectory_class, {}))
    if "start_m" in names:
        names |= {"start_x_m", "start_y_m"}
    return names


# ---- tracker parameters -------------------------------------------------------------------------
def param_specs(model: str) -> list[ParamSpec]:
    """Sliders: the search space of eq. (15) for ``model`` (bounds, log flags, labels from core)."""
    from core.tracking.space import search_space

    return [
        ParamSpec(
            name=p.name,
            low=p.low,
            high=p.high,
            log=p.log,
            label=p.label,
            unit=p.unit,
            title=f"{p.symbol} {p.meaning}",
        )
        for p in search_space(model)
    ]


def _tracker_params_class():
    from core.tracking import TrackerParams

    return TrackerParams


def default_values(model: str) -> dict[str, float]:
    """The table's defaults as flat search-space values (all inside the bounds)."""
    from core.tracking.space import defaults

    return defaults(model)


def default_extra() -> dict:
    tp = _tracker_params_class()()
    return {k: getattr(tp, k) for k in EXTRA_FIELDS}


def make_params(model: str, values: dict[str, float], extra: dict | None = None):
    """Flat values + fixed settings → core ``TrackerParams`` (validated; InputError if bad)."""
    from core.optimization import tracker_params_dict

    d = tracker_params_dict(values, model)
    d.update(extra or {})
    return _tracker_params_class().from_dict(d)


# ---- simulation -------------------------------------------------------------------------------
def simulate(scene, *, fidelity: str = "exact") -> Iterator[FrameData]:
    """Simulate the scene frame by frame through the radar chain (GUI plan: range-Doppler
    maps kept), yielding snapshots as they are ready."""
    from core import pipeline

    the_plan = pipeline.plan(scene, fidelity=fidelity, consumer="gui")
    settings = pipeline.processing_settings(scene)
    for fr in pipeline.iter_frames(scene, the_plan=the_plan):
        truth = np.asarray(fr.truth_xy_m, dtype=float).reshape(-1, 2)
        yield FrameData(
            index=fr.index,
            t_s=fr.t_s,
            cloud=fr.point_cloud,
            truth_xy_m=truth,
            rd_map_db=fr.rd_map_db,
            detections=np.asarray(fr.detections).reshape(-1, 2),
            ra_map_db=fr.ra_map_db,
            synthesis_s=fr.synthesis_s,
            processing_s=fr.processing_s,
            **frame_views(fr.rd_map_db, truth, scene.radar, settings),
        )


def frame_views(rd_map_db, truth_xy_m: np.ndarray, radar: RadarConfig, settings) -> dict:
    """What the range profile and the micro-Doppler views draw of one frame's map: the CFAR
    threshold of every cell in dB (``cfar_threshold_db``) and the Doppler spectrum at each
    person's range (``person_doppler_db``); both ``None`` without a map."""
    if rd_map_db is None:
        return {"cfar_threshold_db": None, "person_doppler_db": None}
    from core.processing import two_stage_thresholds
    from core.processing.micro_doppler import micro_doppler

    rd = np.asarray(rd_map_db)
    # the map's power back from dB: P = 10^(dB/10)
    th = two_stage_thresholds(10.0 ** (rd.astype(np.float64) / 10.0), radar, settings)
    with np.errstate(divide="ignore", invalid="ignore"):
        th_db = (10.0 * np.log10(th.combined)).astype(np.float32)
    # R = |(x, y)| (the persons walk on the floor: z = 0)
    ranges = np.hypot(truth_xy_m[:, 0], truth_xy_m[:, 1])
    cuts = [
        micro_doppler(rd[None], ranges[i : i + 1], radar).power_db[0] for i in range(len(ranges))
    ]
    person_db = np.array(cuts, dtype=np.float32).reshape(len(ranges), rd.shape[1])
    return {"cfar_threshold_db": th_db, "person_doppler_db": person_db}


def fidelity_levels() -> list[str]:
    """Simulator levels, most faithful first (the keys of ``core.simulation.LEVELS``)."""
    from core.simulation import LEVELS

    return list(LEVELS)


def processing_settings(scene) -> dict:
    """The processing chain's settings for ``scene`` (windows, CFAR stages, ranges) as JSON."""
    from core.pipeline import processing_settings as _settings

    return _settings(scene).to_dict()


# ---- tracking ---------------------------------------------------------------------------------
def _truth0(frames: Sequence[FrameData]) -> np.ndarray:
    return np.array(
        [f.truth_xy_m[0] if len(f.truth_xy_m) else (np.nan, np.nan) for f in frames], dtype=float
    ).reshape(-1, 2)


def _people(frames: Sequence[FrameData], track_frames) -> Any:
    """Several-person metrics of the run (:func:`core.evaluation.people.people_run`); None
    without persons."""
    from core.evaluation.people import people_run
    from core.tracking.batch import ConfirmedTracks

    n_persons = max((len(f.truth_xy_m) for f in frames), default=0)
    if n_persons == 0:
        return None
    truth = np.full((len(frames), n_persons, 2), np.nan)
    for k, f in enumerate(frames):
        truth[k, : len(f.truth_xy_m)] = f.truth_xy_m
    return people_run(truth, ConfirmedTracks.from_frames(track_frames))


def _ospa_per_frame(frames: Sequence[FrameData], confirmed_xy: Sequence[np.ndarray]) -> np.ndarray:
    """OSPA (c = 1 m, p = 2) between confirmed tracks and the persons present, per frame."""
    from core.evaluation import ospa

    out = np.zeros(len(frames))
    for k, (f, xy) in enumerate(zip(frames, confirmed_xy)):
        truth = f.truth_xy_m[np.isfinite(f.truth_xy_m).all(axis=1)]
        out[k] = ospa(xy, truth)
    return out


#: set once the compiled tracker kernel is loaded or compiled (:func:`warm_up_tracker`)
TRACKER_COMPILED = threading.Event()


def warm_up_tracker() -> float:
    """Load (or, on a cold cache, compile) the compiled tracker kernel on a two-frame problem;
    run in a background thread at start. Until it returns, :func:`track` uses the readable numpy
    tracker (the same result to round-off). Returns the seconds it took."""
    from core.tracking import TrackerParams, run_tracker

    t0 = time.perf_counter()
    z = np.array([[3.0, 0.1, 0.5], [3.04, 0.1, 0.5]])
    run_tracker((z, np.array([0, 1, 2])), TrackerParams(), 0.08, keep_tracks=True, engine="numba")
    TRACKER_COMPILED.set()
    return time.perf_counter() - t0


def tracker_compiled() -> bool:
    return TRACKER_COMPILED.is_set()


def track(
    frames: Sequence[FrameData],
    params,
    frame_period_s: float,
    *,
    key: str = "",
    engine: str = "numba",
) -> TrackingResult:
    """Re-track the cached point clouds with the compiled kernel, recording every track of every
    frame (ids, ψ, status, gates), and prepare everything the overlay draws, in one step.

    ``run_tracker(..., engine="numba")``: the readable tracker's result (equal to round-off) in
    milliseconds. The loss follows eqs. (12)–(13) against person 0 (the paper's single-person
    scenes). ``engine="numpy"``: the readable tracker (the GUI's choice until
    :data:`TRACKER_COMPILED` is set, so that a cold start shows tracks while numba compiles).
    """
    from core.tracking import run_tracker

    t0 = time.perf_counter()
    counts = np.array([len(f.cloud) for f in frames], dtype=np.int64)
    z = (
        np.concatenate([f.cloud.measurements() for f in frames])
        if len(frames)
        else np.zeros((0, 3))
    )
    f_off = np.concatenate(([0], np.cumsum(counts))).astype(np.int64)
    res = run_tracker((z, f_off), params, frame_period_s, keep_tracks=True, engine=engine)
    tfs, conf_list = [], []
    ids_l, t_l, xy_l, psi_l, conf_l = [], [], [], [], []
    for k, ft in enumerate(res.frames):
        xy = np.asarray(ft.state, dtype=float)[:, :2].reshape(-1, 2)
        confirmed = np.asarray(ft.confirmed, dtype=bool)
        tfs.append(track_frame(ft))
        conf_list.append(xy[confirmed])
        ids_l.append(np.asarray(ft.ids, dtype=np.int64))
        t_l.append(np.full(len(ft.ids), k, dtype=np.int64))
        xy_l.append(xy)
        psi_l.append(np.asarray(ft.psi, dtype=float))
        conf_l.append(confirmed)
    ids = np.concatenate(ids_l) if ids_l else np.zeros(0, dtype=np.int64)
    t_idx = np.concatenate(t_l) if t_l else np.zeros(0, dtype=np.int64)
    xy_all = np.concatenate(xy_l) if xy_l else np.zeros((0, 2))
    psi = np.concatenate(psi_l) if psi_l else np.zeros(0)
    conf = np.concatenate(conf_l) if conf_l else np.zeros(0, dtype=bool)
    order = np.lexsort((t_idx, ids))
    ids, t_idx, xy_all, psi, conf = ids[order], t_idx[order], xy_all[order], psi[order], conf[order]
    breaks = np.flatnonzero(np.diff(ids)) + 1
    psi_t = np.insert(t_idx * frame_period_s, breaks, np.nan)
    psi_v = np.insert(psi, breaks, np.nan)
    psi_c = np.insert(np.where(conf, psi, np.nan), breaks, np.nan)
    has = np.asarray(res.has_estimate, dtype=bool)
    est = np.where(has[:, None], np.asarray(res.estimate_xy, dtype=float), np.nan)
    truth0 = _truth0(frames)
    loss, rmse = running_loss(est, has, truth0)
    return TrackingResult(
        people=_people(frames, res.frames),
        frames=tuple(tfs),
        estimate_xy_m=est,
        truth_xy_m=truth0,
        running_loss=loss,
        running_rmse_m=rmse,
        ospa_m=_ospa_per_frame(frames, conf_list),
        psi_t_s=psi_t,
        psi_value=psi_v,
        psi_confirmed_t_s=psi_t,
        psi_confirmed_value=psi_c,
        trail_t_index=t_idx,
        trail_xy_m=xy_all,
        trail_id=ids,
        params_key=key,
        elapsed_s=time.perf_counter() - t0,
        engine=engine,
    )


def track_frame(ft) -> TrackFrame:
    """A core ``FrameTracks`` as the overlay and the track table draw it.

    ``n_associated`` and ``nis`` are taken when the tracker reports them (attributes of the same
    names, per track); otherwise −1 and NaN.
    """
    n = len(ft.ids)
    state = np.asarray(ft.state, dtype=float)
    # the state dimension from the array itself: reshape(0, -1) cannot infer it for a frame
    # without tracks (a recording that starts with empty frames)
    d = state.shape[-1] if state.ndim == 2 else (state.size // n if n else 4)
    state = state.reshape(n, d)
    cov = np.asarray(ft.covariance, dtype=float).reshape(n, d, d)
    n_assoc = getattr(ft, "n_associated", None)
    nis = getattr(ft, "nis", None)
    return TrackFrame(
        track_id=np.asarray(ft.ids, dtype=np.int64),
        xy_m=state[:, :2],
        gate_center_xy_m=np.asarray(ft.gate_center_xy, dtype=float).reshape(-1, 2),
        gate_shape_xy_m2=np.asarray(ft.gate_shape_xy, dtype=float).reshape(-1, 2, 2),
        psi=np.asarray(ft.psi, dtype=float),
        confirmed=np.asarray(ft.confirmed, dtype=bool),
        velocity_xy_mps=state[:, 2:4],
        # sigma_x = sqrt(P_xx), sigma_y = sqrt(P_yy)
        sigma_xy_m=np.sqrt(np.maximum(cov[:, [0, 1], [0, 1]], 0.0)),
        birth_frame=np.asarray(ft.birth_frame, dtype=np.int64),
        n_associated=(
            np.full(n, -1, dtype=np.int64) if n_assoc is None else np.asarray(n_assoc, np.int64)
        ),
        nis=np.full(n, np.nan) if nis is None else np.asarray(nis, dtype=float),
    )


def running_loss(
    estimate_xy: np.ndarray, has_estimate: np.ndarray, truth_xy: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Eq. (13) and the RMSE over frames ``0..k`` for every k.

    Returns
    -------
    loss
        ``(F,)`` L_k = MSE_k / N_c,k in m² (1.0 m² while N_c,k = 0, as SPEC §5 decides).
    rmse
        ``(F,)`` sqrt(MSE_k) in m (NaN while N_c,k = 0).
    """
    has = np.asarray(has_estimate, dtype=bool) & np.isfinite(truth_xy).all(axis=1)
    e = np.where(has[:, None], np.nan_to_num(estimate_xy) - np.nan_to_num(truth_xy), 0.0)
    # MSE_k = (1/N_c,k) Σ_{j≤k} |x̂_j − x_j|²  over frames with an estimate
    n_c = np.cumsum(has)
    sse = np.cumsum(np.sum(e * e, axis=1))
    with np.errstate(invalid="ignore", divide="ignore"):
        mse = np.where(n_c > 0, sse / np.maximum(n_c, 1), np.nan)
        # L_k = MSE_k / N_c,k
        loss = np.where(n_c > 0, mse / np.maximum(n_c, 1), 1.0)
    return loss, np.sqrt(mse)


# ---- radar files --------------------------------------------------------------------------------
def read_ti_cfg(path: str | os.PathLike) -> RadarConfig:
    from core.formats.ti_cfg import read_ti_cfg as _read

    return _read(path)


# ---- studies ----------------------------------------------------------------------------------
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
        model=form.model,
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
    starts = [s.datetime_start for s in summaries if s.datetime_start is not None]
    if done and starts:
        t0 = min(starts)
        t = np.array([(s.datetime_complete - t0).total_seconds() for s in done])
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
    from core.optimization import enqueue_params, tracker_params_dict

    enqueue_params(
        storage_url(form.storage), form.effective_name, tracker_params_dict(values, model)
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


class Engine:
    """The functions above as one object (tests may substitute parts of it)."""

    paper_document = staticmethod(paper_document)
    scene_from_document = staticmethod(scene_from_document)
    scene_info = staticmethod(scene_info)
    default_aoi = staticmethod(default_aoi)
    class_param_specs = staticmethod(class_param_specs)
    class_param_names = staticmethod(class_param_names)
    param_specs = staticmethod(param_specs)
    default_values = staticmethod(default_values)
    default_extra = staticmethod(default_extra)
    make_params = staticmethod(make_params)
    simulate = staticmethod(simulate)
    fidelity_levels = staticmethod(fidelity_levels)
    processing_settings = staticmethod(processing_settings)
    track = staticmethod(track)
    warm_up_tracker = staticmethod(warm_up_tracker)
    tracker_compiled = staticmethod(tracker_compiled)
    read_ti_cfg = staticmethod(read_ti_cfg)
    scene_dataset = staticmethod(scene_dataset)
    start_study = staticmethod(start_study)
    study_progress = staticmethod(study_progress)
    enqueue_trial = staticmethod(enqueue_trial)
    serve_dashboard = staticmethod(serve_dashboard)


__all__ = [
    "ClassParamSpec",
    "Dashboard",
    "Engine",
    "SceneInfo",
]

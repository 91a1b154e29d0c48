"""Tracking: the tracker panel's parameters as core ``TrackerParams``, the compiled tracker's
warm-up, and a re-track of the cached point clouds prepared for the overlay."""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from app.data import FrameData, ParamSpec, TrackFrame, TrackingResult
from core.errors import InputError
from core.tracking.history import TrackCurves, TrackHistory

#: Non-optimised TrackerParams fields the tracker panel edits.
EXTRA_FIELDS = ("p_g", "confirm_threshold", "delete_threshold", "clutter_density")
#: The trackers the app switches between: the paper's one-point IPDA, RadarTune's tracker for
#: real rooms (:mod:`core.tracking.room`) and TI's people tracker rebuilt (gtrack).
TRACKERS = ("paper", "room", "gtrack")


def param_specs(model: str, mode: str = "paper") -> list[ParamSpec]:
    """Sliders: the search space of ``model`` in ``mode`` (``model="gtrack"``: gtrack's table;
    bounds, log flags, labels from core)."""
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
        for p in search_space(model, mode)
    ]


def _tracker_params_class():
    from core.tracking import TrackerParams

    return TrackerParams


def default_values(model: str, mode: str = "paper") -> dict[str, float]:
    """The table's defaults as flat search-space values (all inside the bounds)."""
    from core.tracking.space import defaults

    return defaults(model, mode)


def default_extra() -> dict:
    tp = _tracker_params_class()()
    return {k: getattr(tp, k) for k in EXTRA_FIELDS}


def make_params(
    model: str, values: dict[str, float], extra: dict | None = None, mode: str = "paper"
):
    """Flat values + fixed settings → core ``TrackerParams`` of ``mode`` (validated; InputError
    if bad); ``model="gtrack"``: a ``GtrackParams`` (the fixed settings are the IPDA's, unused)."""
    from core.tracking.space import GTRACK, tracker_params_dict

    if model == GTRACK:
        from core.tracking.gtrack import GtrackParams

        return GtrackParams.from_dict(tracker_params_dict(values, GTRACK))
    return _tracker_params_class().from_dict(
        {**tracker_params_dict(values, model, mode), **(extra or {})}
    )


def load_params(path: str | os.PathLike) -> tuple[str, dict[str, float], dict]:
    """A tracker parameter file read by core (:meth:`TrackerParams.load`: errors name the file)
    as the tracker panel holds it: the model, the flat search-space values and the
    non-optimised settings the panel edits (:data:`EXTRA_FIELDS`)."""
    from core.tracking.space import flat_params

    d = _tracker_params_class().load(path).to_dict()
    try:
        values = flat_params(d)
    except InputError as exc:
        raise InputError(exc.message, str(path)) from None
    return d["model"], values, {k: d[k] for k in EXTRA_FIELDS}


def load_tracker_file(path: str | os.PathLike) -> tuple[str, str, dict[str, float], dict]:
    """A tracker parameter file of any of the app's trackers: (tracker, model, flat values,
    fixed settings). A gtrack file (``GtrackParams`` JSON, recognised by
    :func:`core.tracking.space.flat_params`) is ``("gtrack", "cv", values, {})``; a
    ``TrackerParams`` file is ``(its mode, its model, ...)`` as :func:`load_params` reads it."""
    from core.files import read_json
    from core.tracking.space import GTRACK, flat_params, search_space

    doc = read_json(Path(path), what="tracker parameters")
    if isinstance(doc, dict) and "model" not in doc and "mode" not in doc:
        try:
            flat = flat_params(doc)
        except InputError:
            flat = {}
        if set(flat) == {p.name for p in search_space(GTRACK)}:
            from core.tracking.gtrack import GtrackParams

            values = flat_params(GtrackParams.load(path).to_dict())  # validated, file named
            return GTRACK, "cv", values, {}
    model, values, extra = load_params(path)
    return _tracker_params_class().load(path).mode, model, values, extra


def curve_fields(curves: TrackCurves) -> dict[str, np.ndarray]:
    """The trails and ψ curves as :class:`~app.data.TrackingResult` fields."""
    return {
        "psi_t_s": curves.psi_t_s,
        "psi_value": curves.psi_value,
        "psi_confirmed_t_s": curves.psi_t_s,
        "psi_confirmed_value": curves.psi_confirmed_value,
        "trail_t_index": curves.trail_t_index,
        "trail_xy_m": curves.trail_xy_m,
        "trail_id": curves.trail_id,
    }


def _truth0(frames: Sequence[FrameData]) -> np.ndarray:
    return np.array(
        [f.truth_xy_m[0] if len(f.truth_xy_m) else (np.nan, np.nan) for f in frames], dtype=float
    ).reshape(-1, 2)


def running_pair_rmse(error_p: np.ndarray, p: float) -> np.ndarray:
    """Running position RMSE (m) over frames ``0..k`` of several persons, each scored against
    the track GOSPA pairs with it (``error_p``: ``(N, P)`` ‖x̂ − x‖^p, NaN where unpaired, from
    :func:`core.evaluation.people.frame_metrics`); NaN while no pair yet. With two people the
    one scene estimate against person 0 read 2–5 m while each was tracked to 0.1 m."""
    e2 = np.abs(np.asarray(error_p, dtype=float)) ** (2.0 / p)
    ok = np.isfinite(e2)
    total = np.cumsum(np.where(ok, e2, 0.0).sum(axis=1))
    count = np.cumsum(ok.sum(axis=1))
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, np.sqrt(total / np.maximum(count, 1)), np.nan)


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
    from core.evaluation import ospa_per_frame, running_trajectory_loss

    t0 = time.perf_counter()
    res, velocity_col = _run(frames, params, frame_period_s, engine)
    tfs, conf_list = [], []
    for ft in res.frames:
        tf = track_frame(ft, velocity_col=velocity_col)
        tfs.append(tf)
        conf_list.append(tf.xy_m[tf.confirmed])
    curves = TrackHistory.of_frames(res.frames).curves(frame_period_s)
    has = np.asarray(res.has_estimate, dtype=bool)
    est = np.where(has[:, None], np.asarray(res.estimate_xy, dtype=float), np.nan)
    truth0 = _truth0(frames)
    loss, rmse = running_trajectory_loss(est, has, truth0)
    people = _people(frames, res.frames)
    if people is not None and len(people.persons) > 1:
        rmse = running_pair_rmse(people.frames.gospa_error2, people.frames.p)
    return TrackingResult(
        people=people,
        frames=tuple(tfs),
        estimate_xy_m=est,
        truth_xy_m=truth0,
        running_loss=loss,
        running_rmse_m=rmse,
        ospa_m=ospa_per_frame(conf_list, [f.truth_xy_m for f in frames]),
        **curve_fields(curves),
        params_key=key,
        elapsed_s=time.perf_counter() - t0,
        engine=engine,
    )


#: the room and gtrack kernels compiled (or loaded from numba's cache) so far; until then
#: :func:`track` runs their readable form (the same result) while a thread compiles them, so
#: that a first switch shows tracks at once instead of after a compilation of a minute or two
_COMPILED: set[str] = set()
_WARMING: set[str] = set()
_WARM_LOCK = threading.Lock()


def _kernel_ready(kind: str, warm) -> bool:
    """True once ``kind``'s compiled kernel is ready; else start ``warm()`` in a thread."""
    with _WARM_LOCK:
        if kind in _COMPILED:
            return True
        if kind not in _WARMING:
            _WARMING.add(kind)

            def run() -> None:
                warm()
                with _WARM_LOCK:
                    _COMPILED.add(kind)

            threading.Thread(target=run, name=f"warm-{kind}", daemon=True).start()
    return False


def _warm_points() -> tuple[np.ndarray, np.ndarray]:
    """Two frames of one point ``[r, az, el, vr, snr]``: a problem small enough to compile on."""
    pts = np.array([[3.0, 0.1, 0.0, 0.5, 100.0], [3.04, 0.1, 0.0, 0.5, 100.0]])
    return pts, np.array([0, 1, 2], dtype=np.int64)


def _warm_gtrack() -> None:
    from core.tracking.gtrack import GtrackParams
    from core.tracking.gtrack.compiled import run_gtrack_compiled

    run_gtrack_compiled(*_warm_points(), GtrackParams())


def _warm_room() -> None:
    from core.tracking import TrackerParams
    from core.tracking.room import room_points, run_room_tracker

    p, off = _warm_points()
    pts = room_points(p[:, 0], p[:, 1], p[:, 3], np.zeros(2), p[:, 0], np.zeros(2), p[:, 4])
    run_room_tracker((pts, off), TrackerParams(mode="room"), 0.08, engine="numba")


class _Run:
    """What :func:`track` reads of a tracker's result (gtrack's has no estimate arrays)."""

    def __init__(self, frames) -> None:
        self.frames = frames
        n = len(frames)
        self.has_estimate = np.zeros(n, dtype=bool)
        self.estimate_xy = np.full((n, 2), np.nan)
        for k, ft in enumerate(frames):
            if ft.estimate >= 0:
                self.has_estimate[k] = True
                self.estimate_xy[k] = np.asarray(ft.state, dtype=float)[ft.estimate, :2]


def _run(frames: Sequence[FrameData], params, frame_period_s: float, engine: str):
    """Run the tracker ``params`` belong to over the cached frames: (result, the first velocity
    column of its state)."""
    import dataclasses

    from core.tracking import run_tracker
    from core.tracking.gtrack import GtrackParams

    counts = np.array([len(f.cloud) for f in frames], dtype=np.int64)
    f_off = np.concatenate(([0], np.cumsum(counts))).astype(np.int64)
    clouds = [f.cloud for f in frames]

    def column(name: str) -> np.ndarray:
        return np.concatenate([getattr(c, name) for c in clouds]) if clouds else np.zeros(0)

    if isinstance(params, GtrackParams):
        from core.limits import FRAME_PERIOD_RANGE_S

        lo, hi = FRAME_PERIOD_RANGE_S
        if lo <= frame_period_s <= hi:  # the cfg's trackingCfg frame period is the data's
            params = dataclasses.replace(params, frame_period_s=frame_period_s)
        points = np.column_stack(
            [column("range_m"), column("azimuth_rad"), column("elevation_rad"),
             column("radial_velocity_mps"), 10.0 ** (column("snr_db") / 10.0)]
        ).reshape(-1, 5)  # fmt: skip
        if engine == "numba" and _kernel_ready("gtrack", _warm_gtrack):
            from core.tracking.gtrack.compiled import run_gtrack_compiled as run
        else:
            from core.tracking.gtrack import run_gtrack as run
        return _Run(run(points, f_off, params).frames), params.dims
    if getattr(params, "mode", "paper") == "room":
        from core.tracking.room import room_points, run_room_tracker

        pts = room_points(
            *(column(n) for n in ("range_m", "azimuth_rad", "radial_velocity_mps", "x_m",
                                  "y_m", "z_m", "snr_db"))
        )  # fmt: skip
        if engine == "numba" and not _kernel_ready("room", _warm_room):
            engine = "numpy"
        return run_room_tracker((pts, f_off), params, frame_period_s, engine=engine), 2
    z = np.concatenate([c.measurements() for c in clouds]) if clouds else np.zeros((0, 3))
    return run_tracker((z, f_off), params, frame_period_s, keep_tracks=True, engine=engine), 2


def track_frame(ft, *, velocity_col: int = 2) -> TrackFrame:
    """A core ``FrameTracks`` as the overlay and the track table draw it (the velocity is
    ``state[:, velocity_col : velocity_col + 2]``: 2 for the IPDA's, 3 for 3-D gtrack's).

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
        velocity_xy_mps=state[:, velocity_col : velocity_col + 2],
        # sigma_x = sqrt(P_xx), sigma_y = sqrt(P_yy)
        sigma_xy_m=np.sqrt(np.maximum(cov[:, [0, 1], [0, 1]], 0.0)),
        birth_frame=np.asarray(ft.birth_frame, dtype=np.int64),
        n_associated=(
            np.full(n, -1, dtype=np.int64) if n_assoc is None else np.asarray(n_assoc, np.int64)
        ),
        nis=np.full(n, np.nan) if nis is None else np.asarray(nis, dtype=float),
    )

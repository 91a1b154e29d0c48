"""Tracking: the tracker panel's parameters as core ``TrackerParams``, the compiled tracker's
warm-up, and a re-track of the cached point clouds prepared for the overlay."""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from app.data import FrameData, ParamSpec, TrackFrame, TrackingResult
from core.errors import InputError

#: Non-optimised TrackerParams fields the tracker panel edits.
EXTRA_FIELDS = ("p_g", "confirm_threshold", "delete_threshold", "clutter_density")


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
    from core.tracking.space import tracker_params_dict

    return _tracker_params_class().from_dict(
        {**tracker_params_dict(values, model), **(extra or {})}
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

"""The IPDA multi-track tracker (SPEC §4), readable reference: it composes the role modules.

Per frame: predict every track (motion model, existence eq. 9) → gate the measurements →
association and update: IPDA per track, or with ``association="jipda"`` joint IPDA over the
clusters of tracks that share validated measurements (:mod:`core.tracking.jipda`; a lone track
gets the IPDA update) → initiate tentative tracks from the
measurements outside all gates → confirm → delete → merge → cap → single-person estimate.

This path is plain numpy (one track at a time) and serves the GUI (every track per frame) and the
tests; :mod:`core.tracking.kernel` runs the same algorithm compiled for Optuna. Result types:
:mod:`core.tracking.results`; input validation and derived constants: :mod:`core.tracking.inputs`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from core.errors import InputError
from core.tracking import ekf, gating, initiation, ipda, jipda, management
from core.tracking.inputs import Frames, TrackerConstants, frame_slices
from core.tracking.params import TrackerParams
from core.tracking.results import FrameTracks, TrackerResult

__all__ = ["run_tracker", "StreamTracker"]


@dataclass(slots=True)
class _Track:  # mutable working record of the reference tracker
    id: int
    x: np.ndarray
    P: np.ndarray
    psi: float
    birth: int = 0
    confirmed: bool = False
    updated: bool = False
    n_associated: int = 0  # measurements gated in this frame (0 when born in it)
    nis: float = math.nan  # ε = ν̃ᵀ S⁻¹ ν̃ of this frame's update (NaN: none)
    gate_center: np.ndarray = field(default_factory=lambda: np.zeros(2))
    gate_shape: np.ndarray = field(default_factory=lambda: np.eye(2))


def _gate_xy(x: np.ndarray, S: np.ndarray, gamma: float) -> tuple[np.ndarray, np.ndarray]:
    px, py, r = ekf.safe_position(x[0], x[1])
    az = np.arctan2(px, py)
    # J = ∂(x, y)/∂(r, az) for x = r sin az, y = r cos az
    J = np.array([[np.sin(az), r * np.cos(az)], [np.cos(az), -r * np.sin(az)]])
    # G = γ J S_ra Jᵀ
    return np.array([px, py]), gamma * (J @ S[:2, :2] @ J.T)


@dataclass(slots=True)
class _Gated:  # one track's prediction and validated measurements in one frame
    x_pred: np.ndarray
    P_pred: np.ndarray
    H: np.ndarray
    L: np.ndarray
    psi_pred: float
    nu: np.ndarray  # (m_τ, 3) innovations of the validated measurements
    log_lr: np.ndarray  # (m_τ,) log Λ_τi
    idx: np.ndarray  # (m_τ,) their indices in the frame


def _ipda_update(t: _Track, g: _Gated, c: TrackerConstants) -> None:
    """The independent IPDA update of one track (existence, then the PDA state update)."""
    assoc = ipda.associate(g.log_lr, c.pdpg)
    t.psi = ipda.update_existence(g.psi_pred, assoc, c.pdpg, len(g.nu))
    t.x, t.P = ipda.pda_update(g.x_pred, g.P_pred, g.H, c.R, g.L, g.nu, assoc)
    _record_update(t, g, assoc.beta)


def _record_update(t: _Track, g: _Gated, beta: np.ndarray) -> None:
    """Record the frame's gated-measurement count and NIS on the track (read only)."""
    t.n_associated = len(g.nu)
    t.nis = ipda.combined_nis(g.nu, beta, g.L)


def _step(
    tracks: list[_Track],
    z: np.ndarray,
    params: TrackerParams,
    c: TrackerConstants,
    next_id: int,
    frame: int = 0,
) -> tuple[list[_Track], int]:
    m = len(z)
    gated = np.zeros((len(tracks), m), dtype=bool)
    gates: list[_Gated] = []
    for k, t in enumerate(tracks):
        # prediction: state, covariance, existence (eq. 9)
        x_pred, P_pred = ekf.predict(t.x, t.P, c.F, c.Q)
        psi_pred = ipda.predict_existence(t.psi, params.p11, params.p21)
        # gate
        z_pred = ekf.measure(x_pred)
        H = ekf.jacobian(x_pred)
        S = gating.innovation_covariance(H, P_pred, c.R)
        L = gating.cholesky(S)
        nu_all = ekf.innovation(z, z_pred) if m else np.zeros((0, 3))
        d2_all = gating.mahalanobis_squared(nu_all, L)
        inside = d2_all <= c.gamma
        gated[k] = inside
        nu, d2 = nu_all[inside], d2_all[inside]
        n_val = len(nu)
        # clutter density: given, or non-parametric ρ̂ = m̂/V
        log_det_S = gating.log_det_from_cholesky(L)
        if params.nonparametric and n_val:
            rho = ipda.nonparametric_density(
                n_val, c.pdpg * psi_pred, gating.gate_volume(L, c.gamma)
            )
        elif params.nonparametric:
            rho = 1.0  # unused: no validated measurement
        else:
            rho = float(params.clutter_density)
        log_lr = ipda.log_likelihood_ratios(d2, log_det_S, params.p_g, rho)
        gates.append(_Gated(x_pred, P_pred, H, L, psi_pred, nu, log_lr, np.flatnonzero(inside)))
        t.updated = True
        t.gate_center, t.gate_shape = _gate_xy(x_pred, S, c.gamma)
    # association: each track alone (IPDA), or jointly within clusters of shared measurements
    if params.association == "jipda" and len(tracks) > 1:
        label = jipda.clusters(gated)
    else:
        label = np.arange(len(tracks))
    for root in np.unique(label):
        members = np.flatnonzero(label == root)
        bound = jipda.event_bound(np.array([len(gates[k].nu) for k in members]))
        if len(members) == 1 or bound > jipda.MAX_JOINT_EVENTS:
            for k in members:
                _ipda_update(tracks[k], gates[k], c)
            continue
        g = [gates[k] for k in members]
        ja = jipda.joint_associate(
            np.array([gk.psi_pred for gk in g]),
            [gk.log_lr for gk in g],
            [gk.idx for gk in g],
            c.pdpg,
        )
        for i, k in enumerate(members):
            gk, t = gates[k], tracks[k]
            t.psi = float(ja.psi[i])
            assoc = ipda.Association(
                delta=math.nan, one_minus_delta=math.nan, beta0=float(ja.beta0[i]), beta=ja.beta[i]
            )
            t.x, t.P = ipda.pda_update(gk.x_pred, gk.P_pred, gk.H, c.R, gk.L, gk.nu, assoc)
            _record_update(t, gk, assoc.beta)
    # initiation from the measurements outside every gate
    for j in np.flatnonzero(initiation.unassociated(gated)):
        x0 = initiation.initial_state(z[j], params.state_dim)
        t = _Track(id=next_id, x=x0, P=c.P0.copy(), psi=params.p_te, birth=frame)
        next_id += 1
        S0 = gating.innovation_covariance(ekf.jacobian(x0), t.P, c.R)
        t.gate_center, t.gate_shape = _gate_xy(x0, S0, c.gamma)
        tracks.append(t)
    if not tracks:
        return tracks, next_id
    psi = np.array([t.psi for t in tracks])
    ids = np.array([t.id for t in tracks])
    conf = management.confirm(
        np.array([t.confirmed for t in tracks]),
        psi,
        np.array([t.updated for t in tracks]),
        params.confirm_threshold,
    )
    for t, cf in zip(tracks, conf):
        t.confirmed = bool(cf)
    keep = management.survivors(psi, params.delete_threshold)
    tracks = [t for t, k in zip(tracks, keep) if k]
    if len(tracks) > 1:
        psi = np.array([t.psi for t in tracks])
        ids = np.array([t.id for t in tracks])
        pos = np.array([t.x[:2] for t in tracks])
        pos_cov = np.array([t.P[:2, :2] for t in tracks])
        if params.association == "jipda":
            keep = management.merge(
                pos,
                pos_cov,
                psi,
                ids,
                c.gamma2,
                confirmed=np.array([t.confirmed for t in tracks]),
                state=np.array([t.x for t in tracks]),
                state_cov=np.array([t.P for t in tracks]),
            )
        else:
            keep = management.merge(pos, pos_cov, psi, ids, c.gamma2)
        tracks = [t for t, k in zip(tracks, keep) if k]
    if len(tracks) > params.max_tracks:
        psi = np.array([t.psi for t in tracks])
        ids = np.array([t.id for t in tracks])
        keep = management.cap(psi, ids, params.max_tracks)
        tracks = [t for t, k in zip(tracks, keep) if k]
    return tracks, next_id


def _frame_tracks(tracks: list[_Track], d: int, estimate: int) -> FrameTracks:
    """The live tracks after a frame as the result type (struct of arrays)."""
    n = len(tracks)
    return FrameTracks(
        ids=np.array([t.id for t in tracks], dtype=np.int64),
        state=np.array([t.x for t in tracks]).reshape(n, d),
        covariance=np.array([t.P for t in tracks]).reshape(n, d, d),
        psi=np.array([t.psi for t in tracks]),
        confirmed=np.array([t.confirmed for t in tracks], dtype=bool),
        gate_center_xy=np.array([t.gate_center for t in tracks]).reshape(n, 2),
        gate_shape_xy=np.array([t.gate_shape for t in tracks]).reshape(n, 2, 2),
        birth_frame=np.array([t.birth for t in tracks], dtype=np.int64),
        n_associated=np.array([t.n_associated for t in tracks], dtype=np.int64),
        nis=np.array([t.nis for t in tracks], dtype=np.float64),
        estimate=estimate,
    )


def run_tracker(
    frames: Frames,
    params: TrackerParams,
    frame_period_s: float = 0.08,
    *,
    keep_tracks: bool = True,
    engine: str = "numpy",
) -> TrackerResult:
    """Track one trajectory (one sequence of frames) from scratch.

    Parameters
    ----------
    frames
        Measurements per frame: a sequence of (m_f, 3) arrays ``[r (m), az (rad), vr (m/s)]``,
        or a pair ``(z (P, 3), frame_offsets (F + 1,))``.
    params
        Tracker parameters.
    frame_period_s
        Time step T between frames (s).
    keep_tracks
        Keep every track of every frame (:attr:`TrackerResult.frames`, for the GUI).
    engine
        ``"numpy"`` (this readable implementation, default) or ``"numba"`` (the compiled kernel
        recording every track, :func:`core.tracking.kernel.run_tracker_compiled`; the same
        result to round-off, ~100× faster).

    Returns
    -------
    TrackerResult
    """
    if engine == "numba":
        from core.tracking.kernel import run_tracker_compiled

        return run_tracker_compiled(frames, params, frame_period_s, keep_tracks=keep_tracks)
    if engine != "numpy":
        raise InputError(f"engine must be 'numpy' or 'numba', got engine={engine!r}")
    zs = frame_slices(frames)
    c = TrackerConstants.build(params, frame_period_s)
    n_f, d, cap = len(zs), params.state_dim, params.max_tracks
    est_xy = np.full((n_f, 2), np.nan)
    has = np.zeros(n_f, dtype=bool)
    est_id = np.full(n_f, -1, dtype=np.int64)
    est_psi = np.full(n_f, np.nan)
    est_x = np.full((n_f, d), np.nan)
    est_P = np.full((n_f, d, d), np.nan)
    conf_xy = np.full((n_f, cap, 2), np.nan)
    n_tracks = np.zeros(n_f, dtype=np.int64)
    n_conf = np.zeros(n_f, dtype=np.int64)
    kept: list[FrameTracks] = []
    tracks: list[_Track] = []
    next_id = 0
    for f, z in enumerate(zs):
        tracks, next_id = _step(tracks, z, params, c, next_id, f)
        psi = np.array([t.psi for t in tracks])
        ids = np.array([t.id for t in tracks], dtype=np.int64)
        conf = np.array([t.confirmed for t in tracks], dtype=bool)
        b = management.best_confirmed(psi, ids, conf)
        n_tracks[f] = len(tracks)
        n_conf[f] = int(conf.sum())
        cx = [t.x[:2] for t in tracks if t.confirmed]
        if cx:
            conf_xy[f, : len(cx)] = cx
        if b >= 0:
            t = tracks[b]
            has[f] = True
            est_xy[f] = t.x[:2]
            est_id[f] = t.id
            est_psi[f] = t.psi
            est_x[f] = t.x
            est_P[f] = t.P
        if keep_tracks:
            kept.append(_frame_tracks(tracks, d, b))
    return TrackerResult(
        estimate_xy=est_xy,
        has_estimate=has,
        estimate_id=est_id,
        estimate_psi=est_psi,
        estimate_state=est_x,
        estimate_covariance=est_P,
        confirmed_xy=conf_xy,
        n_tracks=n_tracks,
        n_confirmed=n_conf,
        frames=tuple(kept) if keep_tracks else None,
    )


class StreamTracker:
    """Tracks frames one at a time, for a stream whose end is not known (a live sensor).

    Mutable: it holds the live tracks between frames. Each :meth:`step` is the frame step of
    :func:`run_tracker` (``engine="numpy"``); fed a run's frames one by one it returns the same
    :class:`FrameTracks` as ``run_tracker`` over the whole run.

    Parameters
    ----------
    params
        Tracker parameters.
    frame_period_s
        Time step T between frames (s), validated as :func:`~core.tracking.run_tracker` does.
    """

    def __init__(self, params: TrackerParams, frame_period_s: float) -> None:
        self.params = params
        self._c = TrackerConstants.build(params, frame_period_s)
        self._tracks: list[_Track] = []
        self._next_id = 0
        self.n_frames = 0

    def step(self, z: np.ndarray) -> FrameTracks:
        """Track one frame of measurements ``z`` (m, 3) ``[r (m), az (rad), vr (m/s)]``."""
        z = np.asarray(z, dtype=np.float64).reshape(-1, 3)
        if not np.all(np.isfinite(z)):
            raise InputError(f"a measurement of frame {self.n_frames} contains NaN or Inf")
        self._tracks, self._next_id = _step(
            self._tracks, z, self.params, self._c, self._next_id, self.n_frames
        )
        self.n_frames += 1
        tracks = self._tracks
        best = management.best_confirmed(
            np.array([t.psi for t in tracks]),
            np.array([t.id for t in tracks], dtype=np.int64),
            np.array([t.confirmed for t in tracks], dtype=bool),
        )
        return _frame_tracks(tracks, self.params.state_dim, best)

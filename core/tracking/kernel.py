"""The IPDA tracker compiled with numba: the hot path of every Optuna trial.

Same algorithm, same order of operations and the same decisions as the readable reference
(:mod:`core.tracking.tracker`, which composes the role modules); this file trades readability for
speed: the tracks live in preallocated arrays, the small matrix products are explicit loops on
scratch buffers (no allocation per track and frame), and one call tracks every selected
trajectory of a data set. ``tests/core/tracking/test_kernel.py`` checks that both paths agree to
1e-10. See docs/decisions/tracker-01-numba-kernel.md for why numba.

One call takes four groups (named tuples; they cross into numba as plain tuples, the cheaper
argument to type, and are named again inside the kernel):
:class:`KernelFrames` (measurements, trajectories), :class:`KernelConstants` (from the
parameters and the frame period, cached per parameter set), :class:`KernelOutputs` (per-frame
estimates) and :class:`~core.tracking.results.TrackRecord` (every track, when recording).

Layout: this module is the Python side (the kernel's constants per parameter set, the entry
points :func:`track_frames` and :func:`run_tracker_compiled`); the compiled kernel and its
argument types are in :mod:`core.tracking.kernel_jit`.
"""

from __future__ import annotations

import functools

import numpy as np

from core.tracking.inputs import Frames, TrackerConstants, packed_frames
from core.tracking.jipda import MAX_JOINT_EVENTS
from core.tracking.kernel_jit import KernelConstants, KernelFrames, KernelOutputs, track_kernel
from core.tracking.params import TrackerParams
from core.tracking.results import TrackerResult, TrackRecord

__all__ = ["run_tracker_compiled", "track_frames"]


@functools.lru_cache(maxsize=256)
def kernel_constants(params: TrackerParams, frame_period_s: float) -> KernelConstants:
    """The kernel's constants, cached per parameter set (shared between calls: never written;
    read-only flags would force a recompile)."""
    c = TrackerConstants.build(params, frame_period_s)
    d = params.state_dim
    f_nnz = np.count_nonzero(c.F, axis=1).astype(np.int64)
    f_cols = np.zeros((d, max(1, int(f_nnz.max()))), dtype=np.int64)
    for i in range(d):
        nz = np.flatnonzero(c.F[i])
        f_cols[i, : len(nz)] = nz
    nonparametric = params.nonparametric
    return KernelConstants(
        F=c.F,
        f_cols=f_cols,
        f_nnz=f_nnz,
        Q=c.Q,
        R=c.R,
        P0=c.P0,
        gamma=float(c.gamma),
        gamma2=float(c.gamma2),
        p_g=float(params.p_g),
        pdpg=float(params.p_d) * float(params.p_g),
        p_te=float(params.p_te),
        p11=float(params.p11),
        p21=float(params.p21),
        clutter_density=1.0 if nonparametric else float(params.clutter_density),
        nonparametric=bool(nonparametric),
        confirm_threshold=float(params.confirm_threshold),
        delete_threshold=float(params.delete_threshold),
        max_tracks=int(params.max_tracks),
        joint=params.association == "jipda",
        max_joint_events=float(MAX_JOINT_EVENTS),
    )


def track_frames(
    z: np.ndarray,
    frame_offsets: np.ndarray,
    trajectory_offsets: np.ndarray,
    trajectories: np.ndarray,
    params: TrackerParams,
    frame_period_s: float,
    *,
    check: bool = False,
    record: bool = False,
):
    """Track the selected trajectories with the compiled kernel.

    Parameters
    ----------
    z
        All measurements (P, 3) ``[r, az, vr]``, sorted by frame.
    frame_offsets
        (F + 1,) point ranges per global frame.
    trajectory_offsets
        (K + 1,) frame ranges per trajectory.
    trajectories
        (K_sel,) indices of the trajectories to track.
    params, frame_period_s
        Tracker parameters and time step T (s).
    check
        Count, per frame, the live tracks whose state, covariance or ψ is unhealthy (non-finite,
        ψ outside [0, 1], P not symmetric positive definite); returned as a 9th array.
    record
        Record every live track of every frame (id, state, covariance, ψ, status, birth frame,
        gate, gated measurements and NIS) into preallocated (F_sel, max_tracks, ...) arrays;
        returned last as a :class:`TrackRecord`. Off, the kernel allocates nothing for it.

    Returns
    -------
    tuple
        ``est_xy (F_sel, 2), has (F_sel,), est_psi (F_sel,), conf_xy (F_sel, max_tracks, 2),
        n_conf (F_sel,), n_tracks (F_sel,), est_state (F_sel, d), est_cov (F_sel, d, d)``
        with NaN where there is no estimate, then ``n_bad`` if ``check`` and the
        :class:`TrackRecord` if ``record``.
    """
    sel = np.ascontiguousarray(trajectories, dtype=np.int64)
    t_off = np.ascontiguousarray(trajectory_offsets, dtype=np.int64)
    lengths = t_off[sel + 1] - t_off[sel]
    out_off = np.concatenate(([0], np.cumsum(lengths))).astype(np.int64)
    n_out = int(out_off[-1])
    d = params.state_dim
    frames = KernelFrames(
        z=np.ascontiguousarray(z, dtype=np.float64),
        frame_offsets=np.ascontiguousarray(frame_offsets, dtype=np.int64),
        trajectory_offsets=t_off,
        trajectories=sel,
        output_offsets=out_off,
    )
    out = KernelOutputs.allocate(n_out, d, params.max_tracks)
    rec = TrackRecord.allocate(n_out if record else 0, params.max_tracks if record else 0, d)
    c = kernel_constants(params, float(frame_period_s))
    # plain tuples cross into numba: it types a NamedTuple argument ~1 µs slower than a tuple
    track_kernel(tuple(frames), tuple(c), tuple(out), bool(check), bool(record), tuple(rec))
    est_xy, has, est_psi, est_x, est_P, conf_xy, n_conf, n_tr, n_bad = out
    out = (est_xy, has, est_psi, conf_xy, n_conf, n_tr, est_x, est_P)
    if check:
        out = (*out, n_bad)
    if record:
        out = (*out, rec._replace(n_tracks=n_tr))
    return out


def run_tracker_compiled(
    frames: Frames,
    params: TrackerParams,
    frame_period_s: float = 0.08,
    *,
    keep_tracks: bool = True,
):
    """:func:`core.tracking.tracker.run_tracker` on the compiled kernel (every track recorded).

    Same input and the same :class:`~core.tracking.results.TrackerResult` (estimates, ids, ψ,
    status, states, covariances, birth frames and gates of every track per frame) as the
    readable tracker, equal to round-off; tracks one 250-frame scene in milliseconds.

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
        Return every track of every frame (:attr:`TrackerResult.frames`; recorded either way,
        for the estimate's id).

    Returns
    -------
    TrackerResult
    """
    TrackerConstants.build(params, frame_period_s)  # validates the frame period
    z, f_off = packed_frames(frames)
    n_f = len(f_off) - 1
    t_off = np.array([0, n_f], dtype=np.int64)
    out = track_frames(
        z, f_off, t_off, np.zeros(1, dtype=np.int64), params, frame_period_s, record=True
    )
    est_xy, has, est_psi, conf_xy, n_conf, n_tr, est_x, est_P, rec = out
    est_id = np.full(n_f, -1, dtype=np.int64)
    rows = np.flatnonzero(rec.estimate >= 0)
    est_id[rows] = rec.ids[rows, rec.estimate[rows]]
    kept = None
    if keep_tracks:
        kept = rec.frames()
    return TrackerResult(
        estimate_xy=est_xy,
        has_estimate=has,
        estimate_id=est_id,
        estimate_psi=est_psi,
        estimate_state=est_x,
        estimate_covariance=est_P,
        confirmed_xy=conf_xy,
        n_tracks=n_tr,
        n_confirmed=n_conf,
        frames=kept,
    )

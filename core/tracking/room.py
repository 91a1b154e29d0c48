"""The tracker for real rooms (SPEC §7, the ``room`` mode): it composes the room roles.

Per frame:

1. zones (:mod:`core.tracking.zones`): points outside the boundary box are dropped; a point is
   *static* when ``|vr| ≤ v_static`` (zero Doppler);
2. every track is predicted (state, covariance, existence eq. 9) and every point goes to the
   track whose body gate explains it best (:mod:`core.tracking.groups`);
3. a track's group is its moving points; a track with none takes its static points instead
   while it stands in a static box and has had no moving point for at most ``t_static``: so a
   person who stops or sits stays tracked there for that long (and furniture never drags a
   walking person's group), and a track that only static points would support outside the
   static boxes (or longer) gets no update and is let go by its existence;
4. each track is updated by its group as one measurement (:func:`groups.group_update`), its
   strength (smoothed SNR sum) and height (mean z of its points) follow;
5. the moving points no track explained form groups (:mod:`core.tracking.allocation`); each
   group starts a tentative track (ψ = P_te) while there is room (``max_tracks``);
6. the ghost rule (:mod:`core.tracking.ghosts`) flags tracks behind others; a tentative track
   that is no candidate is confirmed when ψ ≥ the threshold (after one update); tracks with
   ψ below the deletion threshold are deleted; the reported (counted) tracks are the confirmed
   ones that are no ghost candidate.

:func:`core.tracking.room_loop.room_frames` is the whole loop over the trajectories of a data
set, written once: it runs as plain Python (``engine="numpy"``, the readable reference) and
compiled by numba (:mod:`core.tracking.room_kernel`, ``engine="numba"``);
``tests/core/tracking/test_room_mode.py`` checks both agree. Entry points: :func:`run_room_tracker`
(one sequence of frames, every track) and :func:`track_room_arrays` (selected trajectories, the
data-set path).
"""

from __future__ import annotations

import numpy as np

from core.errors import InputError
from core.tracking.groups import COLUMNS
from core.tracking.params import TrackerParams
from core.tracking.results import TrackerResult, TrackRecord
from core.tracking.room_loop import room_constants, room_frames
from core.tracking.zones import Zones

__all__ = ["room_points", "run_room_tracker", "track_room_arrays"]


def room_points(
    range_m: np.ndarray,
    azimuth_rad: np.ndarray,
    radial_velocity_mps: np.ndarray,
    x_m: np.ndarray,
    y_m: np.ndarray,
    z_m: np.ndarray,
    snr_db: np.ndarray,
) -> np.ndarray:
    """Room points (P, 7) in :data:`core.tracking.groups.COLUMNS` order; InputError on a
    non-finite value (naming the point and column)."""
    pts = np.column_stack(
        [np.asarray(a, dtype=np.float64).reshape(-1) for a in (
            range_m, azimuth_rad, radial_velocity_mps, x_m, y_m, z_m, snr_db
        )]
    )  # fmt: skip
    bad = ~np.isfinite(pts)
    if bad.any():
        i, j = np.argwhere(bad)[0]
        raise InputError(f"point {int(i)}: {COLUMNS[int(j)]} is not finite ({pts[i, j]})")
    return np.ascontiguousarray(pts)


def _outputs(n_out: int, d: int, cap: int, record: bool):
    est = (
        np.full((n_out, 2), np.nan),
        np.zeros(n_out, dtype=np.bool_),
        np.full(n_out, np.nan),
        np.full((n_out, d), np.nan),
        np.full((n_out, d, d), np.nan),
        np.full((n_out, cap, 2), np.nan),
        np.zeros(n_out, dtype=np.int64),
        np.zeros(n_out, dtype=np.int64),
    )
    nr, cr = (n_out, cap) if record else (0, 0)
    rec = TrackRecord.allocate(nr, cr, d)
    extra = (np.full((nr, cr), np.nan), np.zeros((nr, cr), dtype=np.bool_))
    return est, rec, extra


def track_room_arrays(
    pts: np.ndarray,
    frame_offsets: np.ndarray,
    trajectory_offsets: np.ndarray,
    trajectories: np.ndarray,
    params: TrackerParams,
    frame_period_s: float,
    zones: Zones | None = None,
    *,
    record: bool = False,
    engine: str = "numba",
):
    """The room tracker on the selected trajectories.

    Returns
    -------
    tuple
        ``est_xy, has, est_psi, conf_xy, n_conf, n_tracks, est_state, est_cov`` (as
        :func:`core.tracking.kernel.track_frames`), then with ``record`` the
        :class:`TrackRecord` and the (F_sel, max_tracks) height (m) and ghost arrays.
    """
    c = room_constants(params, frame_period_s, zones or Zones())
    sel = np.ascontiguousarray(trajectories, dtype=np.int64)
    t_off = np.ascontiguousarray(trajectory_offsets, dtype=np.int64)
    lengths = t_off[sel + 1] - t_off[sel]
    out_off = np.concatenate(([0], np.cumsum(lengths))).astype(np.int64)
    n_out = int(out_off[-1])
    est, rec, extra = _outputs(n_out, params.state_dim, params.max_tracks, record)
    if engine == "numba":
        from core.tracking.room_kernel import room_kernel as run
    elif engine == "numpy":
        run = room_frames
    else:
        raise InputError(f"engine must be 'numba' or 'numpy', got engine={engine!r}")
    run(
        np.ascontiguousarray(pts, dtype=np.float64),
        np.ascontiguousarray(frame_offsets, dtype=np.int64),
        t_off,
        sel,
        out_off,
        c,
        *est,
        rec.ids,
        rec.state,
        rec.covariance,
        rec.psi,
        rec.confirmed,
        rec.birth_frame,
        rec.gate_center_xy,
        rec.gate_shape_xy,
        rec.n_associated,
        rec.nis,
        rec.estimate,
        *extra,
        bool(record),
    )
    est_xy, has, est_psi, est_x, est_P, conf_xy, n_conf, n_tr = est
    out = (est_xy, has, est_psi, conf_xy, n_conf, n_tr, est_x, est_P)
    if record:
        out = (*out, rec._replace(n_tracks=n_tr), *extra)
    return out


def _pack(frames) -> tuple[np.ndarray, np.ndarray]:
    if isinstance(frames, tuple) and len(frames) == 2 and np.ndim(frames[1]) == 1:
        pts = np.asarray(frames[0], dtype=np.float64).reshape(-1, 7)
        f_off = np.asarray(frames[1], dtype=np.int64)
        if len(f_off) == 0 or f_off[0] != 0 or f_off[-1] != len(pts) or np.any(np.diff(f_off) < 0):
            raise InputError(f"frame_offsets must rise from 0 to the {len(pts)} points")
    else:
        zs = []
        for f, zf in enumerate(frames):
            zf = np.asarray(zf, dtype=np.float64)
            if zf.size % 7:
                raise InputError(
                    f"room points of frame {f} must be (m, 7) {COLUMNS}, got {zf.shape}"
                )
            zs.append(zf.reshape(-1, 7))
        pts = np.concatenate(zs) if zs else np.zeros((0, 7))
        f_off = np.concatenate(([0], np.cumsum([len(zf) for zf in zs]))).astype(np.int64)
    if not np.all(np.isfinite(pts)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(pts), axis=1))[0])
        raise InputError(f"room point {bad} contains NaN or Inf")
    return np.ascontiguousarray(pts), f_off


def run_room_tracker(
    frames,
    params: TrackerParams,
    frame_period_s: float = 0.08,
    zones: Zones | None = None,
    *,
    engine: str = "numpy",
) -> TrackerResult:
    """Track one sequence of room frames; every track of every frame kept.

    Parameters
    ----------
    frames
        Room points per frame: a sequence of (m_f, 7) arrays (:data:`groups.COLUMNS`), or a pair
        ``(pts (P, 7), frame_offsets (F + 1,))``.
    params, frame_period_s, zones
        Parameters (their room fields), time step T (s), the room's zones (default: none).
    engine
        ``"numpy"`` (plain Python, the reference) or ``"numba"`` (compiled).

    Returns
    -------
    TrackerResult
        As the paper tracker's; ``frames[f].height_m`` and ``.ghost`` per track.
    """
    pts, f_off = _pack(frames)
    n_f = len(f_off) - 1
    out = track_room_arrays(
        pts,
        f_off,
        np.array([0, n_f], dtype=np.int64),
        np.zeros(1, dtype=np.int64),
        params,
        frame_period_s,
        zones,
        record=True,
        engine=engine,
    )
    est_xy, has, est_psi, conf_xy, n_conf, n_tr, est_x, est_P, rec, height, ghost = out
    est_id = np.full(n_f, -1, dtype=np.int64)
    rows = np.flatnonzero(rec.estimate >= 0)
    est_id[rows] = rec.ids[rows, rec.estimate[rows]]
    kept = rec.frames(height, ghost)
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

"""The room tracker's loop (SPEC §7, the ``room`` mode), written once for both engines.

:func:`room_frames` composes the room roles over the trajectories of a data set (the steps are
listed in :mod:`core.tracking.room`). It is plain Python marked ``register_jitable``: called from
Python it runs as written (``engine="numpy"``, the readable reference); :mod:`core.tracking.
room_kernel` compiles it with the roles it calls (``engine="numba"``).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba.extending import register_jitable

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)
from core.tracking import ekf, initiation, ipda
from core.tracking.allocation import allocate
from core.tracking.ghosts import ghost_candidates, wall_ghost_candidates
from core.tracking.groups import (
    COL_AZ,
    COL_R,
    COL_SNR,
    COL_VR,
    COL_X,
    COL_Y,
    COL_Z,
    body_covariance_into,
    chol3_into,
    group_update,
    group_work,
    innovation_covariance_into,
    mm,
    mm_nt,
    symmetrize_into,
)
from core.tracking.inputs import TrackerConstants
from core.tracking.params import TrackerParams
from core.tracking.zones import Zones, in_any_box, in_box

__all__ = ["RoomConstants", "room_constants", "room_frames", "STRENGTH_MEMORY"]

#: Weight of the previous strength in a track's smoothed SNR sum (s ← a·s + (1 − a)·Σ SNR).
STRENGTH_MEMORY = 0.7


class RoomConstants(NamedTuple):
    """What the room loop needs from the parameters, the frame period and the zones."""

    F: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    P0: np.ndarray
    gamma: float
    p_g: float
    pdpg: float
    p_te: float
    p11: float
    p21: float
    rho: float
    nonparametric: bool
    confirm_threshold: float
    delete_threshold: float
    max_tracks: int
    static_velocity: float
    body_sigma: float
    body_velocity_sigma: float
    alloc_points: float
    alloc_snr: float
    alloc_distance: float
    alloc_velocity: float
    ghost_gap: float
    ghost_bearing: float
    ghost_velocity: float
    ghost_radius: float
    static_frames: float
    boundary: np.ndarray
    static_boxes: np.ndarray
    walls: np.ndarray
    sensor_height: float


def room_constants(params: TrackerParams, frame_period_s: float, zones: Zones) -> RoomConstants:
    """The room loop's constants (validates the frame period)."""
    c = TrackerConstants.build(params, frame_period_s)
    return RoomConstants(
        F=np.ascontiguousarray(c.F),
        Q=np.ascontiguousarray(c.Q),
        R=np.ascontiguousarray(c.R),
        P0=np.ascontiguousarray(c.P0),
        gamma=float(c.gamma),
        p_g=float(params.p_g),
        pdpg=float(c.pdpg),
        p_te=float(params.p_te),
        p11=float(params.p11),
        p21=float(params.p21),
        rho=1.0 if params.nonparametric else float(params.clutter_density),
        nonparametric=bool(params.nonparametric),
        confirm_threshold=float(params.confirm_threshold),
        delete_threshold=float(params.delete_threshold),
        max_tracks=int(params.max_tracks),
        static_velocity=float(params.static_velocity),
        body_sigma=float(params.body_sigma),
        body_velocity_sigma=float(params.body_velocity_sigma),
        alloc_points=float(params.alloc_points),
        alloc_snr=float(params.alloc_snr),
        alloc_distance=float(params.alloc_distance),
        alloc_velocity=float(params.alloc_velocity),
        ghost_gap=float(params.ghost_gap),
        ghost_bearing=float(params.ghost_bearing),
        ghost_velocity=float(params.ghost_velocity),
        ghost_radius=float(params.ghost_radius),
        # static_time in frames (T validated by TrackerConstants.build above)
        static_frames=float(params.static_time) / float(frame_period_s),
        boundary=zones.boundary_array(),
        static_boxes=zones.static_array(),
        walls=np.ascontiguousarray(zones.wall_array()),
        sensor_height=float(zones.sensor_height_m),
    )


@register_jitable
def _gate_xy(x, S, gamma, gc, gs):
    """The gate's projection on x–y (as :class:`FrameTracks` documents it):
    G = γ J S_ra Jᵀ with J = ∂(x, y)/∂(r, az), written out."""
    px, py, r = ekf.safe_position(x[0], x[1])
    az = math.atan2(px, py)
    j00, j01 = math.sin(az), r * math.cos(az)
    j10, j11 = math.cos(az), -r * math.sin(az)
    # M = J S_ra, G = γ M Jᵀ
    m00 = j00 * S[0, 0] + j01 * S[1, 0]
    m01 = j00 * S[0, 1] + j01 * S[1, 1]
    m10 = j10 * S[0, 0] + j11 * S[1, 0]
    m11 = j10 * S[0, 1] + j11 * S[1, 1]
    gs[0, 0] = gamma * (m00 * j00 + m01 * j01)
    gs[0, 1] = gamma * (m00 * j10 + m01 * j11)
    gs[1, 0] = gamma * (m10 * j00 + m11 * j01)
    gs[1, 1] = gamma * (m10 * j10 + m11 * j11)
    gc[0], gc[1] = px, py


@register_jitable
def _predict_into(x, P, F, Q, xo, Po, FP):
    """Kalman prediction x⁻ = F x, P⁻ = sym(F P Fᵀ + Q) into xo, Po (FP: (d, d) scratch)."""
    d = x.shape[0]
    for i in range(d):
        s = 0.0
        for k in range(d):
            s += F[i, k] * x[k]
        xo[i] = s
    mm(F, P, FP)
    mm_nt(FP, F, Po)
    for i in range(d):
        for j in range(d):
            Po[i, j] += Q[i, j]
    symmetrize_into(Po)


@register_jitable
def room_frames(
    pts,
    frame_offsets,
    trajectory_offsets,
    trajectories,
    output_offsets,
    c,
    est_xy,
    has,
    est_psi,
    est_x,
    est_P,
    conf_xy,
    n_conf,
    n_tr,
    rec_ids,
    rec_state,
    rec_cov,
    rec_psi,
    rec_conf,
    rec_birth,
    rec_gc,
    rec_gs,
    rec_n,
    rec_nis,
    rec_est,
    rec_height,
    rec_ghost,
    record,
):
    """The room tracker over the selected trajectories (see the module docstring).

    ``pts`` (P, 7) sorted by frame, ``frame_offsets`` (F + 1,), ``trajectory_offsets`` (K + 1,),
    ``trajectories`` (K_sel,), ``output_offsets`` (K_sel + 1,); outputs per output frame as
    :func:`core.tracking.kernel.track_frames` returns them, and with ``record`` every live track
    (``rec_*``, (F_sel, max_tracks, ...)) with its height (m: the mean z of its latest group)
    and ghost flag.
    """
    cap = c.max_tracks
    d = c.F.shape[0]
    X = np.zeros((cap + 1, d))
    P = np.zeros((cap + 1, d, d))
    psi = np.zeros(cap + 1)
    ids = np.zeros(cap + 1, dtype=np.int64)
    conf = np.zeros(cap + 1, dtype=np.bool_)
    ghost = np.zeros(cap + 1, dtype=np.bool_)
    birth = np.zeros(cap + 1, dtype=np.int64)
    strength = np.zeros(cap + 1)
    still = np.zeros(cap + 1, dtype=np.int64)  # frames since the track's last moving point
    height = np.zeros(cap + 1)
    npts = np.zeros(cap + 1, dtype=np.int64)
    nis = np.zeros(cap + 1)
    gc = np.zeros((cap + 1, 2))
    gs = np.zeros((cap + 1, 2, 2))
    XP = np.zeros((cap, d))
    PP = np.zeros((cap, d, d))
    HH = np.zeros((cap, 3, d))
    ZP = np.zeros((cap, 3))
    DD = np.zeros((cap, 3, 3))
    rhos = np.zeros(cap)
    # scratch, allocated once for the run (a frame holds at most m_max points)
    m_max = 0
    for ti in range(trajectories.shape[0]):
        for f in range(
            trajectory_offsets[trajectories[ti]], trajectory_offsets[trajectories[ti] + 1]
        ):
            m_max = max(m_max, frame_offsets[f + 1] - frame_offsets[f])
    used_ = np.zeros(m_max, dtype=np.bool_)
    static_ = np.zeros(m_max, dtype=np.bool_)
    owner_ = np.zeros(m_max, dtype=np.int64)
    best_ = np.zeros(m_max)
    free_ = np.zeros(m_max, dtype=np.bool_)
    labels_ = np.zeros(m_max, dtype=np.int64)
    rows = np.zeros(m_max, dtype=np.int64)
    order_ = np.zeros(m_max, dtype=np.int64)
    member_ = np.zeros(m_max, dtype=np.int64)
    zm = np.zeros((cap + 1, 3))
    g_order = np.zeros(cap + 1, dtype=np.int64)
    g_pts = np.zeros((3 * c.walls.shape[0] + 1, 2))
    work = group_work(d)
    FP = np.zeros((d, d))
    HP = np.zeros((3, d))
    H0 = np.zeros((3, d))
    S = np.zeros((3, 3))
    RD = np.zeros((3, 3))
    L = np.zeros((3, 3))
    zc = np.zeros(3)
    for ti in range(trajectories.shape[0]):
        k_traj = trajectories[ti]
        f0 = trajectory_offsets[k_traj]
        f1 = trajectory_offsets[k_traj + 1]
        nt = 0
        next_id = 0
        for f in range(f0, f1):
            o = output_offsets[ti] + (f - f0)
            frame = f - f0
            a, b = frame_offsets[f], frame_offsets[f + 1]
            z = pts[a:b]
            m = b - a
            # 1. zones and static points
            used, static = used_[:m], static_[:m]
            for j in range(m):
                used[j] = in_box(z[j, COL_X], z[j, COL_Y], z[j, COL_Z], c.boundary)
                static[j] = abs(z[j, COL_VR]) <= c.static_velocity
            # 2. predict and gate: each point to the track explaining it best
            owner, best = owner_[:m], best_[:m]
            for j in range(m):
                owner[j] = -1
                best[j] = np.inf
            for k in range(nt):
                _predict_into(X[k], P[k], c.F, c.Q, XP[k], PP[k], FP)
                psi[k] = ipda.predict_existence(psi[k], c.p11, c.p21)
                zp = ZP[k]
                ekf.measure_into(XP[k], zp)
                ekf.jacobian_into(XP[k], HH[k])
                body_covariance_into(zp[0], c.body_sigma, c.body_velocity_sigma, DD[k])
                # S_pt = H P⁻ Hᵀ + (R + D), symmetrised
                for i in range(3):
                    for j in range(3):
                        RD[i, j] = c.R[i, j] + DD[k, i, j]
                innovation_covariance_into(HH[k], PP[k], RD, HP, S)
                chol3_into(S, L)
                log_det = 2.0 * (math.log(L[0, 0]) + math.log(L[1, 1]) + math.log(L[2, 2]))
                if c.nonparametric:
                    # one group in the point gate: ρ̂ = 1/V, V = (4π/3) γ^{3/2} √det S
                    rhos[k] = 1.0 / (4.0 * math.pi / 3.0 * c.gamma**1.5 * math.exp(0.5 * log_det))
                else:
                    rhos[k] = c.rho
                if record:  # the gate's x–y picture is an output only
                    _gate_xy(XP[k], S, c.gamma, gc[k], gs[k])
                l00, l10, l11, l20, l21, l22 = L[0, 0], L[1, 0], L[1, 1], L[2, 0], L[2, 1], L[2, 2]
                for j in range(m):
                    if not used[j]:
                        continue
                    n0 = z[j, COL_R] - zp[0]
                    n1 = ((z[j, COL_AZ] - zp[1] + math.pi) % (2.0 * math.pi)) - math.pi
                    n2 = z[j, COL_VR] - zp[2]
                    # d² = ‖L⁻¹ν‖², forward substitution on the 3×3 factor
                    w0 = n0 / l00
                    w1 = (n1 - l10 * w0) / l11
                    w2 = (n2 - l20 * w0 - l21 * w1) / l22
                    d2 = w0 * w0 + w1 * w1 + w2 * w2
                    if d2 <= c.gamma:
                        score = d2 + log_det
                        if score < best[j]:
                            best[j] = score
                            owner[j] = k
            # 3.-4. each track's group updates it
            for k in range(nt):
                # the group is the track's moving points; with none, its static points while
                # it stands in a static box (its predicted x, y and its height) and has been
                # still for at most static_frames frames
                moving = 0
                for j in range(m):
                    if owner[j] == k and not static[j]:
                        moving += 1
                still[k] = 0 if moving > 0 else still[k] + 1
                in_static = (
                    moving == 0
                    and still[k] <= c.static_frames
                    and in_any_box(XP[k, 0], XP[k, 1], height[k], c.static_boxes)
                )
                n = 0
                snr = 0.0
                zsum = 0.0
                for j in range(m):
                    if owner[j] == k and (in_static or not static[j]):
                        rows[n] = j
                        n += 1
                        snr += max(z[j, COL_SNR], 0.0)
                        zsum += z[j, COL_Z]
                psi[k], nis[k] = group_update(
                    XP[k], PP[k], psi[k], HH[k], ZP[k], z, rows, n, c.R, DD[k], c.pdpg, c.p_g,
                    rhos[k], X[k], P[k], work,
                )  # fmt: skip
                npts[k] = n
                strength[k] = STRENGTH_MEMORY * strength[k] + (1.0 - STRENGTH_MEMORY) * snr
                if n > 0:
                    height[k] = zsum / n
            # 5. groups of unexplained moving points start tentative tracks
            free, labels = free_[:m], labels_[:m]
            for j in range(m):
                free[j] = used[j] and not static[j] and owner[j] < 0
            n_groups = allocate(
                z, free, c.alloc_points, c.alloc_snr, c.alloc_distance, c.alloc_velocity, labels,
                order_[:m], member_[:m],
            )  # fmt: skip
            for g in range(n_groups):
                if nt >= cap:
                    break
                zc[0] = zc[1] = zc[2] = 0.0
                n = 0
                snr = 0.0
                zsum = 0.0
                for j in range(m):
                    if labels[j] == g:
                        zc[0] += z[j, COL_R]
                        zc[1] += z[j, COL_AZ]
                        zc[2] += z[j, COL_VR]
                        snr += max(z[j, COL_SNR], 0.0)
                        zsum += z[j, COL_Z]
                        n += 1
                zc /= n
                initiation.initial_state_into(zc, X[nt])
                P[nt] = c.P0
                psi[nt] = c.p_te
                ids[nt] = next_id
                next_id += 1
                conf[nt] = False
                birth[nt] = frame
                strength[nt] = snr
                still[nt] = 0
                height[nt] = zsum / n
                npts[nt] = 0
                nis[nt] = math.nan
                if record:  # the newborn's gate: S₀ = H(x₀) P₀ H(x₀)ᵀ + R
                    ekf.jacobian_into(X[nt], H0)
                    mm(H0, P[nt], HP)
                    mm_nt(HP, H0, S)
                    for i in range(3):
                        for j in range(3):
                            S[i, j] += c.R[i, j]
                    _gate_xy(X[nt], S, c.gamma, gc[nt], gs[nt])
                nt += 1
            # 6. ghosts, confirmation, deletion
            ghost_candidates(
                X, conf, strength, nt, c.ghost_gap, c.ghost_bearing, c.ghost_velocity, ghost,
                zm, g_order,
            )  # fmt: skip
            wall_ghost_candidates(
                X, conf, height, c.sensor_height, ghost, nt, c.walls, c.ghost_radius, g_pts
            )
            for k in range(nt):
                if not conf[k] and not ghost[k] and birth[k] < frame:
                    conf[k] = psi[k] >= c.confirm_threshold
            keep = 0
            for k in range(nt):
                if psi[k] >= c.delete_threshold:
                    if keep != k:
                        X[keep], P[keep], psi[keep], ids[keep] = X[k], P[k], psi[k], ids[k]
                        conf[keep], ghost[keep], birth[keep] = conf[k], ghost[k], birth[k]
                        strength[keep], height[keep] = strength[k], height[k]
                        still[keep] = still[k]
                        npts[keep], nis[keep] = npts[k], nis[k]
                        gc[keep], gs[keep] = gc[k], gs[k]
                    keep += 1
            nt = keep
            # outputs: the counted tracks are confirmed and no ghost candidate
            bi = -1
            nc = 0
            for k in range(nt):
                if conf[k] and not ghost[k]:
                    conf_xy[o, nc, 0] = X[k, 0]
                    conf_xy[o, nc, 1] = X[k, 1]
                    nc += 1
                    if bi < 0 or psi[k] > psi[bi] or (psi[k] == psi[bi] and ids[k] < ids[bi]):
                        bi = k
            n_conf[o] = nc
            n_tr[o] = nt
            if bi >= 0:
                has[o] = True
                est_xy[o, 0], est_xy[o, 1] = X[bi, 0], X[bi, 1]
                est_psi[o] = psi[bi]
                est_x[o] = X[bi]
                est_P[o] = P[bi]
            if record:
                rec_est[o] = bi
                for k in range(nt):
                    rec_ids[o, k] = ids[k]
                    rec_state[o, k] = X[k]
                    rec_cov[o, k] = P[k]
                    rec_psi[o, k] = psi[k]
                    rec_conf[o, k] = conf[k] and not ghost[k]
                    rec_birth[o, k] = birth[k]
                    rec_gc[o, k] = gc[k]
                    rec_gs[o, k] = gs[k]
                    rec_n[o, k] = npts[k]
                    rec_nis[o, k] = nis[k]
                    rec_height[o, k] = height[k]
                    rec_ghost[o, k] = ghost[k]

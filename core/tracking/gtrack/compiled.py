"""The Python side of gtrack's compiled kernel (:mod:`core.tracking.gtrack.kernel`): fills its
arrays from :class:`GtrackParams`, calls it and returns the readable form's
:class:`~core.tracking.gtrack.tracker.GtrackResult`."""

from __future__ import annotations

import math

import numpy as np

from core.tracking.gtrack import geometry as geo
from core.tracking.gtrack.params import GtrackParams
from core.tracking.gtrack.tracker import (
    DISPERSION_WEIGHT,
    ERASURE_VELOCITY_FACTOR,
    INITIAL_RADIAL_VELOCITY_MPS,
    LOCK_TOLERANCE,
    MIN_STATIC_VELOCITY_MPS,
    P0_SIGMA,
    UNROLL_ALPHA,
    UNROLL_CONFIDENCE,
    GtrackResult,
)
from core.tracking.results import FrameTracks

__all__ = ["run_gtrack_compiled", "kernel_args"]


def kernel_args(params: GtrackParams) -> tuple:
    """The kernel's constant arguments (M, F, Q, R, P0, floats, integers, the three boxes)."""
    p, d = params, params.dims
    M = geo.pose_matrix(p.sensor_azimuth_tilt_deg, 0.0 if d == 2 else p.sensor_elevation_tilt_deg)
    F = geo.transition(d, p.frame_period_s)
    Q = geo.process_noise(d, p.frame_period_s, p.max_acceleration_mps2)
    sig = [p.range_sigma_m] + [p.angle_sigma_rad] * (d - 1) + [p.doppler_sigma_mps]
    R = np.diag(np.square(sig))
    P0 = np.diag(np.repeat(np.square(P0_SIGMA), d))
    fp = np.array(
        [
            p.gating_gain,
            p.gating_width_m,
            p.gating_depth_m,
            p.gating_height_m,
            p.gating_velocity_mps,
            p.snr_thre,
            p.snr_thre_obscured,
            p.velocity_thre_mps,
            p.max_distance_thre_m2,
            p.max_vel_thre_mps,
            p.radial_velocity_resolution_mps,
            p.sensor_height_m if d == 3 else 0.0,
            DISPERSION_WEIGHT,
            p.max_radial_velocity_mps,
            UNROLL_ALPHA,
            UNROLL_CONFIDENCE,
            LOCK_TOLERANCE,
            INITIAL_RADIAL_VELOCITY_MPS,
            p.frame_period_s,
            MIN_STATIC_VELOCITY_MPS,
            ERASURE_VELOCITY_FACTOR,
        ]  # fmt: skip
    )
    ip = np.array(
        [
            d,
            p.max_tracks,
            p.det2act,
            p.det2free,
            p.active2free,
            p.static2free,
            p.exit2free,
            p.sleep2free,
            p.points_thre,
        ],
        dtype=np.int64,  # fmt: skip
    )
    boxes = tuple(np.array(p.box(b)) for b in ("boundary", "static", "presence"))
    return (M, F, Q, R, P0, fp, ip, *boxes, math.radians(p.sensor_azimuth_tilt_deg))


def run_gtrack_compiled(
    points: np.ndarray, frame_offsets: np.ndarray, params: GtrackParams, *, frames: bool = True
) -> GtrackResult:
    """As :func:`core.tracking.gtrack.tracker.run_gtrack`, compiled. ``frames=False`` leaves
    out the per-frame :class:`FrameTracks` (the counts, point ids and presence stay)."""
    from core.tracking.gtrack.kernel import gtrack_kernel

    pts = np.ascontiguousarray(np.asarray(points, dtype=float).reshape(-1, 5))
    off = np.ascontiguousarray(frame_offsets, dtype=np.int64)
    nf, cap, n = len(off) - 1, params.max_tracks, 3 * params.dims
    rec_n = np.zeros(nf, np.int64)
    rec_ids = np.full((nf, cap), -1, np.int64)
    rec_x = np.zeros((nf, cap, n))
    rec_P = np.zeros((nf, cap, n, n))
    rec_conf = np.zeros((nf, cap), np.bool_)
    rec_gc = np.zeros((nf, cap, 2))
    rec_gs = np.zeros((nf, cap, 2, 2))
    rec_birth = np.zeros((nf, cap), np.int64)
    rec_nas = np.zeros((nf, cap), np.int64)
    rec_nis = np.zeros((nf, cap))
    rec_est = np.zeros(nf, np.int64)
    point_track = np.full(len(pts), -1, np.int64)
    presence = np.zeros(nf, np.bool_)
    gtrack_kernel(pts, off, *kernel_args(params), rec_n, rec_ids, rec_x, rec_P, rec_conf,
                  rec_gc, rec_gs, rec_birth, rec_nas, rec_nis, rec_est, point_track,
                  presence)  # fmt: skip
    fts: tuple[FrameTracks, ...] = ()
    if frames:
        fts = tuple(
            FrameTracks(
                ids=rec_ids[f, :k].copy(),
                state=rec_x[f, :k].copy(),
                covariance=rec_P[f, :k].copy(),
                psi=np.full(k, np.nan),
                confirmed=rec_conf[f, :k].copy(),
                gate_center_xy=rec_gc[f, :k].copy(),
                gate_shape_xy=rec_gs[f, :k].copy(),
                birth_frame=rec_birth[f, :k].copy(),
                n_associated=rec_nas[f, :k].copy(),
                nis=rec_nis[f, :k].copy(),
                estimate=int(rec_est[f]),
            )
            for f, k in enumerate(rec_n)
        )
    live = np.arange(cap)[None, :] < rec_n[:, None]
    n_active = np.sum(rec_conf & live, axis=1)
    return GtrackResult(
        frames=fts,
        point_track=point_track,
        presence=presence,
        n_active=n_active,
        n_detect=rec_n - n_active,
    )

"""Synthetic people-counting frames for gtrack's tests and benchmark.

People walk straight lines in the room (world frame of :mod:`~core.tracking.gtrack.geometry`);
each gives ``points_per_person`` points a frame scattered about its centre (σ 0.15 m across,
0.25 m in height about 1 m), with the radial velocity of the centre plus noise and a linear SNR
of 5–15; ``static_points`` zero-Doppler points a frame stand still in the room (furniture). The
points are returned in the sensor frame as gtrack takes them.
"""

from __future__ import annotations

import numpy as np

from core.tracking.gtrack import geometry as geo
from core.tracking.gtrack.params import GtrackParams

__all__ = ["people_frames"]


def people_frames(
    rng: np.random.Generator,
    params: GtrackParams,
    *,
    n_frames: int,
    n_people: int,
    points_per_person: int,
    static_points: int = 0,
    speed_mps: float = 1.0,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points (P, 5) ``[r, az, el, vr, snr]``, frame offsets (F + 1,), truth (F, n_people, 3)."""
    T = params.frame_period_s
    M = geo.pose_matrix(params.sensor_azimuth_tilt_deg, params.sensor_elevation_tilt_deg)
    h = params.sensor_height_m
    start = np.column_stack(
        [rng.uniform(-2.0, 2.0, n_people), rng.uniform(2.0, 6.0, n_people), np.ones(n_people)]
    )
    heading = rng.uniform(0, 2 * np.pi, n_people)
    vel = speed_mps * np.column_stack([np.cos(heading), np.sin(heading), np.zeros(n_people)])
    furniture = np.column_stack(
        [
            rng.uniform(-3, 3, static_points),
            rng.uniform(1, 7, static_points),
            rng.uniform(0.2, 1.0, static_points),
        ]
    )
    pts, off, truth = [], [0], np.zeros((n_frames, n_people, 3))
    for f in range(n_frames):
        pos = start + vel * f * T
        # bounce inside x ∈ [−3, 3], y ∈ [1, 7]
        for k in range(2):
            lo, hi = (-3.0, 3.0) if k == 0 else (1.0, 7.0)
            span = hi - lo
            u = np.mod(pos[:, k] - lo, 2 * span)
            pos[:, k] = lo + np.where(u > span, 2 * span - u, u)
        truth[f] = pos
        frame = []
        for i in range(n_people):
            w = pos[i] + rng.normal(0, [0.15, 0.15, 0.25], (points_per_person, 3))
            frame.append((w, np.full(points_per_person, i)))
        if static_points:
            frame.append(
                (furniture + rng.normal(0, 0.02, furniture.shape), np.full(static_points, -1))
            )
        w = np.concatenate([a for a, _ in frame]) if frame else np.zeros((0, 3))
        who = np.concatenate([b for _, b in frame]) if frame else np.zeros(0, int)
        ps = (w - np.array([0, 0, h])) @ M  # world -> sensor: Mᵀ (p − s), rows
        r = np.linalg.norm(ps, axis=1)
        az = np.arctan2(ps[:, 0], ps[:, 1])
        el = np.arcsin(ps[:, 2] / r)
        v_s = np.where(who[:, None] >= 0, vel[np.maximum(who, 0)], 0.0) @ M
        vr = np.sum(ps * v_s, axis=1) / r
        vr = np.where(who >= 0, vr + rng.normal(0, 0.05, len(r)), 0.0)
        snr = rng.uniform(5, 15, len(r))
        pts.append(np.column_stack([r, az, el, vr, snr]))
        off.append(off[-1] + len(r))
    return np.concatenate(pts), np.asarray(off, dtype=np.int64), truth

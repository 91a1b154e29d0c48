"""Synthetic measurements for tests and the stability sweep (no radar simulation needed).

Truth follows the paper's eq. (6) walk (:func:`core.kinematics.integrate_eq6`); each frame the
person is detected with probability P_D and measured as ``[r, az, vr]`` plus Gaussian noise;
clutter is Poisson with a given mean per frame, uniform in measurement space over the AOI
(r ∈ [0.5, 10] m, |az| ≤ 60°, vr ∈ [−v_max, v_max]). With 2.1 clutter points a frame
(λ = 0.02 m⁻² over the 104.5 m² AOI, :mod:`core.config`'s paper scene) this is the paper-like
scene, whose clutter density is 2.1 / (9.5 m · 2.094 rad · 14.48 m/s) ≈ 0.0073.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass

import numpy as np

from core.config import (
    PAPER_AOI_AREA_M2,
    PAPER_CLUTTER_DENSITY_PER_M2,
    PAPER_MAX_AZIMUTH_DEG,
    PAPER_MAX_RANGE_M,
    PAPER_MIN_RANGE_M,
)
from core.dataset import Dataset
from core.kinematics import integrate_eq6
from core.pointcloud import SOURCE_CLUTTER, PointCloud

__all__ = [
    "SyntheticScene",
    "synthetic_trajectory",
    "synthetic_frames",
    "synthetic_dataset",
    "crossing_paths",
    "circling_paths",
    "people_dataset",
    "room_dataset",
    "PAPER_LIKE",
]


@dataclass(frozen=True, slots=True, kw_only=True)
class SyntheticScene:
    """Measurement model of the synthetic scene.

    Attributes
    ----------
    noise_std
        Standard deviations of [r (m), az (rad), vr (m/s)] of person detections.
    p_d
        Probability that the person is detected in a frame.
    clutter_per_frame
        Mean number of clutter points per frame (Poisson); 0 draws nothing.
    min_range_m, max_range_m, max_azimuth_rad, max_velocity_mps
        The AOI in measurement space, where clutter is uniform.
    frame_period_s
        Δt of eq. (6).
    """

    noise_std: tuple[float, float, float] = (0.05, 0.02, 0.15)
    p_d: float = 0.95
    clutter_per_frame: float = PAPER_CLUTTER_DENSITY_PER_M2 * PAPER_AOI_AREA_M2
    min_range_m: float = PAPER_MIN_RANGE_M
    max_range_m: float = PAPER_MAX_RANGE_M
    max_azimuth_rad: float = math.radians(PAPER_MAX_AZIMUTH_DEG)
    # the paper radar's v_max (7.2414 m/s) to four figures, as the synthetic data sets were drawn
    max_velocity_mps: float = 7.241
    frame_period_s: float = 0.08

    @property
    def measurement_volume(self) -> float:
        """AOI volume in measurement space (m · rad · m/s)."""
        return (
            (self.max_range_m - self.min_range_m)
            * 2.0
            * self.max_azimuth_rad
            * 2.0
            * self.max_velocity_mps
        )

    @property
    def clutter_density(self) -> float:
        """ρ = clutter_per_frame / V (per m · rad · m/s)."""
        return self.clutter_per_frame / self.measurement_volume


PAPER_LIKE = SyntheticScene()


def _inside(p: np.ndarray, scene: SyntheticScene) -> np.ndarray:
    r = np.hypot(p[:, 0], p[:, 1])
    az = np.arctan2(p[:, 0], p[:, 1])
    return (
        (r >= scene.min_range_m + 0.3)
        & (r <= scene.max_range_m - 0.3)
        & (np.abs(az) <= scene.max_azimuth_rad - 0.05)
    )


def synthetic_trajectory(
    trajectory_class: str,
    rng: np.random.Generator,
    scene: SyntheticScene = PAPER_LIKE,
    n_frames: int = 150,
) -> tuple[np.ndarray, np.ndarray]:
    """A simple class a–e walk (SPEC §2) inside the AOI; returns positions, velocities (F, 2).

    The walk is cut where it would leave the AOI (at least 40 frames are kept; the start is
    redrawn otherwise).
    """
    dt = scene.frame_period_s
    for _ in range(1000):
        speed = rng.uniform(0.5, 1.8)
        accel = np.zeros((n_frames, 2))
        if trajectory_class == "a":
            p0 = np.array([rng.uniform(-3, 3), rng.uniform(2, 8)])
            d = [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)][rng.integers(4)]
            v0 = speed * np.array(d)
        elif trajectory_class == "b":
            az = rng.uniform(-0.8, 0.8)
            r = rng.uniform(6, 9.5)
            p0 = r * np.array([math.sin(az), math.cos(az)])
            v0 = -speed * p0 / r
        elif trajectory_class in ("c", "d"):
            p0 = np.array([rng.uniform(-2, 2), rng.uniform(3, 7)])
            h = rng.uniform(0, 2 * math.pi)
            v0 = speed * np.array([math.cos(h), math.sin(h)])
            heading = np.full(n_frames, h)
            sp = np.full(n_frames, speed)
            t = 0
            while t < n_frames:
                t += int(rng.integers(15, 40))
                if trajectory_class == "c":
                    heading[t:] += rng.uniform(-1.5, 1.5)
                else:
                    stop = int(rng.integers(10, 30))
                    sp[t : t + stop] = 0.0
                    t += stop
            # smooth turns/stops over ~6 frames, then accelerations from velocity differences
            k = np.ones(6) / 6.0
            vel = np.column_stack((sp * np.cos(heading), sp * np.sin(heading)))
            vel = np.column_stack(
                [np.convolve(np.pad(vel[:, i], (5, 0), mode="edge"), k, "valid") for i in (0, 1)]
            )
            v0 = vel[0]
            accel[:-1] = np.diff(vel, axis=0) / dt
        elif trajectory_class == "e":
            radius = rng.uniform(1.0, 2.5)
            c = np.array([rng.uniform(-1.5, 1.5), rng.uniform(4, 6.5)])
            phi = rng.uniform(0, 2 * math.pi)
            sgn = 1.0 if rng.random() < 0.5 else -1.0
            omega = sgn * speed / radius
            p0 = c + radius * np.array([math.cos(phi), math.sin(phi)])
            v0 = radius * omega * np.array([-math.sin(phi), math.cos(phi)])
            # a = ω × v (centripetal), applied per step to the current velocity
            p = np.zeros((n_frames, 2))
            v = np.zeros((n_frames, 2))
            p[0], v[0] = p0, v0
            for t in range(1, n_frames):
                a = omega * np.array([-v[t - 1, 1], v[t - 1, 0]])
                v[t] = v[t - 1] + a * dt
                v[t] *= speed / np.hypot(*v[t])
                p[t] = p[t - 1] + v[t] * dt
            pos, vel = p, v
        else:
            raise ValueError(f"trajectory_class must be one of 'abcde', got {trajectory_class!r}")
        if trajectory_class != "e":
            pos, vel = integrate_eq6(p0, v0, accel, dt)
        ok = _inside(pos, scene)
        n_ok = int(np.argmin(ok)) if not ok.all() else n_frames
        if n_ok >= 40:
            return pos[:n_ok], vel[:n_ok]
    raise RuntimeError("could not draw a trajectory inside the AOI")


def synthetic_frames(
    truth_xy: np.ndarray,
    truth_v: np.ndarray,
    rng: np.random.Generator,
    scene: SyntheticScene = PAPER_LIKE,
) -> list[PointCloud]:
    """Point clouds of people walking (F frames): noisy detections plus Poisson clutter.

    ``truth_xy``, ``truth_v`` are (F, 2) for one person or (F, n, 2) for n people (m, m/s); each
    person is detected independently with P_D (source = person index), persons in order, then
    the clutter of the frame.
    """
    truth_xy = np.asarray(truth_xy, dtype=np.float64)
    truth_v = np.asarray(truth_v, dtype=np.float64)
    if truth_xy.ndim == 2:
        truth_xy, truth_v = truth_xy[:, None, :], truth_v[:, None, :]
    clouds = []
    for people_p, people_v in zip(truth_xy, truth_v):
        rows = []
        src = []
        for i, (p, v) in enumerate(zip(people_p, people_v)):
            if rng.random() < scene.p_d:
                r = math.hypot(p[0], p[1])
                az = math.atan2(p[0], p[1])
                # vr = (x·vx + y·vy)/r
                vr = (p[0] * v[0] + p[1] * v[1]) / r if r > 0 else 0.0
                n = rng.normal(0.0, scene.noise_std)
                rows.append((max(r + n[0], 0.0), az + n[1], vr + n[2]))
                src.append(i)
        k = rng.poisson(scene.clutter_per_frame) if scene.clutter_per_frame > 0 else 0
        if k:
            c = np.column_stack(
                (
                    rng.uniform(scene.min_range_m, scene.max_range_m, k),
                    rng.uniform(-scene.max_azimuth_rad, scene.max_azimuth_rad, k),
                    rng.uniform(-scene.max_velocity_mps, scene.max_velocity_mps, k),
                )
            )
            rows.extend(map(tuple, c))
            src.extend([SOURCE_CLUTTER] * k)
        z = np.array(rows, dtype=np.float64).reshape(-1, 3)
        clouds.append(
            PointCloud(
                range_m=z[:, 0],
                azimuth_rad=z[:, 1],
                elevation_rad=np.zeros(len(z)),
                radial_velocity_mps=z[:, 2],
                snr_db=np.full(len(z), 20.0),
                x_m=z[:, 0] * np.sin(z[:, 1]),
                y_m=z[:, 0] * np.cos(z[:, 1]),
                z_m=np.zeros(len(z)),
                source=np.array(src, dtype=np.int32),
            )
        )
    return clouds


def crossing_paths(
    n_people: int,
    n_frames: int,
    scene: SyntheticScene = PAPER_LIKE,
    *,
    centre: tuple[float, float] = (0.0, 5.0),
    speed_mps: float = 1.2,
    spread_rad: float = math.pi,
) -> tuple[np.ndarray, np.ndarray]:
    """n people walking straight lines that all cross at ``centre`` at the middle frame.

    Person i heads at the angle θᵢ = i·spread/n (spread π: evenly spaced directions; two people
    cross at 90°), starting half a walk before the crossing: pᵢ(t) = c + s·(t − F/2)·Δt·uᵢ.

    Returns
    -------
    positions, velocities
        (F, n, 2) in m and m/s.
    """
    dt = scene.frame_period_s
    theta = np.arange(n_people) * spread_rad / n_people
    u = np.column_stack((np.cos(theta), np.sin(theta)))  # (n, 2) headings
    tau = (np.arange(n_frames) - n_frames / 2.0) * dt  # s relative to the crossing
    # pᵢ(t) = c + s τ uᵢ, vᵢ = s uᵢ
    pos = np.asarray(centre)[None, None, :] + speed_mps * tau[:, None, None] * u[None, :, :]
    vel = np.broadcast_to(speed_mps * u[None, :, :], pos.shape).copy()
    return pos, vel


def circling_paths(
    n_people: int,
    n_frames: int,
    scene: SyntheticScene = PAPER_LIKE,
    *,
    centre: tuple[float, float] = (0.0, 5.0),
    speed_mps: float = 1.0,
) -> tuple[np.ndarray, np.ndarray]:
    """n people walking circles round one centre, every second one the other way: a room in
    which they keep crossing.

    Person i walks radius Rᵢ = 1.2 + 0.4·(i mod 3) m, starting at the angle 2πi/n, direction
    sᵢ = (−1)ⁱ: φᵢ(t) = 2πi/n + sᵢ·(v/Rᵢ)·t, pᵢ(t) = c + Rᵢ[cos φᵢ, sin φᵢ].

    Returns
    -------
    positions, velocities
        (F, n, 2) in m and m/s.
    """
    t = np.arange(n_frames) * scene.frame_period_s
    pos = np.zeros((n_frames, n_people, 2))
    vel = np.zeros((n_frames, n_people, 2))
    for i in range(n_people):
        radius = 1.2 + 0.4 * (i % 3)
        omega = (-1.0) ** i * speed_mps / radius
        phi = 2.0 * math.pi * i / n_people + omega * t
        pos[:, i] = np.asarray(centre) + radius * np.column_stack((np.cos(phi), np.sin(phi)))
        # v = R ω [−sin φ, cos φ]
        vel[:, i] = radius * omega * np.column_stack((-np.sin(phi), np.cos(phi)))
    return pos, vel


def people_dataset(
    positions: np.ndarray,
    velocities: np.ndarray,
    seed: int = 0,
    scene: SyntheticScene = PAPER_LIKE,
) -> Dataset:
    """A one-trajectory :class:`Dataset` of several people, (F, n, 2) truth each (m, m/s)."""
    rng = np.random.default_rng(seed)
    positions = np.asarray(positions, dtype=np.float64)
    n_f = len(positions)
    return Dataset.from_frames(
        clouds=synthetic_frames(positions, velocities, rng, scene),
        trajectory=np.zeros(n_f, dtype=np.int64),
        truth_t_s=np.arange(n_f) * scene.frame_period_s,
        truth_xy_m=positions,
        truth_v_mps=np.asarray(velocities, dtype=np.float64),
        trajectory_class=["drawn"],
        scene_json=json.dumps(
            {
                "synthetic": True,
                "seed": seed,
                "persons": int(positions.shape[1]),
                "clutter_per_frame": scene.clutter_per_frame,
                "p_d": scene.p_d,
                "noise_std": list(scene.noise_std),
            }
        ),
        radar_json=json.dumps({"frame_period_s": scene.frame_period_s}),
        fidelity="synthetic",
        seed=seed,
    )


def synthetic_dataset(
    seed: int = 0,
    n_per_class: int = 1,
    classes: str = "abcde",
    scene: SyntheticScene = PAPER_LIKE,
    n_frames: int = 150,
    paths: list[tuple[np.ndarray, np.ndarray]] | None = None,
) -> Dataset:
    """A :class:`Dataset` of synthetic trajectories, round-robin over ``classes``.

    ``paths`` (a list of (positions, velocities) (F, 2)) replaces the drawn trajectories; each
    is labelled ``"drawn"``.
    """
    rng = np.random.default_rng(seed)
    if paths is None:
        labels = [cl for _ in range(n_per_class) for cl in classes]
        paths = [synthetic_trajectory(cl, rng, scene, n_frames) for cl in labels]
    else:
        labels = ["drawn"] * len(paths)
    clouds: list[PointCloud] = []
    traj, t_s, xy, vel = [], [], [], []
    for k, (p, v) in enumerate(paths):
        clouds.extend(synthetic_frames(p, v, rng, scene))
        traj.append(np.full(len(p), k))
        t_s.append(np.arange(len(p)) * scene.frame_period_s)
        xy.append(p[:, None, :])
        vel.append(v[:, None, :])
    scene_json = json.dumps(
        {
            "synthetic": True,
            "seed": seed,
            "clutter_per_frame": scene.clutter_per_frame,
            "p_d": scene.p_d,
            "noise_std": list(scene.noise_std),
        }
    )
    return Dataset.from_frames(
        clouds=clouds,
        trajectory=np.concatenate(traj),
        truth_t_s=np.concatenate(t_s),
        truth_xy_m=np.concatenate(xy),
        truth_v_mps=np.concatenate(vel),
        trajectory_class=labels,
        scene_json=scene_json,
        radar_json=json.dumps({"frame_period_s": scene.frame_period_s}),
        fidelity="synthetic",
        seed=seed,
    )


def room_dataset(
    positions: np.ndarray,
    velocities: np.ndarray,
    seed: int = 0,
    *,
    points_per_person: int = 25,
    moving_clutter: int = 10,
    static_clutter: int = 40,
    body_sigma_m: float = 0.2,
    frame_period_s: float = 0.1,
) -> Dataset:
    """A one-trajectory room :class:`Dataset` of several people as groups of points.

    Each person (truth (F, n, 2) in m and m/s) gives ``points_per_person`` points a frame
    scattered over the body (x, y Gaussian with σ = ``body_sigma_m``, z uniform over 0.2–1.8 m),
    with the centre's radial velocity plus N(0, 0.3 m/s) (limbs), SNR 10–25 dB; then
    ``moving_clutter`` points uniform over the room (±3 m, 0.5–8 m) with radial velocities
    uniform in ±2 m/s and SNR 0–15 dB, and ``static_clutter`` zero-Doppler points (furniture).
    Four people with the defaults make 150 points a frame, the size of TI's people-counting
    output in an office (SPEC §7). Per-point source: the person's index, −1 for clutter.
    """
    rng = np.random.default_rng(seed)
    positions = np.asarray(positions, dtype=np.float64)
    velocities = np.asarray(velocities, dtype=np.float64)
    n_f, n_p = positions.shape[:2]
    clouds = []
    for f in range(n_f):
        xs, ys, zs, vrs, snrs, src = [], [], [], [], [], []
        for i in range(n_p):
            p, v = positions[f, i], velocities[f, i]
            x = p[0] + rng.normal(0.0, body_sigma_m, points_per_person)
            y = p[1] + rng.normal(0.0, body_sigma_m, points_per_person)
            r = np.hypot(x, y)
            xs.append(x)
            ys.append(y)
            zs.append(rng.uniform(0.2, 1.8, points_per_person))
            # vr = (x·vx + y·vy)/r, plus the limbs' spread
            vrs.append((x * v[0] + y * v[1]) / r + rng.normal(0.0, 0.3, points_per_person))
            snrs.append(rng.uniform(10.0, 25.0, points_per_person))
            src.append(np.full(points_per_person, i))
        k = moving_clutter + static_clutter
        xs.append(rng.uniform(-3.0, 3.0, k))
        ys.append(rng.uniform(0.5, 8.0, k))
        zs.append(rng.uniform(0.0, 2.0, k))
        vrs.append(
            np.concatenate((rng.uniform(-2.0, 2.0, moving_clutter), np.zeros(static_clutter)))
        )
        snrs.append(rng.uniform(0.0, 15.0, k))
        src.append(np.full(k, SOURCE_CLUTTER))
        x, y, z = np.concatenate(xs), np.concatenate(ys), np.concatenate(zs)
        r = np.sqrt(x * x + y * y + z * z)
        clouds.append(
            PointCloud(
                range_m=np.hypot(x, y),
                azimuth_rad=np.arctan2(x, y),
                elevation_rad=np.arcsin(z / r),
                radial_velocity_mps=np.concatenate(vrs),
                snr_db=np.concatenate(snrs),
                x_m=x,
                y_m=y,
                z_m=z,
                source=np.concatenate(src).astype(np.int32),
            )
        )
    return Dataset.from_frames(
        clouds=clouds,
        trajectory=np.zeros(n_f, dtype=np.int64),
        truth_t_s=np.arange(n_f) * frame_period_s,
        truth_xy_m=positions,
        truth_v_mps=velocities,
        trajectory_class=["drawn"],
        scene_json=json.dumps(
            {
                "synthetic": True,
                "room": True,
                "seed": seed,
                "persons": n_p,
                "points_per_person": points_per_person,
                "moving_clutter": moving_clutter,
                "static_clutter": static_clutter,
            }
        ),
        radar_json=json.dumps({"frame_period_s": frame_period_s}),
        fidelity="synthetic",
        seed=seed,
    )

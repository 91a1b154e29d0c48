"""Person trajectories through the paper's eq. (6): classes a–e, waypoints, explicit profiles.

Every trajectory, however it is described, is stored as an initial position, an initial
velocity and an acceleration profile, integrated with eq. (6) (Δt = frame period)::

    v(t) = v(t-1) + a(t-1) Δt
    p(t) = p(t-1) + v(t) Δt

Generators build the *desired* velocity of every frame (constant speed on a turn, a stop, a
circle) and turn it into the acceleration profile ``a(t-1) = (v(t) - v(t-1)) / Δt``, so that the
stored positions are exactly eq. (6) of the stored accelerations (:mod:`core.kinematics`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from core.errors import InputError
from core.kinematics import integrate_eq6
from core.scene.aoi import AOI

TRAJECTORY_CLASSES = ("a", "b", "c", "d", "e")
MIN_FRAMES = 75  # 6 s at 80 ms
MAX_FRAMES = 250  # 20 s at 80 ms
SPEED_RANGE_MPS = (0.5, 1.8)  # walking speeds drawn by the generators
_MAX_ATTEMPTS = 500


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class Trajectory:
    """A person's ground truth over ``F`` frames, eq. (6).

    Attributes
    ----------
    position_m
        ``[x, y]`` at each frame's first chirp, shape ``(F, 2)``, m.
    velocity_mps
        ``[vx, vy]``, shape ``(F, 2)``, m/s.
    acceleration_mps2
        ``[ax, ay]``, shape ``(F, 2)``, m/s²; row ``t`` acts between frames ``t`` and ``t+1``
        (the last row is unused by eq. (6)).
    frame_period_s
        Δt, s.
    trajectory_class
        ``"a"`` … ``"e"``, ``"drawn"`` (waypoints) or ``"profile"`` (explicit eq. (6) profile).
    seated
        ``None`` (standing or walking throughout) or shape ``(F,)`` bool: the frames where the
        person sits (a ``sit`` stop of a drawn path; :mod:`core.scene.walking` seats the body).
    """

    position_m: np.ndarray
    velocity_mps: np.ndarray
    acceleration_mps2: np.ndarray
    frame_period_s: float
    trajectory_class: str
    seated: np.ndarray | None = None

    def __post_init__(self) -> None:
        f = len(self.position_m)
        for name in ("position_m", "velocity_mps", "acceleration_mps2"):
            a = getattr(self, name)
            if np.shape(a) != (f, 2):
                raise ValueError(f"Trajectory.{name} must have shape ({f}, 2), got {np.shape(a)}")
            if not np.all(np.isfinite(a)):
                raise InputError(f"trajectory {name} contains non-finite values")
        if f < 1:
            raise InputError("a trajectory needs at least one frame")
        if self.seated is not None and np.shape(self.seated) != (f,):
            raise ValueError(
                f"Trajectory.seated must have shape ({f},), got {np.shape(self.seated)}"
            )

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Trajectory):
            return NotImplemented
        return (
            self.frame_period_s == other.frame_period_s
            and self.trajectory_class == other.trajectory_class
            and np.array_equal(self.position_m, other.position_m)
            and np.array_equal(self.velocity_mps, other.velocity_mps)
            and np.array_equal(self.acceleration_mps2, other.acceleration_mps2)
            and np.array_equal(self.seated_mask, other.seated_mask)
        )

    __hash__ = None  # type: ignore[assignment]

    @property
    def n_frames(self) -> int:
        return len(self.position_m)

    @property
    def seated_mask(self) -> np.ndarray:
        """Shape ``(F,)`` bool: the frames where the person sits (all False if none)."""
        if self.seated is None:
            return np.zeros(self.n_frames, dtype=bool)
        return np.asarray(self.seated, dtype=bool)

    @property
    def t_s(self) -> np.ndarray:
        """Frame times ``t·Δt``, shape ``(F,)``, s."""
        return np.arange(self.n_frames) * self.frame_period_s

    @property
    def speed_mps(self) -> np.ndarray:
        """``|v|``, shape ``(F,)``, m/s."""
        return np.hypot(self.velocity_mps[:, 0], self.velocity_mps[:, 1])

    @property
    def radial_velocity_mps(self) -> np.ndarray:
        """``vr = (x·vx + y·vy) / r`` seen from the radar at the origin, shape ``(F,)``, m/s."""
        p, v = self.position_m, self.velocity_mps
        r = np.maximum(np.hypot(p[:, 0], p[:, 1]), 1e-12)
        return (p[:, 0] * v[:, 0] + p[:, 1] * v[:, 1]) / r


def _from_velocities(
    p0: np.ndarray, velocity: np.ndarray, dt: float, trajectory_class: str
) -> Trajectory:
    """Acceleration ``a(t-1) = (v(t) - v(t-1))/Δt`` from desired velocities, then eq. (6)."""
    a = np.zeros_like(velocity)
    a[:-1] = np.diff(velocity, axis=0) / dt
    p, v = integrate_eq6(p0, velocity[0], a, dt)
    return Trajectory(
        position_m=p,
        velocity_mps=v,
        acceleration_mps2=a,
        frame_period_s=dt,
        trajectory_class=trajectory_class,
    )


def profile_trajectory(
    *,
    initial_position_m: np.ndarray,
    initial_velocity_mps: np.ndarray,
    acceleration_mps2: np.ndarray,
    frames: int | None = None,
    frame_period_s: float = 0.08,
) -> Trajectory:
    """An explicit eq. (6) profile.

    ``acceleration_mps2`` is one ``[ax, ay]`` for all frames (then ``frames`` is required) or one
    per frame, shape ``(F, 2)`` (``frames``, if given, must equal ``F``).
    """
    a = np.asarray(acceleration_mps2, dtype=np.float64)
    if a.shape == (2,):
        if frames is None:
            raise InputError("frames is required when one acceleration is given for all frames")
        a = np.tile(a, (int(frames), 1))
    elif a.ndim != 2 or a.shape[1] != 2:
        raise InputError(f"acceleration_mps2 must be [ax, ay] or a list of them, got {a.shape}")
    elif frames is not None and frames != len(a):
        raise InputError(f"frames={frames} but acceleration_mps2 lists {len(a)} accelerations")
    p, v = integrate_eq6(
        np.asarray(initial_position_m, float), np.asarray(initial_velocity_mps, float), a,
        frame_period_s,
    )  # fmt: skip
    return Trajectory(
        position_m=p,
        velocity_mps=v,
        acceleration_mps2=a,
        frame_period_s=frame_period_s,
        trajectory_class="profile",
    )


def _waypoint_segments(
    w: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Segments ``(W-1, 2)``, lengths, speed gradients ``k`` and start times ``(W,)`` of a path."""
    seg = np.diff(w[:, :2], axis=0)
    length = np.hypot(seg[:, 0], seg[:, 1])
    v0, v1 = w[:-1, 2], w[1:, 2]
    k = np.where(length > 0, (v1 - v0) / np.where(length > 0, length, 1.0), 0.0)
    # segment durations: T = ln(v1/v0)/k, or L/v0 when k = 0
    with np.errstate(divide="ignore", invalid="ignore"):
        dur = np.where(np.abs(k) > 1e-12, np.log(v1 / v0) / k, length / v0)
    dur = np.where(length > 0, dur, 0.0)
    return seg, length, k, np.concatenate(([0.0], np.cumsum(dur)))


def waypoint_duration_s(waypoints: np.ndarray) -> float:
    """How long walking the waypoints ``[x_m, y_m, speed_mps]`` (shape ``(W, 3)``) takes, s."""
    return float(_waypoint_segments(np.asarray(waypoints, dtype=np.float64))[3][-1])


def waypoint_trajectory(waypoints: np.ndarray, *, frame_period_s: float = 0.08) -> Trajectory:
    """A drawn path: waypoints ``[x_m, y_m, speed_mps]`` walked in order.

    Between two waypoints the person walks along the straight segment; the speed varies
    linearly with distance from the first waypoint's speed to the second's, i.e. ``ds/dt = v(s)``
    with ``v(s) = v_i + k (s - s_i)``, ``k = (v_{i+1} - v_i)/L_i``, solved exactly:
    ``s(t) = s_i + v_i (e^{k t} - 1)/k`` (``s_i + v_i t`` for ``k = 0``). Positions are sampled
    every frame and turned into an acceleration profile of eq. (6). The trajectory ends at the
    last waypoint.

    Parameters
    ----------
    waypoints
        Shape ``(W, 3)``, ``W >= 2``: x (m), y (m), speed (m/s, > 0).
    """
    w = np.asarray(waypoints, dtype=np.float64)
    dt = float(frame_period_s)
    seg, length, k, t_start = _waypoint_segments(w)
    v0 = w[:-1, 2]
    n_frames = int(math.floor(t_start[-1] / dt + 1e-9)) + 1
    if n_frames < 2:
        raise InputError("waypoints describe a path shorter than one frame")
    t = np.arange(n_frames) * dt
    i = np.clip(np.searchsorted(t_start, t, side="right") - 1, 0, len(seg) - 1)
    tau = t - t_start[i]
    ki = k[i]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        s = np.where(np.abs(ki) > 1e-12, v0[i] * np.expm1(ki * tau) / ki, v0[i] * tau)
    s = np.clip(s, 0.0, length[i])
    unit = seg[i] / np.where(length[i] > 0, length[i], 1.0)[:, None]
    pos = w[i, :2] + unit * s[:, None]
    vel = np.zeros_like(pos)
    vel[1:] = np.diff(pos, axis=0) / dt
    vel[0] = unit[0] * v0[0]
    return _from_velocities(pos[0], vel, dt, "drawn")


def stopping_waypoint_trajectory(
    waypoints: np.ndarray,
    hold_s: np.ndarray,
    *,
    frame_period_s: float = 0.08,
    sit: np.ndarray | None = None,
) -> Trajectory:
    """A drawn path with stops: waypoints ``[x_m, y_m, speed_mps]``, where a waypoint of speed
    0 is a stop of ``hold_s`` seconds (shape ``(W,)``; 0 elsewhere). ``sit`` (shape ``(W,)``
    bool, optional): the stops where the person sits for the hold (the trajectory's
    ``seated`` frames are that hold's frames; the body sits down over the first second of
    the hold and stands up over its last, :func:`core.scene.walking.sit_transition`).

    Between stops the path is walked as :func:`waypoint_trajectory` walks it; a stop's own
    speed (0) is replaced by its walking neighbour's (the walk arrives and leaves at that
    speed), and the person stands still at the stop for its hold time (the walking body then
    sways and breathes, :mod:`core.scene.walking`). Positions are sampled every frame of one
    continuous clock and turned into an eq. (6) profile.
    """
    w = np.array(waypoints, dtype=np.float64)
    hold = np.asarray(hold_s, dtype=np.float64)
    dt = float(frame_period_s)
    stops = np.flatnonzero(w[:, 2] == 0)
    if not len(stops):
        return waypoint_trajectory(w, frame_period_s=dt)
    sitting = np.zeros(len(w), dtype=bool) if sit is None else np.asarray(sit, dtype=bool)
    # pieces of the clock: ("hold", xy, duration) or ("walk", rows, duration)
    pieces: list[tuple[str, np.ndarray, float]] = []
    sit_piece: list[bool] = []
    ends = sorted({0, len(w) - 1, *stops.tolist()})
    for a, b in zip(ends, [*ends[1:], None]):
        if w[a, 2] == 0:
            pieces.append(("hold", w[a, :2], float(hold[a])))
            sit_piece.append(bool(sitting[a]))
        if b is None:
            break
        rows = w[a : b + 1].copy()
        if rows[0, 2] == 0:
            rows[0, 2] = rows[1, 2] if rows[1, 2] > 0 else _walking_speed(w, a)
        if rows[-1, 2] == 0:
            rows[-1, 2] = rows[-2, 2] if rows[-2, 2] > 0 else _walking_speed(w, b)
        pieces.append(("walk", rows, float(_waypoint_segments(rows)[3][-1])))
        sit_piece.append(False)
    t_end = np.cumsum([d for _, _, d in pieces])
    n_frames = int(math.floor(t_end[-1] / dt + 1e-9)) + 1
    if n_frames < 2:
        raise InputError("waypoints describe a path shorter than one frame")
    t = np.arange(n_frames) * dt
    piece = np.clip(np.searchsorted(t_end, t, side="right"), 0, len(pieces) - 1)
    pos = np.empty((n_frames, 2))
    for j, (kind, data, _) in enumerate(pieces):
        at = np.flatnonzero(piece == j)
        if not len(at):
            continue
        if kind == "hold":
            pos[at] = data
            continue
        tau = t[at] - (t_end[j - 1] if j else 0.0)
        pos[at] = _path_positions(data, tau)
    vel = np.zeros_like(pos)
    vel[1:] = np.diff(pos, axis=0) / dt
    if pieces[0][0] == "walk":  # a walk from the first frame starts at its speed
        rows = pieces[0][1]
        d = rows[1, :2] - rows[0, :2]
        if np.hypot(*d) > 0:
            vel[0] = d / np.hypot(*d) * rows[0, 2]
    traj = _from_velocities(pos[0], vel, dt, "drawn")
    if not any(sit_piece):
        return traj
    seated = np.array(sit_piece)[piece]
    return replace(traj, seated=seated)


def _walking_speed(w: np.ndarray, i: int) -> float:
    """The speed of the walking waypoint nearest to waypoint ``i`` (a stop)."""
    moving = np.flatnonzero(w[:, 2] > 0)
    if not len(moving):
        raise InputError("waypoints: a path of stops only; give some waypoint a speed")
    return float(w[moving[np.argmin(np.abs(moving - i))], 2])


def _path_positions(w: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """Positions ``(n, 2)`` at times ``tau`` (s from the start) along waypoints ``w`` walked as
    :func:`waypoint_trajectory` walks them (clamped at the last waypoint)."""
    seg, length, k, t_start = _waypoint_segments(w)
    v0 = w[:-1, 2]
    i = np.clip(np.searchsorted(t_start, tau, side="right") - 1, 0, len(seg) - 1)
    rel = tau - t_start[i]
    ki = k[i]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        s = np.where(np.abs(ki) > 1e-12, v0[i] * np.expm1(ki * rel) / ki, v0[i] * rel)
    s = np.clip(s, 0.0, length[i])
    unit = seg[i] / np.where(length[i] > 0, length[i], 1.0)[:, None]
    return w[i, :2] + unit * s[:, None]


# ---- random classes a–e ------------------------------------------------------------------------


def _wrap(angle: float) -> float:
    return (angle + math.pi) % (2 * math.pi) - math.pi


def _straight(
    rng: np.random.Generator,
    aoi: AOI,
    dt: float,
    trajectory_class: str,
    *,
    speed_mps: float | None,
    start_m: tuple[float, float] | None,
    orientation: str | None = None,
) -> Trajectory:
    """Classes a (along x or y) and b (radially toward the radar), constant speed.

    The path ends where it would leave the AOI (at most 20 s); speed and start are redrawn
    until it lasts at least 6 s (unless both are fixed by the caller).
    """
    fixed = speed_mps is not None and start_m is not None
    best: tuple[int, np.ndarray, np.ndarray] | None = None
    for _ in range(50 if fixed else _MAX_ATTEMPTS):
        speed = speed_mps if speed_mps is not None else rng.uniform(*SPEED_RANGE_MPS)
        if trajectory_class == "b" and start_m is None:
            # radial approach: r0 >= r_min + 6 s * speed, so the path lasts >= 6 s
            speed = min(speed, (aoi.max_range_m - aoi.min_range_m) / ((MIN_FRAMES + 2) * dt))
            r_lo = aoi.min_range_m + (MIN_FRAMES + 1) * dt * speed
            r0 = rng.uniform(r_lo, aoi.max_range_m)
            az0 = rng.uniform(-aoi.max_azimuth_rad, aoi.max_azimuth_rad)
            p0 = np.array([r0 * math.sin(az0), r0 * math.cos(az0)])
        elif start_m is None:
            p0 = aoi.sample_uniform(1, rng)[0]
        else:
            p0 = np.asarray(start_m, dtype=np.float64)
        if trajectory_class == "a":
            orient = orientation or ("horizontal" if rng.random() < 0.5 else "vertical")
            sign = 1.0 if rng.random() < 0.5 else -1.0
            direction = np.array([sign, 0.0]) if orient == "horizontal" else np.array([0.0, sign])
        else:
            direction = -p0 / np.hypot(*p0)
        v = np.tile(direction * speed, (MAX_FRAMES + 1, 1))
        p = p0 + np.cumsum(np.vstack(([0.0, 0.0], v[1:] * dt)), axis=0)
        inside = aoi.contains(p)
        n = int(np.argmin(inside)) if not inside.all() else len(p)
        n = min(n, MAX_FRAMES)
        if n >= MIN_FRAMES:
            return _from_velocities(p0, v[:n], dt, trajectory_class)
        if fixed and n >= 2 and (best is None or n > best[0]):
            best = (n, p0, v[:n])
    if best is not None:  # speed and start fixed by the caller: the longest direction drawn
        return _from_velocities(best[1], best[2], dt, trajectory_class)
    raise InputError(
        f"class {trajectory_class!r}: cannot place a straight path of at least {MIN_FRAMES} frames "
        f"inside the AOI with speed_mps={speed_mps!r}, start_m={start_m!r}"
    )


def _walk(
    rng: np.random.Generator,
    aoi: AOI,
    dt: float,
    trajectory_class: str,
    *,
    speed_mps: float | None,
    start_m: tuple[float, float] | None,
    duration_s: float | None,
    turn_rate_hz: float,
    min_turn_deg: float,
    max_turn_deg: float,
    turn_duration_s: float,
    stop_rate_hz: float,
    stop_duration_s: tuple[float, float],
    ramp_s: float,
) -> Trajectory:
    """Classes c (random turns) and d (random stops): a walker that keeps inside the AOI.

    Heading changes happen at Poisson times (rate ``turn_rate_hz``), of random size in
    ``[min_turn_deg, max_turn_deg]`` either way, spread evenly over ``turn_duration_s``. When the
    point 2 s ahead would leave the AOI (with a 0.4 m margin) the walker turns toward the AOI
    centre at most 90 °/s. Stops happen at Poisson times (``stop_rate_hz``): a linear
    deceleration over ``ramp_s``, standing still for a time uniform in ``stop_duration_s``, and a
    linear acceleration over ``ramp_s``. The speed is constant otherwise.
    """
    lookahead_s, margin_m, max_rate = 2.0, 0.4, math.radians(90.0)
    for _ in range(_MAX_ATTEMPTS):
        cruise = speed_mps if speed_mps is not None else rng.uniform(*SPEED_RANGE_MPS)
        dur = duration_s if duration_s is not None else rng.uniform(6.0, 20.0)
        n = int(round(dur / dt))
        p0 = (
            np.asarray(start_m, dtype=np.float64)
            if start_m is not None
            else aoi.sample_uniform(1, rng)[0]
        )
        if not aoi.contains(p0, margin_m):
            if start_m is not None:
                raise InputError(f"start_m={list(start_m)} must lie inside the AOI")
            continue
        heading = rng.uniform(-math.pi, math.pi)
        # start roughly toward the inside so the first frames do not leave the AOI at once
        to_centre = math.atan2(*(aoi.centre_m - p0)[::-1])
        if abs(_wrap(heading - to_centre)) > math.radians(100):
            heading = _wrap(heading + math.pi)
        ramp_n = max(1, int(round(ramp_s / dt)))
        # class d: the first stop comes at a random time in the first half, later ones at rate
        first_stop = int(rng.integers(int(1.0 / dt), max(int(1.0 / dt) + 1, n // 2)))
        turn_left, turn_step = 0, 0.0
        phase, phase_left = "walk", 0
        vel = np.zeros((n, 2))
        pos = np.zeros((n, 2))
        pos[0] = p0
        speed = cruise
        vel[0] = speed * np.array([math.sin(heading), math.cos(heading)])
        for t in range(1, n):
            if turn_left == 0:
                u = np.array([math.sin(heading), math.cos(heading)])
                ahead = pos[t - 1] + cruise * lookahead_s * u
                if not aoi.contains(ahead, margin_m):
                    c = aoi.centre_m - pos[t - 1]
                    delta = _wrap(math.atan2(c[0], c[1]) - heading)
                    turn_left = max(3, math.ceil(abs(delta) / (max_rate * dt)))
                    turn_step = delta / turn_left
                elif rng.random() < turn_rate_hz * dt:
                    size = math.radians(rng.uniform(min_turn_deg, max_turn_deg))
                    delta = size if rng.random() < 0.5 else -size
                    turn_left = max(2, int(round(turn_duration_s / dt)))
                    turn_step = delta / turn_left
            if turn_left > 0:
                heading = _wrap(heading + turn_step)
                turn_left -= 1
            if (
                phase == "walk"
                and stop_rate_hz > 0
                and (t == first_stop or rng.random() < stop_rate_hz * dt)
            ):
                phase, phase_left = "decel", ramp_n
            if phase == "decel":
                phase_left -= 1
                speed = cruise * phase_left / ramp_n
                if phase_left == 0:
                    phase = "stand"
                    phase_left = max(1, int(round(rng.uniform(*stop_duration_s) / dt)))
            elif phase == "stand":
                speed = 0.0
                phase_left -= 1
                if phase_left == 0:
                    phase, phase_left = "accel", ramp_n
            elif phase == "accel":
                phase_left -= 1
                speed = cruise * (ramp_n - phase_left) / ramp_n
                if phase_left == 0:
                    phase = "walk"
            vel[t] = speed * np.array([math.sin(heading), math.cos(heading)])
            pos[t] = pos[t - 1] + vel[t] * dt
        traj = _from_velocities(p0, vel, dt, trajectory_class)
        if aoi.contains(traj.position_m).all():
            return traj
    raise InputError(f"class {trajectory_class!r}: cannot keep the walk inside the AOI")


def _circle(
    rng: np.random.Generator,
    aoi: AOI,
    dt: float,
    *,
    speed_mps: float | None,
    radius_m: float | None,
    centre_m: tuple[float, float] | None,
    duration_s: float | None,
    clockwise: bool | None,
) -> Trajectory:
    """Class e: constant speed on a circle (centripetal acceleration), not centred on the radar.

    Positions lie exactly on the circle: the angle advances by ``Δφ = 2 asin(v Δt / (2 R))`` per
    frame, so the chord length per frame is ``v Δt``.
    """
    for _ in range(_MAX_ATTEMPTS):
        speed = speed_mps if speed_mps is not None else rng.uniform(*SPEED_RANGE_MPS)
        radius = radius_m if radius_m is not None else rng.uniform(1.0, 3.5)
        c = (
            np.asarray(centre_m, dtype=np.float64)
            if centre_m is not None
            else aoi.sample_uniform(1, rng)[0]
        )
        ring = c + radius * np.column_stack(
            (np.cos(np.linspace(0, 2 * np.pi, 73)), np.sin(np.linspace(0, 2 * np.pi, 73)))
        )
        if not aoi.contains(ring, 0.05).all():
            if centre_m is not None and radius_m is not None:
                raise InputError(
                    f"class 'e': circle centre_m={list(centre_m)}, radius_m={radius_m} "
                    "does not fit inside the AOI"
                )
            continue
        dur = duration_s if duration_s is not None else rng.uniform(6.0, 20.0)
        n = int(round(dur / dt))
        cw = clockwise if clockwise is not None else bool(rng.random() < 0.5)
        # Δφ = 2 asin(v Δt / 2R), sign by direction
        dphi = 2 * math.asin(min(1.0, speed * dt / (2 * radius))) * (-1 if cw else 1)
        phi = rng.uniform(-math.pi, math.pi) + dphi * np.arange(n)
        pos = c + radius * np.column_stack((np.cos(phi), np.sin(phi)))
        vel = np.zeros_like(pos)
        vel[1:] = np.diff(pos, axis=0) / dt
        # v(0): the chord velocity of the frame before, so the speed is constant from frame 0
        prev = c + radius * np.array([math.cos(phi[0] - dphi), math.sin(phi[0] - dphi)])
        vel[0] = (pos[0] - prev) / dt
        return _from_velocities(pos[0], vel, dt, "e")
    raise InputError("class 'e': cannot place a circle inside the AOI")


# Per-class parameters: name -> (kind, low, high). kind is float, "xy", "orientation" or bool.
CLASS_PARAMETERS: dict[str, dict[str, tuple[Any, float | None, float | None]]] = {
    "a": {
        "speed_mps": (float, 0.1, 3.0),
        "start_m": ("xy", None, None),
        "orientation": ("orientation", None, None),
    },
    "b": {"speed_mps": (float, 0.1, 3.0), "start_m": ("xy", None, None)},
    "c": {
        "speed_mps": (float, 0.1, 3.0),
        "start_m": ("xy", None, None),
        "duration_s": (float, 0.5, 600.0),
        "turn_rate_hz": (float, 0.0, 5.0),
        "min_turn_deg": (float, 0.0, 180.0),
        "max_turn_deg": (float, 0.0, 180.0),
        "turn_duration_s": (float, 0.1, 5.0),
    },
    "d": {
        "speed_mps": (float, 0.1, 3.0),
        "start_m": ("xy", None, None),
        "duration_s": (float, 0.5, 600.0),
        "stop_rate_hz": (float, 0.0, 5.0),
        "min_stop_s": (float, 0.08, 60.0),
        "max_stop_s": (float, 0.08, 60.0),
        "ramp_s": (float, 0.08, 5.0),
        "turn_rate_hz": (float, 0.0, 5.0),
    },
    "e": {
        "speed_mps": (float, 0.1, 3.0),
        "radius_m": (float, 0.3, 10.0),
        "centre_m": ("xy", None, None),
        "duration_s": (float, 0.5, 600.0),
        "clockwise": (bool, None, None),
    },
}


def validate_class_parameters(
    trajectory_class: str, params: Mapping[str, Any], where: str = "trajectory"
) -> dict[str, Any]:
    """Check class parameters; returns them converted. Errors name ``where.<field>``."""
    if trajectory_class not in CLASS_PARAMETERS:
        raise InputError(
            f"{where}.class: unknown trajectory class {trajectory_class!r}; "
            f"expected one of {list(TRAJECTORY_CLASSES)}"
        )
    allowed = CLASS_PARAMETERS[trajectory_class]
    unknown = sorted(set(params) - set(allowed))
    if unknown:
        raise InputError(
            f"{where}: unknown key(s) {unknown} for class {trajectory_class!r}; "
            f"expected some of {sorted(allowed)}"
        )
    out: dict[str, Any] = {}
    for name, value in params.items():
        kind, lo, hi = allowed[name]
        field = f"{where}.{name}"
        if kind is float:
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise InputError(f"{field} must be a number, got {value!r}")
            if not (math.isfinite(value) and lo <= value <= hi):
                raise InputError(f"{field} must be in [{lo}, {hi}], got {value!r}")
            out[name] = float(value)
        elif kind == "xy":
            if (
                not isinstance(value, list | tuple)
                or len(value) != 2
                or not all(
                    isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
                    for v in value
                )
            ):
                raise InputError(f"{field} must be [x_m, y_m], got {value!r}")
            out[name] = (float(value[0]), float(value[1]))
        elif kind == "orientation":
            if value not in ("horizontal", "vertical"):
                raise InputError(f"{field} must be 'horizontal' or 'vertical', got {value!r}")
            out[name] = value
        elif kind is bool:
            if not isinstance(value, bool):
                raise InputError(f"{field} must be true or false, got {value!r}")
            out[name] = value
    for lo_name, hi_name in (("min_turn_deg", "max_turn_deg"), ("min_stop_s", "max_stop_s")):
        if lo_name in out and hi_name in out and out[lo_name] > out[hi_name]:
            raise InputError(f"{where}: {lo_name} must not exceed {hi_name}")
    return out


def generate_trajectory(
    trajectory_class: str,
    rng: np.random.Generator,
    *,
    aoi: AOI | None = None,
    frame_period_s: float = 0.08,
    **class_params: Any,
) -> Trajectory:
    """Draw a random trajectory of one of the paper's classes (Fig. 3).

    Parameters
    ----------
    trajectory_class
        ``"a"`` straight along x or y at constant speed, ``"b"`` straight radially toward the
        radar, ``"c"`` constant speed with random turns, ``"d"`` walking with random stops,
        ``"e"`` constant speed on a circle not centred on the radar.
    rng
        The only source of randomness.
    aoi
        The area the trajectory stays in (default: the paper's).
    frame_period_s
        Δt of eq. (6), s.
    **class_params
        Optional per-class parameters (see :data:`CLASS_PARAMETERS`); unset ones are drawn:
        speed uniform in 0.5–1.8 m/s, duration 6–20 s (a, b: until the path leaves the AOI).

    Returns
    -------
    Trajectory
        Inside the AOI at every frame.
    """
    aoi = aoi or AOI()
    p = validate_class_parameters(trajectory_class, class_params)
    dt = float(frame_period_s)
    if trajectory_class in ("a", "b"):
        return _straight(
            rng,
            aoi,
            dt,
            trajectory_class,
            speed_mps=p.get("speed_mps"),
            start_m=p.get("start_m"),
            orientation=p.get("orientation"),
        )
    if trajectory_class in ("c", "d"):
        is_c = trajectory_class == "c"
        return _walk(
            rng,
            aoi,
            dt,
            trajectory_class,
            speed_mps=p.get("speed_mps"),
            start_m=p.get("start_m"),
            duration_s=p.get("duration_s"),
            turn_rate_hz=p.get("turn_rate_hz", 0.3 if is_c else 0.0),
            min_turn_deg=p.get("min_turn_deg", 30.0),
            max_turn_deg=p.get("max_turn_deg", 120.0),
            turn_duration_s=p.get("turn_duration_s", 0.8),
            stop_rate_hz=0.0 if is_c else p.get("stop_rate_hz", 0.2),
            stop_duration_s=(p.get("min_stop_s", 1.0), p.get("max_stop_s", 3.0)),
            ramp_s=p.get("ramp_s", 0.8),
        )
    return _circle(
        rng,
        aoi,
        dt,
        speed_mps=p.get("speed_mps"),
        radius_m=p.get("radius_m"),
        centre_m=p.get("centre_m"),
        duration_s=p.get("duration_s"),
        clockwise=p.get("clockwise"),
    )

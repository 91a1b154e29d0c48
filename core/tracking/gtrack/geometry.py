"""gtrack's geometry: the sensor pose, the motion model and the spherical measurement with its
Jacobian (2-D and 3-D).

World frame: x across, y away from the sensor along the floor, z up from the floor; the sensor
stands at ``(0, 0, h)`` (3-D) or ``(0, 0)`` (2-D). Its own frame (the points' r, az, el):
``x_s = r cos(el) sin(az)``, ``y_s = r cos(el) cos(az)``, ``z_s = r sin(el)``. The pose maps the
sensor frame to the world: ``p_w = M p_s + (0, 0, h)``, ``M = R_z(azimuth tilt) · R_x(−elevation
tilt)`` (a positive elevation tilt points the boresight down, a positive azimuth tilt turns it
towards +x). In 2-D only the azimuth tilt applies.

State order (derivative-major, as :mod:`core.tracking.models`): 3-D ``[x, y, z, vx, vy, vz,
ax, ay, az]``, 2-D ``[x, y, vx, vy, ax, ay]``; constant acceleration per axis with the noise gain
Γ = [T²/2, T, 1]ᵀ (:func:`core.tracking.models.noise_gain`) and the axis's maximum acceleration as
its standard deviation: ``Q = Γ Γᵀ ⊗ diag(a_x², a_y²(, a_z²))``.

Measurement of one point: 3-D ``[r, az, el, vr]``, 2-D ``[r, az, vr]``, with
``r = |p_s|``, ``az = atan2(x_s, y_s)``, ``el = atan2(z_s, √(x_s² + y_s²))``,
``vr = p_s·v_s / r``. The 2-D form is :func:`core.tracking.ekf.measure` on the sensor-frame
state; positions closer than :data:`core.tracking.ekf.MIN_RANGE_M` are moved out to it.
"""

from __future__ import annotations

import math

import numpy as np

from core.tracking import ekf
from core.tracking.models import noise_gain

__all__ = [
    "pose_matrix",
    "sensor_to_world",
    "spherical_to_sensor",
    "transition",
    "process_noise",
    "measure",
    "jacobian",
    "meas_dim",
    "ANGLE_ROWS",
]

#: Rows of the measurement vector that are angles (wrapped), per dims.
ANGLE_ROWS = {2: (1,), 3: (1, 2)}


def meas_dim(dims: int) -> int:
    """Length of one point's measurement: 3 (2-D) or 4 (3-D)."""
    return 3 if dims == 2 else 4


def pose_matrix(azimuth_tilt_deg: float, elevation_tilt_deg: float) -> np.ndarray:
    """M (3, 3): sensor-frame vectors to world vectors."""
    a, e = math.radians(azimuth_tilt_deg), math.radians(elevation_tilt_deg)
    rz = np.array([[math.cos(a), math.sin(a), 0.0], [-math.sin(a), math.cos(a), 0.0], [0, 0, 1.0]])
    # R_x(−e): the sensor's y axis (boresight) to (0, cos e, −sin e)
    rx = np.array([[1.0, 0, 0], [0, math.cos(e), math.sin(e)], [0, -math.sin(e), math.cos(e)]])
    return rz @ rx


def spherical_to_sensor(r: np.ndarray, az: np.ndarray, el: np.ndarray) -> np.ndarray:
    """Sensor-frame Cartesian points (n, 3) from range (m), azimuth and elevation (rad)."""
    ce = np.cos(el)
    return np.stack([r * ce * np.sin(az), r * ce * np.cos(az), r * np.sin(el)], axis=-1)


def sensor_to_world(p_s: np.ndarray, M: np.ndarray, height_m: float) -> np.ndarray:
    """World points (n, 3) from sensor-frame points (n, 3)."""
    return p_s @ M.T + np.array([0.0, 0.0, height_m])


def transition(dims: int, period_s: float) -> np.ndarray:
    """F (3d, 3d), constant acceleration per axis."""
    T = float(period_s)
    f1 = np.array([[1.0, T, T * T / 2.0], [0.0, 1.0, T], [0.0, 0.0, 1.0]])
    return np.kron(f1, np.eye(dims))


def process_noise(dims: int, period_s: float, max_accel: tuple[float, ...]) -> np.ndarray:
    """Q (3d, 3d) = Γ Γᵀ ⊗ diag(a²) with the per-axis maximum accelerations a (m/s²)."""
    g = noise_gain("ca", period_s)
    return np.kron(np.outer(g, g), np.diag(np.square(max_accel[:dims])))


def _sensor_state(x: np.ndarray, dims: int, M: np.ndarray, height_m: float):
    """Sensor-frame position and velocity (3,) each of a world state."""
    if dims == 2:
        p = np.array([x[0], x[1], 0.0])
        v = np.array([x[2], x[3], 0.0])
    else:
        p = np.array([x[0], x[1], x[2] - height_m])
        v = np.array([x[3], x[4], x[5]])
    return M.T @ p, M.T @ v


def measure(x: np.ndarray, dims: int, M: np.ndarray, height_m: float) -> np.ndarray:
    """h(x): the measurement ([r, az, el, vr] or [r, az, vr]) a point at the state would give."""
    p, v = _sensor_state(x, dims, M, height_m)
    if dims == 2:
        return ekf.measure(np.array([p[0], p[1], v[0], v[1]]))
    r = float(np.linalg.norm(p))
    if r < ekf.MIN_RANGE_M:
        p = p * (ekf.MIN_RANGE_M / r) if r > 0 else np.array([0.0, ekf.MIN_RANGE_M, 0.0])
        r = ekf.MIN_RANGE_M
    rho = math.hypot(p[0], p[1])
    # h = [|p|, atan2(x, y), atan2(z, ρ), p·v/|p|]
    return np.array([r, math.atan2(p[0], p[1]), math.atan2(p[2], rho), float(p @ v) / r])


def jacobian(x: np.ndarray, dims: int, M: np.ndarray, height_m: float) -> np.ndarray:
    """H = ∂h/∂x (m, 3d) at the state."""
    p, v = _sensor_state(x, dims, M, height_m)
    n = 3 * dims
    if dims == 2:
        R2 = M[:2, :2]
        Js = ekf.jacobian(np.array([p[0], p[1], v[0], v[1]]))  # ∂h/∂(p_s, v_s)
        H = np.zeros((3, n))
        H[:, 0:2] = Js[:, 0:2] @ R2.T
        H[:, 2:4] = Js[:, 2:4] @ R2.T
        return H
    r = float(np.linalg.norm(p))
    if r < ekf.MIN_RANGE_M:
        p = p * (ekf.MIN_RANGE_M / r) if r > 0 else np.array([0.0, ekf.MIN_RANGE_M, 0.0])
        r = ekf.MIN_RANGE_M
    rho2 = max(p[0] * p[0] + p[1] * p[1], 1e-12)
    rho = math.sqrt(rho2)
    Jp = np.zeros((4, 3))
    Jv = np.zeros((4, 3))
    # ∂r/∂p = p/r
    Jp[0] = p / r
    # ∂az/∂p = (y, −x, 0)/ρ²
    Jp[1] = np.array([p[1], -p[0], 0.0]) / rho2
    # ∂el/∂p = (−x z, −y z, ρ²)/(r² ρ)
    Jp[2] = np.array([-p[0] * p[2], -p[1] * p[2], rho2]) / (r * r * rho)
    # ∂vr/∂p = v/r − (p·v) p/r³, ∂vr/∂v = p/r
    Jp[3] = v / r - float(p @ v) * p / r**3
    Jv[3] = p / r
    H = np.zeros((4, n))
    H[:, 0:3] = Jp @ M.T
    H[:, 3:6] = Jv @ M.T
    return H

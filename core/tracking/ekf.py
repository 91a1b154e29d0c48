"""EKF maths for the radar measurement z = [r, az, vr] (SPEC §4, paper eq. 11).

``h(x) = [√(x²+y²), atan2(x, y), (x·vx + y·vy)/√(x²+y²)]``; the Jacobian is analytic. The
Jacobian is singular at r = 0, so position is evaluated at a range of at least
:data:`MIN_RANGE_M` along the same bearing (along boresight when x = y = 0): no NaN can arise.
Azimuth innovations are wrapped to (−π, π].

The functions marked ``register_jitable`` are plain Python here and compile inside the room
tracker's kernel (:mod:`core.tracking.room_kernel`): one definition for both.
"""

from __future__ import annotations

import numpy as np
from numba.extending import register_jitable

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)

__all__ = [
    "MIN_RANGE_M",
    "wrap_angle",
    "safe_position",
    "measure",
    "jacobian",
    "innovation",
    "predict",
    "joseph_update",
    "symmetrize",
]

#: Range below which h(x) and its Jacobian are evaluated at this range (same bearing).
MIN_RANGE_M = 1e-2


def wrap_angle(a: np.ndarray | float) -> np.ndarray:
    """Wrap angles (rad) to (−π, π]."""
    a = np.asarray(a, dtype=np.float64)
    w = np.mod(a + np.pi, 2.0 * np.pi) - np.pi  # [−π, π)
    return np.where(w == -np.pi, np.pi, w)


@register_jitable
def safe_position(x: float, y: float) -> tuple[float, float, float]:
    """Position moved out to at least MIN_RANGE_M along its bearing; returns (x, y, r)."""
    r = float(np.hypot(x, y))
    if r >= MIN_RANGE_M:
        return float(x), float(y), r
    if r == 0.0:
        return 0.0, MIN_RANGE_M, MIN_RANGE_M
    s = MIN_RANGE_M / r
    return float(x) * s, float(y) * s, MIN_RANGE_M


@register_jitable
def measure_into(state: np.ndarray, z: np.ndarray) -> None:
    """Write the predicted measurement h(x) = [r (m), az (rad), vr (m/s)] into z (3,)."""
    x, y, r = safe_position(state[0], state[1])
    vx, vy = state[2], state[3]
    # h = [r, atan2(x, y), (x·vx + y·vy)/r]
    z[0] = r
    z[1] = np.arctan2(x, y)
    z[2] = (x * vx + y * vy) / r


@register_jitable
def measure(state: np.ndarray) -> np.ndarray:
    """Predicted measurement h(x) = [r (m), az (rad), vr (m/s)], shape (3,)."""
    z = np.empty(3)
    measure_into(state, z)
    return z


@register_jitable
def jacobian_into(state: np.ndarray, H: np.ndarray) -> None:
    """Write the Jacobian H = ∂h/∂x at the state into H (3, n), n = len(state)."""
    x, y, r = safe_position(state[0], state[1])
    vx, vy = state[2], state[3]
    r2 = r * r
    r3 = r2 * r
    for i in range(3):
        for j in range(H.shape[1]):
            H[i, j] = 0.0
    # ∂r/∂(x, y) = (x, y)/r
    H[0, 0], H[0, 1] = x / r, y / r
    # ∂az/∂(x, y) = (y, −x)/r²
    H[1, 0], H[1, 1] = y / r2, -x / r2
    # ∂vr/∂x = y(vx·y − vy·x)/r³, ∂vr/∂y = x(vy·x − vx·y)/r³, ∂vr/∂(vx, vy) = (x, y)/r
    cross = vx * y - vy * x
    H[2, 0], H[2, 1] = y * cross / r3, -x * cross / r3
    H[2, 2], H[2, 3] = x / r, y / r


@register_jitable
def jacobian(state: np.ndarray) -> np.ndarray:
    """Jacobian H = ∂h/∂x at the state, shape (3, n) with n = len(state)."""
    H = np.zeros((3, len(state)))
    jacobian_into(state, H)
    return H


def innovation(z: np.ndarray, z_pred: np.ndarray) -> np.ndarray:
    """Innovations ν = z − ẑ with the azimuth wrapped to (−π, π]; z (m, 3) → (m, 3)."""
    nu = np.atleast_2d(z) - z_pred
    nu[:, 1] = wrap_angle(nu[:, 1])
    return nu


@register_jitable
def symmetrize(P: np.ndarray) -> np.ndarray:
    """(P + Pᵀ)/2."""
    return 0.5 * (P + P.T)


@register_jitable
def predict(x: np.ndarray, P: np.ndarray, F: np.ndarray, Q: np.ndarray):
    """Kalman prediction; returns (x⁻, P⁻)."""
    # x⁻ = F x
    x_pred = F @ x
    # P⁻ = F P Fᵀ + Q
    P_pred = symmetrize(F @ P @ F.T + Q)
    return x_pred, P_pred


@register_jitable
def joseph_update(P_pred: np.ndarray, K: np.ndarray, H: np.ndarray, R: np.ndarray) -> np.ndarray:
    """Updated covariance in the Joseph form (positive semi-definite for any gain K)."""
    I_KH = np.eye(P_pred.shape[0]) - K @ H
    # P_c = (I − K H) P⁻ (I − K H)ᵀ + K R Kᵀ
    return symmetrize(I_KH @ P_pred @ I_KH.T + K @ R @ K.T)

"""Track initiation (SPEC §4): every measurement outside the gates of all existing tracks starts
a tentative track with position from (r, az), velocity vr along the line of sight, accelerations
0, ``P(0|0) = diag(p0,ii²)`` and ψ = P_te.
"""

from __future__ import annotations

import numpy as np
from numba.extending import register_jitable

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)

__all__ = ["unassociated", "initial_state", "initial_covariance"]


def unassociated(gated: np.ndarray) -> np.ndarray:
    """Measurements outside every gate: ``gated`` (n_tracks, m) bool → (m,) bool."""
    if gated.shape[0] == 0:
        return np.ones(gated.shape[1], dtype=bool)
    return ~np.any(gated, axis=0)


@register_jitable
def initial_state_into(z: np.ndarray, x: np.ndarray) -> None:
    """Write the state of a new track from one measurement z = [r, az, vr] into x (n,)."""
    r, az, vr = float(z[0]), float(z[1]), float(z[2])
    s, c = np.sin(az), np.cos(az)
    x[:] = 0.0
    # [x, y] = r [sin az, cos az]; [vx, vy] = vr [sin az, cos az]
    x[0], x[1], x[2], x[3] = r * s, r * c, vr * s, vr * c


@register_jitable
def initial_state(z: np.ndarray, state_dim: int) -> np.ndarray:
    """State (state_dim,) of a new track from one measurement z = [r, az, vr]."""
    x = np.zeros(state_dim)
    initial_state_into(z, x)
    return x


def initial_covariance(p0: tuple[float, ...]) -> np.ndarray:
    """P(0|0) = diag(p0,ii²), shape (n, n)."""
    return np.diag(np.asarray(p0, dtype=np.float64) ** 2)

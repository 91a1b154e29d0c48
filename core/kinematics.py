"""The paper's eq. (6): a person's walk integrated frame by frame.

The one statement of the walk both the scenes (:mod:`core.scene.trajectory`) and the synthetic
tracker scenes (:mod:`core.tracking.synthetic`) integrate::

    v(t) = v(t-1) + a(t-1) Δt
    p(t) = p(t-1) + v(t) Δt
"""

from __future__ import annotations

import numpy as np

__all__ = ["integrate_eq6"]


def integrate_eq6(
    initial_position_m: np.ndarray,
    initial_velocity_mps: np.ndarray,
    acceleration_mps2: np.ndarray,
    frame_period_s: float,
) -> tuple[np.ndarray, np.ndarray]:
    """Integrate eq. (6) over ``F = len(acceleration_mps2)`` frames.

    Parameters
    ----------
    initial_position_m, initial_velocity_mps
        ``p(0)``, ``v(0)``, shape ``(2,)``.
    acceleration_mps2
        ``a(t)``, shape ``(F, 2)``; ``a(F-1)`` is not used.
    frame_period_s
        Δt, s.

    Returns
    -------
    position_m, velocity_mps
        Shape ``(F, 2)`` each.
    """
    a = np.asarray(acceleration_mps2, dtype=np.float64)
    dt = float(frame_period_s)
    f = len(a)
    v = np.empty((f, 2))
    p = np.empty((f, 2))
    v[0] = initial_velocity_mps
    p[0] = initial_position_m
    for t in range(1, f):
        # v(t) = v(t-1) + a(t-1) Δt
        v[t] = v[t - 1] + a[t - 1] * dt
        # p(t) = p(t-1) + v(t) Δt
        p[t] = p[t - 1] + v[t] * dt
    return p, v

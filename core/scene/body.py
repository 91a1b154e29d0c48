"""Blob person model ("blob", formerly "extended"): torso, arms and legs with micro-Doppler, z = 0.

The paper models a person as one point scatterer (the default). The extended model spreads the
person's RCS over five scatterers that move with the walking person and swing along the walking
direction with the gait:

- torso at the trajectory position, 50 % of the RCS (linear power);
- two arms at ±0.22 m across the walking direction, 10 % each, swinging with amplitude
  ``A_arm = 0.15 m · s`` in opposite phase;
- two legs at ±0.10 m across, 15 % each, amplitude ``A_leg = 0.30 m · s``, each leg in phase
  with the opposite arm;

where ``s = speed / 1.4 m/s`` (clipped to [0, 1.3]) and the gait frequency is
``f = speed / L_stride`` with ``L_stride = 1.4 m`` (one full cycle per two steps). A limb at
phase ``φ`` is displaced by ``A sin(2π f t + φ)`` along the walking direction and moves at the
body velocity plus ``2π f A cos(2π f t + φ)`` along it. The scatterers stay at z = 0 so the
scene stays planar (no elevation processing). A standing person (speed 0) has no swing: all
scatterers coincide with the body parts' rest positions and move with v = 0.
"""

from __future__ import annotations

import math

import numpy as np

#: (lateral offset m, swing amplitude at 1.4 m/s in m, phase rad, RCS fraction)
BODY_PARTS = (
    (0.0, 0.0, 0.0, 0.50),  # torso
    (0.22, 0.15, 0.0, 0.10),  # right arm
    (-0.22, 0.15, math.pi, 0.10),  # left arm
    (0.10, 0.30, math.pi, 0.15),  # right leg (opposite the right arm)
    (-0.10, 0.30, 0.0, 0.15),  # left leg
)
STRIDE_LENGTH_M = 1.4
REFERENCE_SPEED_MPS = 1.4
N_BODY_SCATTERERS = len(BODY_PARTS)


def body_scatterers(
    position_m: np.ndarray, velocity_mps: np.ndarray, heading_rad: float, t_s: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Scatterers of one person in one frame.

    Parameters
    ----------
    position_m, velocity_mps
        The person's ``[x, y]`` and ``[vx, vy]`` (m, m/s), shape ``(2,)``.
    heading_rad
        Walking direction (``atan2(vx, vy)``, used when standing still, from the last motion).
    t_s
        Time of the frame (s), the gait phase.

    Returns
    -------
    position_m, velocity_mps
        Shape ``(5, 2)`` each.
    rcs_fraction
        Shape ``(5,)``, sums to 1: share of the person's RCS (linear power) per scatterer.
    """
    speed = float(np.hypot(*velocity_mps))
    u = np.array([math.sin(heading_rad), math.cos(heading_rad)])  # along the walk
    n = np.array([u[1], -u[0]])  # across (to the right)
    s = min(speed / REFERENCE_SPEED_MPS, 1.3)
    omega = 2 * math.pi * speed / STRIDE_LENGTH_M  # ω = 2π f, f = v / L_stride
    pos = np.empty((N_BODY_SCATTERERS, 2))
    vel = np.empty((N_BODY_SCATTERERS, 2))
    frac = np.empty(N_BODY_SCATTERERS)
    for i, (lateral, amp, phase, share) in enumerate(BODY_PARTS):
        a = amp * s
        # d(t) = A sin(ω t + φ),  ḋ(t) = ω A cos(ω t + φ)
        d = a * math.sin(omega * t_s + phase)
        dd = omega * a * math.cos(omega * t_s + phase)
        pos[i] = position_m + lateral * n + d * u
        vel[i] = velocity_mps + dd * u
        frac[i] = share
    return pos, vel, frac


def walking_headings(velocity_mps: np.ndarray) -> np.ndarray:
    """Walking direction per frame, ``atan2(vx, vy)``; held while standing still.

    Parameters
    ----------
    velocity_mps
        Shape ``(F, 2)``.

    Returns
    -------
    numpy.ndarray
        Shape ``(F,)``, rad (0 before the first motion).
    """
    v = np.asarray(velocity_mps, dtype=np.float64)
    moving = np.hypot(v[:, 0], v[:, 1]) > 1e-9
    heading = np.where(moving, np.arctan2(v[:, 0], v[:, 1]), np.nan)
    # forward-fill the last heading through stops
    idx = np.where(moving, np.arange(len(v)), 0)
    np.maximum.accumulate(idx, out=idx)
    out = heading[idx]
    return np.where(np.isnan(out), 0.0, out)

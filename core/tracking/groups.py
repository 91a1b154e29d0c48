"""A track's points as one group (the room tracker, SPEC §7): the group measurement and its
update.

Points of a room frame are rows of 7 columns (:data:`COLUMNS`): the measurement
``[r (m), az (rad), vr (m/s)]`` the EKF uses, the position ``x, y, z`` (m) the zones and the
height use, and the SNR (dB) allocation and the ghost rule use.

A person is not a point: its points scatter over the body. Each point is modelled as the body's
centre plus a body offset plus the measurement noise, the offsets independent with covariance
``D(r) = diag(σ_body², (σ_body/r)², σ_vbody²)`` in (r, az, vr) (σ_body the body's spread in m,
σ_vbody the spread of the limbs' radial velocities). So

- a point is gated against ``S_pt = H P⁻ Hᵀ + R + D``, and goes to the track that explains it
  best (smallest ``d² + log det S_pt``, a hard assignment as TI's gtrack makes);
- the track's n points give one measurement, their mean ``z̄`` (innovation ν̄ = mean of νᵢ, the
  azimuth wrapped), with covariance ``R_c = (R + D)/n`` (the mean of n independent draws);
- that one measurement updates the track by IPDA with one validated measurement
  (:mod:`core.tracking.ipda`): ``Λ = N(ν̄; 0, S_c)/(P_G ρ)`` with ``S_c = H P⁻ Hᵀ + R_c``,
  ``1 − δ = 1 − P_D P_G + P_D P_G Λ``, ``ψ = (1 − δ) ψ⁻/(1 − δ ψ⁻)``,
  ``β₁ = P_D P_G Λ/(1 − δ)``, ``β₀ = 1 − β₁``, ``x = x⁻ + β₁ K ν̄``,
  ``P = β₀ P⁻ + β₁ P_c + β₁ β₀ K ν̄ ν̄ᵀ Kᵀ`` (P_c in the Joseph form with R_c). ψ keeps its
  meaning: the probability that the track is a person, the group counting as one detection.
  ρ is the density of such groups (the parameter ``clutter_density``; non-parametric: one group
  in the point gate, ρ̂ = 1/V(S_pt)).

The functions run as plain Python and inside the compiled room kernel (``register_jitable``).
"""

from __future__ import annotations

import math

import numpy as np
from numba.extending import register_jitable

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)
from core.tracking import ekf
from core.tracking.ipda import LOG_2PI

__all__ = [
    "COLUMNS",
    "COL_R",
    "COL_AZ",
    "COL_VR",
    "COL_X",
    "COL_Y",
    "COL_Z",
    "COL_SNR",
    "body_covariance",
    "chol3",
    "inv_from_chol3",
    "group_update",
]

#: Columns of a room point.
COLUMNS = ("range_m", "azimuth_rad", "radial_velocity_mps", "x_m", "y_m", "z_m", "snr_db")
COL_R, COL_AZ, COL_VR, COL_X, COL_Y, COL_Z, COL_SNR = range(7)


@register_jitable
def body_covariance(r: float, sigma: float, sigma_v: float) -> np.ndarray:
    """D(r) = diag(σ_body², (σ_body/r)², σ_vbody²), (3, 3) in (m, rad, m/s)."""
    D = np.zeros((3, 3))
    D[0, 0] = sigma * sigma
    D[1, 1] = (sigma / r) ** 2
    D[2, 2] = sigma_v * sigma_v
    return D


@register_jitable
def chol3(S: np.ndarray) -> np.ndarray:
    """Lower Cholesky factor L (3, 3) of a symmetric positive-definite S (S = L Lᵀ), written out
    (a LAPACK call per track costs more than the arithmetic at this size)."""
    L = np.zeros((3, 3))
    L[0, 0] = math.sqrt(S[0, 0])
    L[1, 0] = S[1, 0] / L[0, 0]
    L[2, 0] = S[2, 0] / L[0, 0]
    L[1, 1] = math.sqrt(S[1, 1] - L[1, 0] * L[1, 0])
    L[2, 1] = (S[2, 1] - L[2, 0] * L[1, 0]) / L[1, 1]
    L[2, 2] = math.sqrt(S[2, 2] - L[2, 0] * L[2, 0] - L[2, 1] * L[2, 1])
    return L


@register_jitable
def inv_from_chol3(L: np.ndarray) -> np.ndarray:
    """S⁻¹ = L⁻ᵀ L⁻¹ (3, 3) from the lower Cholesky factor."""
    M = np.zeros((3, 3))  # M = L⁻¹, lower triangular
    M[0, 0] = 1.0 / L[0, 0]
    M[1, 1] = 1.0 / L[1, 1]
    M[2, 2] = 1.0 / L[2, 2]
    M[1, 0] = -L[1, 0] * M[0, 0] / L[1, 1]
    M[2, 1] = -L[2, 1] * M[1, 1] / L[2, 2]
    M[2, 0] = -(L[2, 0] * M[0, 0] + L[2, 1] * M[1, 0]) / L[2, 2]
    return M.T @ M


@register_jitable
def _wrap(a: float) -> float:
    w = ((a + math.pi) % (2.0 * math.pi)) - math.pi
    if w == -math.pi:
        w = math.pi
    return w


@register_jitable
def group_update(
    x_pred: np.ndarray,
    P_pred: np.ndarray,
    psi_pred: float,
    H: np.ndarray,
    z_pred: np.ndarray,
    pts: np.ndarray,
    rows: np.ndarray,
    R: np.ndarray,
    D: np.ndarray,
    pdpg: float,
    p_g: float,
    rho: float,
):
    """IPDA update of one track with its group of points (see the module docstring).

    Parameters
    ----------
    x_pred, P_pred, psi_pred
        Prediction (d,), (d, d) and ψ⁻.
    H, z_pred
        Jacobian (3, d) and predicted measurement (3,) at x_pred.
    pts, rows
        The frame's points (m, 7) and the indices (n,) of the track's group, n ≥ 0.
    R, D
        Measurement noise and body covariance (3, 3).
    pdpg, p_g, rho
        P_D·P_G, P_G and the group density ρ (> 0).

    Returns
    -------
    x, P, psi, nis
        Updated state, covariance, existence and ν̄ᵀ S_c⁻¹ ν̄ (NaN when n = 0).
    """
    n = rows.shape[0]
    if n == 0 or psi_pred <= 0.0:
        if psi_pred <= 0.0:
            psi = 0.0
        elif psi_pred >= 1.0:
            psi = 1.0
        else:
            # ψ = (1 − P_D P_G) ψ⁻ / (1 − P_D P_G ψ⁻)
            psi = (1.0 - pdpg) * psi_pred / (1.0 - pdpg * psi_pred)
        return x_pred.copy(), P_pred.copy(), psi, math.nan
    # ν̄ = mean of the innovations, azimuth wrapped
    nu = np.zeros(3)
    for i in range(n):
        j = rows[i]
        nu[0] += pts[j, 0] - z_pred[0]
        nu[1] += _wrap(pts[j, 1] - z_pred[1])
        nu[2] += pts[j, 2] - z_pred[2]
    nu /= n
    # R_c = (R + D)/n; S_c = H P⁻ Hᵀ + R_c
    Rc = (R + D) / n
    S = H @ P_pred @ H.T + Rc
    S = 0.5 * (S + S.T)
    L = chol3(S)
    # d² = ‖L⁻¹ν̄‖², forward substitution
    w0 = nu[0] / L[0, 0]
    w1 = (nu[1] - L[1, 0] * w0) / L[1, 1]
    w2 = (nu[2] - L[2, 0] * w0 - L[2, 1] * w1) / L[2, 2]
    d2 = w0 * w0 + w1 * w1 + w2 * w2
    log_det = 2.0 * (math.log(L[0, 0]) + math.log(L[1, 1]) + math.log(L[2, 2]))
    # log Λ = log N(ν̄; 0, S_c) − log(P_G ρ)
    log_lr = -0.5 * d2 - 0.5 * log_det - 1.5 * LOG_2PI - math.log(p_g * rho)
    # 1 − δ = (1 − P_D P_G) + P_D P_G Λ, in the log domain
    a0 = math.log1p(-pdpg) if pdpg < 1.0 else -math.inf
    a1 = math.log(pdpg) + log_lr
    top = max(a0, a1)
    lse = top + math.log(math.exp(a0 - top) + math.exp(a1 - top))
    beta1 = math.exp(a1 - lse)
    beta0 = math.exp(a0 - lse)
    one_minus_delta = math.exp(lse)
    if psi_pred >= 1.0:
        psi = 1.0
    else:
        # ψ = (1 − δ) ψ⁻ / ((1 − ψ⁻) + (1 − δ) ψ⁻)
        psi = one_minus_delta * psi_pred / ((1.0 - psi_pred) + one_minus_delta * psi_pred)
        psi = min(1.0, max(0.0, psi))
    # K = P⁻ Hᵀ S_c⁻¹
    K = (P_pred @ H.T) @ inv_from_chol3(L)
    x = x_pred + beta1 * (K @ nu)
    Pc = ekf.joseph_update(P_pred, K, H, Rc)
    Knu = K @ nu
    # P = β₀ P⁻ + β₁ P_c + β₁ β₀ (K ν̄)(K ν̄)ᵀ
    P = beta0 * P_pred + beta1 * Pc + beta1 * beta0 * np.outer(Knu, Knu)
    return x, ekf.symmetrize(P), psi, d2

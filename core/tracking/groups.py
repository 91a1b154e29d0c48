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
    "body_covariance_into",
    "chol3_into",
    "inv_from_chol3",
    "inv_from_chol3_into",
    "mm",
    "mm_nt",
    "mm_tn",
    "symmetrize_into",
    "innovation_covariance_into",
    "group_work",
    "group_update",
]

#: Columns of a room point.
COLUMNS = ("range_m", "azimuth_rad", "radial_velocity_mps", "x_m", "y_m", "z_m", "snr_db")
COL_R, COL_AZ, COL_VR, COL_X, COL_Y, COL_Z, COL_SNR = range(7)


@register_jitable
def body_covariance_into(r: float, sigma: float, sigma_v: float, D: np.ndarray) -> None:
    """Write D(r) = diag(σ_body², (σ_body/r)², σ_vbody²) into D (3, 3), (m, rad, m/s)."""
    for i in range(3):
        for j in range(3):
            D[i, j] = 0.0
    D[0, 0] = sigma * sigma
    D[1, 1] = (sigma / r) ** 2
    D[2, 2] = sigma_v * sigma_v


@register_jitable
def body_covariance(r: float, sigma: float, sigma_v: float) -> np.ndarray:
    """D(r) = diag(σ_body², (σ_body/r)², σ_vbody²), (3, 3) in (m, rad, m/s)."""
    D = np.zeros((3, 3))
    body_covariance_into(r, sigma, sigma_v, D)
    return D


@register_jitable
def chol3_into(S: np.ndarray, L: np.ndarray) -> None:
    """Write the lower Cholesky factor of a symmetric positive-definite S (3, 3) into L
    (S = L Lᵀ), written out (a LAPACK call per track costs more than the arithmetic here)."""
    L[0, 1] = L[0, 2] = L[1, 2] = 0.0
    L[0, 0] = math.sqrt(S[0, 0])
    L[1, 0] = S[1, 0] / L[0, 0]
    L[2, 0] = S[2, 0] / L[0, 0]
    L[1, 1] = math.sqrt(S[1, 1] - L[1, 0] * L[1, 0])
    L[2, 1] = (S[2, 1] - L[2, 0] * L[1, 0]) / L[1, 1]
    L[2, 2] = math.sqrt(S[2, 2] - L[2, 0] * L[2, 0] - L[2, 1] * L[2, 1])


@register_jitable
def chol3(S: np.ndarray) -> np.ndarray:
    """Lower Cholesky factor L (3, 3) of a symmetric positive-definite S (S = L Lᵀ)."""
    L = np.zeros((3, 3))
    chol3_into(S, L)
    return L


@register_jitable
def inv_from_chol3_into(L: np.ndarray, M: np.ndarray, Sinv: np.ndarray) -> None:
    """Write S⁻¹ = L⁻ᵀ L⁻¹ (3, 3) from the lower Cholesky factor into Sinv (M: scratch)."""
    # M = L⁻¹, lower triangular
    M[0, 1] = M[0, 2] = M[1, 2] = 0.0
    M[0, 0] = 1.0 / L[0, 0]
    M[1, 1] = 1.0 / L[1, 1]
    M[2, 2] = 1.0 / L[2, 2]
    M[1, 0] = -L[1, 0] * M[0, 0] / L[1, 1]
    M[2, 1] = -L[2, 1] * M[1, 1] / L[2, 2]
    M[2, 0] = -(L[2, 0] * M[0, 0] + L[2, 1] * M[1, 0]) / L[2, 2]
    mm_tn(M, M, Sinv)


@register_jitable
def inv_from_chol3(L: np.ndarray) -> np.ndarray:
    """S⁻¹ = L⁻ᵀ L⁻¹ (3, 3) from the lower Cholesky factor."""
    Sinv = np.zeros((3, 3))
    inv_from_chol3_into(L, np.zeros((3, 3)), Sinv)
    return Sinv


@register_jitable
def mm(A: np.ndarray, B: np.ndarray, C: np.ndarray) -> None:
    """C = A B, written out (small matrices: a BLAS call costs more than the arithmetic)."""
    for i in range(A.shape[0]):
        for j in range(B.shape[1]):
            s = 0.0
            for k in range(A.shape[1]):
                s += A[i, k] * B[k, j]
            C[i, j] = s


@register_jitable
def mm_nt(A: np.ndarray, B: np.ndarray, C: np.ndarray) -> None:
    """C = A Bᵀ, written out."""
    for i in range(A.shape[0]):
        for j in range(B.shape[0]):
            s = 0.0
            for k in range(A.shape[1]):
                s += A[i, k] * B[j, k]
            C[i, j] = s


@register_jitable
def mm_tn(A: np.ndarray, B: np.ndarray, C: np.ndarray) -> None:
    """C = Aᵀ B, written out."""
    for i in range(A.shape[1]):
        for j in range(B.shape[1]):
            s = 0.0
            for k in range(A.shape[0]):
                s += A[k, i] * B[k, j]
            C[i, j] = s


@register_jitable
def symmetrize_into(A: np.ndarray) -> None:
    """A ← (A + Aᵀ)/2 in place (square A)."""
    for i in range(A.shape[0]):
        for j in range(i + 1, A.shape[0]):
            s = 0.5 * (A[i, j] + A[j, i])
            A[i, j] = s
            A[j, i] = s


@register_jitable
def innovation_covariance_into(
    H: np.ndarray, P: np.ndarray, R: np.ndarray, HP: np.ndarray, S: np.ndarray
) -> None:
    """S = H P Hᵀ + R, symmetrised, into S (3, 3); HP (3, d) scratch."""
    mm(H, P, HP)
    mm_nt(HP, H, S)
    for i in range(3):
        for j in range(3):
            S[i, j] += R[i, j]
    symmetrize_into(S)


@register_jitable
def group_work(d: int):
    """Scratch arrays of :func:`group_update` for a state of dimension d."""
    return (
        np.zeros(3), np.zeros((3, 3)), np.zeros((3, 3)), np.zeros((3, 3)), np.zeros((3, 3)),
        np.zeros((3, 3)), np.zeros((3, d)), np.zeros((d, 3)), np.zeros((d, 3)), np.zeros(d),
        np.zeros((d, d)), np.zeros((d, d)), np.zeros((d, d)),
    )  # fmt: skip


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
    n: int,
    R: np.ndarray,
    D: np.ndarray,
    pdpg: float,
    p_g: float,
    rho: float,
    x_out: np.ndarray,
    P_out: np.ndarray,
    work,
):
    """IPDA update of one track with its group of points (see the module docstring).

    Parameters
    ----------
    x_pred, P_pred, psi_pred
        Prediction (d,), (d, d) and ψ⁻.
    H, z_pred
        Jacobian (3, d) and predicted measurement (3,) at x_pred.
    pts, rows, n
        The frame's points (m, 7) and the indices ``rows[:n]`` of the track's group, n ≥ 0.
    R, D
        Measurement noise and body covariance (3, 3).
    pdpg, p_g, rho
        P_D·P_G, P_G and the group density ρ (> 0).
    x_out, P_out
        (d,) and (d, d) outputs: the updated state and covariance (may not alias the inputs).
    work
        Scratch arrays, :func:`group_work`.

    Returns
    -------
    psi, nis
        Updated existence and ν̄ᵀ S_c⁻¹ ν̄ (NaN when n = 0).
    """
    nu, Rc, S, L, M, Sinv, HP, PHt, K, Knu, A, B, Pc = work
    d = x_pred.shape[0]
    if n == 0 or psi_pred <= 0.0:
        if psi_pred <= 0.0:
            psi = 0.0
        elif psi_pred >= 1.0:
            psi = 1.0
        else:
            # ψ = (1 − P_D P_G) ψ⁻ / (1 − P_D P_G ψ⁻)
            psi = (1.0 - pdpg) * psi_pred / (1.0 - pdpg * psi_pred)
        x_out[:] = x_pred
        P_out[:, :] = P_pred
        return psi, math.nan
    # ν̄ = mean of the innovations, azimuth wrapped
    nu[0] = nu[1] = nu[2] = 0.0
    for i in range(n):
        j = rows[i]
        nu[0] += pts[j, 0] - z_pred[0]
        nu[1] += _wrap(pts[j, 1] - z_pred[1])
        nu[2] += pts[j, 2] - z_pred[2]
    for i in range(3):
        nu[i] /= n
    # R_c = (R + D)/n; S_c = H P⁻ Hᵀ + R_c
    for i in range(3):
        for j in range(3):
            Rc[i, j] = (R[i, j] + D[i, j]) / n
    innovation_covariance_into(H, P_pred, Rc, HP, S)
    chol3_into(S, L)
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
    mm_nt(P_pred, H, PHt)
    inv_from_chol3_into(L, M, Sinv)
    mm(PHt, Sinv, K)
    # K ν̄; x = x⁻ + β₁ K ν̄
    for i in range(d):
        s = 0.0
        for k in range(3):
            s += K[i, k] * nu[k]
        Knu[i] = s
        x_out[i] = x_pred[i] + beta1 * s
    # P_c = (I − K H) P⁻ (I − K H)ᵀ + K R_c Kᵀ (Joseph form), symmetrised
    mm(K, H, A)
    for i in range(d):
        for j in range(d):
            A[i, j] = (1.0 if i == j else 0.0) - A[i, j]
    mm(A, P_pred, B)
    mm_nt(B, A, Pc)
    mm(K, Rc, PHt)  # K R_c (d, 3), PHt reused
    mm_nt(PHt, K, B)
    for i in range(d):
        for j in range(d):
            Pc[i, j] += B[i, j]
    symmetrize_into(Pc)
    # P = β₀ P⁻ + β₁ P_c + β₁ β₀ (K ν̄)(K ν̄)ᵀ, symmetrised
    for i in range(d):
        for j in range(d):
            P_out[i, j] = (
                beta0 * P_pred[i, j] + beta1 * Pc[i, j] + beta1 * beta0 * (Knu[i] * Knu[j])
            )
    symmetrize_into(P_out)
    return psi, d2

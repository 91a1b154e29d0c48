"""Validation gate in measurement space (SPEC §4).

``S = H P⁻ Hᵀ + R``; a measurement is validated when ``νᵀ S⁻¹ ν ≤ γ`` with
``γ = χ²⁻¹_n(P_G)`` (n = 3 for z = [r, az, vr]). Distances use the Cholesky factor of S
(``S = L Lᵀ``, ``d² = ‖L⁻¹ν‖²``), never an explicit inverse.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from scipy.special import gammaincinv

__all__ = [
    "gate_threshold",
    "innovation_covariance",
    "cholesky",
    "mahalanobis_squared",
    "log_det_from_cholesky",
    "gate_volume",
]


@functools.lru_cache(maxsize=64)
def gate_threshold(p_g: float, dof: int = 3) -> float:
    """γ = χ²⁻¹_dof(P_G), the gate threshold on the squared Mahalanobis distance.

    Through the regularised incomplete gamma function (``scipy.stats.chi2.ppf`` computes the
    same expression, bit for bit, but importing ``scipy.stats`` costs about a second of start-up).
    """
    # χ²⁻¹_ν(p) = 2 P⁻¹(ν/2, p), P the regularised lower incomplete gamma function
    return float(2.0 * gammaincinv(dof / 2.0, p_g))


def innovation_covariance(H: np.ndarray, P_pred: np.ndarray, R: np.ndarray) -> np.ndarray:
    """Innovation covariance, shape (3, 3)."""
    # S = H P⁻ Hᵀ + R
    S = H @ P_pred @ H.T + R
    return 0.5 * (S + S.T)


def cholesky(S: np.ndarray) -> np.ndarray:
    """Lower Cholesky factor L of a symmetric positive-definite S (S = L Lᵀ)."""
    return np.linalg.cholesky(S)


def mahalanobis_squared(nu: np.ndarray, L: np.ndarray) -> np.ndarray:
    """Squared Mahalanobis distances νᵢᵀ S⁻¹ νᵢ for innovations ν (m, 3) → (m,)."""
    if len(nu) == 0:
        return np.zeros(0)
    # d² = ‖L⁻¹ ν‖²
    # (a plain LAPACK solve: scipy's solve_triangular is ~100x slower on 3x3 here)
    w = np.linalg.solve(L, np.atleast_2d(nu).T)
    return np.sum(w * w, axis=0)


def log_det_from_cholesky(L: np.ndarray) -> float:
    """log det S = 2 Σ log Lᵢᵢ."""
    return float(2.0 * np.sum(np.log(np.diag(L))))


def gate_volume(L: np.ndarray, gamma: float) -> float:
    """Volume of the gate ellipsoid {ν : νᵀS⁻¹ν ≤ γ} in measurement units (m · rad · m/s)."""
    n = L.shape[0]
    # V = c_n γ^{n/2} √det S, c_n = π^{n/2} / Γ(n/2 + 1) (c_3 = 4π/3)
    c_n = math.pi ** (n / 2.0) / math.gamma(n / 2.0 + 1.0)
    return float(c_n * gamma ** (n / 2.0) * np.prod(np.diag(L)))

"""Exact false-alarm probabilities of a CFAR detector on a non-coherent sum of ``L`` channels,
and their inversion to the threshold factor (SPEC §3, step 5).

Under noise only, a cell of the range-Doppler map is the sum of ``L`` (= 12 virtual channels)
independent exponentials of equal mean ``mu``: ``X ~ Gamma(L, mu)``. A training sum of ``N``
cells is ``Z ~ Gamma(N L, mu)``. The thresholds below are exact for this model (the single-look
formula ``(1 + T)^-N`` is the special case ``L = 1``).

A detector declares ``X > alpha * mu_hat`` with ``mu_hat`` the per-cell noise estimate:

- CA (``N = 2n`` cells): ``mu_hat = Z / N``. With ``T = alpha / N``, ``X / (X + Z) ~ Beta(L, NL)``:
  ``Pfa = P(X > T Z) = 1 - I_{T/(1+T)}(L, NL)`` (regularised incomplete beta), inverted in
  closed form with ``betainccinv``.
- CASO (``n`` cells per side, ``M = nL``): ``mu_hat = min(Z1, Z2) / n``, ``T = alpha / n``.
  With ``f_min = 2 f (1 - F)`` and Erlang tails,
  ``Pfa = 2 sum_{j<M} sum_{k<L} T^k Gamma(M+j+k) / (j! k! Gamma(M) (2+T)^(M+j+k))``.
- CAGO: ``f_max = 2 f - f_min``, so ``Pfa_GO(T) = 2 (1 - I_{T/(1+T)}(L, M)) - Pfa_SO(T)``.

The detectors that use these thresholds are in :mod:`core.processing.cfar`.
"""

from __future__ import annotations

import functools

import numpy as np
from scipy.integrate import quad
from scipy.optimize import brentq
from scipy.special import betaincc, betainccinv, gammaincc, gammaln, logsumexp

__all__ = ["pfa_ca", "pfa_cago", "pfa_caso", "threshold_factor"]


def pfa_ca(t: float, n_cells: float, n_channels: int) -> float:
    """Pfa of ``X > T * Z`` with ``X ~ Gamma(L)``, ``Z ~ Gamma(n_cells L)`` (sum of the cells)."""
    # Pfa = 1 - I_{T/(1+T)}(L, N L)
    return float(betaincc(n_channels, n_cells * n_channels, t / (1.0 + t)))


def pfa_caso(t: float, n_side: float, n_channels: int) -> float:
    """Pfa of ``X > T * min(Z1, Z2)``, each side ``Z ~ Gamma(n_side L)``.

    Exact finite double sum for integer ``M = n_side L``; for a non-integer (effective) shape
    the same integral ``int 2 f_M(z) Q(M, z) Q(L, T z) dz`` is evaluated numerically.
    """
    m, l = n_side * n_channels, n_channels
    if abs(m - round(m)) > 1e-9:
        return _pfa_so_numeric(t, m, l)
    m = round(m)
    j = np.arange(m)[:, None]
    k = np.arange(l)[None, :]
    # log of T^k Gamma(M+j+k) / (j! k! Gamma(M) (2+T)^(M+j+k))
    log_terms = (
        k * np.log(t)
        + gammaln(m + j + k)
        - gammaln(j + 1)
        - gammaln(k + 1)
        - gammaln(m)
        - (m + j + k) * np.log(2.0 + t)
    )
    return float(2.0 * np.exp(logsumexp(log_terms)))


def _pfa_so_numeric(t: float, m: float, l: int) -> float:
    def integrand(z: float) -> float:
        # 2 f_M(z) (1 - F_M(z)) P(X > T z)
        log_f = (m - 1) * np.log(z) - z - gammaln(m)
        return 2.0 * np.exp(log_f) * gammaincc(m, z) * gammaincc(l, t * z)

    hi = m + 60.0 * np.sqrt(m) + 60.0
    val, _ = quad(integrand, 0.0, hi, points=[m], limit=400, epsabs=0.0, epsrel=1e-11)
    return float(val)


def pfa_cago(t: float, n_side: float, n_channels: int) -> float:
    """Pfa of ``X > T * max(Z1, Z2)``: ``2 P(X > T Z1) - Pfa_SO``."""
    return 2.0 * pfa_ca(t, n_side, n_channels) - pfa_caso(t, n_side, n_channels)


@functools.lru_cache(maxsize=256)
def threshold_factor(
    method: str, n_train: int, pfa: float, n_channels: int, n_effective: float | None = None
) -> float:
    """``alpha`` such that ``X > alpha * mu_hat`` has false-alarm probability ``pfa``.

    Parameters
    ----------
    method
        ``"ca"`` (``n_train`` is the total number of training cells), ``"caso"`` or ``"cago"``
        (``n_train`` cells on each side).
    n_channels
        ``L``, the number of exponential looks summed per cell (12 virtual channels).
    n_effective
        Effective number of independent cells among the ``n_train`` (window-correlated cells,
        see :func:`core.processing.spectrum.effective_cells`); None: all independent (exact).
        The training sum is then moment-matched by ``Gamma(n_eff L)`` with the same mean.
    """
    ne = float(n_train if n_effective is None else n_effective)
    if method == "ca":
        b = float(betainccinv(n_channels, ne * n_channels, pfa))
        # T/(1+T) = b  ->  T = b / (1 - b);  alpha = N_eff T
        return ne * b / (1.0 - b)
    f = {"caso": pfa_caso, "cago": pfa_cago}[method]
    # Pfa(T) decreases monotonically in T: step up in log T until it falls below pfa (small
    # steps keep the bracket where Pfa_GO = 2 P1 - Pfa_SO has no cancellation), then solve
    hi = -8.0
    while f(np.exp(hi), ne, n_channels) > pfa:
        hi += 0.25
    log_t = brentq(
        lambda u: np.log(f(np.exp(u), ne, n_channels)) - np.log(pfa), hi - 0.25, hi, xtol=1e-13
    )
    # with Z' = Z n_eff / n ~ Gamma(n_eff L): X > T Z'  <=>  X > (T n_eff) * (Z / n)
    return ne * float(np.exp(log_t))

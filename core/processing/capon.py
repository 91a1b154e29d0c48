"""Beamforming over the virtual array: steering vectors, spatial covariance, Capon (MVDR) and
Bartlett spectra (the angle stages of TI's people-counting chain).

A reflector at azimuth ``az`` and elevation ``el`` gives virtual channel ``v`` (azimuth position
``a_v``, elevation position ``e_v``, units of lambda/2) the phase of the simulator's steering
vector (``core.simulation.baseband.steering_vectors``)::

    s_v(u, w) = exp(j pi (a_v u + e_v w)),   u = sin(az) cos(el),  w = sin(el)

With ``R`` the spatial covariance of the channels over ``K`` snapshots (``R = X X^H / K``):

- Bartlett (delay and sum): ``P_B(s) = s^H R s / N^2``, the power of the matched beam;
- Capon / MVDR: ``P_C(s) = 1 / (s^H (R + d I)^-1 s)`` with diagonal loading
  ``d = loading * tr(R) / N`` (Capon 1969; TI's people-counting chain loads the same way, its
  ``dynamicRangeAngleCfg`` ``rangeAngleDiagonalLoading``); the MVDR weights
  ``w = (R + d I)^-1 s / (s^H (R + d I)^-1 s)`` pass ``s`` with unit gain and minimise the rest.

For one reflector in white noise of power ``sigma^2`` per channel, ``R = p s0 s0^H +
sigma^2 I``; Capon's spectrum peaks at ``s0`` with height ``p + sigma^2 / N`` and its
half-power width shrinks with the SNR, while Bartlett's beam is the array's own
(``|sum_v exp(j pi a_v (u - u0))|^2 / N^2``: for 8 elements at lambda/2, -3 dB at
``|u - u0| = 0.111``).
"""

from __future__ import annotations

import functools

import numba
import numpy as np

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)

__all__ = [
    "bartlett_spectrum",
    "capon_spectrum_lags",
    "covariance_and_mean",
    "capon_spectrum",
    "capon_weights",
    "loaded_inverse",
    "spatial_covariance",
    "steering",
]


def steering(
    azimuth_positions: np.ndarray, elevation_positions: np.ndarray, u: np.ndarray, w: np.ndarray
) -> np.ndarray:
    """Steering vectors ``exp(j pi (a_v u + e_v w))``.

    Parameters
    ----------
    azimuth_positions, elevation_positions
        ``(n_ch,)`` channel positions in units of lambda/2.
    u, w
        ``(n_angles,)`` direction sines ``sin(az) cos(el)`` and ``sin(el)``.

    Returns
    -------
    numpy.ndarray
        ``(n_angles, n_ch)`` complex128.
    """
    a = np.asarray(azimuth_positions, dtype=np.float64)
    e = np.asarray(elevation_positions, dtype=np.float64)
    phase = np.outer(np.asarray(u, dtype=np.float64), a) + np.outer(
        np.asarray(w, dtype=np.float64), e
    )
    return np.exp(1j * np.pi * phase)


def spatial_covariance(snapshots: np.ndarray) -> np.ndarray:
    """Per-range-bin spatial covariance ``R_k = X_k X_k^H / K``.

    Parameters
    ----------
    snapshots
        ``[channel, snapshot (loop), range bin]`` complex.

    Returns
    -------
    numpy.ndarray
        ``[range bin, channel, channel]`` complex128, Hermitian.
    """
    x = np.asarray(snapshots)
    xs = np.ascontiguousarray(x.transpose(2, 0, 1)).astype(np.complex128, copy=False)
    # R_k = X_k X_k^H / K
    return np.matmul(xs, np.conj(xs.transpose(0, 2, 1))) / x.shape[1]


def loaded_inverse(cov: np.ndarray, loading: float) -> np.ndarray:
    """``(R + d I)^-1`` with ``d = loading * tr(R) / N`` per range bin (``cov``: ``[k, N, N]``).

    A bin with no power at all (``tr R = 0``) gets the identity (its spectrum is then zero).
    """
    r = np.asarray(cov)
    n = r.shape[-1]
    tr = np.real(np.trace(r, axis1=-2, axis2=-1)) / n
    # d = loading tr(R) / N; a floor keeps an all-zero bin invertible
    d = np.maximum(loading * tr, np.finfo(np.float64).tiny)
    loaded = r + d[:, None, None] * np.eye(n)
    return np.linalg.inv(loaded)


def capon_spectrum(cov: np.ndarray, steer: np.ndarray, loading: float) -> np.ndarray:
    """Capon (MVDR) spectrum ``P = 1 / (s^H (R + d I)^-1 s)``.

    Parameters
    ----------
    cov
        ``[range bin, N, N]`` spatial covariance.
    steer
        ``(n_angles, N)`` steering vectors.
    loading
        Diagonal loading relative to the mean channel power.

    Returns
    -------
    numpy.ndarray
        ``[range bin, angle]`` float64 power (the covariance's units).
    """
    inv = loaded_inverse(cov, loading)
    # q = s^H R^-1 s, one quadratic form per range bin and angle
    b = np.matmul(np.conj(steer)[None], inv)  # [k, angle, N]
    q = np.einsum("kan,an->ka", b, steer).real
    tiny = np.finfo(np.float64).tiny
    return 1.0 / np.maximum(q, tiny)


def capon_weights(inv_cov: np.ndarray, steer: np.ndarray) -> np.ndarray:
    """MVDR weights ``w = R^-1 s / (s^H R^-1 s)`` for one steering vector per row.

    Parameters
    ----------
    inv_cov
        ``(n, N, N)`` loaded inverse covariances.
    steer
        ``(n, N)`` steering vectors.

    Returns
    -------
    numpy.ndarray
        ``(n, N)`` complex128; the beam output is ``w^H x``.
    """
    num = np.einsum("nij,nj->ni", inv_cov, steer)
    den = np.einsum("ni,ni->n", np.conj(steer), num)
    return num / den[:, None]


def bartlett_spectrum(cov: np.ndarray, steer: np.ndarray) -> np.ndarray:
    """Bartlett (delay-and-sum) spectrum ``P = s^H R s / N^2``: ``[range bin, angle]`` float64."""
    n = steer.shape[1]
    b = np.matmul(np.conj(steer)[None], np.asarray(cov))  # [k, angle, N]
    return np.einsum("kan,an->ka", b, steer).real / n**2


# ---- the fast path of the people-counting chain ----------------------------------------------
@numba.njit(cache=True, nogil=True, fastmath=True)
def _cov_mean_kernel(x):  # pragma: no cover
    """``x`` complex64 ``[ch, snapshot, range]`` -> (``R - xbar xbar^H`` ``[range, ch, ch]``,
    ``xbar`` ``[range, ch]``), complex128."""
    n_c, n_m, n_r = x.shape
    acc = np.zeros((n_c, n_c, n_r), np.complex128)
    mean = np.zeros((n_c, n_r), np.complex128)
    for m in range(n_m):
        for i in range(n_c):
            for k in range(n_r):
                mean[i, k] += x[i, m, k]
            for j in range(i + 1):
                for k in range(n_r):
                    acc[i, j, k] += np.complex128(x[i, m, k]) * np.conj(np.complex128(x[j, m, k]))
    cov = np.empty((n_r, n_c, n_c), np.complex128)
    out_mean = np.empty((n_r, n_c), np.complex128)
    for k in range(n_r):
        for i in range(n_c):
            out_mean[k, i] = mean[i, k] / n_m
    for k in range(n_r):
        for i in range(n_c):
            for j in range(i + 1):
                # (1/K) sum x x^H - xbar xbar^H = (1/K) sum (x - xbar)(x - xbar)^H
                c = acc[i, j, k] / n_m - out_mean[k, i] * np.conj(out_mean[k, j])
                cov[k, i, j] = c
                cov[k, j, i] = np.conj(c)
    return cov, out_mean


def covariance_and_mean(snapshots: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The covariance after static clutter removal and the removed mean, in one pass.

    ``R_k = (1/K) sum_m (x_km - xbar_k)(x_km - xbar_k)^H = (1/K) sum_m x_km x_km^H - xbar_k
    xbar_k^H``: :func:`spatial_covariance` of the clutter-removed snapshots
    (:func:`core.processing.spectrum.remove_static_clutter`) without forming them, and
    ``xbar_k`` (the zero-Doppler part the static chain uses).

    Parameters
    ----------
    snapshots
        ``[channel, snapshot (loop), range bin]`` complex.

    Returns
    -------
    cov, mean
        ``[range bin, channel, channel]`` and ``[range bin, channel]``, complex128.
    """
    x = np.ascontiguousarray(snapshots, dtype=np.complex64)
    return _cov_mean_kernel(x)


@functools.lru_cache(maxsize=32)
def _lag_tables(positions: tuple[int, ...], u: tuple[float, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Gather matrix ``G [n*n, n_lag]`` summing ``Q_ij`` by ``d = a_j - a_i >= 0`` and
    ``E [n_lag, angle] = w_d exp(j pi u d)`` (``w_0 = 1``, ``w_d = 2``)."""
    a = np.asarray(positions)
    n = len(a)
    diff = a[None, :] - a[:, None]  # d_ij = a_j - a_i
    lags = np.unique(diff[diff >= 0])
    g = np.zeros((n * n, len(lags)))
    for li, d in enumerate(lags):
        g[:, li] = (diff == d).ravel()
    w = np.where(lags == 0, 1.0, 2.0)
    e = w[:, None] * np.exp(1j * np.pi * np.outer(lags, np.asarray(u)))
    g.flags.writeable = False
    e.flags.writeable = False
    return g.astype(np.complex128), e


def capon_spectrum_lags(
    cov: np.ndarray, positions: tuple[int, ...], u: np.ndarray, loading: float
) -> np.ndarray:
    """:func:`capon_spectrum` of a linear array (integer positions, no elevation) by lags.

    With ``Q = (R + d I)^-1`` Hermitian, ``s^H Q s = sum_ij Q_ij exp(j pi u (a_j - a_i)) =
    c_0 + 2 Re sum_{d>0} c_d exp(j pi u d)``, ``c_d = sum_{a_j - a_i = d} Q_ij``: one small
    product per range bin instead of one quadratic form per angle (same numbers, tested).

    Returns ``[range bin, angle]`` float64.
    """
    inv = loaded_inverse(cov, loading)
    g, e = _lag_tables(tuple(int(p) for p in positions), tuple(float(v) for v in u))
    n_k = inv.shape[0]
    c = inv.reshape(n_k, -1) @ g  # [k, lag]
    q = (c @ e).real
    return 1.0 / np.maximum(q, np.finfo(np.float64).tiny)

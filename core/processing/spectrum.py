"""Range FFT, static clutter removal, Doppler FFT and range-Doppler map (SPEC §3, steps 1-4).

Array layouts (all complex64 unless stated):

- baseband cube ``[virtual channel, loop, ADC sample]``
- range cube ``[virtual channel, loop, range bin]``
- Doppler cube ``[virtual channel, range bin, Doppler bin]``, zero velocity centred: Doppler
  index ``j`` is Doppler bin ``j - n_loops // 2``
- range-Doppler map ``[range bin, Doppler bin]``, float32, power in V² summed over channels
"""

from __future__ import annotations

import functools

import numba
import numpy as np
import scipy.fft

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)
from core.config import WINDOWS
from core.errors import InputError


@functools.lru_cache(maxsize=64)
def _window(name: str, n: int) -> np.ndarray:
    k = np.arange(n)
    if name == "rect":
        w = np.ones(n)
    elif name == "hann":
        # periodic (DFT-even) Hann: w[k] = 0.5 - 0.5 cos(2 pi k / N); its loss is exactly 1.761 dB
        w = 0.5 - 0.5 * np.cos(2 * np.pi * k / n)
    elif name == "hamming":
        w = 0.54 - 0.46 * np.cos(2 * np.pi * k / n)
    elif name == "blackman":
        w = 0.42 - 0.5 * np.cos(2 * np.pi * k / n) + 0.08 * np.cos(4 * np.pi * k / n)
    else:
        raise InputError(f"window must be one of {WINDOWS}, got {name!r}")
    w = w.astype(np.float32)
    w.flags.writeable = False
    return w


def window(name: str, n: int) -> np.ndarray:
    """Window of length ``n`` (float32, read-only): ``rect``, ``hann``, ``hamming``, ``blackman``.

    Periodic (DFT-even) forms, as used before an FFT.
    """
    return _window(name, int(n))


def window_loss_db(name: str, n: int) -> float:
    """SNR loss of a window after an ``n``-point FFT, in dB (<= 0).

    ``L = (sum w)^2 / (N sum w^2)``: the coherent gain over the noise gain, relative to a
    rectangular window (periodic Hann: 2/3, i.e. -1.761 dB).
    """
    w = window(name, n).astype(np.float64)
    # L = (sum w)^2 / (N * sum w^2)
    return float(10 * np.log10(w.sum() ** 2 / (n * np.sum(w**2))))


def cell_power_correlation(name: str, n_fft: int, lag: int) -> float:
    """Correlation of the powers of two FFT cells ``lag`` bins apart, white noise input.

    ``|rho(k)|^2`` with ``rho(k) = sum w^2 exp(-j 2 pi k n / N) / sum w^2`` (periodic Hann:
    ``4/9`` for neighbours, ``1/36`` two bins apart, 0 beyond).
    """
    w2 = window(name, n_fft).astype(np.float64) ** 2
    n = np.arange(n_fft)
    rho = np.sum(w2 * np.exp(-2j * np.pi * lag * n / n_fft)) / w2.sum()
    return float(abs(rho) ** 2)


def effective_cells(name: str, n_fft: int, n_cells: int) -> float:
    """Effective number of independent cells in a run of ``n_cells`` adjacent FFT cells.

    ``N_eff = N^2 / sum_ij |rho(i - j)|^2``: the number of independent cells whose sum has the
    same mean-to-variance ratio (rectangular window: ``N``; periodic Hann, 8 cells: 4.40).
    """
    r = [cell_power_correlation(name, n_fft, k) for k in range(n_cells)]
    # sum_ij |rho(i-j)|^2 = N + 2 sum_k (N - k) |rho(k)|^2
    total = n_cells + 2 * sum((n_cells - k) * r[k] for k in range(1, n_cells))
    return n_cells**2 / total


def clutter_removal_noise_profile(name: str, n: int) -> np.ndarray:
    """Relative noise power per Doppler bin after mean removal and the Doppler window.

    ``g_k = 1 - |W_k|^2 / (N sum w^2)`` with ``W_k`` the window's DFT; zero velocity centred
    (index ``j`` is bin ``j - N/2``). Periodic Hann: 1/3 at zero Doppler, 5/6 next to it, 1
    elsewhere; rectangular: 0 at zero Doppler. Returns a read-only float64 array ``(n,)``.
    """
    return _noise_profile(name, int(n))


@functools.lru_cache(maxsize=64)
def _noise_profile(name: str, n: int) -> np.ndarray:
    w = window(name, n).astype(np.float64)
    W = np.fft.fftshift(np.fft.fft(w))
    # E|Y_k|^2 / E|Y_k|^2 (no removal) = 1 - |W_k|^2 / (N sum w^2)
    g = 1.0 - np.abs(W) ** 2 / (n * np.sum(w**2))
    g.flags.writeable = False
    return g


def range_fft(cube: np.ndarray, window_name: str = "hann", *, workers: int | None = None):
    """Range FFT along ADC samples.

    Parameters
    ----------
    cube
        Baseband cube ``[virtual channel, loop, ADC sample]``, complex.
    window_name
        Window applied along samples.

    Returns
    -------
    numpy.ndarray
        Range cube ``[virtual channel, loop, range bin]``, complex64. Range bin ``k`` is at range
        ``k * range_resolution_m`` (complex sampling: all bins are positive ranges).
    """
    x = np.asarray(cube)
    if window_name == "rect":
        return scipy.fft.fft(x.astype(np.complex64, copy=False), axis=-1, workers=workers)
    # the windowed copy is ours: transform it in place
    y = (x * window(window_name, x.shape[-1])).astype(np.complex64, copy=False)
    return scipy.fft.fft(y, axis=-1, workers=workers, overwrite_x=True)


def remove_static_clutter(range_cube: np.ndarray) -> np.ndarray:
    """Subtract the mean over loops per virtual channel and range bin (axis 1).

    ``y[v, m, k] = x[v, m, k] - mean_m x[v, m, k]``: removes everything at exactly zero Doppler.
    """
    x = np.asarray(range_cube)
    return x - x.mean(axis=1, keepdims=True, dtype=np.complex64)


@functools.lru_cache(maxsize=64)
def _doppler_taps(window_name: str, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Window with the fftshift folded in, and the non-zero bins of its DFT (index, value)."""
    w = window(window_name, n).astype(np.float64)
    if n % 2 == 0:
        # fftshift folded into the window: X[k - N/2] <-> x[m] * (-1)^m
        w = w * np.where(np.arange(n) % 2 == 0, 1.0, -1.0)
    W = np.fft.fft(w)
    if n % 2 == 1:
        W = np.fft.fftshift(W)
    idx = np.flatnonzero(np.abs(W) > 1e-9 * np.abs(W).max())
    return w.astype(np.float32), idx, W[idx].astype(np.complex64)


#: up to this many loops the Doppler transform is one matrix product (measured: for 32 loops a
#: 32 x 32 complex64 product over all channels and range bins takes about half the time of the
#: strided FFT plus the separate window and clutter-removal passes)
DOPPLER_MATRIX_MAX_LOOPS = 64


@functools.lru_cache(maxsize=64)
def doppler_matrix(window_name: str, n: int, remove_static: bool) -> np.ndarray:
    """The whole Doppler step as one ``(n, n)`` complex64 matrix ``M`` (read-only).

    ``Y[j] = sum_m M[j, m] x[m]`` with Doppler index ``j`` zero velocity centred::

        M = F diag(w) (I - 1 1' / n)        # F[j, m] = exp(-j 2 pi (j - n // 2) m / n)

    i.e. window, DFT, fftshift and (optionally) static clutter removal, all linear, composed in
    float64 and rounded once.
    """
    w = window(window_name, n).astype(np.float64)
    j = np.arange(n) - n // 2
    m = np.arange(n)
    # F diag(w): exp(-j 2 pi j m / n) w[m]
    mat = np.exp(-2j * np.pi * np.outer(j, m) / n) * w[None, :]
    if remove_static:
        # (F diag(w)) (I - 1 1' / n): subtract each row's mean
        mat = mat - mat.mean(axis=1, keepdims=True)
    out = mat.astype(np.complex64)
    out.flags.writeable = False
    return out


def doppler_fft(
    range_cube: np.ndarray,
    window_name: str = "hann",
    *,
    remove_static: bool = False,
    workers: int | None = None,
) -> np.ndarray:
    """Doppler transform along loops, zero velocity centred.

    Parameters
    ----------
    range_cube
        ``[virtual channel, loop, range bin]``, complex.
    window_name
        Window along loops.
    remove_static
        Static clutter removal folded into the transform (same result as
        :func:`remove_static_clutter` first, one pass less): the transform is linear.
    workers
        Threads for the FFT path.

    Returns
    -------
    numpy.ndarray
        Doppler cube ``[virtual channel, range bin, Doppler bin]``, complex64; index ``j`` is
        Doppler bin ``j - n_loops // 2`` (velocity ``(j - n_loops // 2) * velocity_resolution``).
        A transposed view of a ``[v, Doppler, range]`` array (the transform runs along loops
        without a transposing copy); ``numpy.ascontiguousarray`` gives a contiguous copy if
        needed.

    Up to :data:`DOPPLER_MATRIX_MAX_LOOPS` loops this is one matrix product with
    :func:`doppler_matrix`; beyond, a windowed FFT with the clutter removal applied on the few
    bins where the window's DFT is non-zero (``FFT(w (x - mean x)) = FFT(w x) - mean(x) W``).
    """
    x = np.asarray(range_cube)
    n = x.shape[1]
    if n <= DOPPLER_MATRIX_MAX_LOOPS:
        mat = doppler_matrix(window_name, n, bool(remove_static))
        # Y[v] = M X[v]: [Doppler, loop] @ [loop, range]
        return np.matmul(mat, x.astype(np.complex64, copy=False)).transpose(0, 2, 1)
    w, idx, taps = _doppler_taps(window_name, n)
    y = (x * w[:, None]).astype(np.complex64, copy=False)
    # FFT along loops in place; the result is returned as a [v, range, Doppler] view
    out = scipy.fft.fft(y, axis=1, workers=workers, overwrite_x=True)
    if n % 2 == 1:
        out = np.fft.fftshift(out, axes=1)
    if remove_static:
        mu = x.mean(axis=1, dtype=np.complex64)  # [v, range]
        # Y_j = X_j - mean * W_j on the bins where the window's DFT is non-zero
        out[:, idx, :] -= mu[:, None, :] * taps[:, None]
    return out.transpose(0, 2, 1)


@numba.njit(cache=True, nogil=True, fastmath=True)
def _power_sum_kernel(y):  # pragma: no cover
    """``y`` float32 ``[v, Doppler, 2 range]`` (interleaved re, im) -> ``[range, Doppler]``."""
    n_v, n_j, n2 = y.shape
    acc = np.zeros((n_j, n2), np.float32)
    for v in range(n_v):
        for j in range(n_j):
            for k in range(n2):
                acc[j, k] += y[v, j, k] * y[v, j, k]
    out = np.empty((n2 // 2, n_j), np.float32)
    for j in range(n_j):
        for k in range(n2 // 2):
            out[k, j] = acc[j, 2 * k] + acc[j, 2 * k + 1]
    return out


def range_doppler_map(doppler_cube: np.ndarray) -> np.ndarray:
    """Non-coherent sum over virtual channels: ``P[k, j] = sum_v |X[v, k, j]|^2``.

    Returns
    -------
    numpy.ndarray
        ``[range bin, Doppler bin]`` float32 power (V²), Doppler zero velocity centred,
        C-contiguous.
    """
    x = np.asarray(doppler_cube)
    base = x.transpose(0, 2, 1)
    if x.dtype == np.complex64 and base.flags.c_contiguous:
        # the layout doppler_fft returns: a [v, Doppler, range] array seen transposed
        return _power_sum_kernel(base.view(np.float32))
    # P = sum_v (re^2 + im^2)
    return np.einsum("vkj,vkj->kj", x.real, x.real) + np.einsum("vkj,vkj->kj", x.imag, x.imag)

"""Compiled Gaussian receiver noise for the exact chain, with the range window in the same loop.

The exact chain draws ``2 x 12 x 32 x 256 = 196 608`` normals per frame. NumPy's
``Generator.standard_normal`` spends most of that time calling the bit generator through a
function pointer; here the generator is compiled into the loop that also adds the noise to the
signal and applies the range window, at about 5 ns a normal (measured: 1.0 ms for a frame's
noise with the window, against 2.3 ms for NumPy's draws alone in the chain it replaced).

The draws are NumPy's single-precision ziggurat normals (``standard_normal(dtype=float32)``) on
xoshiro256++ bits seeded from the caller's ``numpy.random.Generator``; the generator, the
ziggurat tables and the rare tail and wedge draws are :mod:`core.simulation.rng_kernels`, the
one module of the simulation's compiled random numbers. Fed the same words the normals are
NumPy's bit for bit (tested), so the distribution is NumPy's; only the source of the bits
differs.
"""

from __future__ import annotations

import numba
import numpy as np

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)
from core.simulation.rng_kernels import FI, KI, WI, next_u32, recorded_stream, seed_state, slow_draw


@numba.njit(cache=True, nogil=True)
def _accumulate_normals(f, sigma, w, s, ki, wi, fi):  # pragma: no cover
    """``f[i, j] = (f[i, j] + sigma g) w[j]`` with ``g`` the next N(0, 1) draw, row by row.

    The ziggurat's common path is written out here, in the loop, on purpose (see
    :func:`core.simulation.rng_kernels.slow_draw`).
    """
    n_rows, n = f.shape
    sig = np.float32(sigma)
    for i in range(n_rows):
        row = f[i]
        for j in range(n):
            while True:
                r = next_u32(s)
                # 8 bits choose the layer, 1 the sign, 23 the abscissa
                idx = np.int64(r & np.uint32(0xFF))
                sign = (r >> np.uint32(8)) & np.uint32(1)
                rabs = (r >> np.uint32(9)) & np.uint32(0x007FFFFF)
                x = np.float32(np.int32(rabs)) * wi[idx]
                if sign:
                    x = -x
                if rabs < ki[idx]:
                    break  # inside the layer's rectangle: 98.5 % of the draws
                x = slow_draw(s, idx, rabs, x, fi)
                if not np.isnan(x):
                    break
            row[j] = (row[j] + sig * x) * w[j]


def _normals(state: np.ndarray, n: int) -> np.ndarray:
    out = np.zeros((1, int(n)), dtype=np.float32)
    _accumulate_normals(out, 1.0, np.ones(int(n), dtype=np.float32), state, KI, WI, FI)
    return out[0]


def standard_normals(rng: np.random.Generator, n: int) -> np.ndarray:
    """``n`` independent N(0, 1) draws (float32) from a generator seeded by ``rng``."""
    return _normals(seed_state(rng), n)


def normals_from_stream(words: np.ndarray, n: int) -> np.ndarray:
    """``n`` N(0, 1) draws (float32) from recorded 64-bit words (tests against NumPy).

    The caller supplies enough words: two draws take one word, the rare rejections more
    (``0.55 n`` words are plenty).
    """
    return _normals(recorded_stream(words), n)


def add_complex_noise(
    cube: np.ndarray,
    power_v2: float,
    rng: np.random.Generator,
    window: np.ndarray | None = None,
) -> None:
    """Add circular complex Gaussian noise to ``cube`` in place, then apply ``window``.

    Parameters
    ----------
    cube
        complex64 ``[virtual channel, loop, ADC sample]``, C-contiguous; overwritten.
    power_v2
        ``E|n|^2`` per sample (V²): real and imaginary parts are N(0, power / 2).
    rng
        Seeds the compiled generator (four 64-bit words are drawn from it).
    window
        Window along the last axis (length ``cube.shape[-1]``); None: no window.

    Element ``[v, m, n]`` takes the ``2 k``-th and ``2 k + 1``-th normal of the stream (``k``
    its flat index) as real and imaginary part, so :func:`complex_noise` with the same ``rng``
    state gives the same noise.
    """
    if cube.dtype != np.complex64 or not cube.flags.c_contiguous or cube.ndim != 3:
        raise ValueError("cube must be a C-contiguous complex64 array [channel, loop, sample]")
    n = cube.shape[-1]
    w = np.ones(n) if window is None else np.asarray(window)
    # real and imaginary parts each carry half the power: sigma = sqrt(E|n|^2 / 2)
    sigma = float(np.sqrt(power_v2 / 2.0))
    # the cube as rows of interleaved (re, im) float32 pairs, one window value per pair
    rows = cube.view(np.float32).reshape(-1, 2 * n)
    pair_window = np.repeat(w.astype(np.float32), 2)
    _accumulate_normals(rows, sigma, pair_window, seed_state(rng), KI, WI, FI)


def complex_noise(shape: tuple[int, ...], power_v2: float, rng: np.random.Generator) -> np.ndarray:
    """Circular complex Gaussian noise, complex64 of ``shape`` (3-D), ``E|n|^2 = power_v2``."""
    out = np.zeros(shape, dtype=np.complex64)
    add_complex_noise(out, power_v2, rng)
    return out

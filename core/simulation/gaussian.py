"""Compiled Gaussian noise: xoshiro256++ bits turned into normals by the ziggurat method.

The exact chain draws ``2 x 12 x 32 x 256 = 196 608`` normals per frame. NumPy's
``Generator.standard_normal`` spends most of that time in calls through the bit generator's
function pointer; here the generator is inlined into the compiled loop that also adds the noise
to the signal and applies the range window, so the noise costs about a nanosecond a sample.

- Bits: xoshiro256++ (Blackman & Vigna, "Scrambled linear pseudorandom number generators",
  ACM TOMS 2021), a 256-bit state seeded from the caller's ``numpy.random.Generator`` (four
  ``uint64`` words), so a seed still fixes every frame.
- Normals: the 256-layer ziggurat of Marsaglia & Tsang (J. Stat. Softw. 5(8), 2000) exactly as
  NumPy implements ``random_standard_normal`` for float64 (8 bits choose the layer, 1 bit the
  sign, 52 bits the abscissa; the tail beyond ``r = 3.6541528853610088`` by Marsaglia's
  exponential method). Fed the same 64-bit words it returns NumPy's numbers bit for bit (the
  tests check this against ``Generator(PCG64)`` with its raw stream), so the distribution is
  NumPy's, only the source of bits differs.
"""

from __future__ import annotations

import numba
import numpy as np

#: edge of the ziggurat's base strip (256 layers) and the area of every layer: the base strip's
#: rectangle plus the tail, ``v = r f(r) + sqrt(pi / 2) erfc(r / sqrt 2)``, f(x) = exp(-x^2 / 2)
ZIGGURAT_R = 3.6541528853610088
ZIGGURAT_V = 0.004928673233974658
_M52 = 2.0**52


def _ziggurat_tables() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``ki`` (uint64 acceptance limits), ``wi`` (abscissa scale) and ``fi`` (density at the
    layer edges) for the 256-layer ziggurat with 52-bit abscissae (Marsaglia & Tsang's
    ``zigset`` recurrence: ``x_{i-1} = sqrt(-2 ln(v / x_i + f(x_i)))``, ``f(x) = exp(-x^2 / 2)``).
    """
    ki = np.zeros(256, dtype=np.uint64)
    wi = np.zeros(256)
    fi = np.zeros(256)
    dn = tn = ZIGGURAT_R
    q = ZIGGURAT_V / np.exp(-0.5 * dn * dn)
    ki[0] = np.uint64((dn / q) * _M52)
    ki[1] = 0
    wi[0] = q / _M52
    wi[255] = dn / _M52
    fi[0] = 1.0
    fi[255] = np.exp(-0.5 * dn * dn)
    for i in range(254, 0, -1):
        # x_i from x_{i+1}: the layers have equal area v
        dn = np.sqrt(-2.0 * np.log(ZIGGURAT_V / dn + np.exp(-0.5 * dn * dn)))
        ki[i + 1] = np.uint64((dn / tn) * _M52)
        tn = dn
        fi[i] = np.exp(-0.5 * dn * dn)
        wi[i] = dn / _M52
    return ki, wi, fi


KI, WI, FI = _ziggurat_tables()
for _a in (KI, WI, FI):
    _a.flags.writeable = False

_INV_R = 1.0 / ZIGGURAT_R
_TWO_M53 = 2.0**-53


@numba.njit(inline="always")
def _rotl(x, k):  # pragma: no cover
    return (x << np.uint64(k)) | (x >> np.uint64(64 - k))


@numba.njit(inline="always")
def xoshiro_next(s):  # pragma: no cover
    """Next 64-bit word of xoshiro256++ with the state ``s`` (uint64[4], updated in place)."""
    s0, s1, s2, s3 = s[0], s[1], s[2], s[3]
    out = _rotl(s0 + s3, 23) + s0
    t = s1 << np.uint64(17)
    s2 ^= s0
    s3 ^= s1
    s1 ^= s2
    s0 ^= s3
    s2 ^= t
    s3 = _rotl(s3, 45)
    s[0], s[1], s[2], s[3] = s0, s1, s2, s3
    return out


@numba.njit(inline="always")
def stream_next(s):  # pragma: no cover
    """Next word of a recorded stream: ``s[0]`` is the read position, the words follow it."""
    i = s[0]
    s[0] = i + np.uint64(1)
    return s[i]


@numba.njit(inline="always")
def next_u64(s):  # pragma: no cover
    """Next 64-bit word: xoshiro256++ for a 4-word state, else a recorded stream (tests)."""
    if s.size == 4:
        return xoshiro_next(s)
    return stream_next(s)


@numba.njit(inline="always")
def next_double(s):  # pragma: no cover
    # NumPy's next_double: the 53 high bits, in [0, 1)
    return np.float64(next_u64(s) >> np.uint64(11)) * _TWO_M53


@numba.njit(nogil=True)
def _slow_draw(s, idx, rabs, x, fi):  # pragma: no cover
    """The 1.5 % of draws outside their layer's rectangle: the tail or the wedge test.

    Returns the draw, or NaN when it is rejected (the caller starts afresh). Kept out of line:
    inlined, it slows the common path several times over.
    """
    if idx == 0:
        # tail beyond r (Marsaglia 1964): x = r + E1 / r, accepted when 2 E2 > (E1 / r)^2
        while True:
            xx = -_INV_R * np.log1p(-next_double(s))
            yy = -np.log1p(-next_double(s))
            if yy + yy > xx * xx:
                if (rabs >> np.uint64(8)) & np.uint64(1):
                    return -(ZIGGURAT_R + xx)
                return ZIGGURAT_R + xx
    # wedge: accepted under the density f(x) = exp(-x^2 / 2)
    if (fi[idx - 1] - fi[idx]) * next_double(s) + fi[idx] < np.exp(-0.5 * x * x):
        return x
    return np.nan


@numba.njit(cache=True, nogil=True)
def _accumulate_normals(f, sigma, w, s, ki, wi, fi):  # pragma: no cover
    """``f[i, j] = (f[i, j] + sigma g) w[j]`` with ``g`` the next N(0, 1) draw, row by row.

    The ziggurat's common path is written out here, in the loop, on purpose (see
    :func:`_slow_draw`).
    """
    n_rows, n = f.shape
    for i in range(n_rows):
        row = f[i]
        for j in range(n):
            while True:
                r = next_u64(s)
                # 8 bits choose the layer, 1 the sign, 52 the abscissa
                idx = np.int64(r & np.uint64(0xFF))
                r >>= np.uint64(8)
                sign = r & np.uint64(1)
                rabs = (r >> np.uint64(1)) & np.uint64(0x000FFFFFFFFFFFFF)
                x = np.float64(rabs) * wi[idx]
                if sign:
                    x = -x
                if rabs < ki[idx]:
                    break  # inside the layer's rectangle: 98.5 % of the draws
                x = _slow_draw(s, idx, rabs, x, fi)
                if not np.isnan(x):
                    break
            row[j] = (row[j] + sigma * x) * w[j]


def seed_state(rng: np.random.Generator) -> np.ndarray:
    """A xoshiro256++ state (uint64[4]) drawn from ``rng``; never the all-zero state."""
    s = rng.integers(0, 2**64, size=4, dtype=np.uint64, endpoint=False)
    if not s.any():
        s[0] = 1
    return s


def standard_normals(rng: np.random.Generator, n: int) -> np.ndarray:
    """``n`` independent N(0, 1) draws (float64) from a xoshiro256++ state seeded by ``rng``."""
    out = np.zeros((1, int(n)))
    _accumulate_normals(out, 1.0, np.ones(int(n)), seed_state(rng), KI, WI, FI)
    return out[0]


def normals_from_stream(words: np.ndarray, n: int) -> np.ndarray:
    """``n`` N(0, 1) draws from recorded 64-bit words (for tests against NumPy's ziggurat).

    The caller supplies enough words: each draw takes one, the rare rejections one or two more
    (``1.1 n`` words are plenty).
    """
    s = np.concatenate((np.array([1], dtype=np.uint64), np.asarray(words, dtype=np.uint64)))
    out = np.zeros((1, int(n)))
    _accumulate_normals(out, 1.0, np.ones(int(n)), s, KI, WI, FI)
    return out[0]


def _pair_window(w: np.ndarray) -> np.ndarray:
    return np.repeat(w, 2)


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
        Window along the last axis (float, length ``cube.shape[-1]``); None: no window.

    Element ``[v, m, n]`` takes the ``2 k``-th and ``2 k + 1``-th normal of the stream (``k``
    its flat index) as real and imaginary part, so :func:`complex_noise` with the same ``rng``
    state gives the same noise.
    """
    if cube.dtype != np.complex64 or not cube.flags.c_contiguous or cube.ndim != 3:
        raise ValueError("cube must be a C-contiguous complex64 array [channel, loop, sample]")
    n = cube.shape[-1]
    w = np.ones(n) if window is None else np.asarray(window, dtype=np.float64)
    # real and imaginary parts each carry half the power: sigma = sqrt(E|n|^2 / 2)
    sigma = float(np.sqrt(power_v2 / 2.0))
    # the cube as rows of interleaved (re, im) float32 pairs, one window value per pair
    rows = cube.view(np.float32).reshape(-1, 2 * n)
    _accumulate_normals(rows, sigma, _pair_window(w), seed_state(rng), KI, WI, FI)


def complex_noise(shape: tuple[int, ...], power_v2: float, rng: np.random.Generator) -> np.ndarray:
    """Circular complex Gaussian noise, complex64 of ``shape`` (3-D), ``E|n|^2 = power_v2``."""
    out = np.zeros(shape, dtype=np.complex64)
    add_complex_noise(out, power_v2, rng)
    return out

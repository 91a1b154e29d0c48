"""Compiled Gaussian noise: xoshiro256++ bits turned into normals by the ziggurat method.

The exact chain draws ``2 x 12 x 32 x 256 = 196 608`` normals per frame. NumPy's
``Generator.standard_normal`` spends most of that time calling the bit generator through a
function pointer; here the generator is compiled into the loop that also adds the noise to the
signal and applies the range window, at about 5 ns a normal (measured: 1.0 ms for a frame's
noise with the window, against 2.3 ms for NumPy's draws alone in the chain it replaced).

- Bits: xoshiro256++ (Blackman & Vigna, "Scrambled linear pseudorandom number generators",
  ACM TOMS 47(4), 2021) with a 256-bit state seeded from the caller's
  ``numpy.random.Generator`` (four ``uint64`` words), so a seed still fixes every frame. Each
  64-bit word is used as two 32-bit words, low half first (as NumPy's ``next_uint32`` does).
- Normals: the 256-layer ziggurat of Marsaglia & Tsang (J. Stat. Softw. 5(8), 2000) in single
  precision, as NumPy's ``random_standard_normal_f`` (``standard_normal(dtype=float32)``) does
  it: 8 bits choose the layer, 1 the sign, 23 the abscissa; wedges by a uniform test against
  the density; the tail beyond ``r = 3.6541528853610088`` by Marsaglia's exponential method.
  Fed the same words it returns NumPy's numbers bit for bit (the tests check this against
  ``Generator(PCG64)`` fed its own raw stream), so the distribution is NumPy's; only the source
  of the bits differs.

The state is a ``uint64`` array: ``[s0, s1, s2, s3, buffered high half, has-buffer flag]``; a
longer array is a recorded stream for tests (``[0, 0, 0, 0, 0, 0, read position, words...]``).
"""

from __future__ import annotations

import numba
import numpy as np

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)

#: edge of the ziggurat's base strip (256 layers) and the area of every layer: the base strip's
#: rectangle plus the tail, ``v = r f(r) + sqrt(pi / 2) erfc(r / sqrt 2)``, f(x) = exp(-x^2 / 2)
ZIGGURAT_R = 3.6541528853610088
ZIGGURAT_V = 0.004928673233974658
_STATE_WORDS = 6


def ziggurat_tables(
    layers: int = 256, r: float = ZIGGURAT_R, v: float = ZIGGURAT_V, bits: int = 23
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Ziggurat tables for N(0, 1) (Marsaglia & Tsang 2000, ``zigset``).

    Layer ``i`` spans ``[0, x_i]`` under ``f(x) = exp(-x^2 / 2)``; every layer (and the base
    strip with its tail beyond ``r``) has area ``v``:
    ``x_{i-1} = sqrt(-2 ln(v / x_i + f(x_i)))``. Abscissae are ``bits``-bit integers.

    Returns
    -------
    ki : numpy.ndarray
        ``(layers,)`` int64 acceptance limits (``|abscissa| < ki[i]`` is inside the rectangle).
    wi, fi : numpy.ndarray
        ``(layers,)`` float64 abscissa scale ``x_i / 2^bits`` and density at the layer edges.
    """
    scale = 2.0**bits
    ki = np.zeros(layers, dtype=np.int64)
    wi = np.zeros(layers)
    fi = np.zeros(layers)
    dn = tn = r
    # q = v / f(r): the base strip's width in units of r
    q = v / np.exp(-0.5 * dn * dn)
    ki[0] = int((dn / q) * scale)
    wi[0] = q / scale
    wi[-1] = dn / scale
    fi[0] = 1.0
    fi[-1] = np.exp(-0.5 * dn * dn)
    for i in range(layers - 2, 0, -1):
        # x_i from x_{i+1}: the layers have equal area v
        dn = np.sqrt(-2.0 * np.log(v / dn + np.exp(-0.5 * dn * dn)))
        ki[i + 1] = int((dn / tn) * scale)
        tn = dn
        fi[i] = np.exp(-0.5 * dn * dn)
        wi[i] = dn / scale
    return ki, wi, fi


def _single_precision_tables() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    ki, wi, fi = ziggurat_tables()
    out = (ki.astype(np.uint32), wi.astype(np.float32), fi.astype(np.float32))
    for a in out:
        a.flags.writeable = False
    return out


#: the single-precision tables (23-bit abscissae), as NumPy's ``ki_float``/``wi_float``/``fi_float``
KI, WI, FI = _single_precision_tables()

_R_F = np.float32(ZIGGURAT_R)
_INV_R_F = np.float32(1.0 / ZIGGURAT_R)
_TWO_M24_F = np.float32(2.0**-24)


@numba.njit(inline="always")
def _rotl(x, k):  # pragma: no cover
    return (x << np.uint64(k)) | (x >> np.uint64(64 - k))


@numba.njit(inline="always")
def xoshiro_step(s0, s1, s2, s3):  # pragma: no cover
    """One xoshiro256++ step on a state held in four locals: ``(word, s0, s1, s2, s3)``."""
    out = _rotl(s0 + s3, 23) + s0
    t = s1 << np.uint64(17)
    s2 ^= s0
    s3 ^= s1
    s1 ^= s2
    s0 ^= s3
    s2 ^= t
    s3 = _rotl(s3, 45)
    return out, s0, s1, s2, s3


@numba.njit(inline="always")
def xoshiro_next(s):  # pragma: no cover
    """Next 64-bit word of xoshiro256++ with the state ``s[0:4]`` (updated in place)."""
    out, s[0], s[1], s[2], s[3] = xoshiro_step(s[0], s[1], s[2], s[3])
    return out


@numba.njit(inline="always")
def _next_u64(s):  # pragma: no cover
    if s.size == _STATE_WORDS:
        return xoshiro_next(s)
    # a recorded stream: s[6] is the read position
    i = s[6]
    s[6] = i + np.uint64(1)
    return s[i]


@numba.njit(inline="always")
def next_u32(s):  # pragma: no cover
    """Next 32-bit word: the low half of a fresh 64-bit word, then its buffered high half."""
    if s[5]:
        s[5] = np.uint64(0)
        return np.uint32(s[4])
    w = _next_u64(s)
    s[4] = w >> np.uint64(32)
    s[5] = np.uint64(1)
    return np.uint32(w & np.uint64(0xFFFFFFFF))


@numba.njit(inline="always")
def _next_float(s):  # pragma: no cover
    # NumPy's next_float: the 24 high bits, in [0, 1)
    return np.float32(next_u32(s) >> np.uint32(8)) * _TWO_M24_F


@numba.njit(nogil=True)
def slow_draw(s, idx, rabs, x, fi):  # pragma: no cover
    """The 1.5 % of draws outside their layer's rectangle: the tail or the wedge test.

    Returns the draw, or NaN when it is rejected (the caller starts afresh). Kept out of line:
    inlined, it slows the common path several times over.
    """
    if idx == 0:
        # tail beyond r (Marsaglia 1964): x = r + E1 / r, accepted when 2 E2 > (E1 / r)^2
        while True:
            xx = -_INV_R_F * np.log1p(-_next_float(s))
            yy = -np.log1p(-_next_float(s))
            if yy + yy > xx * xx:
                if (rabs >> np.uint32(8)) & np.uint32(1):
                    return -(_R_F + xx)
                return _R_F + xx
    # wedge: accepted under the density f(x) = exp(-x^2 / 2) (evaluated in double, as NumPy)
    xd = np.float64(x)
    if (fi[idx - 1] - fi[idx]) * _next_float(s) + fi[idx] < np.exp(-0.5 * xd * xd):
        return x
    return np.float32(np.nan)


@numba.njit(cache=True, nogil=True)
def _accumulate_normals(f, sigma, w, s, ki, wi, fi):  # pragma: no cover
    """``f[i, j] = (f[i, j] + sigma g) w[j]`` with ``g`` the next N(0, 1) draw, row by row.

    The ziggurat's common path is written out here, in the loop, on purpose (see
    :func:`slow_draw`).
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


def state_from(rng: np.random.Generator | None) -> np.ndarray:
    """A 256-bit xoshiro state ``(4,)`` uint64 from four raw 64-bit draws of ``rng``.

    Never all zero. ``None`` gives a fixed state (noise-free frames). Every compiled sampler
    (this module's, the ``fast`` and ``measurement`` levels') seeds a frame this way.
    """
    if rng is None:
        return np.array([1, 2, 3, 4], dtype=np.uint64)
    s = rng.bit_generator.random_raw(4)
    if not s.any():
        s[0] = 1
    return s


def seed_state(rng: np.random.Generator) -> np.ndarray:
    """A generator state (uint64[6], no buffered half) seeded from ``rng`` (:func:`state_from`)."""
    s = np.zeros(_STATE_WORDS, dtype=np.uint64)
    s[:4] = state_from(rng)
    return s


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
    head = np.array([0, 0, 0, 0, 0, 0, _STATE_WORDS + 1], dtype=np.uint64)
    return _normals(np.concatenate((head, np.asarray(words, dtype=np.uint64))), n)


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

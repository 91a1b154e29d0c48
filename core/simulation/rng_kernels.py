"""Compiled random draws for the ``fast`` level: xoshiro256++, ziggurat normals, Gamma.

The ``fast`` level draws ~6000 Gamma(12) cells per frame; inside one compiled call per
trajectory it cannot use a ``numpy.random.Generator`` (numba unboxes one per call, ~20 µs), so it
draws from its own generator, seeded per frame from four raw 64-bit draws of that frame's
generator (:func:`state_from`). The pipeline's per-frame streams (``stage_rng(seed, "noise", f)``)
still decide every frame.

- :func:`next_u64`: xoshiro256++ (Blackman & Vigna 2021; the step of
  :mod:`core.simulation.gaussian`, shared with the exact chain's noise), 256-bit state ``(4,)``
  uint64.
- :func:`uniform`: ``U[0, 1)`` with 53 random bits.
- :func:`normal`: ``N(0, 1)`` by the ziggurat method (Marsaglia & Tsang 2000, 128 layers) with
  the layer index and the value taken from disjoint bits of one 64-bit draw (the original
  32-bit version shares bits between them, Doornik 2005); the tail beyond ``r = 3.4426`` by
  Marsaglia's exponential rejection.
- :func:`gamma_dc`: ``Gamma(k, 1)``, ``k >= 1``, by Marsaglia & Tsang (2000) with the squeeze
  ``u < 1 - 0.0331 x^4`` (no logarithm for ~92 % of the Gamma(12) draws); ``d = k - 1/3``,
  ``c = 1/sqrt(9 d)`` are passed in so that a loop over cells computes them once.

The laws are tested in ``tests/core/simulation/test_rng_kernels.py`` (moments, Kolmogorov-Smirnov
against the exact distribution functions, tail probabilities).
"""

from __future__ import annotations

import numba
import numpy as np

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)
from core.simulation import gaussian
from core.simulation.gaussian import (  # noqa: F401  (state_from: re-exported for fast)
    FI,
    KI,
    WI,
    next_u32,
    slow_draw,
    state_from,
    xoshiro_step,
    ziggurat_tables,
)

#: ziggurat: number of layers and the start of the tail
_ZIG_LAYERS = 128
_ZIG_R = 3.442619855899
_ZIG_V = 9.91256303526217e-3


def _ziggurat_tables() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``kn`` (int64 acceptance bounds on a signed 32-bit value), ``wn``, ``fn`` (float64):
    :func:`core.simulation.gaussian.ziggurat_tables` for 128 layers and 31-bit abscissae."""
    out = ziggurat_tables(_ZIG_LAYERS, _ZIG_R, _ZIG_V, 31)
    for a in out:
        a.flags.writeable = False
    return out


_KN, _WN, _FN = _ziggurat_tables()


# The hot loops keep the 256-bit state in four local variables (registers) and pass it through
# these functions as ``(value, s0, s1, s2, s3)`` tuples, inlined: three times faster than loading
# and storing an array state on every draw. The array-state functions below are the same draws.
xoshiro = xoshiro_step


@numba.njit(inline="always")
def _unit(u):  # pragma: no cover
    """U[0, 1) from the upper 53 bits of a 64-bit draw."""
    return float(u >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@numba.njit(inline="always")
def normal_l(s0, s1, s2, s3):  # pragma: no cover
    """N(0, 1) by the ziggurat method (see the module docstring): ``(x, s0, s1, s2, s3)``."""
    kn, wn, fn = _KN, _WN, _FN
    while True:
        u, s0, s1, s2, s3 = xoshiro(s0, s1, s2, s3)
        iz = np.int64(u & np.uint64(127))
        # signed 32-bit value from the upper half (disjoint from the layer bits)
        hz = np.int64(u >> np.uint64(32)) - np.int64(2147483648)
        x = hz * wn[iz]
        if abs(hz) < kn[iz]:
            return x, s0, s1, s2, s3  # inside the layer's rectangle: ~97 % of the draws
        if iz == 0:
            # the tail |x| > r: Marsaglia (1964), x = r + E1 / r accepted when 2 E2 > (E1/r)^2
            while True:
                u, s0, s1, s2, s3 = xoshiro(s0, s1, s2, s3)
                xt = -np.log(1.0 - _unit(u)) / _ZIG_R
                u, s0, s1, s2, s3 = xoshiro(s0, s1, s2, s3)
                y = -np.log(1.0 - _unit(u))
                if y + y >= xt * xt:
                    break
            return (_ZIG_R + xt if hz > 0 else -_ZIG_R - xt), s0, s1, s2, s3
        # the wedge between this layer and the next: accept under the density
        u, s0, s1, s2, s3 = xoshiro(s0, s1, s2, s3)
        if fn[iz] + _unit(u) * (fn[iz - 1] - fn[iz]) < np.exp(-0.5 * x * x):
            return x, s0, s1, s2, s3


@numba.njit(inline="always")
def gamma_l(s0, s1, s2, s3, d, c):  # pragma: no cover
    """Gamma(k, 1), ``k >= 1``, ``d = k - 1/3``, ``c = 1/sqrt(9 d)`` (Marsaglia-Tsang):
    ``(g, s0, s1, s2, s3)``."""
    while True:
        x, s0, s1, s2, s3 = normal_l(s0, s1, s2, s3)
        v = 1.0 + c * x
        if v <= 0.0:
            continue
        v = v * v * v
        u, s0, s1, s2, s3 = xoshiro(s0, s1, s2, s3)
        w = 1.0 - _unit(u)  # (0, 1]
        x2 = x * x
        # squeeze: w < 1 - 0.0331 x^4 implies the acceptance test below
        if w < 1.0 - 0.0331 * x2 * x2:
            return d * v, s0, s1, s2, s3
        # accept when ln w < x^2/2 + d - d v + d ln v
        if np.log(w) < 0.5 * x2 + d * (1.0 - v + np.log(v)):
            return d * v, s0, s1, s2, s3


@numba.njit(cache=True, nogil=True)
def next_u64(s):  # pragma: no cover
    """Next 64-bit output of xoshiro256++ with state ``s`` (4,) uint64 (advanced in place)."""
    u, s[0], s[1], s[2], s[3] = xoshiro(s[0], s[1], s[2], s[3])
    return u


@numba.njit(cache=True, nogil=True)
def uniform(s):  # pragma: no cover
    """U[0, 1) with 53 random bits."""
    return _unit(next_u64(s))


@numba.njit(cache=True, nogil=True)
def normal(s):  # pragma: no cover
    """N(0, 1), array state (the same draws as :func:`normal_l`)."""
    x, s[0], s[1], s[2], s[3] = normal_l(s[0], s[1], s[2], s[3])
    return x


@numba.njit(cache=True, nogil=True)
def gamma_dc(s, d, c):  # pragma: no cover
    """Gamma(k, 1) for ``k >= 1``, array state (the same draws as :func:`gamma_l`)."""
    g, s[0], s[1], s[2], s[3] = gamma_l(s[0], s[1], s[2], s[3], d, c)
    return g


@numba.njit(cache=True, nogil=True)
def gamma(s, k):  # pragma: no cover
    """Gamma(k, 1); ``k < 1`` via ``Gamma(k + 1) U^(1/k)``."""
    if k < 1.0:
        return gamma(s, k + 1.0) * uniform(s) ** (1.0 / k)
    d = k - 1.0 / 3.0
    return gamma_dc(s, d, 1.0 / np.sqrt(9.0 * d))


@numba.njit(cache=True, nogil=True)
def fill_normal(s, n):  # pragma: no cover
    """``n`` normal draws (for tests)."""
    out = np.empty(n)
    for i in range(n):
        out[i] = normal(s)
    return out


@numba.njit(cache=True, nogil=True)
def fill_gamma(s, k, n):  # pragma: no cover
    """``n`` Gamma(k) draws (for tests)."""
    out = np.empty(n)
    for i in range(n):
        out[i] = gamma(s, k)
    return out


# ---- the noise map's Gamma(L): NumPy's single-precision algorithm on the shared generator -----
_F1 = np.float32(1.0)
_F_THIRD = np.float32(1.0 / 3.0)
_F_NINE = np.float32(9.0)
_F_SQUEEZE = np.float32(0.0331)
_F_HALF = np.float32(0.5)
_F_2M24 = np.float32(2.0**-24)
_R_F = np.float32(gaussian.ZIGGURAT_R)
_INV_R_F = np.float32(1.0 / gaussian.ZIGGURAT_R)


@numba.njit(inline="always")
def _u32_l(s0, s1, s2, s3, buf, has):  # pragma: no cover
    """:func:`core.simulation.gaussian.next_u32` on a state in registers: the low half of a
    fresh 64-bit word, then its buffered high half. ``(word, s0, s1, s2, s3, buf, has)``."""
    if has:
        return np.uint32(buf), s0, s1, s2, s3, buf, False
    w, s0, s1, s2, s3 = xoshiro_step(s0, s1, s2, s3)
    return np.uint32(w & np.uint64(0xFFFFFFFF)), s0, s1, s2, s3, w >> np.uint64(32), True


@numba.njit(inline="always")
def _slow_l(idx, rabs, x, fi, s0, s1, s2, s3, buf, has):  # pragma: no cover
    """:func:`core.simulation.gaussian.slow_draw` on a state in registers (the ziggurat's rare
    tail and wedge draws). ``(x or NaN, s0, s1, s2, s3, buf, has)``."""
    if idx == 0:
        # tail beyond r (Marsaglia 1964): x = r + E1 / r, accepted when 2 E2 > (E1 / r)^2
        while True:
            r, s0, s1, s2, s3, buf, has = _u32_l(s0, s1, s2, s3, buf, has)
            xx = -_INV_R_F * np.log1p(-(np.float32(r >> np.uint32(8)) * _F_2M24))
            r, s0, s1, s2, s3, buf, has = _u32_l(s0, s1, s2, s3, buf, has)
            yy = -np.log1p(-(np.float32(r >> np.uint32(8)) * _F_2M24))
            if yy + yy > xx * xx:
                if (rabs >> np.uint32(8)) & np.uint32(1):
                    return -(_R_F + xx), s0, s1, s2, s3, buf, has
                return _R_F + xx, s0, s1, s2, s3, buf, has
    # wedge: accepted under the density f(x) = exp(-x^2 / 2) (evaluated in double, as NumPy)
    xd = np.float64(x)
    r, s0, s1, s2, s3, buf, has = _u32_l(s0, s1, s2, s3, buf, has)
    if (fi[idx - 1] - fi[idx]) * (np.float32(r >> np.uint32(8)) * _F_2M24) + fi[idx] < np.exp(
        -0.5 * xd * xd
    ):
        return x, s0, s1, s2, s3, buf, has
    return np.float32(np.nan), s0, s1, s2, s3, buf, has


@numba.njit(inline="always")
def gamma_f32_l(s0, s1, s2, s3, buf, has, b, c, ki, wi, fi):  # pragma: no cover
    """Gamma(k) in float32, NumPy's ``random_standard_gamma_f`` (Marsaglia-Tsang on its float32
    ziggurat normal and 24-bit uniforms) fed the 32-bit words of the state
    ``(s0, s1, s2, s3, buffered high half, has buffer)`` of :mod:`core.simulation.gaussian`,
    held in registers; ``b = k - 1/3``, ``c = 1/sqrt(9 b)`` in float32
    (:func:`gamma_f32_constants`). Returns ``(g, s0, s1, s2, s3, buf, has)``."""
    while True:
        while True:
            # the float32 ziggurat normal (as gaussian._accumulate_normals)
            while True:
                r, s0, s1, s2, s3, buf, has = _u32_l(s0, s1, s2, s3, buf, has)
                idx = np.int64(r & np.uint32(0xFF))
                sign = (r >> np.uint32(8)) & np.uint32(1)
                rabs = (r >> np.uint32(9)) & np.uint32(0x007FFFFF)
                x = np.float32(np.int32(rabs)) * wi[idx]
                if sign:
                    x = -x
                if rabs < ki[idx]:
                    break
                x, s0, s1, s2, s3, buf, has = _slow_l(idx, rabs, x, fi, s0, s1, s2, s3, buf, has)
                if not np.isnan(x):
                    break
            v = _F1 + c * x
            if v > np.float32(0.0):
                break
        v = v * v * v
        # NumPy's next_float: the 24 high bits of a 32-bit word, in [0, 1)
        r, s0, s1, s2, s3, buf, has = _u32_l(s0, s1, s2, s3, buf, has)
        u = np.float32(r >> np.uint32(8)) * _F_2M24
        x2 = x * x
        # squeeze, then the exact test ln u < x^2/2 + b (1 - v + ln v)
        if u < _F1 - _F_SQUEEZE * x2 * x2 or np.log(u) < _F_HALF * x2 + b * (_F1 - v + np.log(v)):
            return b * v, s0, s1, s2, s3, buf, has


@numba.njit(inline="always")
def gamma_f32(s, b, c, ki, wi, fi):  # pragma: no cover
    """:func:`gamma_f32_l` on the six-word array state ``s`` (advanced)."""
    g, s0, s1, s2, s3, buf, has = gamma_f32_l(
        s[0], s[1], s[2], s[3], s[4], s[5] != 0, b, c, ki, wi, fi
    )
    s[0], s[1], s[2], s[3], s[4], s[5] = s0, s1, s2, s3, buf, np.uint64(has)
    return g


@numba.njit(inline="always")
def _gamma_f32_array(s, b, c, ki, wi, fi):  # pragma: no cover
    """:func:`gamma_f32` on the array state with :func:`core.simulation.gaussian.next_u32`,
    which also reads recorded streams (tests: bit-equal to NumPy on the same words)."""
    while True:
        while True:
            while True:
                r = next_u32(s)
                idx = np.int64(r & np.uint32(0xFF))
                sign = (r >> np.uint32(8)) & np.uint32(1)
                rabs = (r >> np.uint32(9)) & np.uint32(0x007FFFFF)
                x = np.float32(np.int32(rabs)) * wi[idx]
                if sign:
                    x = -x
                if rabs < ki[idx]:
                    break
                x = slow_draw(s, idx, rabs, x, fi)
                if not np.isnan(x):
                    break
            v = _F1 + c * x
            if v > np.float32(0.0):
                break
        v = v * v * v
        u = np.float32(next_u32(s) >> np.uint32(8)) * np.float32(2.0**-24)
        x2 = x * x
        if u < _F1 - _F_SQUEEZE * x2 * x2 or np.log(u) < _F_HALF * x2 + b * (_F1 - v + np.log(v)):
            return b * v


def gamma_f32_constants(k: float) -> tuple[np.float32, np.float32]:
    """``b = k - 1/3`` and ``c = 1 / sqrt(9 b)`` in float32, as NumPy computes them."""
    b = np.float32(k) - _F_THIRD
    return b, np.float32(_F1 / np.sqrt(_F_NINE * b))


@numba.njit(cache=True, nogil=True)
def _gammas_f32(s, n, b, c, ki, wi, fi, registers):  # pragma: no cover
    out = np.empty(n, dtype=np.float32)
    for i in range(n):
        if registers:
            out[i] = gamma_f32(s, b, c, ki, wi, fi)
        else:
            out[i] = _gamma_f32_array(s, b, c, ki, wi, fi)
    return out


def gammas_f32(state6_: np.ndarray, k: float, n: int, *, registers: bool = True) -> np.ndarray:
    """``n`` Gamma(k) float32 draws from the six-word state (advanced), by :func:`gamma_f32`
    (``registers=False``: the array-state reference)."""
    return _gammas_f32(state6_, n, *gamma_f32_constants(k), KI, WI, FI, registers)


def gammas_f32_from_stream(words: np.ndarray, k: float, n: int) -> np.ndarray:
    """``n`` Gamma(k) float32 draws from recorded 64-bit words (tests against NumPy)."""
    head = np.array([0, 0, 0, 0, 0, 0, 7], dtype=np.uint64)
    s = np.concatenate((head, np.asarray(words, dtype=np.uint64)))
    return _gammas_f32(s, n, *gamma_f32_constants(k), KI, WI, FI, False)


def state6(state4: np.ndarray) -> np.ndarray:
    """The six-word state of :mod:`core.simulation.gaussian` (no buffered half) from ``(4,)``."""
    return np.concatenate((np.asarray(state4, dtype=np.uint64), np.zeros(2, dtype=np.uint64)))

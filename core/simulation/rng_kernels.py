"""The simulation's compiled random numbers: every bit generator and every draw its kernels use.

A compiled kernel cannot use a ``numpy.random.Generator`` (numba unboxes one per call, about
20 µs), so each kernel draws from a generator of this module, seeded per frame from four raw
64-bit draws of that frame's NumPy generator (:func:`state_from`): the pipeline's per-frame
streams (``stage_rng(seed, "noise", f)``) still decide every frame.

Two bit generators (Blackman & Vigna, "Scrambled linear pseudorandom number generators",
ACM TOMS 47(4), 2021), each with a 256-bit state:

- **xoshiro256++** (:func:`xoshiro_step`), used by the exact chain's noise
  (:mod:`core.simulation.gaussian`) and by the ``fast`` level, through two kinds of draws:

  - *NumPy's single-precision algorithms on 32-bit words* (each 64-bit word used as two 32-bit
    words, low half first, as NumPy's ``next_uint32`` does): the 256-layer float32 ziggurat of
    ``standard_normal(dtype=float32)`` (8 bits choose the layer, 1 the sign, 23 the abscissa;
    wedges by a uniform test against the density; the tail beyond ``r = 3.6541528853610088`` by
    Marsaglia's exponential method) and NumPy's ``random_standard_gamma_f`` on it
    (:func:`gamma_f32_l`). Fed the same words they return NumPy's numbers bit for bit (the tests
    check this against ``Generator(PCG64)`` fed its own raw stream). The state is six words,
    ``[s0, s1, s2, s3, buffered high half, has-buffer flag]``; a longer array is a recorded
    stream for tests (``[0, 0, 0, 0, 0, 0, read position, words...]``).
  - *double precision on 64-bit words* (state ``(4,)``): :func:`uniform` (53 bits),
    :func:`normal_l` (the ziggurat of Marsaglia & Tsang, J. Stat. Softw. 5(8), 2000, 128 layers,
    the layer index and the value from disjoint bits of one word, Doornik 2005; the tail beyond
    ``r = 3.4426`` by Marsaglia's exponential rejection), :func:`gamma_l` (Marsaglia & Tsang 2000
    with the squeeze ``u < 1 - 0.0331 x^4``: no logarithm for ~92 % of the Gamma(12) draws).

- **xoshiro256**** (:func:`ss_next_u64`), used by the ``measurement`` level: :func:`ss_uniform`,
  :func:`ss_normal` (Box-Muller), :func:`ss_gamma`, :func:`ss_poisson`, :func:`ss_randint`.

Each level's data sets are fixed by its stream; the two generators and the three normal
samplers are kept as they are so that no data set moves (one generator for all would change
every ``measurement`` data set for no gain in quality: both pass BigCrush).

The hot loops keep a state in local variables (registers) and pass it through the ``*_l``
functions as ``(value, s0, s1, s2, s3[, buf, has])`` tuples, inlined: three times faster than
loading and storing an array state on every draw. The array-state functions are the same draws.
The laws are tested in ``tests/core/simulation/test_rng_kernels.py`` and ``test_gaussian.py``
(moments, Kolmogorov-Smirnov against the exact distribution functions, tails, NumPy bit for bit).
"""

from __future__ import annotations

import numba
import numpy as np

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)

# ---- seeding ----------------------------------------------------------------------------------

#: words of the 32-bit-word state: ``[s0, s1, s2, s3, buffered high half, has-buffer flag]``
STATE_WORDS = 6


def state_from(rng: np.random.Generator | None) -> np.ndarray:
    """A 256-bit xoshiro state ``(4,)`` uint64 from four raw 64-bit draws of ``rng``.

    Never all zero. ``None`` gives a fixed state (noise-free frames). Every compiled sampler
    (the exact chain's noise, the ``fast`` and ``measurement`` levels') seeds a frame this way.
    """
    if rng is None:
        return np.array([1, 2, 3, 4], dtype=np.uint64)
    s = rng.bit_generator.random_raw(4)
    if not s.any():
        s[0] = 1
    return s


def seed_state(rng: np.random.Generator) -> np.ndarray:
    """A six-word state (no buffered half) seeded from ``rng`` (:func:`state_from`)."""
    return state6(state_from(rng))


def state6(state4: np.ndarray) -> np.ndarray:
    """The six-word state (no buffered half) from a ``(4,)`` state."""
    return np.concatenate((np.asarray(state4, dtype=np.uint64), np.zeros(2, dtype=np.uint64)))


def recorded_stream(words: np.ndarray) -> np.ndarray:
    """A state that replays recorded 64-bit ``words`` (tests against NumPy)."""
    head = np.array([0, 0, 0, 0, 0, 0, STATE_WORDS + 1], dtype=np.uint64)
    return np.concatenate((head, np.asarray(words, dtype=np.uint64)))


# ---- xoshiro256++ -----------------------------------------------------------------------------


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


@numba.njit(cache=True, nogil=True)
def next_u64(s):  # pragma: no cover
    """Next 64-bit output of xoshiro256++ with state ``s`` (4,) uint64 (advanced in place)."""
    u, s[0], s[1], s[2], s[3] = xoshiro_step(s[0], s[1], s[2], s[3])
    return u


@numba.njit(inline="always")
def _next_u64_or_recorded(s):  # pragma: no cover
    if s.size == STATE_WORDS:
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
    w = _next_u64_or_recorded(s)
    s[4] = w >> np.uint64(32)
    s[5] = np.uint64(1)
    return np.uint32(w & np.uint64(0xFFFFFFFF))


@numba.njit(inline="always")
def _u32_l(s0, s1, s2, s3, buf, has):  # pragma: no cover
    """:func:`next_u32` on a state in registers: the low half of a fresh 64-bit word, then its
    buffered high half. ``(word, s0, s1, s2, s3, buf, has)``."""
    if has:
        return np.uint32(buf), s0, s1, s2, s3, buf, False
    w, s0, s1, s2, s3 = xoshiro_step(s0, s1, s2, s3)
    return np.uint32(w & np.uint64(0xFFFFFFFF)), s0, s1, s2, s3, w >> np.uint64(32), True


# ---- NumPy's single-precision ziggurat and Gamma on 32-bit words --------------------------------

#: edge of the ziggurat's base strip (256 layers) and the area of every layer: the base strip's
#: rectangle plus the tail, ``v = r f(r) + sqrt(pi / 2) erfc(r / sqrt 2)``, f(x) = exp(-x^2 / 2)
ZIGGURAT_R = 3.6541528853610088
ZIGGURAT_V = 0.004928673233974658


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


_F1 = np.float32(1.0)
_F_THIRD = np.float32(1.0 / 3.0)
_F_NINE = np.float32(9.0)
_F_SQUEEZE = np.float32(0.0331)
_F_HALF = np.float32(0.5)


@numba.njit(inline="always")
def _slow_l(idx, rabs, x, fi, s0, s1, s2, s3, buf, has):  # pragma: no cover
    """:func:`slow_draw` on a state in registers (the ziggurat's rare
    tail and wedge draws). ``(x or NaN, s0, s1, s2, s3, buf, has)``."""
    if idx == 0:
        # tail beyond r (Marsaglia 1964): x = r + E1 / r, accepted when 2 E2 > (E1 / r)^2
        while True:
            r, s0, s1, s2, s3, buf, has = _u32_l(s0, s1, s2, s3, buf, has)
            xx = -_INV_R_F * np.log1p(-(np.float32(r >> np.uint32(8)) * _TWO_M24_F))
            r, s0, s1, s2, s3, buf, has = _u32_l(s0, s1, s2, s3, buf, has)
            yy = -np.log1p(-(np.float32(r >> np.uint32(8)) * _TWO_M24_F))
            if yy + yy > xx * xx:
                if (rabs >> np.uint32(8)) & np.uint32(1):
                    return -(_R_F + xx), s0, s1, s2, s3, buf, has
                return _R_F + xx, s0, s1, s2, s3, buf, has
    # wedge: accepted under the density f(x) = exp(-x^2 / 2) (evaluated in double, as NumPy)
    xd = np.float64(x)
    r, s0, s1, s2, s3, buf, has = _u32_l(s0, s1, s2, s3, buf, has)
    if (fi[idx - 1] - fi[idx]) * (np.float32(r >> np.uint32(8)) * _TWO_M24_F) + fi[idx] < np.exp(
        -0.5 * xd * xd
    ):
        return x, s0, s1, s2, s3, buf, has
    return np.float32(np.nan), s0, s1, s2, s3, buf, has


@numba.njit(inline="always")
def gamma_f32_l(s0, s1, s2, s3, buf, has, b, c, ki, wi, fi):  # pragma: no cover
    """Gamma(k) in float32, NumPy's ``random_standard_gamma_f`` (Marsaglia-Tsang on its float32
    ziggurat normal and 24-bit uniforms) fed the 32-bit words of the state
    ``(s0, s1, s2, s3, buffered high half, has buffer)`` held in registers; ``b = k - 1/3``,
    ``c = 1/sqrt(9 b)`` in float32 (:func:`gamma_f32_constants`).
    Returns ``(g, s0, s1, s2, s3, buf, has)``."""
    while True:
        while True:
            # the float32 ziggurat normal (as the exact chain's noise kernel draws it)
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
        u = np.float32(r >> np.uint32(8)) * _TWO_M24_F
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
    """:func:`gamma_f32` on the array state with :func:`next_u32`,
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
    return _gammas_f32(recorded_stream(words), n, *gamma_f32_constants(k), KI, WI, FI, False)


# ---- double precision on 64-bit words: 128-layer ziggurat, Gamma ------------------------------

#: ziggurat: number of layers and the start of the tail
_ZIG_LAYERS = 128
_ZIG_R = 3.442619855899
_ZIG_V = 9.91256303526217e-3


def _ziggurat_tables() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``kn`` (int64 acceptance bounds on a signed 32-bit value), ``wn``, ``fn`` (float64):
    :func:`ziggurat_tables` for 128 layers and 31-bit abscissae."""
    out = ziggurat_tables(_ZIG_LAYERS, _ZIG_R, _ZIG_V, 31)
    for a in out:
        a.flags.writeable = False
    return out


_KN, _WN, _FN = _ziggurat_tables()


@numba.njit(inline="always")
def _unit(u):  # pragma: no cover
    """U[0, 1) from the upper 53 bits of a 64-bit draw."""
    return float(u >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@numba.njit(inline="always")
def normal_l(s0, s1, s2, s3):  # pragma: no cover
    """N(0, 1) by the 128-layer ziggurat (see the module docstring): ``(x, s0, s1, s2, s3)``."""
    kn, wn, fn = _KN, _WN, _FN
    while True:
        u, s0, s1, s2, s3 = xoshiro_step(s0, s1, s2, s3)
        iz = np.int64(u & np.uint64(127))
        # signed 32-bit value from the upper half (disjoint from the layer bits)
        hz = np.int64(u >> np.uint64(32)) - np.int64(2147483648)
        x = hz * wn[iz]
        if abs(hz) < kn[iz]:
            return x, s0, s1, s2, s3  # inside the layer's rectangle: ~97 % of the draws
        if iz == 0:
            # the tail |x| > r: Marsaglia (1964), x = r + E1 / r accepted when 2 E2 > (E1/r)^2
            while True:
                u, s0, s1, s2, s3 = xoshiro_step(s0, s1, s2, s3)
                xt = -np.log(1.0 - _unit(u)) / _ZIG_R
                u, s0, s1, s2, s3 = xoshiro_step(s0, s1, s2, s3)
                y = -np.log(1.0 - _unit(u))
                if y + y >= xt * xt:
                    break
            return (_ZIG_R + xt if hz > 0 else -_ZIG_R - xt), s0, s1, s2, s3
        # the wedge between this layer and the next: accept under the density
        u, s0, s1, s2, s3 = xoshiro_step(s0, s1, s2, s3)
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
        u, s0, s1, s2, s3 = xoshiro_step(s0, s1, s2, s3)
        w = 1.0 - _unit(u)  # (0, 1]
        x2 = x * x
        # squeeze: w < 1 - 0.0331 x^4 implies the acceptance test below
        if w < 1.0 - 0.0331 * x2 * x2:
            return d * v, s0, s1, s2, s3
        # accept when ln w < x^2/2 + d - d v + d ln v
        if np.log(w) < 0.5 * x2 + d * (1.0 - v + np.log(v)):
            return d * v, s0, s1, s2, s3


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


# ---- xoshiro256** and the measurement level's draws -------------------------------------------


@numba.njit(cache=True, nogil=True)
def ss_next_u64(s):  # pragma: no cover
    """Next 64-bit output of xoshiro256** with state ``s`` (4,) uint64 (advanced in place)."""
    result = _rotl(s[1] * np.uint64(5), 7) * np.uint64(9)
    t = s[1] << np.uint64(17)
    s[2] ^= s[0]
    s[3] ^= s[1]
    s[1] ^= s[2]
    s[0] ^= s[3]
    s[2] ^= t
    s[3] = _rotl(s[3], 45)
    return result


@numba.njit(cache=True, nogil=True)
def ss_uniform(s):  # pragma: no cover
    """U[0, 1) with 53 random bits."""
    return float(ss_next_u64(s) >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@numba.njit(cache=True, nogil=True)
def ss_normal(s):  # pragma: no cover
    """N(0, 1) by Box-Muller: sqrt(-2 ln u1) cos(2 pi u2), u1 in (0, 1]."""
    u1 = 1.0 - ss_uniform(s)
    return np.sqrt(-2.0 * np.log(u1)) * np.cos(2.0 * np.pi * ss_uniform(s))


@numba.njit(cache=True, nogil=True)
def ss_gamma(s, k):  # pragma: no cover
    """Gamma(k, 1) by Marsaglia & Tsang (2000); k < 1 via Gamma(k + 1) U^(1/k)."""
    if k < 1.0:
        return ss_gamma(s, k + 1.0) * ss_uniform(s) ** (1.0 / k)
    d = k - 1.0 / 3.0
    c = 1.0 / np.sqrt(9.0 * d)
    while True:
        x = ss_normal(s)
        v = 1.0 + c * x
        if v <= 0.0:
            continue
        v = v * v * v
        u = 1.0 - ss_uniform(s)
        # accept when ln u < x^2/2 + d - d v + d ln v
        if np.log(u) < 0.5 * x * x + d - d * v + d * np.log(v):
            return d * v


@numba.njit(cache=True, nogil=True)
def ss_poisson(s, lam):  # pragma: no cover
    """Poisson(lam) by multiplying uniforms (Knuth; the rates here are well below 1)."""
    limit = np.exp(-lam)
    k = 0
    p = 1.0 - ss_uniform(s)
    while p > limit:
        k += 1
        p *= 1.0 - ss_uniform(s)
    return k


@numba.njit(cache=True, nogil=True)
def ss_randint(s, n):  # pragma: no cover
    """Uniform integer in ``0 .. n-1`` (n >= 1; the bias of the modulo is below 2^-50)."""
    return np.int64(ss_next_u64(s) % np.uint64(n))

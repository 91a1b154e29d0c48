"""Compiled noise generator: the bits, the ziggurat, and the distribution of the noise."""

from __future__ import annotations

import numpy as np
import scipy.stats

from core.simulation.gaussian import (
    add_complex_noise,
    complex_noise,
    normals_from_stream,
    standard_normals,
)
from core.simulation.rng_kernels import ZIGGURAT_R, xoshiro_next


def test_xoshiro256pp_first_words_by_hand() -> None:
    # state (1, 2, 3, 4): out1 = rotl(1 + 4, 23) + 1 = 5 * 2^23 + 1 = 41943041; the update gives
    # s0 = 7, s3 = rotl(6, 45) = 6 * 2^45, so out2 = rotl(7 + 6 * 2^45, 23) + 7
    # = (7 * 2^23 | 6 * 2^4) + 7 = 58720352 + 7 (the 6 * 2^68 term wraps round to bit 4)
    import numba

    @numba.njit
    def two(s):
        return xoshiro_next(s), xoshiro_next(s)

    a, b = two(np.array([1, 2, 3, 4, 0, 0], dtype=np.uint64))
    assert (int(a), int(b)) == (41943041, 58720359)


def test_ziggurat_is_numpys_on_the_same_bits() -> None:
    # NumPy's Generator(PCG64).standard_normal(dtype=float32) is the same single-precision
    # ziggurat on PCG64's 32-bit words (low half of each 64-bit word first): fed those words,
    # ours must return the very same numbers; a different table entry or accept/reject decision
    # would shift the stream and differ by O(1) from there on
    n = 1_000_000
    words = np.random.Generator(np.random.PCG64(2024)).bit_generator.random_raw(n)
    ours = normals_from_stream(words, n)
    ref = np.random.Generator(np.random.PCG64(2024)).standard_normal(n, dtype=np.float32)
    np.testing.assert_array_equal(ours, ref)
    # the stream exercised the tail and the wedges, not only the rectangles
    assert np.sum(np.abs(ref) > ZIGGURAT_R) > 50


def test_normals_distribution_and_tail() -> None:
    n = 2_000_000
    x = standard_normals(np.random.default_rng(7), n)
    # KS distance to N(0, 1): the 0.1 % critical value for n = 2e6 is 1.95 / sqrt(n) = 0.0014
    assert scipy.stats.kstest(x, "norm").statistic < 1.95 / np.sqrt(n)
    assert abs(x.mean()) < 5 / np.sqrt(n)
    assert abs(x.var() - 1) < 5 * np.sqrt(2 / n)
    # beyond the base strip's edge (the tail algorithm): P(|x| > r) = 2 Phi(-r) = 2.58e-4
    p = 2 * scipy.stats.norm.sf(ZIGGURAT_R)
    count = np.sum(np.abs(x) > ZIGGURAT_R)
    assert abs(count - n * p) < 5 * np.sqrt(n * p)
    # lag-1 correlation of consecutive draws
    assert abs(np.corrcoef(x[:-1], x[1:])[0, 1]) < 5 / np.sqrt(n)


def test_complex_noise_power_and_independent_parts() -> None:
    z = complex_noise((12, 32, 256), 2.5, np.random.default_rng(3))
    assert z.dtype == np.complex64
    n = z.size
    # E|n|^2 = 2.5, each part N(0, 1.25)
    assert abs(np.mean(np.abs(z) ** 2) / 2.5 - 1) < 5 / np.sqrt(n)
    assert abs(np.var(z.real) / 1.25 - 1) < 5 * np.sqrt(2 / n)
    assert abs(np.corrcoef(z.real.ravel(), z.imag.ravel())[0, 1]) < 5 / np.sqrt(n)
    # same seed, same noise; another seed, other noise
    np.testing.assert_array_equal(z, complex_noise((12, 32, 256), 2.5, np.random.default_rng(3)))
    assert not np.array_equal(z, complex_noise((12, 32, 256), 2.5, np.random.default_rng(4)))


def test_add_noise_windowed_is_signal_plus_the_same_noise_times_window() -> None:
    rng = np.random.default_rng(11)
    sig = (rng.standard_normal((2, 3, 16)) + 1j * rng.standard_normal((2, 3, 16))).astype(
        np.complex64
    )
    w = np.hanning(16)
    cube = sig.copy()
    add_complex_noise(cube, 0.3, np.random.default_rng(5), window=w)
    noise = complex_noise((2, 3, 16), 0.3, np.random.default_rng(5))
    np.testing.assert_allclose(cube, (sig + noise) * w, rtol=1e-5, atol=1e-6)

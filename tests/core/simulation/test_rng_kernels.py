"""The ``fast`` level's compiled draws follow their laws (moments, KS, tails)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from core.simulation import rng_kernels as rk

N = 400_000


def _state(seed: int) -> np.ndarray:
    return rk.state_from(np.random.default_rng(seed))


def test_state_from_is_four_raw_draws_and_never_zero() -> None:
    s = rk.state_from(np.random.default_rng(5))
    assert s.dtype == np.uint64 and s.shape == (4,)
    np.testing.assert_array_equal(s, np.random.default_rng(5).bit_generator.random_raw(4))
    np.testing.assert_array_equal(rk.state_from(None), [1, 2, 3, 4])


def test_ziggurat_tables() -> None:
    # layer i spans x up to x_i; x_127 = r, f(x) = exp(-x^2/2) at the layer tops
    assert rk._WN[-1] * 2.0**31 == pytest.approx(rk._ZIG_R)
    assert rk._FN[-1] == pytest.approx(np.exp(-0.5 * rk._ZIG_R**2))
    x = rk._WN[1:] * 2.0**31
    assert np.all(np.diff(x) > 0)
    # every layer has the same area v: x_i (f(x_{i-1}) - f(x_i)) for the rectangles above
    area = x[1:] * (rk._FN[1:-1] - rk._FN[2:])
    np.testing.assert_allclose(area, rk._ZIG_V, rtol=1e-9)


def test_normal_moments_ks_and_tails() -> None:
    x = rk.fill_normal(_state(1), N)
    assert abs(x.mean()) < 5 / np.sqrt(N)
    assert x.var() == pytest.approx(1.0, abs=5 * np.sqrt(2 / N))
    # E x^4 = 3 (sd of the estimate sqrt(96 / N))
    assert np.mean(x**4) == pytest.approx(3.0, abs=5 * np.sqrt(96 / N))
    assert stats.kstest(x, "norm").pvalue > 1e-3
    # the tail beyond r = 3.44 (its own sampler) and the wedges: P(|x| > t)
    for t in (1.0, 2.5, 3.44, 4.0):
        p = 2 * stats.norm.sf(t)
        assert np.mean(np.abs(x) > t) == pytest.approx(p, abs=5 * np.sqrt(p / N) + 1e-6)


@pytest.mark.parametrize("k", [11.0, 12.0, 2.5, 0.4])
def test_gamma_moments_and_ks(k: float) -> None:
    g = rk.fill_gamma(_state(2), k, N)
    assert g.mean() == pytest.approx(k, abs=5 * np.sqrt(k / N))
    assert g.var() == pytest.approx(k, rel=0.02)
    assert stats.kstest(g, stats.gamma(k).cdf).pvalue > 1e-3


def test_gamma12_upper_tail_where_the_cfar_decides() -> None:
    """The two-stage CFAR's false alarms live at P ~ 1e-3..1e-4 of Gamma(12)."""
    g = rk.fill_gamma(_state(3), 12.0, 2_000_000)
    for p in (1e-2, 1e-3, 1e-4):
        t = stats.gamma(12).isf(p)
        assert np.mean(g > t) == pytest.approx(p, abs=5 * np.sqrt(p / 2_000_000))


def test_array_and_register_state_give_the_same_draws() -> None:
    a, b = _state(4), _state(4)
    x = rk.fill_normal(a, 1000)
    s0, s1, s2, s3 = b
    y = []
    for _ in range(1000):
        v, *st = rk.normal_l(s0, s1, s2, s3)
        s0, s1, s2, s3 = (np.uint64(q) for q in st)
        y.append(v)
    np.testing.assert_array_equal(x, y)
    np.testing.assert_array_equal(a, [s0, s1, s2, s3])


def test_noise_map_gamma_is_numpys_float32_algorithm_bit_for_bit() -> None:
    """The noise map's Gamma(12): NumPy's standard_gamma(dtype=float32) fed the same words
    (recorded PCG64 stream; 50 000 draws take ~750 wedge and ~13 tail normals, so the rare
    paths are compared too), and the register-state version equals the array-state one."""
    words = np.random.Generator(np.random.PCG64(5)).bit_generator.random_raw(120_000)
    ref = np.random.Generator(np.random.PCG64(5)).standard_gamma(12.0, 50_000, dtype=np.float32)
    np.testing.assert_array_equal(rk.gammas_f32_from_stream(words, 12.0, 50_000), ref)
    a = rk.state6(_state(6))
    b = a.copy()
    x = rk.gammas_f32(a, 12.0, 100_000)
    np.testing.assert_array_equal(x, rk.gammas_f32(b, 12.0, 100_000, registers=False))
    np.testing.assert_array_equal(a, b)
    assert x.mean() == pytest.approx(12.0, abs=5 * np.sqrt(12 / 100_000))
    assert stats.kstest(x, stats.gamma(12).cdf).pvalue > 1e-3

"""CFAR thresholds for a non-coherent sum of 12 channels, and false-alarm rates on noise maps."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import integrate, stats

from core.config import CfarSettings, ProcessingSettings, RadarConfig
from core.processing import (
    CaCfar,
    CagoCfar,
    CasoCfar,
    doppler_fft,
    make_cfar,
    pfa_ca,
    pfa_cago,
    pfa_caso,
    range_doppler_map,
    range_fft,
    threshold_factor,
    two_stage_cfar,
)
from core.simulation import synthesize_noise

RADAR = RadarConfig()
L = 12


def numeric_pfa(t: float, n_side: int, combine: str) -> float:
    """P(X > T * comb(Z1, Z2)) by integrating over the Gamma(nL) densities of both sides."""
    g = stats.gamma(n_side * L)
    sx = stats.gamma(L).sf
    if combine == "so":
        dens = lambda z: 2 * g.pdf(z) * g.sf(z)  # noqa: E731
    else:
        dens = lambda z: 2 * g.pdf(z) * g.cdf(z)  # noqa: E731
    hi = 4.0 * n_side * L  # the densities vanish long before 4x their mean
    val, _ = integrate.quad(lambda z: dens(z) * sx(t * z), 0, hi, points=[n_side * L], limit=200)
    return val


@pytest.mark.parametrize("t", [0.05, 0.15, 0.4])
def test_closed_forms_match_numerical_integration(t: float) -> None:
    assert pfa_caso(t, 8, L) == pytest.approx(numeric_pfa(t, 8, "so"), rel=1e-6)
    assert pfa_cago(t, 8, L) == pytest.approx(numeric_pfa(t, 8, "go"), rel=1e-6)
    g = stats.gamma(16 * L)
    ca, _ = integrate.quad(
        lambda z: g.pdf(z) * stats.gamma(L).sf(t * z), 0, 800, points=[16 * L], limit=200
    )
    assert pfa_ca(t, 16, L) == pytest.approx(ca, rel=1e-6)


def test_single_look_ca_is_textbook_formula() -> None:
    # L = 1: Pfa = (1 + T)^-N
    for t in (0.1, 0.5):
        assert pfa_ca(t, 16, 1) == pytest.approx((1 + t) ** -16, rel=1e-12)


@pytest.mark.parametrize(
    ("method", "n", "pfa"), [("ca", 8, 1e-3), ("caso", 8, 1e-4), ("cago", 8, 1e-4)]
)
def test_threshold_factor_inverts_pfa(method: str, n: int, pfa: float) -> None:
    alpha = threshold_factor(method, n, pfa, L)
    f = {"ca": pfa_ca, "caso": pfa_caso, "cago": pfa_cago}[method]
    assert f(alpha / n, n, L) == pytest.approx(pfa, rel=1e-8)


def test_gamma_thresholds_are_far_below_single_look() -> None:
    # the Gamma(12) sum fluctuates far less than one exponential: the single-look factor
    # N (Pfa^(-1/N) - 1) would be several times too high
    single = 8 * (1e-3 ** (-1 / 8) - 1)
    alpha = threshold_factor("ca", 8, 1e-3, L)
    assert alpha < single / 3
    # CASO needs a higher factor than CA for the same Pfa, CAGO a lower one
    assert threshold_factor("caso", 8, 1e-4, L) > threshold_factor("ca", 16, 1e-4, L)
    assert threshold_factor("cago", 8, 1e-4, L) < threshold_factor("ca", 16, 1e-4, L)


def test_make_cfar_returns_strategies() -> None:
    s = ProcessingSettings()
    assert isinstance(make_cfar(s.range_cfar, L), CasoCfar)
    assert isinstance(make_cfar(s.doppler_cfar, L), CaCfar)
    assert isinstance(make_cfar(CfarSettings(method="cago"), L), CagoCfar)


def noise_maps(n_frames: int, seed: int) -> np.ndarray:
    """Noise-only range-Doppler maps through the chain; rectangular windows keep cells i.i.d."""
    rng = np.random.default_rng(seed)
    return np.stack(
        [
            range_doppler_map(doppler_fft(range_fft(synthesize_noise(RADAR, rng), "rect"), "rect"))
            for _ in range(n_frames)
        ]
    )


@pytest.mark.slow
def test_empirical_false_alarm_rate_per_stage() -> None:
    maps = noise_maps(400, seed=2024)  # 400 x 256 x 32 = 3.3e6 cells
    n_cells = maps.size
    assert n_cells >= 1e6
    s = ProcessingSettings()
    for cfg, axis in ((s.range_cfar, 1), (s.doppler_cfar, 2)):
        mask, noise = make_cfar(cfg, L).detect(maps, axis=axis)
        rate = mask.sum() / n_cells
        assert rate == pytest.approx(cfg.pfa, rel=0.2), (cfg.method, rate)
        # the noise estimate is unbiased for CA (mean cell power), biased low for CASO
        ratio = np.nanmean(noise) / maps.mean()
        assert (0.98 < ratio < 1.02) if cfg.method == "ca" else (0.8 < ratio < 0.98)
    # the range stage at its edges (one-sided CA) keeps the design rate as well
    mask, _ = make_cfar(s.range_cfar, L).detect(maps, axis=1)
    edges = np.r_[0:12, 244:256]
    edge_rate = mask[:, edges].mean()
    assert edge_rate == pytest.approx(1e-4, rel=0.5)


def test_two_stage_cfar_finds_a_target_once() -> None:
    rng = np.random.default_rng(3)
    rd = rng.gamma(L, 1.0, size=(256, 32))
    rd[80, 20] += 400.0  # about 15 dB over the 12-channel noise sum
    rd[79, 20] += 150.0
    rd[80, 21] += 100.0
    det = two_stage_cfar(rd, RADAR, ProcessingSettings())
    assert list(zip(det.range_bin, det.doppler_index)) == [(80, 20)]
    # SNR = cell power / noise estimate; the noise estimate is near the mean cell power (12)
    assert det.noise_power[0] == pytest.approx(12.0, rel=0.2)
    assert det.snr_db[0] == pytest.approx(10 * np.log10(rd[80, 20] / det.noise_power[0]))


def test_range_limits_exclude_near_cells() -> None:
    rd = np.full((256, 32), 12.0)
    rd[3, 10] = 1e4  # 0.17 m: inside the leakage zone, outside 0.3 m
    rd[200, 10] = 1e4  # 11.3 m: beyond the AOI
    rd[100, 10] = 1e4
    det = two_stage_cfar(rd, RADAR, ProcessingSettings())
    assert det.range_bin.tolist() == [100]

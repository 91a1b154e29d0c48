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
    expected_false_alarms_per_frame,
    make_cfar,
    pfa_ca,
    pfa_cago,
    pfa_caso,
    range_doppler_map,
    range_fft,
    remove_static_clutter,
    threshold_factor,
    two_stage_cfar,
    two_stage_pfa,
)
from core.processing.cfar_thresholds import _pfa_so_numeric
from core.processing.spectrum import (
    cell_power_correlation,
    clutter_removal_noise_profile,
    effective_cells,
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


def test_numeric_and_closed_form_caso_agree() -> None:
    # the numerical integral (used for effective, non-integer cell counts) at an integer count
    for t in (0.2, 0.35):
        assert _pfa_so_numeric(t, 8 * L, L) == pytest.approx(pfa_caso(t, 8, L), rel=1e-7)
    # fewer effective cells -> higher threshold for the same Pfa
    assert threshold_factor("caso", 8, 1e-4, L, 4.4) > threshold_factor("caso", 8, 1e-4, L)


def test_window_noise_model() -> None:
    # periodic Hann: neighbour power correlation 4/9, 1/36 two bins apart, 0 beyond
    assert cell_power_correlation("hann", 256, 1) == pytest.approx(4 / 9)
    assert cell_power_correlation("hann", 256, 2) == pytest.approx(1 / 36)
    assert cell_power_correlation("hann", 256, 3) < 1e-12
    # N_eff = N^2 / (N + 2 (N-1) 4/9 + 2 (N-2) / 36)
    assert effective_cells("hann", 256, 8) == pytest.approx(64 / (8 + 14 * 4 / 9 + 12 / 36))
    assert effective_cells("rect", 256, 8) == pytest.approx(8)
    # mean removal + Hann: 1/3 of the noise at zero Doppler, 5/6 next to it
    g = clutter_removal_noise_profile("hann", 32)
    assert g[16] == pytest.approx(1 / 3) and g[15] == g[17] == pytest.approx(5 / 6)
    assert np.allclose(np.delete(g, [15, 16, 17]), 1.0)


def noise_maps(n_frames: int, seed: int, settings: ProcessingSettings) -> np.ndarray:
    """Noise-only range-Doppler maps through the chain's stages."""
    rng = np.random.default_rng(seed)
    maps = []
    for _ in range(n_frames):
        rc = range_fft(synthesize_noise(RADAR, rng), settings.range_window)
        if settings.static_clutter_removal:
            rc = remove_static_clutter(rc)
        maps.append(range_doppler_map(doppler_fft(rc, settings.doppler_window)))
    return np.stack(maps)


EXACT = ProcessingSettings(range_window="rect", doppler_window="rect", static_clutter_removal=False)


@pytest.fixture(scope="module")
def exact_maps() -> np.ndarray:
    """Rectangular windows, no clutter removal: i.i.d. Gamma(12) cells, 400 x 256 x 32."""
    return noise_maps(400, 2024, EXACT)


@pytest.mark.slow
def test_empirical_false_alarm_rate_per_stage(exact_maps) -> None:
    """Exact model: rectangular windows, no clutter removal -> i.i.d. Gamma(12) cells."""
    s = EXACT
    maps = exact_maps  # 3.3e6 cells
    n_cells = maps.size
    assert n_cells >= 1e6
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


@pytest.mark.slow
def test_default_chain_false_alarm_rate_per_stage() -> None:
    """Hann windows and static clutter removal, thresholds from the chain's noise model."""
    s = ProcessingSettings()
    maps = noise_maps(200, 7, s)  # 1.6e6 cells
    whitened = maps / clutter_removal_noise_profile(s.doppler_window, RADAR.n_loops)
    ne_r = effective_cells(s.range_window, RADAR.n_samples, s.range_cfar.n_train)
    ne_d = effective_cells(s.doppler_window, RADAR.n_loops, s.doppler_cfar.n_train)
    for cfg, axis, ne in ((s.range_cfar, 1, ne_r), (s.doppler_cfar, 2, ne_d)):
        mask, _ = make_cfar(cfg, L, ne).detect(whitened, axis=axis)
        assert mask.mean() == pytest.approx(cfg.pfa, rel=0.2), (cfg.method, mask.mean())
        # without the noise model the Hann-correlated training cells let through 2-3x more
        naive, _ = make_cfar(cfg, L).detect(maps, axis=axis)
        assert naive.mean() > 1.5 * cfg.pfa
    # false alarms of the whole two-stage detector per frame (0.3 m ... 10 m): the joint
    # probability (an upper bound: peak grouping removes some) predicts them
    per_frame = np.mean([len(two_stage_cfar(m, RADAR, s)) for m in maps])
    predicted = expected_false_alarms_per_frame(RADAR, s)
    assert predicted == pytest.approx(0.20, abs=0.01)
    assert 0.6 * predicted < per_frame <= 1.1 * predicted


@pytest.mark.slow
def test_joint_two_stage_rate_exact_model(exact_maps) -> None:
    s = EXACT
    # each stage alone integrates back to its design Pfa
    one = ProcessingSettings(
        range_window="rect",
        doppler_window="rect",
        static_clutter_removal=False,
        doppler_cfar=CfarSettings(method="ca", n_train=4, n_guard=2, pfa=0.999999, cyclic=True),
    )
    assert two_stage_pfa(one) == pytest.approx(1e-4, rel=1e-3)
    maps = exact_maps
    rm, _ = make_cfar(s.range_cfar, L).detect(maps, axis=1)
    dm, _ = make_cfar(s.doppler_cfar, L).detect(maps, axis=2)
    joint = two_stage_pfa(s)
    assert joint > 100 * s.range_cfar.pfa * s.doppler_cfar.pfa
    assert (rm & dm).mean() == pytest.approx(joint, rel=0.2)


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


def reference_two_stage(rd, settings, ne_r, ne_d, profile):
    """Both stages composed from the numpy strategies (CaCfar/CasoCfar/CagoCfar.detect)."""
    k = np.arange(rd.shape[0]) * RADAR.range_resolution_m
    inside = np.flatnonzero((k >= settings.min_range_m) & (k <= settings.max_range_m))
    lo, hi = inside[0], inside[-1]
    margin = settings.range_cfar.n_train + settings.range_cfar.n_guard
    a, b = max(0, lo - margin), min(rd.shape[0], hi + 1 + margin)
    sub = rd[a:b] if profile is None else rd[a:b] / profile
    mask_r, noise_r = make_cfar(settings.range_cfar, L, ne_r).detect(sub, axis=0)
    mask_d, _ = make_cfar(settings.doppler_cfar, L, ne_d).detect(sub, axis=1)
    mask = mask_r & mask_d
    mask[: lo - a] = False
    mask[hi + 1 - a :] = False
    r, d = np.nonzero(mask)
    return r + a, d, noise_r[r, d]


@pytest.mark.parametrize(
    "settings",
    [
        ProcessingSettings(peak_grouping=False, static_clutter_removal=False),
        ProcessingSettings(
            peak_grouping=False,
            static_clutter_removal=False,
            cfar_noise_model=False,
            range_cfar=CfarSettings(method="cago", n_train=6, n_guard=2, pfa=1e-2),
            doppler_cfar=CfarSettings(method="caso", n_train=3, n_guard=1, pfa=0.05),
        ),
        ProcessingSettings(
            peak_grouping=False,
            static_clutter_removal=False,
            range_cfar=CfarSettings(method="ca", n_train=4, n_guard=1, pfa=1e-2, cyclic=True),
            doppler_cfar=CfarSettings(method="ca", n_train=2, n_guard=1, pfa=0.05, cyclic=False),
        ),
    ],
)
def test_compiled_two_stage_equals_composed_strategies(settings) -> None:
    rng = np.random.default_rng(21)
    rd = rng.gamma(L, 1.0, size=(256, 32))
    rd[rng.integers(0, 256, 40), rng.integers(0, 32, 40)] *= 8.0
    ne_r = ne_d = None
    if settings.cfar_noise_model:
        ne_r = effective_cells(settings.range_window, 256, settings.range_cfar.n_train)
        ne_d = effective_cells(settings.doppler_window, 32, settings.doppler_cfar.n_train)
    det = two_stage_cfar(rd, RADAR, settings)
    r, d, noise = reference_two_stage(rd, settings, ne_r, ne_d, None)
    assert len(r) > 20
    np.testing.assert_array_equal(det.range_bin, r)
    np.testing.assert_array_equal(det.doppler_index, d)
    np.testing.assert_array_equal(det.noise_power, noise)

"""Range-azimuth heat map: a single moving reflector peaks at the range bin and angle index
derived from its position, and static clutter removal leaves a static reflector out."""

from __future__ import annotations

import numpy as np
import pytest

from core.config import RadarConfig
from core.processing import doppler_fft, range_fft
from core.processing.range_azimuth import azimuth_sines, range_azimuth_map
from core.simulation import AntennaGain, Scatterers, synthesize_signal

RADAR = RadarConfig()
IDEAL = AntennaGain.ideal(RADAR)
T_MID = 0.5 * RADAR.n_loops * RADAR.n_tx * RADAR.chirp_period_s


def _cube(range_m: float, u: float, vr: float) -> np.ndarray:
    """Noise-free Doppler cube (clutter removed) of one reflector at ``range_m`` mid-frame,
    ``sin(az) = u``, moving radially at ``vr``."""
    az = np.arcsin(u)
    d = np.array([np.sin(az), np.cos(az), 0.0])
    sc = Scatterers(
        position_m=((range_m - vr * T_MID) * d).reshape(1, 3),
        velocity_mps=(vr * d).reshape(1, 3),
        rcs_dbsm=np.array([0.0]),
        source=np.array([0], dtype=np.int32),
    )
    rc = range_fft(synthesize_signal(RADAR, sc, IDEAL), "hann")
    return doppler_fft(rc, "hann", remove_static=True)


@pytest.mark.parametrize(("k", "vr"), [(8, 1.0), (-12, -2.3), (0, 0.9)])
def test_peak_at_the_reflectors_range_bin_and_angle_index(k: int, vr: float) -> None:
    # range bin: 4.00 m / 5.630 cm = 71.05 -> 71 (SPEC §1); angle: u = 2 k / 64 lands exactly on
    # the centred index 32 + k of a 64-point FFT over the 8-element row (spacing lambda/2)
    u = 2 * k / 64
    ra = range_azimuth_map(_cube(4.00, u, vr), RADAR)
    assert ra.shape == (RADAR.n_samples, 64)
    r, i = np.unravel_index(np.argmax(ra), ra.shape)
    assert r == 71
    assert i == 32 + k
    assert azimuth_sines()[i] == pytest.approx(u)


def test_tdm_compensation_moves_a_fast_target_back_to_its_angle() -> None:
    # at 5 m/s (Doppler bin ~11) the TDM phase 2 pi d k / (Nc Ntx) shifts the uncompensated
    # spectrum; with compensation the peak sits on the true index
    u = 2 * 6 / 64
    cube = _cube(5.0, u, 5.0)
    on = range_azimuth_map(cube, RADAR)
    off = range_azimuth_map(cube, RADAR, compensate_tdm=False)
    assert np.argmax(on.max(axis=0)) == 32 + 6
    assert np.argmax(off.max(axis=0)) != 32 + 6


def test_static_reflector_removed_and_power_is_parseval() -> None:
    cube = _cube(3.0, 0.3, 0.0)
    ra = range_azimuth_map(cube, RADAR)
    moving = range_azimuth_map(_cube(3.0, 0.3, 1.5), RADAR)
    assert ra.max() < 1e-6 * moving.max()
    # Parseval along the (zero-padded) array: sum_i |X_i|^2 = N sum_p |x_p|^2, per cell
    from core.processing.angle import azimuth_row, tdm_compensate

    ch, _ = azimuth_row(RADAR)
    c = _cube(3.0, 0.3, 1.5)
    n_d = c.shape[2]
    d = np.arange(n_d) - RADAR.n_loops // 2
    ph = tdm_compensate(np.ones((n_d, RADAR.n_virtual)), d, RADAR)[:, ch].T  # [ch, Doppler]
    x = c[ch] * ph[:, None, :]
    expected = 64 * np.sum(np.abs(x) ** 2, axis=(0, 2))
    np.testing.assert_allclose(moving.sum(axis=1), expected, rtol=1e-4, atol=1e-12)


def test_equals_the_zero_padded_fft_summed_over_doppler() -> None:
    # the definition, written out: FFT of the zero-padded row per (range, Doppler), |.|^2 summed
    rng = np.random.default_rng(3)
    shape = (RADAR.n_virtual, 40, RADAR.n_loops)
    cube = (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)).astype(np.complex64)
    from core.processing.angle import azimuth_row, tdm_compensate

    ch, pos = azimuth_row(RADAR)
    d = np.arange(RADAR.n_loops) - RADAR.n_loops // 2
    ph = tdm_compensate(np.ones((RADAR.n_loops, RADAR.n_virtual)), d, RADAR)[:, ch].T
    row = np.zeros((64, 40, RADAR.n_loops), dtype=np.complex128)
    row[pos] = cube[ch] * ph[:, None, :]
    spec = np.fft.fftshift(np.fft.fft(row, axis=0), axes=0)
    expected = (np.abs(spec) ** 2).sum(axis=2).T
    np.testing.assert_allclose(range_azimuth_map(cube, RADAR), expected, rtol=2e-5)

"""Exact baseband synthesis: noise level, signal formula, SNR after FFTs, range/Doppler bins."""

from __future__ import annotations

import numpy as np
import pytest

from core.config import SPEED_OF_LIGHT_MPS, RadarConfig
from core.processing import doppler_fft, range_fft
from core.simulation import (
    AntennaGain,
    Scatterers,
    received_power_w,
    receiver_voltage_scale,
    signal_amplitude_v,
    synthesize_baseband,
    synthesize_signal,
)

RADAR = RadarConfig()
IDEAL = AntennaGain.ideal(RADAR)
T_MID = 0.5 * RADAR.n_loops * RADAR.n_tx * RADAR.chirp_period_s


def one(pos, vel, rcs=-8.0, source=0) -> Scatterers:
    return Scatterers(
        position_m=np.atleast_2d(np.asarray(pos, dtype=float)),
        velocity_mps=np.atleast_2d(np.asarray(vel, dtype=float)),
        rcs_dbsm=np.array([rcs], dtype=float),
        source=np.array([source], dtype=np.int32),
    )


def reference_cube(radar: RadarConfig, sc: Scatterers, antenna: AntennaGain) -> np.ndarray:
    """The SPEC §2 formula evaluated element by element in complex128 (slow, obvious)."""
    out = np.zeros((radar.n_virtual, radar.n_loops, radar.n_samples), dtype=np.complex128)
    n = np.arange(radar.n_samples)
    for i in range(len(sc)):
        p, v = sc.position_m[i], sc.velocity_mps[i]
        r0 = np.linalg.norm(p)
        az, el = np.arctan2(p[0], p[1]), np.arctan2(p[2], np.hypot(p[0], p[1]))
        amp = signal_amplitude_v(radar, received_power_w(radar, r0, az, sc.rcs_dbsm[i], antenna))
        for m in range(radar.n_loops):
            for k in range(radar.n_tx):
                t = (m * radar.n_tx + k) * radar.chirp_period_s
                r = np.linalg.norm(p + v * t)
                fb = 2 * radar.slope_hz_per_s * r / SPEED_OF_LIGHT_MPS
                for rx in range(radar.n_rx):
                    ch = k * radar.n_rx + rx
                    ang = np.pi * (
                        radar.azimuth_positions[ch] * np.sin(az) * np.cos(el)
                        + radar.elevation_positions[ch] * np.sin(el)
                    )
                    phase = 2 * np.pi * fb * n / radar.sample_rate_hz + 4 * np.pi * r / (
                        radar.wavelength_m
                    )
                    out[ch, m] += amp * np.exp(1j * (phase + ang))
    return out


@pytest.mark.parametrize("n_samples", [256, 101])
def test_signal_matches_spec_formula(n_samples: int) -> None:
    # 101 samples: not a multiple of the kernel's 8 interleaved recurrences (the tail path)
    import dataclasses

    radar = dataclasses.replace(RADAR, n_samples=n_samples)
    sc = Scatterers(
        position_m=np.array([[1.5, 4.0, 0.7], [-2.0, 6.5, 0.0]]),
        velocity_mps=np.array([[0.8, -1.3, 0.2], [5.0, 3.0, 0.0]]),
        rcs_dbsm=np.array([-8.0, 3.0]),
        source=np.array([0, -1], dtype=np.int32),
    )
    ant = AntennaGain.draw(radar, np.random.default_rng(0))
    sig, noise = synthesize_baseband(radar, sc, np.random.default_rng(0), antenna=ant, noise=False)
    assert sig.dtype == np.complex64 and sig.shape == (12, 32, n_samples)
    assert not noise.any()
    ref = reference_cube(radar, sc, ant)
    err = np.max(np.abs(sig - ref)) / np.max(np.abs(ref))
    assert err < 2e-5


def test_noise_power_per_sample() -> None:
    _, n = synthesize_baseband(RADAR, Scatterers.empty(), np.random.default_rng(5), antenna=IDEAL)
    assert n.dtype == np.complex64 and n.shape == (12, 32, 256)
    p = np.mean(np.abs(n.astype(np.complex128)) ** 2)
    # input-referred: E|n|^2 / (R 10^(Ge/20)) = k T F Be = -94.27 dBm
    assert 10 * np.log10(p / receiver_voltage_scale(RADAR) / 1e-3) == pytest.approx(-94.27, abs=0.1)
    # circular: equal real/imaginary variance, no pseudo-covariance, no correlation in time
    x = n.ravel().astype(np.complex128)
    assert np.var(x.real) / np.var(x.imag) == pytest.approx(1.0, abs=0.02)
    assert abs(np.mean(x * x)) / p < 0.01
    assert abs(np.mean(x[1:] * np.conj(x[:-1]))) / p < 0.01
    # Gaussian: |n|^2 exponential -> P(|n|^2 > 5 E|n|^2) = exp(-5)
    assert np.mean(np.abs(x) ** 2 > 5 * p) == pytest.approx(np.exp(-5), rel=0.1)


def test_signal_and_noise_differ_by_seed_only_in_noise() -> None:
    sc = one([0.5, 3.0, 0.0], [0.0, 1.0, 0.0])
    s1, n1 = synthesize_baseband(RADAR, sc, np.random.default_rng(1), antenna=IDEAL)
    s2, n2 = synthesize_baseband(RADAR, sc, np.random.default_rng(1), antenna=IDEAL)
    s3, n3 = synthesize_baseband(RADAR, sc, np.random.default_rng(2), antenna=IDEAL)
    np.testing.assert_array_equal(n1, n2)
    np.testing.assert_array_equal(s1, s3)
    assert not np.array_equal(n1, n3)


@pytest.mark.parametrize(("range_m", "expected_db"), [(1.0, 82.4), (5.0, 54.4), (10.0, 42.4)])
def test_snr_after_both_ffts_rectangular(range_m: float, expected_db: float) -> None:
    """On-bin target, rectangular windows: per-channel SNR 82.4 / 54.4 / 42.4 dB."""
    res, vres = RADAR.range_resolution_m, RADAR.velocity_resolution_mps
    k = round(range_m / res)
    d = 3
    v = d * vres  # on a Doppler bin
    # radial motion with the range on bin k at the middle of the frame
    sc = one([0.0, k * res - v * T_MID, 0.0], [0.0, v, 0.0])
    sig, noise = synthesize_baseband(RADAR, sc, np.random.default_rng(11), antenna=IDEAL)
    S = doppler_fft(range_fft(sig, "rect"), "rect")
    N = doppler_fft(range_fft(noise, "rect"), "rect")
    j = d + RADAR.n_loops // 2
    peak = np.abs(S[:, k, j].astype(np.complex128)) ** 2  # per channel
    noise_cell = np.mean(np.abs(N.astype(np.complex128)) ** 2)
    snr_db = 10 * np.log10(peak / noise_cell)
    assert np.all(np.abs(snr_db - expected_db) < 0.5), snr_db
    # the signal lands in exactly this cell: the highest of the map
    rd = np.sum(np.abs(S) ** 2, axis=0)
    assert np.unravel_index(np.argmax(rd), rd.shape) == (k, j)


def test_scatterers_validate_shapes_and_values() -> None:
    from core.errors import InputError

    with pytest.raises(InputError, match="velocity_mps"):
        Scatterers(
            position_m=np.ones((2, 3)),
            velocity_mps=np.ones((1, 3)),
            rcs_dbsm=np.zeros(2),
            source=np.zeros(2, dtype=np.int32),
        )
    with pytest.raises(InputError, match="rcs_dbsm must be finite"):
        one([1.0, 2.0, 0.0], [0.0, 0.0, 0.0], rcs=np.nan)
    with pytest.raises(InputError, match="range 0"):
        one([0.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    sc = one([3.0, 4.0, 0.0], [0.0, 0.0, 0.0])
    assert sc.range_m[0] == pytest.approx(5.0) and sc.is_planar
    assert sc.radial_velocity_mps[0] == 0.0


def test_only_visible_scatterers_are_synthesised() -> None:
    """Behind the radar or beyond the maximum range (where the beat frequency would alias to
    a short range) nothing is received; in front and in range everything is."""
    inside = one([1.0, 5.0, 0.0], [0.0, 1.0, 0.0])
    far = one([0.0, RADAR.max_range_m + 6.0, 0.0], [0.0, 1.0, 0.0], rcs=30.0)
    behind = one([0.0, -3.0, 0.0], [0.0, 1.0, 0.0], rcs=30.0)
    both = Scatterers.concatenate([inside, far, behind])
    np.testing.assert_array_equal(
        synthesize_signal(RADAR, both, IDEAL), synthesize_signal(RADAR, inside, IDEAL)
    )
    assert not synthesize_signal(RADAR, far, IDEAL).any()

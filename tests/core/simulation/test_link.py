"""Antenna gain eq. (1), radar equation (4), receiver eqs. (2)-(3), RCS eq. (5), SNR budget."""

from __future__ import annotations

import numpy as np
import pytest

from core.config import CfarSettings, ProcessingSettings, RadarConfig
from core.simulation import (
    AntennaGain,
    draw_person_rcs_dbsm,
    noise_power_v2,
    post_processing_snr_db,
    rcs_for_snr_db,
    received_power_w,
    receiver_voltage_scale,
    signal_amplitude_v,
)

RADAR = RadarConfig()
IDEAL = AntennaGain.ideal(RADAR)
RECT = ProcessingSettings(range_window="rect", doppler_window="rect")


def dbm(p_w):
    return 10 * np.log10(np.asarray(p_w) / 1e-3)


def test_received_power_at_one_metre() -> None:
    # Pr = Pt Gt Gr lambda^2 sigma / ((4 pi)^3 R^4): -51.00 dBm for -8 dBsm at 1 m, G = 12 dB
    assert dbm(received_power_w(RADAR, 1.0, 0.0, -8.0, IDEAL)) == pytest.approx(-51.00, abs=0.02)
    # R^-4 law and linear in sigma
    p1 = received_power_w(RADAR, np.array([1.0, 2.0]), 0.0, np.array([-8.0, 2.0]), IDEAL)
    assert p1[0] / p1[1] == pytest.approx(16 / 10, rel=1e-12)


def test_receiver_voltages_match_paper_equations() -> None:
    ps = 1e-8
    # Vspp = sqrt(8 Ps R 10^(Ge/20)); amplitude = Vspp / (2 sqrt 2)
    vspp = np.sqrt(8 * ps * 50.0 * 10 ** (36 / 20))
    assert signal_amplitude_v(RADAR, ps) == pytest.approx(vspp / (2 * np.sqrt(2)), rel=1e-12)
    # E|n|^2 = Vnpp^2 / 8 with Vnpp = sqrt(8 k T F Be R 10^(Ge/20)); referred to the input
    # this is the noise power per sample, -94.27 dBm
    assert dbm(noise_power_v2(RADAR) / receiver_voltage_scale(RADAR)) == pytest.approx(
        -94.27, abs=0.01
    )
    # SNR per sample = Ps / (k T F Be): 43.27 dB for the 1 m target
    snr = signal_amplitude_v(RADAR, received_power_w(RADAR, 1.0, 0.0, -8.0, IDEAL)) ** 2 / (
        noise_power_v2(RADAR)
    )
    assert 10 * np.log10(snr) == pytest.approx(43.27, abs=0.02)


def test_post_processing_snr_budget() -> None:
    snr = post_processing_snr_db(RADAR, np.array([1.0, 5.0, 10.0]), 0.0, -8.0, IDEAL, RECT)
    np.testing.assert_allclose(snr, [82.4, 54.4, 42.4], atol=0.05)
    hann = post_processing_snr_db(RADAR, 5.0, 0.0, -8.0, IDEAL, ProcessingSettings())
    assert snr[1] - hann == pytest.approx(3.52, abs=0.01)


def test_rcs_for_snr_inverts_snr() -> None:
    rng = np.random.default_rng(1)
    r = rng.uniform(0.5, 10, 50)
    az = rng.uniform(-1, 1, 50)
    target = rng.uniform(15, 30, 50)
    ant = AntennaGain.draw(RADAR, rng)
    rcs = rcs_for_snr_db(RADAR, r, az, target, ant)
    np.testing.assert_allclose(post_processing_snr_db(RADAR, r, az, rcs, ant), target, atol=1e-9)
    # an unrelated CFAR setting does not change the budget
    s2 = ProcessingSettings(range_cfar=CfarSettings(pfa=1e-6))
    np.testing.assert_allclose(rcs_for_snr_db(RADAR, r, az, target, ant, s2), rcs, atol=1e-12)


def test_antenna_gain_realisation() -> None:
    a = AntennaGain.draw(RADAR, np.random.default_rng(7))
    b = AntennaGain.draw(RADAR, np.random.default_rng(7))
    c = AntennaGain.draw(RADAR, np.random.default_rng(8))
    np.testing.assert_array_equal(a.table_db, b.table_db)
    assert not np.array_equal(a.table_db, c.table_db)
    # Gt = Gmax + G - max G: the peak is Gmax
    assert a.table_db.max() == pytest.approx(12.0)
    # residual around the deterministic shape has the variance of eq. (1): 0.09 dB^2
    shape = 20 * np.log10(np.cos(0.01309 * a.grid_deg) + 0.01)
    resid = a.table_db - shape
    assert np.var(resid - resid.mean()) == pytest.approx(0.09, rel=0.25)
    # shape: 20 log10((cos(0.01309 theta) + 0.01) / 1.01): -2.97 dB at 60 deg, -8.2 dB at 90 deg
    g = a.gain_db(np.radians([0.0, 60.0, -60.0, 90.0]))
    assert g[0] - g[1] == pytest.approx(2.97, abs=1.2)
    assert g[0] - g[3] == pytest.approx(8.20, abs=1.2)
    # interpolation between grid points
    assert a.gain_db(np.radians(10.5)) == pytest.approx(a.table_db[100:102].mean())
    assert np.all(IDEAL.gain_db(np.radians([-80, 0, 33.3])) == 12.0)


def test_person_rcs_draws_eq5() -> None:
    x = draw_person_rcs_dbsm(np.random.default_rng(3), 200_000)
    assert x.mean() == pytest.approx(-8.0, abs=0.05)
    assert x.var() == pytest.approx(16.0, rel=0.02)

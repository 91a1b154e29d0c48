"""TI's detection chains: Capon resolution, the static chain, the cfg lines that select them."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from core.config import (
    AOP_AZIMUTH_POSITIONS,
    AOP_ELEVATION_POSITIONS,
    ProcessingSettings,
    default_chain,
)
from core.errors import InputError
from core.formats.ti_cfg import read_ti_cfg, read_ti_chain
from core.processing.capon import (
    capon_spectrum,
    capon_spectrum_lags,
    covariance_and_mean,
    spatial_covariance,
    steering,
)
from core.processing.chains import angle_grid
from core.processing.spectrum import remove_static_clutter
from core.simulation.antenna import AntennaGain
from core.simulation.chain_frame import simulate_frame_chain
from core.simulation.scatterers import Scatterers

RADAR_DIR = Path(__file__).resolve().parents[3] / "resources" / "radar"


def _one(pos, vel, rcs=-8.0, source=0) -> Scatterers:
    return Scatterers(
        position_m=np.atleast_2d(np.asarray(pos, dtype=float)),
        velocity_mps=np.atleast_2d(np.asarray(vel, dtype=float)),
        rcs_dbsm=np.array([rcs]),
        source=np.array([source]),
    )


# ---- Capon ---------------------------------------------------------------------------------------
def _snapshots(u0: float, snr_db: float, n_ch: int = 8, k: int = 96, seed: int = 0):
    rng = np.random.default_rng(seed)
    s0 = np.exp(1j * np.pi * u0 * np.arange(n_ch))
    amp = 10 ** (snr_db / 20)
    sig = amp * np.exp(2j * np.pi * rng.random(k))  # random phase per snapshot
    noise = (rng.standard_normal((n_ch, k)) + 1j * rng.standard_normal((n_ch, k))) / np.sqrt(2)
    return (s0[:, None] * sig[None, :] + noise)[:, :, None]  # [ch, snapshot, 1 range bin]


def _half_power_width(p: np.ndarray, u: np.ndarray) -> float:
    i = int(np.argmax(p))
    half = p[i] / 2
    lo = i
    while lo > 0 and p[lo] > half:
        lo -= 1
    hi = i
    while hi < len(p) - 1 and p[hi] > half:
        hi += 1
    return float(u[hi] - u[lo])


def test_capon_peaks_at_the_true_angle_with_the_predicted_resolution():
    """One source on an 8-element lambda/2 array: Capon peaks at it; its half-power width is
    what the MVDR formula predicts for that SNR, and much narrower than the array's own beam."""
    u = np.linspace(-0.99, 0.99, 8001)
    s = steering(np.arange(8), np.zeros(8), u, np.zeros(len(u)))
    for u0 in (-0.5, 0.0, 0.3071):
        cov = spatial_covariance(_snapshots(u0, 20.0))
        p = capon_spectrum(cov, s, 1e-3)[0]
        assert abs(u[np.argmax(p)] - u0) < 0.01
    # the resolution the array predicts: R = p s0 s0^H + I (no estimation noise), the Capon
    # spectrum 1 / (s^H R^-1 s), R^-1 = I - p s0 s0^H / (1 + N p): with B(u) = |s^H s0|^2,
    # 1/P = N - p B / (1 + N p), half power where 1/P = 2 / P(u0)
    n, snr = 8, 100.0
    s0 = np.exp(1j * np.pi * 0.2 * np.arange(n))
    r_exact = snr * np.outer(s0, s0.conj()) + np.eye(n)
    p_exact = capon_spectrum(r_exact[None], s, 0.0)[0]
    b = np.abs(s.conj() @ s0) ** 2
    p_formula = 1.0 / (n - snr * b / (1 + n * snr))
    assert np.allclose(p_exact, p_formula, rtol=1e-9)
    w_capon = _half_power_width(p_exact, u)
    w_bartlett = _half_power_width(b, u)
    # Bartlett's (the array's beam) -3 dB width for 8 elements at lambda/2: 0.111 in u
    assert w_bartlett == pytest.approx(2 * 0.1107, abs=0.002)
    # solving N - p B/(1+Np) = 2/P(u0) for B gives the Capon -3 dB edge; far narrower
    b_half = (n - 2 / p_formula.max()) * (1 + n * snr) / snr
    edge = u[np.argmin(np.abs(np.where(u > 0.2, b, np.inf) - b_half))]
    assert w_capon == pytest.approx(2 * (edge - 0.2), abs=0.002)
    assert w_capon < 0.3 * w_bartlett


def test_capon_by_lags_equals_the_quadratic_forms():
    x = _snapshots(0.25, 15.0, k=64)
    x = np.concatenate([x, _snapshots(-0.4, 10.0, k=64, seed=1)], axis=2)
    u = np.sin(angle_grid(70.0, 0.75))
    cov = spatial_covariance(x)
    ref = capon_spectrum(cov, steering(np.arange(8), np.zeros(8), u, np.zeros(len(u))), 1e-3)
    assert np.allclose(capon_spectrum_lags(cov, tuple(range(8)), u, 1e-3), ref, rtol=1e-9)


def test_covariance_and_mean_is_the_clutter_removed_covariance():
    rng = np.random.default_rng(3)
    x = (rng.standard_normal((12, 32, 5)) + 1j * rng.standard_normal((12, 32, 5))).astype(
        np.complex64
    )
    x += 3.0  # a static part
    cov, mean = covariance_and_mean(x)
    ref = spatial_covariance(remove_static_clutter(x).astype(np.complex128))
    assert np.allclose(cov, ref, atol=1e-5)
    assert np.allclose(mean, x.mean(axis=1).T, atol=1e-6)


# ---- the chains on simulated frames ------------------------------------------------------------
def _chain(name: str):
    path = RADAR_DIR / f"{name}.cfg"
    return read_ti_cfg(path), read_ti_chain(path)


def _frame(radar, chain, scatterers, seed=1):
    settings = ProcessingSettings(max_range_m=7.0)
    out = simulate_frame_chain(
        radar,
        scatterers,
        np.random.default_rng(seed),
        antenna=AntennaGain.ideal(radar),
        chain=chain,
        settings=settings,
        elevation=True,
    )
    return out.point_cloud


def _static_enabled(chain):
    pc = dataclasses.replace(chain.people_counting, static_enabled=True)
    return dataclasses.replace(chain, people_counting=pc)


def test_people_counting_moving_person_gives_dynamic_points_at_its_place():
    radar, chain = _chain("people_counting_isk")
    pos = np.array([1.0, 3.0, 0.3])
    pc = _frame(radar, chain, _one(pos, [0.0, -0.5, 0.0]))
    mine = pc.source == 0
    assert mine.sum() >= 1
    r = np.linalg.norm(pos)
    vr = -0.5 * pos[1] / r
    assert np.all(np.abs(pc.range_m[mine] - r) < 2 * radar.range_resolution_m)
    assert np.all(np.abs(pc.radial_velocity_mps[mine] - vr) < radar.velocity_resolution_mps)
    # azimuth within 1.5 deg, elevation within 1 deg (TDM phase across slots is not removed
    # before the Capon map, as in TI's chain: a small azimuth bias for a moving target)
    best = np.argmax(np.where(mine, pc.snr_db, -np.inf))
    az, el = np.degrees(pc.azimuth_rad[best]), np.degrees(pc.elevation_rad[best])
    assert az == pytest.approx(np.degrees(np.arctan2(1, 3)), abs=1.5)
    assert el == pytest.approx(np.degrees(np.arcsin(0.3 / r)), abs=1)


def test_a_static_reflector_gives_a_point_only_in_the_static_chain():
    radar, chain = _chain("people_counting_isk")
    chair = _one([-1.0, 4.0, -0.2], [0.0, 0.0, 0.0], rcs=0.0, source=-1)
    r = np.linalg.norm([-1.0, 4.0, -0.2])
    dynamic = _frame(radar, chain, chair)  # TI's file: static detection off
    assert not np.any(np.abs(dynamic.range_m - r) < 2 * radar.range_resolution_m)
    both = _frame(radar, _static_enabled(chain), chair)
    near = np.abs(both.range_m - r) < 2 * radar.range_resolution_m
    assert near.any()
    assert np.all(both.radial_velocity_mps[near] == 0.0)
    best = np.argmax(np.where(near, both.snr_db, -np.inf))
    assert np.degrees(both.azimuth_rad[best]) == pytest.approx(np.degrees(np.arctan2(-1, 4)), abs=3)


def test_a_breathing_person_is_static_only_while_its_chest_moves_slowly():
    """A still person: a torso that does not move and a chest moving slowly. Clutter removal
    leaves of the chest the part of its phase that changes within the frame's chirps
    (T = 25.7 ms): about (4 pi v T / lambda)^2 / 12 of its power. At 0.3 mm/s (shallow
    breathing, or any breath near its turning point) that is -45 dB: below the dynamic CFAR at
    5 m, and only the static chain sees the person. At 3 mm/s (2 mm at 0.25 Hz, mid-breath) it
    is -25 dB and the dynamic chain does see the chest (physics, not a defect; TI's firmware
    has a fine-motion mode for such people); at 5 cm/s certainly."""
    radar, chain = _chain("people_counting_isk")
    chain = _static_enabled(chain)
    torso = [0.3, 5.0, 0.0]
    chest = [0.3, 4.9, 0.1]

    def person(chest_speed):
        d = np.asarray(chest) / np.linalg.norm(chest)
        return Scatterers(
            position_m=np.array([torso, chest]),
            velocity_mps=np.array([[0.0, 0.0, 0.0], -chest_speed * d]),
            rcs_dbsm=np.array([-8.0, -14.0]),
            source=np.array([0, 0]),
        )

    for seed in range(3):
        pc = _frame(radar, chain, person(0.0003), seed=seed)
        near = np.abs(pc.range_m - 5.0) < 3 * radar.range_resolution_m
        assert near.any()
        assert np.all(pc.radial_velocity_mps[near] == 0.0), "dynamic point on a still person"
    for speed in (0.0031, 0.05):
        moving = _frame(radar, chain, person(speed))
        near = np.abs(moving.range_m - 4.9) < 3 * radar.range_resolution_m
        assert np.any(moving.radial_velocity_mps[near] != 0.0)


def test_oob_chain_points_with_height_and_multi_object():
    radar, chain = _chain("oob_isk")
    pos = np.array([0.8, 3.0, 0.5])
    pc = _frame(radar, chain, _one(pos, [0.0, -0.4, 0.0]))
    mine = pc.source == 0
    assert mine.any()
    best = np.argmax(np.where(mine, pc.snr_db, -np.inf))
    assert pc.z_m[best] == pytest.approx(0.5, abs=0.15)
    assert pc.x_m[best] == pytest.approx(0.8, abs=0.15)
    # two reflectors in the same range and Doppler cell, 40 degrees apart: two points
    r = 3.0
    two = Scatterers(
        position_m=np.array(
            [[r * np.sin(a), r * np.cos(a), 0.0] for a in np.radians([-20.0, 20.0])]
        ),
        velocity_mps=np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]),
        rcs_dbsm=np.array([-8.0, -9.0]),
        source=np.array([0, 1]),
    )
    pc2 = _frame(radar, chain, two)
    at_r = np.abs(pc2.range_m - r) < radar.range_resolution_m
    az = np.sort(np.degrees(pc2.azimuth_rad[at_r]))
    assert np.any(np.abs(az + 20) < 3) and np.any(np.abs(az - 20) < 3)
    single = dataclasses.replace(chain.oob, multi_object_threshold=None)
    off = dataclasses.replace(chain, oob=single)
    pc3 = _frame(radar, off, two)
    assert np.sum(np.abs(pc3.range_m - r) < radar.range_resolution_m) < at_r.sum()


# ---- the cfg lines -------------------------------------------------------------------------------
def test_shipped_cfgs_select_their_chains_and_layouts():
    radar, chain = _chain("oob_isk")
    assert chain.name == "oob" and chain.oob.range_cfar.method == "caso"
    assert chain.oob.range_cfar.threshold_db == 15.0 and chain.oob.doppler_cfar.cyclic
    assert chain.oob.max_range_m == 8.92 and chain.oob.multi_object_threshold == 0.5
    assert "calibDcRangeSig (line 24)" in chain.ignored
    radar, chain = _chain("people_counting_aop")
    assert chain.name == "people-counting"
    assert radar.azimuth_positions == AOP_AZIMUTH_POSITIONS
    assert radar.elevation_positions == AOP_ELEVATION_POSITIONS
    assert chain.people_counting.dynamic_cfar.range_threshold_db == 5.0
    assert not chain.people_counting.static_enabled
    assert any(t.startswith("antPhaseRot") for t in chain.ignored)
    # TI's ISK geometry lines give the layout RadarTune always used for the ISK
    radar_isk, _ = _chain("people_counting_isk")
    assert radar_isk.azimuth_positions == read_ti_cfg(RADAR_DIR / "paper.cfg").azimuth_positions
    assert radar_isk.elevation_positions == (0, 0, 0, 0, 1, 1, 1, 1, 0, 0, 0, 0)
    # 394758 = 0x060606: 6 dB back-off on each TX
    assert radar_isk.tx_power_dbm == pytest.approx(6.0)
    assert read_ti_chain(RADAR_DIR / "paper.cfg").name == "paper"


def test_default_chains_are_the_shipped_cfgs():
    oob = read_ti_chain(RADAR_DIR / "oob_isk.cfg").oob
    default = default_chain("oob").oob
    assert (default.range_cfar, default.doppler_cfar) == (oob.range_cfar, oob.doppler_cfar)
    assert default.multi_object_threshold == oob.multi_object_threshold
    pc = read_ti_chain(RADAR_DIR / "people_counting_isk_static.cfg").people_counting
    assert default_chain("people-counting").people_counting == pc
    with pytest.raises(InputError, match="chain must be one of"):
        default_chain("pplcount")


@pytest.mark.parametrize(
    ("replace", "message"),
    [
        (
            (
                "dynamicRACfarCfg -1 4 4 2 2 8 12 4 8 5.00 8.00 0.40 1 1",
                "dynamicRACfarCfg -1 4 4 2",
            ),
            "dynamicRACfarCfg needs 14 fields, got 4 (field 5 'cfarDiscardRightAngle' missing)",
        ),
        (
            ("dynamicRangeAngleCfg -1 0.75", "dynamicRangeAngleCfg -1 0.7x"),
            "dynamicRangeAngleCfg field 2 'angleSearchStep': expected a number, got '0.7x'",
        ),
        (
            ("fovCfg -1 70.0 20.0", "fovCfg -1 170.0 20.0"),
            "fovCfg field 2 'azimuthFovDeg': must be in [1, 90]",
        ),
        (
            (
                "staticRangeAngleCfg -1 0 8 8",
                "staticRangeAngleCfg -1 0 0 8\ncfarCfg -1 0 2 8 4 3 0 15 1",
            ),
            "one chain per file",
        ),
    ],
)
def test_bad_chain_lines_name_file_line_and_field(tmp_path, replace, message):
    text = (RADAR_DIR / "people_counting_isk.cfg").read_text()
    assert replace[0] in text
    bad = tmp_path / "bad.cfg"
    bad.write_text(text.replace(replace[0], replace[1]))
    with pytest.raises(InputError) as err:
        read_ti_chain(bad)
    assert message in str(err.value)
    assert "bad.cfg" in str(err.value)

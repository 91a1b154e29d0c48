"""The whole exact chain: bins, interpolation, aliasing, angles, TDM, static clutter removal.

Strong targets (SNR 50-60 dB) also produce weak detections on their window sidelobes and, after
static clutter removal, at zero Doppler (the removed mean of an off-bin tone); those carry the
label -2. The checks below look at the strongest detection.
"""

from __future__ import annotations

import numpy as np
import pytest

from core.config import ProcessingSettings, RadarConfig
from core.pointcloud import SOURCE_CLUTTER, SOURCE_OTHER
from core.processing import (
    build_point_cloud,
    doppler_fft,
    label_sources,
    range_doppler_map,
    range_fft,
    remove_static_clutter,
    two_stage_cfar,
)
from core.simulation import AntennaGain, Scatterers, simulate_frame, synthesize_signal

RADAR = RadarConfig()
IDEAL = AntennaGain.ideal(RADAR)
T_MID = 0.5 * RADAR.n_loops * RADAR.n_tx * RADAR.chirp_period_s


def scat(pos, vel, rcs, source) -> Scatterers:
    return Scatterers(
        position_m=np.asarray(pos, dtype=float).reshape(-1, 3),
        velocity_mps=np.asarray(vel, dtype=float).reshape(-1, 3),
        rcs_dbsm=np.asarray(rcs, dtype=float).reshape(-1),
        source=np.asarray(source, dtype=np.int32).reshape(-1),
    )


def radial(range_m: float, az_deg: float, vr: float, rcs=-8.0, source=0, el_deg=0.0):
    """A scatterer moving radially, at ``range_m`` in the middle of the frame."""
    az, el = np.radians(az_deg), np.radians(el_deg)
    u = np.array([np.sin(az) * np.cos(el), np.cos(az) * np.cos(el), np.sin(el)])
    return scat((range_m - vr * T_MID) * u, vr * u, rcs, source)


def test_four_metre_target_range_bin_and_interpolation() -> None:
    out = simulate_frame(RADAR, radial(4.00, 10.0, 1.0), np.random.default_rng(1), antenna=IDEAL)
    pc = out.point_cloud
    i = np.argmax(pc.snr_db)
    assert out.detections[i, 0] == 71
    assert pc.range_m[i] == pytest.approx(4.00, abs=0.01)
    assert pc.source[i] == 0
    assert pc.radial_velocity_mps[i] == pytest.approx(1.0, abs=0.1)
    assert pc.snr_db[i] > 40
    assert out.rd_map_db is None


def test_nine_metres_per_second_aliases_to_bin_minus_12() -> None:
    out = simulate_frame(
        RADAR, radial(5.0, 0.0, 9.0), np.random.default_rng(2), antenna=IDEAL, keep_rd_map=True
    )
    assert out.rd_map_db.shape == (256, 32)
    pc = out.point_cloud
    i = np.argmax(pc.snr_db)
    assert out.detections[i, 1] - RADAR.n_loops // 2 == -12
    # the map peaks there too
    assert np.unravel_index(np.argmax(out.rd_map_db), (256, 32))[1] == 16 - 12
    # +9 m/s appears near 9 - 2 v_max = -5.48 m/s, and is still labelled as the person. The
    # chirp's range phase moves with the beat frequency (range migration), so the Doppler
    # scale is that of the mid-sampling frequency Fc + S (N-1) / (2 Fs): 2.2 % higher here
    scale = 1 + RADAR.slope_hz_per_s * (RADAR.n_samples - 1) / (
        2 * RADAR.sample_rate_hz * RADAR.start_frequency_hz
    )
    expected = 9.0 * scale - 2 * RADAR.max_velocity_mps
    assert pc.radial_velocity_mps[i] == pytest.approx(expected, abs=0.05)
    assert abs(pc.radial_velocity_mps[i] - (9.0 - 2 * RADAR.max_velocity_mps)) < 0.5
    assert pc.source[i] == 0


@pytest.mark.parametrize("az_deg", [-50.0, -33.0, -12.5, 0.0, 7.0, 24.0, 41.0, 50.0])
def test_azimuth_within_one_degree(az_deg: float) -> None:
    sc = radial(6.0, az_deg, -1.3, rcs=5.0)
    out = simulate_frame(RADAR, sc, np.random.default_rng(3), antenna=IDEAL)
    pc = out.point_cloud
    i = np.argmax(pc.snr_db)
    assert pc.source[i] == 0
    assert np.degrees(pc.azimuth_rad[i]) == pytest.approx(az_deg, abs=1.0)
    assert pc.elevation_rad[i] == 0.0 and pc.z_m[i] == 0.0
    # Cartesian point consistent with range and azimuth
    assert np.hypot(pc.x_m[i], pc.y_m[i]) == pytest.approx(pc.range_m[i])
    assert np.degrees(np.arctan2(pc.x_m[i], pc.y_m[i])) == pytest.approx(az_deg, abs=1.0)


def _angle_error_deg(compensate: bool, vr: float, az_deg: float) -> float:
    sc = radial(5.0, az_deg, vr, rcs=5.0)
    cube = synthesize_signal(RADAR, sc, IDEAL)
    s = ProcessingSettings()
    dc = doppler_fft(remove_static_clutter(range_fft(cube)))
    rd = range_doppler_map(dc)
    det = two_stage_cfar(rd + 1e-30, RADAR, s)
    pc = build_point_cloud(dc, rd, det, RADAR, s, compensate_tdm=compensate)
    assert len(pc) >= 1
    best = np.argmax(pc.snr_db)
    return float(np.degrees(pc.azimuth_rad[best]) - az_deg)


def test_tdm_compensation_removes_bias_of_moving_target() -> None:
    for az_deg in (-20.0, 15.0):
        with_comp = _angle_error_deg(True, 5.0, az_deg)
        without = _angle_error_deg(False, 5.0, az_deg)
        assert abs(with_comp) < 0.5
        assert abs(without) > 3.0
    # a slow target is hardly biased even without it
    assert abs(_angle_error_deg(False, 0.5, 15.0)) < abs(_angle_error_deg(False, 5.0, 15.0))


def test_elevation_only_when_the_scene_needs_it() -> None:
    sc = radial(5.0, 20.0, 1.0, rcs=5.0, el_deg=12.0)
    out = simulate_frame(RADAR, sc, np.random.default_rng(4), antenna=IDEAL)
    pc = out.point_cloud
    i = np.argmax(pc.snr_db)
    assert np.degrees(pc.elevation_rad[i]) == pytest.approx(12.0, abs=1.0)
    assert np.degrees(pc.azimuth_rad[i]) == pytest.approx(20.0, abs=1.0)
    assert pc.z_m[i] == pytest.approx(5.0 * np.sin(np.radians(12.0)), abs=0.1)
    off = simulate_frame(RADAR, sc, np.random.default_rng(4), antenna=IDEAL, elevation=False)
    assert np.all(off.point_cloud.elevation_rad == 0.0)


def test_static_reflector_suppressed_person_kept() -> None:
    wall = scat([2.0, 6.0, 0.0], [0.0, 0.0, 0.0], 10.0, SOURCE_CLUTTER)
    person = radial(4.0, -15.0, 1.2, rcs=-8.0, source=0)
    both = Scatterers.concatenate([wall, person])
    cube = synthesize_signal(RADAR, both, IDEAL)
    rc = range_fft(cube)
    kept = range_doppler_map(doppler_fft(rc))
    removed = range_doppler_map(doppler_fft(remove_static_clutter(rc)))
    k_wall = round(np.hypot(2.0, 6.0) / RADAR.range_resolution_m)
    zero = RADAR.n_loops // 2
    wall_cells = (slice(k_wall - 1, k_wall + 2), slice(zero - 1, zero + 2))
    suppression_db = 10 * np.log10(kept[wall_cells].max() / removed[wall_cells].max())
    assert suppression_db > 60
    k_p = round(4.0 / RADAR.range_resolution_m)
    person_cells = (slice(k_p - 2, k_p + 3), slice(None))
    loss_db = 10 * np.log10(kept[person_cells].max() / removed[person_cells].max())
    assert abs(loss_db) < 0.5
    # with noise, through the whole chain: the person is detected, the wall is not
    out = simulate_frame(RADAR, both, np.random.default_rng(5), antenna=IDEAL)
    pc = out.point_cloud
    assert pc.source[np.argmax(pc.snr_db)] == 0
    assert SOURCE_CLUTTER not in pc.source
    near_wall = (np.abs(out.detections[:, 0] - k_wall) <= 1) & (
        np.abs(out.detections[:, 1] - zero) <= 1
    )
    assert not near_wall.any()


def test_clutter_and_noise_labels() -> None:
    # label_sources: nearest reflector within one cell; Doppler aliasing allowed
    vmax = RADAR.max_velocity_mps
    src = label_sources(
        np.array([3.0, 3.02, 7.0, 5.0]),
        np.array([1.0, -vmax + 0.1, 2.0, 1.0]),
        np.array([3.0, 3.0, 7.0]),
        np.array([1.2, vmax - 0.1, -2.0]),
        np.array([0, 1, SOURCE_CLUTTER]),
        RADAR,
    )
    assert src.tolist() == [0, 1, SOURCE_OTHER, SOURCE_OTHER]
    # a clutter reflector (moving) through the chain is labelled -1
    cl = radial(7.0, -30.0, -3.0, rcs=0.0, source=SOURCE_CLUTTER)
    out = simulate_frame(RADAR, cl, np.random.default_rng(6), antenna=IDEAL)
    pc = out.point_cloud
    assert pc.source[np.argmax(pc.snr_db)] == SOURCE_CLUTTER


def test_same_seed_same_frame_other_seed_other_noise() -> None:
    sc = Scatterers.concatenate([radial(3.0, 5.0, 0.8), radial(8.0, -40.0, -2.0, 3.0, -1)])
    a = simulate_frame(RADAR, sc, np.random.default_rng(9), antenna=IDEAL, keep_rd_map=True)
    b = simulate_frame(RADAR, sc, np.random.default_rng(9), antenna=IDEAL, keep_rd_map=True)
    c = simulate_frame(RADAR, sc, np.random.default_rng(10), antenna=IDEAL, keep_rd_map=True)
    np.testing.assert_array_equal(a.rd_map_db, b.rd_map_db)
    np.testing.assert_array_equal(a.point_cloud.range_m, b.point_cloud.range_m)
    assert not np.array_equal(a.rd_map_db, c.rd_map_db)
    assert len(a.point_cloud) == len(a.detections)


def test_fused_clutter_removal_equals_separate_stage() -> None:
    sc = Scatterers.concatenate(
        [scat([2.0, 6.0, 0.0], [0.0, 0.0, 0.0], 10.0, -1), radial(4.0, 10.0, 1.3)]
    )
    rc = range_fft(synthesize_signal(RADAR, sc, IDEAL))
    for name in ("hann", "rect", "blackman"):
        a = doppler_fft(remove_static_clutter(rc), name)
        b = doppler_fft(rc, name, remove_static=True)
        assert np.max(np.abs(a - b)) < 1e-5 * np.max(np.abs(a))


def test_truncated_map_gives_the_same_points() -> None:
    sc = Scatterers.concatenate([radial(3.0, 5.0, 0.8), radial(9.8, -40.0, -2.0, 3.0, -1)])
    a = simulate_frame(RADAR, sc, np.random.default_rng(12), antenna=IDEAL)
    b = simulate_frame(RADAR, sc, np.random.default_rng(12), antenna=IDEAL, keep_rd_map=True)
    np.testing.assert_array_equal(a.detections, b.detections)
    np.testing.assert_allclose(a.point_cloud.range_m, b.point_cloud.range_m)
    np.testing.assert_allclose(a.point_cloud.azimuth_rad, b.point_cloud.azimuth_rad)
    assert b.rd_map_db.shape == (256, 32)


@pytest.mark.parametrize("name", ["long_range", "high_velocity"])
def test_variant_radars_run_through_the_chain(name: str) -> None:
    from pathlib import Path

    from core.formats.ti_cfg import read_ti_cfg

    radar = read_ti_cfg(Path(__file__).resolve().parents[3] / "resources" / "radar" / f"{name}.cfg")
    antenna = AntennaGain.ideal(radar)
    t_mid = 0.5 * radar.n_loops * radar.n_tx * radar.chirp_period_s
    vr = 12.0 if name == "high_velocity" else -2.0  # 12 m/s is unambiguous only on this radar
    az = np.radians(-25.0)
    u = np.array([np.sin(az), np.cos(az), 0.0])
    sc = scat((6.0 - vr * t_mid) * u, vr * u, 5.0, 0)
    out = simulate_frame(radar, sc, np.random.default_rng(13), antenna=antenna, keep_rd_map=True)
    assert out.rd_map_db.shape == (radar.n_samples, radar.n_loops)
    pc = out.point_cloud
    i = np.argmax(pc.snr_db)
    assert pc.source[i] == 0
    assert pc.range_m[i] == pytest.approx(6.0, abs=radar.range_resolution_m / 2)
    assert np.degrees(pc.azimuth_rad[i]) == pytest.approx(-25.0, abs=1.0)
    assert pc.radial_velocity_mps[i] == pytest.approx(vr, rel=0.05)


def test_doppler_matrix_equals_windowed_fft() -> None:
    from core.processing import spectrum

    rng = np.random.default_rng(2)
    x = (rng.standard_normal((12, 32, 40)) + 1j * rng.standard_normal((12, 32, 40))).astype(
        np.complex64
    )
    for name in ("hann", "rect", "blackman"):
        for remove in (False, True):
            a = doppler_fft(x, name, remove_static=remove)
            # the FFT path, written out: window, FFT along loops, fftshift, minus the mean's part
            y = x - x.mean(axis=1, keepdims=True) if remove else x
            w = spectrum.window(name, 32)[None, :, None]
            b = np.fft.fftshift(np.fft.fft(y * w, axis=1), axes=1).transpose(0, 2, 1)
            assert np.max(np.abs(a - b)) < 1e-5 * np.max(np.abs(b))


def test_range_doppler_map_kernel_equals_plain_sum() -> None:
    rng = np.random.default_rng(4)
    y = (rng.standard_normal((12, 32, 50)) + 1j * rng.standard_normal((12, 32, 50))).astype(
        np.complex64
    )
    view = y.transpose(0, 2, 1)  # the layout doppler_fft returns
    ref = np.sum(np.abs(view.astype(np.complex128)) ** 2, axis=0)
    np.testing.assert_allclose(range_doppler_map(view), ref, rtol=1e-5)
    # any other layout takes the general path
    np.testing.assert_allclose(range_doppler_map(np.ascontiguousarray(view)), ref, rtol=1e-5)


def test_frame_adds_exactly_the_noise_of_synthesize_noise() -> None:
    # simulate_frame fuses noise and range window into one pass; it must equal the chain
    # written out from synthesize_signal + synthesize_noise with the same generator state
    from core.simulation import synthesize_noise

    sc = Scatterers.concatenate([radial(3.0, 5.0, 0.8), radial(7.5, -30.0, -2.0, 3.0, -1)])
    out = simulate_frame(RADAR, sc, np.random.default_rng(21), antenna=IDEAL, keep_rd_map=True)
    cube = synthesize_signal(RADAR, sc, IDEAL) + synthesize_noise(RADAR, np.random.default_rng(21))
    rd = range_doppler_map(doppler_fft(range_fft(cube), remove_static=True))
    ref_db = 10 * np.log10(rd)
    assert np.max(np.abs(out.rd_map_db - ref_db)) < 1e-3

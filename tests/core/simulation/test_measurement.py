"""The ``measurement`` level: tables from the chain's responses, SNR, Pd and spreads."""

from __future__ import annotations

import numpy as np
import pytest

from core.config import DEFAULT_PROCESSING, PAPER_RADAR
from core.errors import InputError
from core.pointcloud import POINT_FIELDS, SOURCE_OTHER
from core.simulation import (
    FIDELITY_LEVELS,
    AntennaGain,
    FrameOutput,
    Scatterers,
    post_processing_snr_db,
    simulate_frame,
)
from core.simulation.false_alarm_pool import _measure_false_alarms, chain_false_alarms
from core.simulation.measurement import (
    _constants,
    chain_tables,
    frame_seed,
    simulate_frame_measurement,
    simulate_frames_measurement,
)
from core.simulation.rng_kernels import (
    ss_gamma as _gamma,
)
from core.simulation.rng_kernels import (
    ss_normal as _normal,
)
from core.simulation.rng_kernels import (
    ss_poisson as _poisson,
)
from core.simulation.rng_kernels import (
    ss_randint as _randint,
)
from core.simulation.rng_kernels import (
    ss_uniform as _uniform,
)

RADAR = PAPER_RADAR
ANT = AntennaGain.ideal(RADAR)
T_MID = 0.5 * RADAR.n_loops * RADAR.n_tx * RADAR.chirp_period_s


def person(range_m: float, az_deg: float, vr_mps: float, rcs_dbsm: float) -> Scatterers:
    """A reflector at ``range_m``/``az_deg`` at mid-frame, moving radially at ``vr_mps``."""
    a = np.radians(az_deg)
    u = np.array([np.sin(a), np.cos(a), 0.0])
    return Scatterers(
        position_m=((range_m - vr_mps * T_MID) * u)[None, :],
        velocity_mps=(vr_mps * u)[None, :],
        rcs_dbsm=np.array([rcs_dbsm]),
        source=np.array([0], dtype=np.int32),
    )


def test_tables_hann_values() -> None:
    """Periodic Hann: on-bin |R|^2 = (N/2)^2, half-bin straddle loss -1.42 dB, 0-Doppler notch."""
    tab = chain_tables(RADAR, DEFAULT_PROCESSING)
    n = RADAR.n_samples
    assert tab.range_gain[0] == pytest.approx((n / 2) ** 2, rel=1e-6)
    mid = len(tab.range_frac) // 2
    assert tab.range_frac[mid] == 0.5
    assert 10 * np.log10(tab.range_gain[mid] / tab.range_gain[0]) == pytest.approx(-1.42, abs=0.01)
    assert tab.range_est[0] == pytest.approx(0.0, abs=1e-9)
    # Doppler: nu = +5 bins: |D|^2 = (M/2)^2, refined estimate 5, peak cell index 16 + 5
    j = np.argmin(np.abs(tab.doppler_nu - 5.0))
    assert tab.doppler_gain[j] == pytest.approx((RADAR.n_loops / 2) ** 2, rel=1e-6)
    assert tab.doppler_est[j] == pytest.approx(5.0, abs=1e-9)
    assert tab.doppler_index[j] == RADAR.n_loops // 2 + 5
    # static clutter removal: nothing left at exactly zero Doppler
    j0 = np.argmin(np.abs(tab.doppler_nu))
    assert tab.doppler_gain[j0] < 1e-20
    # azimuth estimator: unbiased on the FFT grid, small bias between grid points
    assert np.max(np.abs(tab.u_est - tab.u_grid)[np.abs(tab.u_grid) < 0.9]) < 0.01


def test_noiseless_snr_equals_link_budget_on_bin() -> None:
    """A reflector centred in its range and Doppler cells reports the link budget's SNR."""
    scale = _constants(RADAR, DEFAULT_PROCESSING)["doppler_scale"]
    for k, nu, rcs in ((71, 3, -8.0), (150, -7, 0.0)):
        r = k * RADAR.range_resolution_m
        vr = nu * RADAR.velocity_resolution_mps / scale
        sc = person(r, 0.0, vr, rcs)
        out = simulate_frame_measurement(RADAR, sc, None, antenna=ANT, noise=False)
        # the non-coherent sum over L channels: L rho over the per-cell noise
        expected = post_processing_snr_db(RADAR, np.array([r]), np.zeros(1), rcs, ANT)[0]
        assert out.point_cloud.snr_db[0] - 10 * np.log10(12) == pytest.approx(expected, abs=0.02)
        assert out.point_cloud.range_m[0] == pytest.approx(r, abs=1e-6)
        assert out.point_cloud.radial_velocity_mps[0] == pytest.approx(
            nu * RADAR.velocity_resolution_mps, abs=1e-6
        )
        np.testing.assert_array_equal(out.detections, [[k, 16 + nu]])


def test_spreads_follow_cramer_rao() -> None:
    """Azimuth and range spreads at a fixed SNR: the documented Cramer-Rao formulas."""
    scale = _constants(RADAR, DEFAULT_PROCESSING)["doppler_scale"]
    k, nu = 160, 4
    r = k * RADAR.range_resolution_m
    sc = person(r, 0.0, nu * RADAR.velocity_resolution_mps / scale, -20.0)
    rng = np.random.default_rng(2)
    rho = 10 ** (post_processing_snr_db(RADAR, np.array([r]), np.zeros(1), -20.0, ANT)[0] / 10)
    az, rr = [], []
    for _ in range(1500):
        pc = simulate_frame_measurement(RADAR, sc, rng, antenna=ANT).point_cloud
        i = np.flatnonzero(pc.source == 0)
        if i.size:
            az.append(np.sin(pc.azimuth_rad[i[0]]))
            rr.append(pc.range_m[i[0]] / RADAR.range_resolution_m)
    assert len(az) > 1400
    # var(u) = 6 / (pi^2 rho M (M^2 - 1)), M = 8;  var(bin) = 6 / (4 pi^2 L rho)
    sd_u = np.sqrt(6 / (np.pi**2 * rho * 8 * 63))
    sd_bin = np.sqrt(6 / (4 * np.pi**2 * 12 * rho))
    assert np.std(az) == pytest.approx(sd_u, rel=0.08)
    assert np.std(rr) == pytest.approx(sd_bin, rel=0.08)


def test_detection_probability_and_snr_match_exact_chain() -> None:
    """Near the CFAR threshold Pd and the reported SNR agree with the exact chain."""
    sc = person(9.0, 15.0, 1.1, -44.0)
    n = 60
    pd, snr = {}, {}
    for name in ("exact", "measurement"):
        rng = np.random.default_rng(11)
        hits, s = 0, []
        for _ in range(n):
            pc = FIDELITY_LEVELS[name](RADAR, sc, rng, antenna=ANT).point_cloud
            m = pc.source == 0
            hits += bool(m.any())
            s += list(pc.snr_db[m])
        pd[name], snr[name] = hits / n, np.median(s)
    assert 0.15 < pd["exact"] < 0.95  # the test sits on the slope of the Pd curve
    assert abs(pd["measurement"] - pd["exact"]) < 0.25
    assert abs(snr["measurement"] - snr["exact"]) < 1.0


@pytest.mark.parametrize("level", ["exact", "fast", "measurement"])
def test_levels_share_the_signature_and_output(level) -> None:
    sc = person(4.0, -10.0, 1.0, -8.0)
    out = FIDELITY_LEVELS[level](
        RADAR,
        sc,
        np.random.default_rng(0),
        antenna=ANT,
        settings=DEFAULT_PROCESSING,
        keep_rd_map=True,
        elevation=None,
    )
    assert isinstance(out, FrameOutput)
    assert out.rd_map_db.shape == (RADAR.n_samples, RADAR.n_loops)
    assert out.detections.shape == (len(out.point_cloud), 2)
    i = np.flatnonzero(out.point_cloud.source == 0)
    assert i.size >= 1
    assert out.point_cloud.range_m[i[0]] == pytest.approx(4.0, abs=0.03)
    assert np.degrees(out.point_cloud.azimuth_rad[i[0]]) == pytest.approx(-10.0, abs=1.0)
    assert out.point_cloud.radial_velocity_mps[i[0]] == pytest.approx(1.0, abs=0.1)
    assert simulate_frame is FIDELITY_LEVELS["exact"]


def scene_frames(n: int, seed: int) -> list[Scatterers]:
    """``n`` frames: a person at 3-10 m plus 0-4 clutter reflectors of low RCS."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        k = 1 + rng.integers(0, 5)
        pos = np.column_stack((rng.uniform(-3, 3, k), rng.uniform(2, 10, k), np.zeros(k)))
        out.append(
            Scatterers(
                position_m=pos,
                velocity_mps=np.column_stack((rng.normal(0, 1, (k, 2)), np.zeros(k))),
                rcs_dbsm=rng.uniform(-30, 0, k),
                source=np.array([0] + [-1] * (k - 1), dtype=np.int32),
            )
        )
    return out


def test_batch_equals_per_frame_bit_for_bit() -> None:
    """The batch entry point gives every frame exactly what the per-frame call gives."""
    frames = scene_frames(40, 5)
    frames[7] = Scatterers.empty()  # a frame without reflectors: only false alarms
    rngs = [np.random.default_rng([9, f]) for f in range(len(frames))]
    batch = simulate_frames_measurement(RADAR, frames, rngs, antenna=ANT)
    rngs = [np.random.default_rng([9, f]) for f in range(len(frames))]
    per = [simulate_frame_measurement(RADAR, sc, r, antenna=ANT) for sc, r in zip(frames, rngs)]
    clouds = batch.clouds()
    assert [len(c) for c in clouds] == [len(o.point_cloud) for o in per]
    assert int(batch.counts.sum()) == len(batch.point_cloud) == len(batch.detections)
    for c, o in zip(clouds, per):
        for name in (*POINT_FIELDS, "source"):
            np.testing.assert_array_equal(getattr(c, name), getattr(o.point_cloud, name))
    np.testing.assert_array_equal(batch.detections, np.concatenate([o.detections for o in per]))
    # the false alarms of the pool appear (label -2) and the person is seen in most frames
    assert np.any(batch.point_cloud.source == SOURCE_OTHER)
    assert sum(np.any(c.source == 0) for c in clouds) >= 30
    with pytest.raises(InputError, match="rngs"):
        simulate_frames_measurement(RADAR, frames, rngs[:3], antenna=ANT)


def test_compiled_generator_moments() -> None:
    """The kernel's draws have the laws they claim: U[0,1), N(0,1), Gamma(k), Poisson(lam)."""
    n = 200_000
    s = frame_seed(np.random.default_rng(1))
    u = np.array([_uniform(s) for _ in range(n)])
    z = np.array([_normal(s) for _ in range(n)])
    # standard errors: U: 0.29/sqrt(n) = 6.5e-4; N: 2.2e-3 (mean), 3.2e-3 (var)
    assert abs(u.mean() - 0.5) < 4e-3 and abs(u.var() - 1 / 12) < 2e-3
    assert 0.0 <= u.min() and u.max() < 1.0
    assert abs(z.mean()) < 0.012 and abs(z.var() - 1.0) < 0.015
    assert abs(np.mean(z**4) - 3.0) < 0.06
    for k in (11.0, 35.7, 0.4):
        g = np.array([_gamma(s, k) for _ in range(n // 4)])
        # Gamma(k): mean k, variance k, skewness 2 / sqrt(k)
        assert abs(g.mean() / k - 1) < 5 * np.sqrt(1 / (k * len(g)))
        assert abs(g.var() / k - 1) < 0.04
        skew = np.mean((g - g.mean()) ** 3) / g.std() ** 3
        assert abs(skew - 2 / np.sqrt(k)) < 0.1 * 2 / np.sqrt(k) + 0.03
    p = np.array([_poisson(s, 0.16) for _ in range(n)])
    assert abs(p.mean() - 0.16) < 5e-3 and abs(p.var() - 0.16) < 6e-3
    # P(0) = exp(-0.16), P(2) = 0.16^2/2 exp(-0.16)
    assert abs(np.mean(p == 0) - np.exp(-0.16)) < 5e-3
    assert abs(np.mean(p == 2) - 0.0128 * np.exp(-0.16)) < 2e-3
    ints = np.array([_randint(s, 7) for _ in range(n)])
    np.testing.assert_allclose(np.bincount(ints, minlength=7) / n, 1 / 7, atol=4e-3)
    # the state comes from the frame's generator: same generator, same stream
    np.testing.assert_array_equal(
        frame_seed(np.random.default_rng(3)), frame_seed(np.random.default_rng(3))
    )


def test_false_alarm_pool_cached_on_disk(tmp_path, monkeypatch) -> None:
    """The pool is written once, read back equal, and a corrupt file is recomputed."""
    monkeypatch.setenv("RADARTUNE_CACHE", str(tmp_path))
    fresh = _measure_false_alarms(RADAR, DEFAULT_PROCESSING, 20)
    first = chain_false_alarms.__wrapped__(RADAR, DEFAULT_PROCESSING, 20)
    files = list((tmp_path / "false_alarms").glob("*.npz"))
    assert len(files) == 1 and not list((tmp_path / "false_alarms").glob("*.tmp*"))
    loaded = chain_false_alarms.__wrapped__(RADAR, DEFAULT_PROCESSING, 20)
    for fa in (first, loaded):
        assert fa.rate_per_frame == fresh.rate_per_frame and fa.n_frames == 20
        for name in ("doppler_index", "snr_db", "azimuth_rad", "range_frac"):
            np.testing.assert_array_equal(getattr(fa, name), getattr(fresh, name))
    files[0].write_bytes(b"not a npz")
    again = chain_false_alarms.__wrapped__(RADAR, DEFAULT_PROCESSING, 20)
    np.testing.assert_array_equal(again.snr_db, fresh.snr_db)

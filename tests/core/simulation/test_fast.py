"""The ``fast`` level against the exact chain: same spectrum, noise statistics and detections."""

from __future__ import annotations

import numpy as np
import pytest

from core.config import DEFAULT_PROCESSING, PAPER_RADAR, CfarSettings, ProcessingSettings
from core.processing import (
    doppler_fft,
    range_doppler_map,
    range_fft,
    remove_static_clutter,
    two_stage_cfar,
)
from core.simulation import AntennaGain, Scatterers, simulate_frame, synthesize_signal
from core.simulation.fast import (
    cell_noise_power_v2,
    fast_spectrum,
    simulate_frame_fast,
)
from core.simulation.fast_cfar import two_stage_cfar_compiled
from core.simulation.link import noise_power_v2

RADAR = PAPER_RADAR
ANT = AntennaGain.ideal(RADAR)


def scatterers(positions, velocities, rcs, source=None) -> Scatterers:
    n = len(rcs)
    return Scatterers(
        position_m=np.asarray(positions, dtype=float).reshape(n, 3),
        velocity_mps=np.asarray(velocities, dtype=float).reshape(n, 3),
        rcs_dbsm=np.asarray(rcs, dtype=float),
        source=np.asarray(source if source is not None else range(n), dtype=np.int32),
    )


SCENE = scatterers(
    [[1.0, 4.0, 0.0], [-2.0, 6.0, 0.0], [2.5, 2.0, 0.0]],
    [[0.5, -1.2, 0.0], [1.5, 0.3, 0.0], [-3.0, 0.5, 0.0]],
    [-8.0, 0.0, -5.0],
)


#: processing settings that cover every range window family the fast level's closed form uses
WINDOWS = [
    DEFAULT_PROCESSING,
    ProcessingSettings(range_window="rect", doppler_window="hamming"),
    ProcessingSettings(range_window="blackman", static_clutter_removal=False),
]


def exact_doppler_cube(sc: Scatterers, settings=DEFAULT_PROCESSING) -> np.ndarray:
    rc = range_fft(synthesize_signal(RADAR, sc, ANT), settings.range_window)
    if settings.static_clutter_removal:
        rc = remove_static_clutter(rc)
    return doppler_fft(rc, settings.doppler_window)


@pytest.mark.parametrize("settings", WINDOWS)
def test_noise_free_spectrum_equals_exact(settings) -> None:
    """Closed-form cells equal the exact chain's Doppler cube; the patch holds its energy."""
    dc = exact_doppler_cube(SCENE, settings)
    spec = fast_spectrum(RADAR, SCENE, None, antenna=ANT, settings=settings, noise=False)
    k, d = spec.patch.T
    x_exact = dc[:, k, d].T
    # first order in the beat tone's drift within the frame: the remainder is below -45 dB
    err = np.linalg.norm(spec.signal - x_exact) / np.linalg.norm(x_exact)
    assert err < 0.005
    rd = range_doppler_map(dc).astype(np.float64)
    assert rd[k, d].sum() / rd.sum() > 0.9999
    # outside the patch the exact map is below the noise by the patch threshold (-30 dB) with
    # 2 dB margin (several scatterers below the threshold each can add up; more with the
    # rectangular window's far sidelobes)
    margin = 10**-2.8 if settings.range_window == "hann" else 10**-2.5
    s2 = cell_noise_power_v2(RADAR, settings)
    outside = np.ones(rd.shape, bool)
    outside[k, d] = False
    assert np.all(
        rd[outside] < RADAR.n_virtual * margin * s2[None, :].repeat(rd.shape[0], 0)[outside]
    )
    # the peak cell and its power
    assert np.unravel_index(rd.argmax(), rd.shape) == np.unravel_index(
        spec.rd_map.argmax(), rd.shape
    )
    assert spec.rd_map.max() == pytest.approx(rd.max(), rel=0.03)


def test_cell_noise_power_formula() -> None:
    """Hann windows: sigma^2 sum w_r^2 = 96 sigma^2; Doppler 12 - |W(d)|^2/32 (W(0)=16, W(1)=-8)."""
    s2 = cell_noise_power_v2(RADAR, DEFAULT_PROCESSING) / noise_power_v2(RADAR)
    # sum w_r^2 = 3 N / 8 = 96; sum w_d^2 = 12; |W(0)|^2 / 32 = 8, |W(+-1)|^2 / 32 = 2
    expected = np.full(32, 96.0 * 12.0)
    expected[16] = 96.0 * (12 - 8)
    expected[[15, 17]] = 96.0 * (12 - 2)
    np.testing.assert_allclose(s2, expected, rtol=1e-5)


def test_noise_cells_match_exact_chain_gamma12() -> None:
    """Noise-only map: per Doppler bin mean 12 s2[d] and variance 12 s2[d]^2, as exact."""
    rng = np.random.default_rng(1)
    s2 = cell_noise_power_v2(RADAR, DEFAULT_PROCESSING)
    empty = Scatterers.empty()
    fast = np.stack(
        [fast_spectrum(RADAR, empty, rng, antenna=ANT).rd_map for _ in range(40)]
    ).astype(np.float64)
    from core.simulation import synthesize_noise

    exact = np.stack(
        [
            range_doppler_map(
                doppler_fft(remove_static_clutter(range_fft(synthesize_noise(RADAR, rng))))
            )
            for _ in range(10)
        ]
    ).astype(np.float64)
    for maps, n in ((fast, 40), (exact, 10)):
        x = maps / s2[None, None, :]
        # mean of 256 * n Gamma(12) draws per bin: sd 12^0.5 / (256 n)^0.5
        np.testing.assert_allclose(x.mean(axis=(0, 1)), 12.0, atol=5 * np.sqrt(12 / (256 * n)))
        assert x.var() == pytest.approx(12.0, rel=0.06)


def test_compiled_cfar_equals_library_cfar() -> None:
    rng = np.random.default_rng(3)
    variants = [
        DEFAULT_PROCESSING,
        ProcessingSettings(
            range_cfar=CfarSettings(method="ca", pfa=1e-2),
            doppler_cfar=CfarSettings(method="caso", n_train=3, n_guard=1, pfa=1e-2, cyclic=True),
        ),
        ProcessingSettings(
            range_cfar=CfarSettings(method="ca", pfa=1e-2, cyclic=True),
            doppler_cfar=CfarSettings(method="caso", n_train=4, n_guard=2, pfa=1e-2),
            peak_grouping=False,
            min_range_m=2.0,
        ),
        ProcessingSettings(cfar_noise_model=False),
        ProcessingSettings(doppler_window="rect"),
        ProcessingSettings(
            range_cfar=CfarSettings(method="cago", pfa=1e-2),
            doppler_cfar=CfarSettings(method="cago", n_train=3, n_guard=1, pfa=1e-2, cyclic=True),
        ),
    ]
    n_det = 0
    for settings in variants:
        for _ in range(30):
            rd = rng.standard_gamma(12, (256, 32)) * rng.uniform(0.5, 2, 32)
            for _ in range(5):
                rd[rng.integers(0, 256), rng.integers(0, 32)] *= 10 ** rng.uniform(0, 3)
            rd = rd.astype(np.float32)
            a = two_stage_cfar(rd, RADAR, settings)
            b = two_stage_cfar_compiled(rd, RADAR, settings)
            np.testing.assert_array_equal(a.range_bin, b.range_bin)
            np.testing.assert_array_equal(a.doppler_index, b.doppler_index)
            np.testing.assert_allclose(a.noise_power, b.noise_power, rtol=1e-12)
            np.testing.assert_array_equal(a.power, b.power)
            n_det += len(a)
    assert n_det > 100


def test_strong_targets_detected_in_same_cells_as_exact() -> None:
    """High-SNR reflectors: the same detected cells, ranges, velocities and azimuths."""
    sc = scatterers(
        [[1.0, 4.0, 0.0], [-3.0, 6.0, 0.0], [2.0, 7.5, 0.0]],
        [[0.5, -1.2, 0.0], [1.5, 0.3, 0.0], [0.0, 2.0, 0.0]],
        [5.0, 5.0, 5.0],
    )
    for seed in range(3):
        e = simulate_frame(RADAR, sc, np.random.default_rng(seed), antenna=ANT)
        f = simulate_frame_fast(RADAR, sc, np.random.default_rng(seed), antenna=ANT)
        pe = {tuple(c) for c, s in zip(e.detections, e.point_cloud.source) if s >= 0}
        pf = {tuple(c) for c, s in zip(f.detections, f.point_cloud.source) if s >= 0}
        assert pe == pf and len(pe) == 3
        for src in range(3):
            ie = np.flatnonzero(e.point_cloud.source == src)[0]
            i_f = np.flatnonzero(f.point_cloud.source == src)[0]
            assert abs(e.point_cloud.range_m[ie] - f.point_cloud.range_m[i_f]) < 0.01
            assert (
                abs(e.point_cloud.radial_velocity_mps[ie] - f.point_cloud.radial_velocity_mps[i_f])
                < 0.05
            )
            assert abs(e.point_cloud.azimuth_rad[ie] - f.point_cloud.azimuth_rad[i_f]) < 0.02
            assert abs(e.point_cloud.snr_db[ie] - f.point_cloud.snr_db[i_f]) < 1.5


def test_rd_map_only_when_asked_and_reproducible() -> None:
    a = simulate_frame_fast(RADAR, SCENE, np.random.default_rng(5), antenna=ANT, keep_rd_map=True)
    b = simulate_frame_fast(RADAR, SCENE, np.random.default_rng(5), antenna=ANT, keep_rd_map=True)
    c = simulate_frame_fast(RADAR, SCENE, np.random.default_rng(6), antenna=ANT, keep_rd_map=True)
    assert (
        simulate_frame_fast(RADAR, SCENE, np.random.default_rng(5), antenna=ANT).rd_map_db is None
    )
    assert a.rd_map_db.shape == (256, 32) and a.rd_map_db.dtype == np.float32
    np.testing.assert_array_equal(a.rd_map_db, b.rd_map_db)
    assert not np.array_equal(a.rd_map_db, c.rd_map_db)


@pytest.mark.parametrize("elevation", [False, True])
def test_compiled_points_equal_library_points(elevation) -> None:
    """Refinement, TDM compensation, azimuth DFT and elevation as core.processing computes them."""
    from core.processing import Detections
    from core.simulation.fast import points_compiled, points_from_channels

    rng = np.random.default_rng(4)
    rd = (rng.standard_gamma(12, (256, 32)) + 0.0).astype(np.float32)
    r = rng.integers(0, 256, 200)
    d = rng.integers(0, 32, 200)
    rd[r, d] *= 50
    det = Detections(
        range_bin=r, doppler_index=d, power=rd[r, d].astype(float), noise_power=np.ones(200)
    )
    # steering-like channel values plus noise
    u = rng.uniform(-0.9, 0.9, 200)
    pos = np.asarray(RADAR.azimuth_positions) + 1j * 0
    x = np.exp(1j * np.pi * np.outer(u, pos)) + 0.3 * rng.standard_normal((200, 12))
    a = points_from_channels(RADAR, DEFAULT_PROCESSING, rd, det, x, elevation)
    b = points_compiled(RADAR, DEFAULT_PROCESSING, rd, det, x, elevation)
    for name in ("range_m", "radial_velocity_mps", "azimuth_rad", "elevation_rad", "x_m", "y_m"):
        np.testing.assert_allclose(getattr(b, name), getattr(a, name), rtol=1e-9, atol=1e-12)


def test_noise_free_frame_runs_and_reports_infinite_snr_where_the_noise_estimate_is_zero() -> None:
    f = simulate_frame_fast(RADAR, SCENE, None, antenna=ANT, noise=False)
    assert len(f.point_cloud) >= 3
    assert set(f.point_cloud.source.tolist()) >= {0, 1, 2}
    assert not np.any(np.isnan(f.point_cloud.snr_db))


def test_only_the_exact_level_times_its_two_halves_apart() -> None:
    """The exact chain reports its synthesis and processing seconds; the fast level, one kernel
    for both, reports none; the timings are not part of the result (equal outputs compare
    equal)."""
    import math

    import numpy as np

    from core.config import PAPER_RADAR
    from core.simulation import AntennaGain, Scatterers, simulate_frame
    from core.simulation.fast import simulate_frame_fast

    sc = Scatterers(
        position_m=np.array([[0.5, 4.0, 0.0]]),
        velocity_mps=np.array([[0.0, 1.0, 0.0]]),
        rcs_dbsm=np.array([-8.0]),
        source=np.array([0], dtype=np.int64),
    )
    ant = AntennaGain.draw(PAPER_RADAR, np.random.default_rng(0))
    a = simulate_frame(PAPER_RADAR, sc, np.random.default_rng(1), antenna=ant)
    b = simulate_frame(PAPER_RADAR, sc, np.random.default_rng(1), antenna=ant)
    assert a.synthesis_s > 0 and a.processing_s > 0
    assert np.array_equal(a.detections, b.detections)
    fast = simulate_frame_fast(PAPER_RADAR, sc, np.random.default_rng(1), antenna=ant)
    assert math.isnan(fast.synthesis_s) and math.isnan(fast.processing_s)


def test_slow_time_rotation_equals_the_phase_of_every_chirp() -> None:
    """The slow-time phasors by rotation (one cos/sin per scatterer) against the phase of each
    chirp, ``y_c = exp(j (4 pi R_c / lambda + delta_c (N - 1) / 2))``, ``delta_c = theta'
    (R_c - R_mid)``: a foot at 0.6 m sweeping at 6 m/s across (the phase step departs from its
    mean by up to 0.009 rad: the Taylor branch), a reflector at 0.2 m crossing at 10 m/s (0.17 rad:
    the cos/sin branch), a torso at 3 m and a static reflector, without clutter removal."""
    from core.simulation.fast_model import beat_rad_per_sample_per_m, slow_time_sequences

    sc = scatterers(
        [[0.5, 0.3, -0.2], [0.05, 0.2, 0.0], [0.4, 3.0, 0.2], [-2.0, 5.0, 0.0]],
        [[-6.0, 0.5, 1.0], [10.0, 0.0, 0.0], [0.1, -1.3, 0.0], [0.0, 0.0, 0.0]],
        [-10.0, -10.0, 0.0, 5.0],
    )
    settings = ProcessingSettings(static_clutter_removal=False)
    y, y1 = slow_time_sequences(RADAR, sc, settings)
    n_tx, n_loops = RADAR.n_tx, RADAR.n_loops
    c = np.arange(n_tx * n_loops)
    t = c * RADAR.chirp_period_s
    r = np.linalg.norm(sc.position_m[:, None, :] + sc.velocity_mps[:, None, :] * t[:, None], axis=2)
    r_mid = np.linalg.norm(sc.position_m + sc.velocity_mps * t[len(c) // 2], axis=1)
    delta = beat_rad_per_sample_per_m(RADAR) * (r - r_mid[:, None])
    phi = 4 * np.pi * r / RADAR.wavelength_m + delta * (RADAR.n_samples - 1) / 2
    want = np.exp(1j * phi).reshape(len(sc), n_loops, n_tx).transpose(0, 2, 1)  # [i, slot, loop]
    assert np.max(np.abs(y - want)) < 1e-9
    assert (
        np.max(np.abs(y1 - delta.reshape(len(sc), n_loops, n_tx).transpose(0, 2, 1) * want)) < 1e-11
    )


@pytest.mark.parametrize("name", ["hann", "hamming", "blackman", "rect"])
def test_range_envelopes_bound_the_window_response_beyond_each_offset(name) -> None:
    """``env[:, g]`` bounds ``|R(Delta)|^2`` and ``|R1(Delta)|^2`` (the window's response and
    that of ``w_m (m - (N - 1)/2)``, by direct DTFT) at 20 000 random offsets ``|Delta| >= g/Q``
    of both signs, off the envelope's grid; it never increases; and for the Hann window it is
    within 4x of the largest response beyond 8 and 40 bins (an envelope that bounds nothing
    useful would fail)."""
    from core.simulation.fast_model import (
        ENVELOPE_PER_BIN,
        cosine_sum_coefficients,
        range_envelopes,
    )

    n = RADAR.n_samples
    env = range_envelopes(name, n)
    q = ENVELOPE_PER_BIN
    assert env.shape == (2, q * n // 2 + 1)
    assert np.all(np.diff(env, axis=1) <= 0)
    b = cosine_sum_coefficients(name, n)
    half = (len(b) - 1) // 2
    m = np.arange(n)
    w = np.real(
        np.sum(b[:, None] * np.exp(2j * np.pi * np.outer(np.arange(-half, half + 1), m) / n), 0)
    )
    delta = np.random.default_rng(3).uniform(-n / 2, n / 2, 20_000)
    ph = np.exp(2j * np.pi * np.outer(delta, m) / n)
    resp = np.abs(ph @ w) ** 2, np.abs(ph @ (w * (m - (n - 1) / 2))) ** 2
    g = np.floor(np.abs(delta) * q).astype(int)
    for row in (0, 1):
        assert np.all(resp[row] <= env[row, g])
    if name == "hann":
        for bins in (8, 40):
            beyond = np.abs(delta) >= bins
            assert env[0, bins * q] < 4 * resp[0][beyond].max()


@pytest.mark.parametrize("settings", WINDOWS)
def test_range_pruning_changes_no_bit_of_the_patches(settings) -> None:
    """The patch kernel computes a scatterer's range responses only within its envelope's
    reach: against no pruning (an infinite envelope), every output is the same bit for bit —
    patch cells, channel values, noise draws, the map and the generator state — for strong and
    weak scatterers, ones whose reach wraps past bin 0, with and without a range limit. An
    envelope 60 dB too low changes the result (the envelope is used)."""
    from core.simulation.baseband import steering_vectors
    from core.simulation.fast import spectrum_tables
    from core.simulation.fast_model import (
        beat_rad_per_sample_per_m,
        patches_kernel,
        slow_time_sequences,
    )
    from core.simulation.link import received_power_w, signal_amplitude_v
    from core.simulation.rng_kernels import state_from

    rng = np.random.default_rng(5)
    n = 40
    pos = np.column_stack((rng.uniform(-3, 3, n), rng.uniform(0.02, 9, n), rng.uniform(-1, 1, n)))
    pos[:4] = [[0.0, 0.03, 0.0], [0.0, 0.06, 0.0], [0.1, 0.5, 0.0], [0.0, 0.9, 0.2]]  # wrap
    sc = scatterers(pos, rng.normal(0, 1.5, (n, 3)), rng.uniform(-30, 25, n))
    spec = spectrum_tables(RADAR, settings, True)
    power = received_power_w(RADAR, sc.range_m, sc.azimuth_rad, sc.rcs_dbsm, ANT)
    amp = signal_amplitude_v(RADAR, power)
    t_mid = 0.5 * RADAR.n_loops * RADAR.n_tx * RADAR.chirp_period_s
    theta = beat_rad_per_sample_per_m(RADAR) * np.linalg.norm(
        sc.position_m + sc.velocity_mps * t_mid, axis=1
    )
    slow, slow1 = slow_time_sequences(RADAR, sc, settings)
    steer = np.ascontiguousarray(steering_vectors(RADAR, sc))

    def run(env, k_max):
        state = np.zeros(6, np.uint64)
        state[:4] = state_from(np.random.default_rng(9))
        rd = np.ones((RADAR.n_samples, RADAR.n_loops), np.float32)
        out = patches_kernel(
            state, rd, amp, theta, slow, slow1, spec.wd, spec.b, spec.s2, steer, spec.slot,
            spec.threshold, spec.half_r, spec.tw_d, env, True, k_max,
        )  # fmt: skip
        return (*out, rd, state)

    for k_max in (RADAR.n_samples, 120):
        pruned = run(spec.env, k_max)
        full = run(np.full_like(spec.env, np.inf), k_max)
        for a, b in zip(pruned, full, strict=True):
            assert a.shape == b.shape and np.array_equal(a, b)
        assert len(pruned[0]) > 100
    low = run(spec.env * 1e-6, RADAR.n_samples)
    assert not all(np.array_equal(a, b) for a, b in zip(low, run(spec.env, RADAR.n_samples)))

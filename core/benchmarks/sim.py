"""``radartune bench sim``: frames per second of the exact radar chain on the paper scene.

The paper scene per frame: one walking person (RCS from eq. 5) and Poisson(0.02 m⁻² x AOI area
= 2.09) clutter reflectors with a post-processing SNR of 15-30 dB and |v_r| >= 2 velocity bins,
i.e. about 1 + Poisson(2.1) scatterers. The same frames run through

- the exact chain, :func:`core.simulation.simulate_frame` (numba synthesis, complex64,
  ``scipy.fft``), and
- a plain, straightforward numpy implementation of the same chain written here (loop over
  scatterers, complex128 ``numpy.exp`` over the whole cube, ``numpy.fft``, the same CFAR
  thresholds with sliding sums, angle FFT per detection),

in the same run, single-threaded, interleaved in blocks (10 exact frames, 1 plain frame) so
that both see the same load, and the ratio is reported (the machine is shared and noisy).
If ``core.pipeline.paper_dataset`` is importable, generating the 35-trajectory data set
(uncached, one process) is timed too.

The walking-body case (:func:`walking_case`): the same class-a walk with the paper's clutter
(0.02 m^-2), once with the walking body (17 segments at their heights, elevation processed) and
once with the point person, the frames built by the pipeline's reflector stage; the exact
chain runs both interleaved in blocks (frames/s and their ratio in the same run), and the fast
level runs the walking frames in one batch before each of the exact chain's passes (its frames/s
against the exact chain's, the same load for both).
"""

from __future__ import annotations

import time

import numpy as np

from core.benchmarks.sim_room import run_case as room_case
from core.benchmarks.sim_room import summary_line as room_summary_line
from core.config import (
    PAPER_AOI_AREA_M2,
    PAPER_CLUTTER_DENSITY_PER_M2,
    PAPER_MAX_AZIMUTH_DEG,
    PAPER_MAX_RANGE_M,
    PAPER_MIN_RANGE_M,
    SPEED_OF_LIGHT_MPS,
    ProcessingSettings,
    RadarConfig,
)


def paper_scene_frames(radar: RadarConfig, n_frames: int, rng: np.random.Generator, antenna):
    """Scatterers of ``n_frames`` frames: a person walking a straight line plus clutter."""
    from core.simulation import Scatterers, draw_person_rcs_dbsm, rcs_for_snr_db

    settings = ProcessingSettings()
    frames = []
    pos = np.array([-2.0, 3.0, 0.0])
    vel = np.array([0.9, 0.8, 0.0])
    vres = radar.velocity_resolution_mps
    for f in range(n_frames):
        p = pos + vel * radar.frame_period_s * (f % 100)
        n_c = rng.poisson(PAPER_CLUTTER_DENSITY_PER_M2 * PAPER_AOI_AREA_M2)
        # uniform in the AOI sector: r^2 uniform, az uniform
        r = np.sqrt(rng.uniform(PAPER_MIN_RANGE_M**2, PAPER_MAX_RANGE_M**2, n_c))
        az = np.radians(rng.uniform(-PAPER_MAX_AZIMUTH_DEG, PAPER_MAX_AZIMUTH_DEG, n_c))
        u = np.column_stack((np.sin(az), np.cos(az), np.zeros(n_c)))
        # |v_r| uniform over [2 bins, v_max], random sign
        vr = rng.uniform(2 * vres, radar.max_velocity_mps, n_c) * rng.choice([-1.0, 1.0], n_c)
        rcs = rcs_for_snr_db(radar, r, az, rng.uniform(15, 30, n_c), antenna, settings)
        frames.append(
            Scatterers(
                position_m=np.vstack((p, r[:, None] * u)),
                velocity_mps=np.vstack((vel, vr[:, None] * u)),
                rcs_dbsm=np.concatenate((draw_person_rcs_dbsm(rng, 1), rcs)),
                source=np.concatenate(([0], np.full(n_c, -1))).astype(np.int32),
            )
        )
    return frames


# ---- the plain reference implementation ---------------------------------------------------------
def _plain_cfar_sums(p: np.ndarray, n: int, g: int, axis: int, cyclic: bool):
    """Left and right training sums with a plain sliding window (numpy.convolve per line)."""
    p = np.moveaxis(p, axis, 0)
    size = p.shape[0]
    kernel = np.ones(n)
    left = np.full(p.shape, np.nan)
    right = np.full(p.shape, np.nan)
    off = n + g if cyclic else 0
    i = np.arange(size)
    lo = i + off - g - n
    hi = i + off + g + 1
    for col in range(p.shape[1]):
        line = p[:, col]
        if cyclic:
            line = np.concatenate((line[-(n + g) :], line, line[: n + g]))
        sums = np.convolve(line, kernel, mode="valid")  # sums[j] = line[j] + ... + line[j+n-1]
        ok_l = lo >= 0
        ok_r = hi + n <= len(line)
        left[ok_l, col] = sums[lo[ok_l]]
        right[ok_r, col] = sums[hi[ok_r]]
    return np.moveaxis(left, 0, axis), np.moveaxis(right, 0, axis)


def plain_frame(radar: RadarConfig, scatterers, rng: np.random.Generator, antenna, settings):
    """The same chain written plainly. Returns (range_m, azimuth_rad, velocity_mps, snr_db)."""
    from core.processing.cfar import make_cfar
    from core.simulation.link import noise_power_v2, received_power_w, signal_amplitude_v

    n_v, n_l, n_s = radar.n_virtual, radar.n_loops, radar.n_samples
    lam = radar.wavelength_m
    cube = np.zeros((radar.n_tx, n_l, radar.n_rx, n_s), dtype=np.complex128)
    n = np.arange(n_s)
    for i in range(len(scatterers)):
        p0, v = scatterers.position_m[i], scatterers.velocity_mps[i]
        r0 = np.linalg.norm(p0)
        az = np.arctan2(p0[0], p0[1])
        el = np.arctan2(p0[2], np.hypot(p0[0], p0[1]))
        amp = signal_amplitude_v(
            radar, received_power_w(radar, r0, az, scatterers.rcs_dbsm[i], antenna)
        )
        t = (np.arange(n_l)[None, :] * radar.n_tx + np.arange(radar.n_tx)[:, None]) * (
            radar.chirp_period_s
        )
        r = np.linalg.norm(p0[None, None, :] + v[None, None, :] * t[..., None], axis=-1)
        fb = 2 * radar.slope_hz_per_s * r / SPEED_OF_LIGHT_MPS
        apos = np.reshape(radar.azimuth_positions, (radar.n_tx, radar.n_rx))
        epos = np.reshape(radar.elevation_positions, (radar.n_tx, radar.n_rx))
        ang = np.pi * (apos * np.sin(az) * np.cos(el) + epos * np.sin(el))  # (tx, rx)
        phase = (
            2 * np.pi * fb[:, :, None, None] * n / radar.sample_rate_hz
            + 4 * np.pi * r[:, :, None, None] / lam
            + ang[:, None, :, None]
        )
        cube += amp * np.exp(1j * phase)
    sigma = np.sqrt(noise_power_v2(radar) / 2)
    cube += sigma * (rng.standard_normal(cube.shape) + 1j * rng.standard_normal(cube.shape))
    x = cube.transpose(0, 2, 1, 3).reshape(n_v, n_l, n_s)
    w_r = np.hanning(n_s + 1)[:-1]
    w_d = np.hanning(n_l + 1)[:-1]
    x = np.fft.fft(x * w_r, axis=2)
    x = x - x.mean(axis=1, keepdims=True)
    x = np.fft.fftshift(np.fft.fft(x * w_d[None, :, None], axis=1), axes=1)  # [v, doppler, range]
    rd = np.sum(np.abs(x) ** 2, axis=0).T  # [range, doppler]
    # CFAR: the same thresholds and noise model as the exact chain, plain sliding sums
    from core.processing.cfar import effective_cells_or_none
    from core.processing.spectrum import clutter_removal_noise_profile

    prof = clutter_removal_noise_profile("hann", n_l)
    white = rd / prof
    rc, dc = settings.range_cfar, settings.doppler_cfar
    cr = make_cfar(rc, n_v, effective_cells_or_none("hann", n_s, rc.n_train))
    cd = make_cfar(dc, n_v, effective_cells_or_none("hann", n_l, dc.n_train))
    left, right = _plain_cfar_sums(white, rc.n_train, rc.n_guard, 0, False)
    both = ~np.isnan(left) & ~np.isnan(right)
    mu_r = np.where(both, np.minimum(left, right), np.where(np.isnan(left), right, left))
    mu_r = mu_r / rc.n_train
    alpha_r = np.where(both, cr.alpha(), cr.alpha_one_side())
    left_d, right_d = _plain_cfar_sums(white, dc.n_train, dc.n_guard, 1, True)
    mu_d = (left_d + right_d) / (2 * dc.n_train)
    det = (white > alpha_r * mu_r) & (white > cd.alpha() * mu_d)
    k = np.arange(n_s) * radar.range_resolution_m
    det &= ((k >= settings.min_range_m) & (k <= settings.max_range_m))[:, None]
    out = []
    for rb, db in zip(*np.nonzero(det)):
        nb = [
            rd[rr, dd % n_l]
            for rr in (rb - 1, rb, rb + 1)
            for dd in (db - 1, db, db + 1)
            if 0 <= rr < n_s and (rr, dd) != (rb, db)
        ]
        if rd[rb, db] < max(nb):
            continue
        d = db - n_l // 2
        chan = x[:, db, rb] * np.exp(
            -2j * np.pi * d * (np.arange(n_v) // radar.n_rx) / (n_l * radar.n_tx)
        )
        row = np.zeros(64, dtype=complex)
        row[:4] = chan[0:4]
        row[4:8] = chan[8:12]
        spec = np.abs(np.fft.fftshift(np.fft.fft(row))) ** 2
        kk = int(np.argmax(spec))
        az = np.arcsin(np.clip(2 * (kk - 32) / 64, -1, 1))
        snr = 10 * np.log10(white[rb, db] / mu_r[rb, db])
        out.append((rb * radar.range_resolution_m, az, d * radar.velocity_resolution_mps, snr))
    return out


# ---- the benchmark ------------------------------------------------------------------------------
def _time_frames(fn, frames) -> tuple[float, float, list]:
    """Wall-clock and CPU seconds (this process) for running ``fn`` on every frame."""
    results = []
    t0, c0 = time.perf_counter(), time.process_time()
    for f in frames:
        results.append(fn(f))
    return time.perf_counter() - t0, time.process_time() - c0, results


def run(quick: bool = False) -> dict:
    from core.simulation import AntennaGain, simulate_frame

    radar = RadarConfig()
    settings = ProcessingSettings()
    rng = np.random.default_rng(2024)
    antenna = AntennaGain.draw(radar, rng)
    n_exact = 60 if quick else 1000
    n_plain = 15 if quick else 100
    frames = paper_scene_frames(radar, n_exact, rng, antenna)
    n_scatterers = float(np.mean([len(f) for f in frames]))
    # warm up (numba compilation, FFT plans, threshold caches)
    simulate_frame(radar, frames[0], np.random.default_rng(0), antenna=antenna)
    plain_frame(radar, frames[0], np.random.default_rng(0), antenna, settings)

    # interleaved blocks (10 exact frames, then 1 plain frame) so that both see the same load
    rng_e = np.random.default_rng(1)
    rng_p = np.random.default_rng(1)
    block = n_exact // n_plain
    t_exact = c_exact = t_plain = c_plain = 0.0
    outs: list = []
    plain: list = []
    for b in range(n_plain):
        chunk = frames[b * block : (b + 1) * block]
        t, c, o = _time_frames(
            lambda f: simulate_frame(radar, f, rng_e, antenna=antenna, settings=settings), chunk
        )
        t_exact, c_exact = t_exact + t, c_exact + c
        outs += o
        t, c, o = _time_frames(
            lambda f: plain_frame(radar, f, rng_p, antenna, settings), frames[b : b + 1]
        )
        t_plain, c_plain = t_plain + t, c_plain + c
        plain += o
    n_exact = len(outs)
    fps_exact = n_exact / t_exact
    fps_plain = n_plain / t_plain
    person_found = float(np.mean([0 in o.point_cloud.source for o in outs]))
    points = float(np.mean([len(o.point_cloud) for o in outs]))
    plain_points = float(np.mean([len(p) for p in plain]))
    result = {
        "frames_exact": n_exact,
        "frames_plain": n_plain,
        "mean_scatterers_per_frame": n_scatterers,
        "exact_fps": fps_exact,
        "exact_ms_per_frame": 1e3 / fps_exact,
        "plain_fps": fps_plain,
        "plain_ms_per_frame": 1e3 / fps_plain,
        "speedup": fps_exact / fps_plain,
        # CPU time of this process: less sensitive to other load on a shared machine
        "exact_fps_cpu": n_exact / c_exact,
        "plain_fps_cpu": n_plain / c_plain,
        "speedup_cpu": (n_exact / c_exact) / (n_plain / c_plain),
        "load_average_1min": _load(),
        "goal": {"speedup": 4.0, "fps": 250.0},
        "exact_points_per_frame": points,
        "plain_points_per_frame": plain_points,
        "exact_person_detected_fraction": person_found,
    }
    result["walking_body"] = walking_case(quick)
    result["room"] = room_case(quick)
    from core.benchmarks import chains

    result["detection_chains"] = chains.run(quick, scene_frames=paper_scene_frames)
    result["stages_ms"] = _stage_profile(radar, settings, antenna, frames[: 50 if quick else 300])
    result["dataset"] = _time_dataset(quick)
    return result


#: Fast-level batches (one trajectory's frames each) timed per pass of the exact chain.
FAST_BATCHES_PER_PASS = 5


def walking_case(quick: bool = False) -> dict:
    """The exact chain on a walking body and on the point person, and the fast level.

    Returns frames/s (wall clock and CPU) of the exact chain for both persons, their ratio,
    the fast level's frames/s on the walking frames and its speed-up over the exact chain,
    the reflector stage's ms per frame and the mean scatterers and points per frame.
    """
    from core.simulation import simulate_frame
    from core.simulation.fast import simulate_frames_fast

    built = {model: _walking_case_frames(model) for model in ("walking", "point")}
    radar, antenna, settings, walk, t_refl = built["walking"]
    point = built["point"][3]
    n = min(len(walk), len(point))
    reps = 1 if quick else max(1, 600 // n)
    # warm up both paths (planar and with elevation) and the fast level
    for fr in (walk[0], point[0]):
        simulate_frame(radar, fr, np.random.default_rng(0), antenna=antenna, settings=settings)
    simulate_frames_fast(
        radar, walk[:2], [np.random.default_rng(0)] * 2, antenna=antenna, settings=settings
    )
    rng_w, rng_p = np.random.default_rng(1), np.random.default_rng(1)
    block = 10
    spent = {"walking": [0.0, 0.0, 0], "point": [0.0, 0.0, 0]}
    pts = {"walking": [], "point": []}
    rngs = [np.random.default_rng(100 + i) for i in range(n)]
    t_fast = c_fast = 0.0
    # a fast batch takes ~1/10 of the exact chain's pass: run it several times per pass so that
    # one scheduler hiccup on the shared machine does not decide its rate
    fast_batches = 1 if quick else FAST_BATCHES_PER_PASS
    per_pass = []  # (fast s/frame, exact walking s/frame) of each pass, wall clock
    for _ in range(reps):
        # the fast level's batches between the exact chain's passes (the same load for both)
        t0, c0 = time.perf_counter(), time.process_time()
        for _ in range(fast_batches):
            simulate_frames_fast(radar, walk[:n], rngs, antenna=antenna, settings=settings)
        t_pass = time.perf_counter() - t0
        t_fast, c_fast = t_fast + t_pass, c_fast + time.process_time() - c0
        before = spent["walking"][0]
        for b in range(0, n, block):
            for name, frames, rng in (("walking", walk, rng_w), ("point", point, rng_p)):
                t, c, out = _time_frames(
                    lambda f, rng=rng: simulate_frame(
                        radar, f, rng, antenna=antenna, settings=settings
                    ),
                    frames[b : b + block],
                )
                spent[name][0] += t
                spent[name][1] += c
                spent[name][2] += len(out)
                pts[name] += [int(np.sum(o.point_cloud.source == 0)) for o in out]
        per_pass.append((t_pass / (fast_batches * n), (spent["walking"][0] - before) / n))
    stages = {
        name: _fast_stage_profile(radar, antenna, settings, frames[:n], reps)
        for name, frames in (("walking", walk), ("point", point))
    }
    return _walking_case_result(
        spent, pts, stages, walk[:n], point[:n], n=n, t_refl_s=t_refl / len(walk),
        fast_frames=fast_batches * reps * n, t_fast=t_fast, c_fast=c_fast, per_pass=per_pass,
        fast_batches=fast_batches,
    )  # fmt: skip


def _walking_case_frames(model: str) -> tuple:
    """The walking case's scene with person ``model``: (radar, antenna, settings, scatterers of
    every frame, seconds the reflector stage took)."""
    from core.pipeline.plan import plan, processing_settings
    from core.pipeline.reflectors import Reflectors
    from core.scene import Scene
    from core.simulation import AntennaGain

    sc = Scene.from_dict(
        {
            "schema_version": 1,
            "seed": 11,
            "clutter_density_per_m2": PAPER_CLUTTER_DENSITY_PER_M2,
            "persons": [
                {"model": model, "trajectory": {"class": "a", "seed": 5, "speed_mps": 1.3}}
            ],
        }
    )
    antenna = AntennaGain.draw(sc.radar, np.random.default_rng(7))
    settings = processing_settings(sc)
    t0 = time.perf_counter()
    frames, _ = Reflectors.build(sc, plan(sc), sc.seed, antenna, settings).frames()
    return sc.radar, antenna, settings, frames, time.perf_counter() - t0


def _walking_case_result(
    spent, pts, stages, walk, point, *, n, t_refl_s, fast_frames, t_fast, c_fast, per_pass,
    fast_batches,
) -> dict:  # fmt: skip
    """The walking case's figures from its timings (see :func:`walking_case`)."""
    fps = {k: v[2] / v[0] for k, v in spent.items()}
    fps_cpu = {k: v[2] / v[1] for k, v in spent.items()}
    fast_fps = fast_frames / t_fast
    pass_ratio = [e / f for f, e in per_pass]
    return {
        "frames": spent["walking"][2],
        "frames_per_trajectory": n,
        "scatterers_per_frame_walking": float(np.mean([len(f) for f in walk])),
        "scatterers_per_frame_point": float(np.mean([len(f) for f in point])),
        "person_points_per_frame_walking": float(np.mean(pts["walking"])),
        "person_points_per_frame_point": float(np.mean(pts["point"])),
        "reflectors_ms_per_frame_walking": 1e3 * t_refl_s,
        "exact_fps_walking": fps["walking"],
        "exact_fps_point": fps["point"],
        "exact_point_over_walking": fps["point"] / fps["walking"],
        "exact_fps_cpu_walking": fps_cpu["walking"],
        "exact_fps_cpu_point": fps_cpu["point"],
        "exact_point_over_walking_cpu": fps_cpu["point"] / fps_cpu["walking"],
        "fast_fps_walking": fast_fps,
        "fast_fps_cpu_walking": fast_frames / c_fast,
        "fast_over_exact_walking": fast_fps / fps["walking"],
        "fast_over_exact_walking_cpu": (fast_frames / c_fast) / fps_cpu["walking"],
        # the same ratio pass by pass (each pass: its fast batches against its exact frames)
        "fast_over_exact_walking_per_pass": {
            "median": float(np.median(pass_ratio)),
            "min": float(np.min(pass_ratio)),
            "max": float(np.max(pass_ratio)),
            "passes": len(pass_ratio),
        },
        "fast_batches_per_pass": fast_batches,
        "fast_stages_ms_walking": stages["walking"],
        "fast_stages_ms_point": stages["point"],
        "goal": {
            "exact_fps_walking": 150.0,
            "exact_point_over_walking": 2.0,
            "fast_over_exact": 10,
        },
    }


def _fast_stage_profile(
    radar: RadarConfig, antenna, settings: ProcessingSettings, frames, reps: int
) -> dict:
    """CPU ms per frame of the ``fast`` level's stages on ``frames`` (one batch, ``reps`` times).

    The per-scatterer inputs (link budget, slow-time sequences, steering vectors; computed once
    for all frames), the noise map, the patches (range and Doppler responses of every
    scatterer, patch cells and their sums: :func:`~core.simulation.fast_model.patches_kernel`)
    run separately with the same functions as :func:`~core.simulation.fast.simulate_frames_fast`;
    ``rest`` (CFAR, detected channels, points, labels) is the whole batch minus those.
    """
    from core.simulation import Scatterers
    from core.simulation.baseband import steering_vectors
    from core.simulation.fast import simulate_frames_fast, spectrum_tables
    from core.simulation.fast_model import (
        beat_rad_per_sample_per_m,
        noise_map,
        patches_kernel,
        slow_time_sequences,
    )
    from core.simulation.link import received_power_w, signal_amplitude_v
    from core.simulation.rng_kernels import state_from

    n_f = len(frames)
    rngs = [np.random.default_rng(100 + i) for i in range(n_f)]
    every = Scatterers.concatenate(list(frames))
    start = np.concatenate(([0], np.cumsum([len(f) for f in frames]))).astype(np.int64)
    spec = spectrum_tables(radar, settings, False)
    t_mid = 0.5 * radar.n_loops * radar.n_tx * radar.chirp_period_s
    rd = np.empty((radar.n_samples, radar.n_loops), dtype=np.float32)
    spent = dict.fromkeys(("whole", "inputs", "noise map", "patches"), 0.0)
    for _ in range(reps):
        c0 = time.process_time()
        simulate_frames_fast(radar, frames, rngs, antenna=antenna, settings=settings)
        c1 = time.process_time()
        power = received_power_w(radar, every.range_m, every.azimuth_rad, every.rcs_dbsm, antenna)
        amp = signal_amplitude_v(radar, power)
        r_mid = np.linalg.norm(every.position_m + every.velocity_mps * t_mid, axis=1)
        theta = beat_rad_per_sample_per_m(radar) * r_mid
        slow, slow1 = slow_time_sequences(radar, every, settings)
        steer = np.ascontiguousarray(steering_vectors(radar, every))
        c2 = time.process_time()
        states = np.zeros((n_f, 6), dtype=np.uint64)
        for f in range(n_f):
            states[f, :4] = state_from(rngs[f])
        for f in range(n_f):
            noise_map(states[f], rd, spec.s2, spec.n_use, spec.n_v)
        c3 = time.process_time()
        for f in range(n_f):
            a, b = start[f], start[f + 1]
            patches_kernel(
                states[f], rd, amp[a:b], theta[a:b], slow[a:b], slow1[a:b], spec.wd, spec.b,
                spec.s2, steer[a:b], spec.slot, spec.threshold, spec.half_r, spec.tw_d, spec.env,
                True, spec.n_use,
            )  # fmt: skip
        c4 = time.process_time()
        spent["whole"] += c1 - c0
        spent["inputs"] += c2 - c1
        spent["noise map"] += c3 - c2
        spent["patches"] += c4 - c3
    ms = {k: 1e3 * v / (reps * n_f) for k, v in spent.items()}
    ms["rest"] = ms["whole"] - ms["inputs"] - ms["noise map"] - ms["patches"]
    ms["scatterers_per_frame"] = len(every) / n_f
    return ms


def _stage_profile(radar: RadarConfig, settings: ProcessingSettings, antenna, frames) -> dict:
    """CPU ms per frame of each stage of the exact chain, run one after the other as in
    :func:`core.simulation.simulate_frame` (the same functions, timed separately)."""
    import scipy.fft

    from core.processing import doppler_fft, range_doppler_map
    from core.processing.spectrum import window
    from core.simulation.baseband import synthesize_signal
    from core.simulation.frame import frame_from_spectrum, processed_range_bins
    from core.simulation.gaussian import add_complex_noise
    from core.simulation.link import noise_power_v2

    rng = np.random.default_rng(3)
    w = window(settings.range_window, radar.n_samples)
    power = noise_power_v2(radar)
    n_bins = processed_range_bins(radar, settings)
    stages = ("signal", "noise + range window", "range FFT", "Doppler", "range-Doppler map")
    spent = dict.fromkeys((*stages, "CFAR, angles, points, labels"), 0.0)

    def timed(name, fn, *args, **kwargs):
        c0 = time.process_time()
        out = fn(*args, **kwargs)
        spent[name] += time.process_time() - c0
        return out

    for f in frames:
        cube = timed("signal", synthesize_signal, radar, f, antenna)
        timed("noise + range window", add_complex_noise, cube, power, rng, window=w)
        rc = timed("range FFT", scipy.fft.fft, cube, axis=-1, overwrite_x=True)
        dc = timed(
            "Doppler", doppler_fft, rc[:, :, :n_bins], settings.doppler_window, remove_static=True
        )
        rd = timed("range-Doppler map", range_doppler_map, dc)
        timed(
            "CFAR, angles, points, labels", frame_from_spectrum, dc, rd, radar, f, settings=settings
        )
    return {k: 1e3 * v / len(frames) for k, v in spent.items()}


def _load() -> float | None:
    try:
        import os

        return os.getloadavg()[0]
    except (OSError, AttributeError):
        return None


def _time_dataset(quick: bool) -> dict | None:
    """Generation time of the paper data set (seed 0), uncached, one process.

    The point person at the exact level first (the top-level figures, as before), then both
    person models (``point``, ``walking``) at the ``exact`` and ``fast`` levels, each once in
    this process (wall clock and process CPU time): the "data-set generation time for the
    35 trajectories reported for both models". ``quick``: 2 trajectories.
    """
    try:
        from core.pipeline import paper_dataset
    except ImportError:
        return None
    import tempfile

    n_traj = 2 if quick else 35
    paper_dataset(0, 1, cache_dir=None, jobs=1, use_cache=False)  # warm up
    runs = {}
    for model in ("point", "walking"):
        for fidelity in ("exact", "fast"):
            with tempfile.TemporaryDirectory() as tmp:
                t0, c0 = time.perf_counter(), time.process_time()
                ds = paper_dataset(
                    0,
                    n_traj,
                    fidelity=fidelity,
                    person_model=model,
                    cache_dir=tmp,
                    jobs=1,
                    use_cache=False,
                )
                seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
            n_frames = int(ds.n_frames)
            runs.setdefault(model, {})[fidelity] = {
                "seconds": seconds,
                "cpu_s": cpu,
                "frames": n_frames,
                "frames_per_s": n_frames / seconds,
                "frames_per_s_cpu": n_frames / cpu,
            }
    for levels in runs.values():
        levels["fast_over_exact_cpu"] = levels["exact"]["cpu_s"] / levels["fast"]["cpu_s"]
    first = runs["point"]["exact"]
    return {
        "trajectories": n_traj,
        "seconds": first["seconds"],
        "jobs": 1,
        "frames": first["frames"],
        "frames_per_s": first["frames_per_s"],
        "models": runs,
        "load_average_1min": _load(),
    }


def summary(result: dict) -> str:
    lines = [
        "radar chain, paper scene "
        f"({result['mean_scatterers_per_frame']:.2f} scatterers/frame, one core)",
        f"  exact chain : {result['exact_fps']:7.1f} frames/s "
        f"({result['exact_ms_per_frame']:.2f} ms/frame, {result['frames_exact']} frames)",
        f"  plain numpy : {result['plain_fps']:7.1f} frames/s "
        f"({result['plain_ms_per_frame']:.2f} ms/frame, {result['frames_plain']} frames)",
        f"  speed-up    : {result['speedup']:.1f}x (goal >= 4x and >= 250 frames/s)",
        f"  by CPU time : exact {result['exact_fps_cpu']:.1f} frames/s, plain "
        f"{result['plain_fps_cpu']:.1f} frames/s, {result['speedup_cpu']:.1f}x "
        f"(load average {result['load_average_1min']})",
        f"  points/frame: exact {result['exact_points_per_frame']:.2f}, "
        f"plain {result['plain_points_per_frame']:.2f}; person detected in "
        f"{100 * result['exact_person_detected_fraction']:.0f} % of frames",
    ]
    wb = result.get("walking_body")
    if wb:
        lines.append(
            f"  walking body ({wb['scatterers_per_frame_walking']:.1f} scatterers/frame, "
            f"{wb['person_points_per_frame_walking']:.1f} person points/frame; point person "
            f"{wb['person_points_per_frame_point']:.2f}): exact {wb['exact_fps_walking']:.0f} "
            f"frames/s, point person {wb['exact_fps_point']:.0f} frames/s in the same run "
            f"({wb['exact_point_over_walking']:.2f}x; CPU "
            f"{wb['exact_point_over_walking_cpu']:.2f}x; goal >= 150 frames/s, <= 2x); fast "
            f"{wb['fast_fps_walking']:.0f} frames/s = {wb['fast_over_exact_walking']:.1f}x exact "
            f"(CPU {wb['fast_over_exact_walking_cpu']:.1f}x; pass by pass median "
            f"{wb['fast_over_exact_walking_per_pass']['median']:.1f}x, "
            f"{wb['fast_over_exact_walking_per_pass']['min']:.1f}-"
            f"{wb['fast_over_exact_walking_per_pass']['max']:.1f}x; goal >= 10x); reflectors "
            f"{wb['reflectors_ms_per_frame_walking']:.3f} ms/frame"
        )
    if result.get("room"):
        lines.append(room_summary_line(result["room"]))
    if "detection_chains" in result:
        from core.benchmarks import chains

        lines += chains.summary_lines(result["detection_chains"])
    stages = result.get("stages_ms")
    if stages:
        lines.append(
            "  stages (CPU ms/frame): "
            + ", ".join(f"{k} {v:.2f}" for k, v in stages.items())
            + f"; sum {sum(stages.values()):.2f}"
        )
    ds = result.get("dataset")
    if ds:
        lines.append(
            f"  paper data set ({ds['trajectories']} trajectories, uncached, 1 process): "
            f"{ds['seconds']:.1f} s"
            + (f", {ds['frames_per_s']:.0f} frames/s" if "frames_per_s" in ds else "")
        )
        for model, levels in ds.get("models", {}).items():
            lines.append(
                f"    {model:8s}: "
                + ", ".join(
                    f"{lv} {levels[lv]['seconds']:.1f} s (CPU {levels[lv]['cpu_s']:.1f} s)"
                    for lv in ("exact", "fast")
                )
                + f"; fast/exact by CPU {levels['fast_over_exact_cpu']:.1f}x"
            )
    elif ds is None:
        lines.append("  paper data set: core.pipeline.paper_dataset not importable, skipped")
    return "\n".join(lines)

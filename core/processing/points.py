"""Point cloud from detections (SPEC §3, steps 6-7) and ground-truth labels."""

from __future__ import annotations

import functools

import numba
import numpy as np

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)
from core.config import DEFAULT_PROCESSING, ProcessingSettings, RadarConfig
from core.pointcloud import SOURCE_OTHER, PointCloud
from core.processing import angle as _angle
from core.processing.angle import (
    azimuth_row,
    elevation_pairs,
    estimate_angles,
    log_parabolic_offset,
)
from core.processing.cfar import Detections


def refine_bins(rd_map: np.ndarray, det: Detections) -> tuple[np.ndarray, np.ndarray]:
    """Fractional range bin and Doppler bin (zero velocity = 0) of each detection.

    A parabola through the log power of the peak and its two neighbours, along range (no
    interpolation at the axis ends) and along Doppler (cyclic).
    """
    rd = np.asarray(rd_map, dtype=np.float64)
    n_r, n_d = rd.shape
    r, d = det.range_bin, det.doppler_index
    inner = (r > 0) & (r < n_r - 1)
    rl, rh = np.clip(r - 1, 0, n_r - 1), np.clip(r + 1, 0, n_r - 1)
    dr = np.where(inner, log_parabolic_offset(rd[rl, d], rd[r, d], rd[rh, d]), 0.0)
    dd = log_parabolic_offset(rd[r, (d - 1) % n_d], rd[r, d], rd[r, (d + 1) % n_d])
    return r + dr, d - n_d // 2 + dd


def build_point_cloud(
    doppler_cube: np.ndarray,
    rd_map: np.ndarray,
    det: Detections,
    radar: RadarConfig,
    settings: ProcessingSettings = DEFAULT_PROCESSING,
    *,
    elevation: bool = False,
    compensate_tdm: bool = True,
) -> PointCloud:
    """Points (range, angles, radial velocity, SNR, Cartesian position) of the detections.

    Parameters
    ----------
    doppler_cube
        ``[virtual channel, range bin, Doppler bin]`` complex, zero velocity centred.
    rd_map
        ``[range bin, Doppler bin]`` power.
    det
        Detections of :func:`core.processing.two_stage_cfar`.
    elevation
        Estimate elevation (non-planar scenes); otherwise elevation and ``z`` are 0.

    Returns
    -------
    PointCloud
        ``source`` is :data:`~core.pointcloud.SOURCE_OTHER` for every point; the simulator sets
        the ground truth with :func:`label_sources`.
    """
    if len(det) == 0:
        return PointCloud.empty()
    r_bin, d_bin = refine_bins(rd_map, det)
    channels = np.asarray(doppler_cube)[:, det.range_bin, det.doppler_index].T
    az, el = estimate_angles(
        channels,
        d_bin,
        radar,
        fft_size=settings.angle_fft_size,
        elevation=elevation,
        compensate_tdm=compensate_tdm,
    )
    rng_m = r_bin * radar.range_resolution_m
    vr = d_bin * radar.velocity_resolution_mps
    horiz = rng_m * np.cos(el)
    return PointCloud(
        range_m=rng_m,
        azimuth_rad=az,
        elevation_rad=el,
        radial_velocity_mps=vr,
        snr_db=det.snr_db,
        x_m=horiz * np.sin(az),
        y_m=horiz * np.cos(az),
        z_m=rng_m * np.sin(el),
        source=np.full(len(det), SOURCE_OTHER, dtype=np.int32),
    )


def label_sources(
    range_m: np.ndarray,
    radial_velocity_mps: np.ndarray,
    reflector_range_m: np.ndarray,
    reflector_velocity_mps: np.ndarray,
    reflector_source: np.ndarray,
    radar: RadarConfig,
) -> np.ndarray:
    """Ground-truth label of each point: the source of the nearest reflector within one cell.

    A point matches a reflector when their ranges differ by at most one range bin and their
    radial velocities by at most one velocity bin modulo ``2 v_max`` (Doppler aliasing). Among
    matches the nearest in bin units wins; unmatched points get ``SOURCE_OTHER`` (-2).

    Returns
    -------
    numpy.ndarray
        ``(n_points,)`` int32.
    """
    n = len(range_m)
    out = np.full(n, SOURCE_OTHER, dtype=np.int32)
    if n == 0 or len(reflector_range_m) == 0:
        return out
    dr = (np.asarray(range_m)[:, None] - np.asarray(reflector_range_m)[None, :]) / (
        radar.range_resolution_m
    )
    span = 2 * radar.max_velocity_mps
    dv = np.asarray(radial_velocity_mps)[:, None] - np.asarray(reflector_velocity_mps)[None, :]
    dv = (dv + span / 2) % span - span / 2
    dv /= radar.velocity_resolution_mps
    ok = (np.abs(dr) <= 1.0) & (np.abs(dv) <= 1.0)
    dist = np.where(ok, dr**2 + dv**2, np.inf)
    best = np.argmin(dist, axis=1)
    hit = ok[np.arange(n), best]
    out[hit] = np.asarray(reflector_source)[best[hit]]
    return out


# ---- compiled: refinement, angles and labels for a handful of detections ----------------------
# The same maths as refine_bins, estimate_angles (log-parabolic peak refinement, TDM-MIMO
# compensation, zero-padded azimuth DFT, elevation from the elevated row) and label_sources,
# without numpy's per-call overhead on a few points; tests hold them equal (1e-9).
@numba.njit(cache=True, nogil=True)
def _log_parabola(a, b, c):  # pragma: no cover
    tiny = 2.2250738585072014e-308
    la = np.log(max(a, tiny))
    lb = np.log(max(b, tiny))
    lc = np.log(max(c, tiny))
    # delta = (a - c) / (2 (a - 2b + c))
    den = la - 2.0 * lb + lc
    if den < 0:
        delta = 0.5 * (la - lc) / den
        if not np.isfinite(delta):
            delta = 0.0
    else:
        delta = 0.0
    return min(0.5, max(-0.5, delta))


@numba.njit(cache=True, nogil=True)
def angles_of(
    x, db, n_tx, n_rx, n_loops, row_ch, row_pos, upper, lower, tw_a, elevation, spec
):  # pragma: no cover
    """Azimuth and elevation of one cell's channel values ``x`` (L,), the chain's step 6.

    TDM-MIMO compensation with the (refined) Doppler bin ``db``, zero-padded DFT of the azimuth
    row, log-parabolic peak refinement, elevation from the elevated pairs. ``spec`` is a work
    array of ``fft_size``; ``tw_a`` ``(fft_size, n_row)`` the DFT's twiddles
    ``exp(-j 2 pi (j - N/2) p / N)`` (:func:`angle_twiddles`).
    """
    fft_size = tw_a.shape[0]
    n_v = x.shape[0]
    # x_v exp(-j 2 pi d k(v) / (Nc Ntx))
    xc = np.empty(n_v, dtype=np.complex128)
    for v in range(n_v):
        xc[v] = x[v] * np.exp(-2j * np.pi * db * (v // n_rx) / (n_loops * n_tx))
    # spec[j] = |sum_p x_p exp(-j 2 pi (j - N/2) p / N)|^2  (fftshifted)
    best = 0
    for j in range(fft_size):
        acc = 0.0 + 0.0j
        for q in range(row_ch.shape[0]):
            acc += xc[row_ch[q]] * tw_a[j, q]
        spec[j] = acc.real**2 + acc.imag**2
        if spec[j] > spec[best]:
            best = j
    delta = _log_parabola(spec[(best - 1) % fft_size], spec[best], spec[(best + 1) % fft_size])
    # u = sin(az) cos(el) = 2 (k - N/2 + delta) / N
    u = 2.0 * (best - fft_size // 2 + delta) / fft_size
    e = 0.0
    if elevation and upper.shape[0] > 0:
        z = 0.0 + 0.0j
        for q in range(upper.shape[0]):
            z += xc[upper[q]] * np.conj(xc[lower[q]])
        # sin(el) = arg(sum x_upper conj(x_lower)) / pi
        e = np.arcsin(min(1.0, max(-1.0, np.angle(z) / np.pi)))
    return np.arcsin(min(1.0, max(-1.0, u / np.cos(e)))), e


@numba.njit(cache=True, nogil=True)
def points_kernel(
    rd, r, d, x, n_tx, n_rx, row_ch, row_pos, upper, lower, tw_a, elevation
):  # pragma: no cover
    n_r, n_d = rd.shape
    n_det = r.shape[0]
    r_bin = np.empty(n_det)
    d_bin = np.empty(n_det)
    az = np.empty(n_det)
    el = np.zeros(n_det)
    spec = np.empty(tw_a.shape[0])
    for i in range(n_det):
        ri, di = r[i], d[i]
        dr = 0.0
        if 0 < ri < n_r - 1:
            dr = _log_parabola(
                np.float64(rd[ri - 1, di]), np.float64(rd[ri, di]), np.float64(rd[ri + 1, di])
            )
        dd = _log_parabola(
            np.float64(rd[ri, (di - 1) % n_d]),
            np.float64(rd[ri, di]),
            np.float64(rd[ri, (di + 1) % n_d]),
        )
        r_bin[i] = ri + dr
        db = di - n_d // 2 + dd
        d_bin[i] = db
        az[i], el[i] = angles_of(
            x[i], db, n_tx, n_rx, n_d, row_ch, row_pos, upper, lower, tw_a, elevation, spec
        )
    return r_bin, d_bin, az, el


@functools.lru_cache(maxsize=16)
def angle_twiddles(radar: RadarConfig, fft_size: int) -> np.ndarray:
    """``exp(-j 2 pi (j - N/2) p / N)`` for the azimuth row, ``(fft_size, n_row)`` complex128."""
    _, row_pos = _azimuth_rows(radar)
    j = np.arange(fft_size)[:, None] - fft_size // 2
    out = np.exp(-2j * np.pi * ((j * row_pos[None, :]) % fft_size) / fft_size)
    out.flags.writeable = False
    return out


def detection_rows(radar: RadarConfig, elevation: bool):
    """:func:`array_rows`; without elevation the elevation pairs are empty (not looked up)."""
    row_ch, row_pos = _azimuth_rows(radar)
    if elevation:
        # looked up through the module on every call (elevation processing is observable)
        upper, lower = _angle.elevation_pairs(radar)
        return row_ch, row_pos, upper.astype(np.int64), lower.astype(np.int64)
    e = np.zeros(0, dtype=np.int64)
    return row_ch, row_pos, e, e


@functools.lru_cache(maxsize=16)
def _azimuth_rows(radar: RadarConfig):
    row_ch, row_pos = azimuth_row(radar)
    return row_ch.astype(np.int64), row_pos.astype(np.int64)


@functools.lru_cache(maxsize=16)
def array_rows(radar: RadarConfig) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The virtual array's azimuth row (channels, positions) and elevation pairs (upper, lower),
    as int64 arrays for the compiled angle estimate."""
    row_ch, row_pos = azimuth_row(radar)
    upper, lower = elevation_pairs(radar)
    return (
        row_ch.astype(np.int64),
        row_pos.astype(np.int64),
        upper.astype(np.int64),
        lower.astype(np.int64),
    )


@numba.njit(cache=True, nogil=True)
def _label_kernel(range_m, vr_m, pos, vel, source, t_mid, res_r, res_v, span):  # pragma: no cover
    """:func:`label_sources` with reflectors at mid-frame ``t_mid``, compiled."""
    n = range_m.shape[0]
    n_s = pos.shape[0]
    out = np.full(n, -2, dtype=np.int32)
    r_ref = np.empty(n_s)
    v_ref = np.empty(n_s)
    for s in range(n_s):
        p0 = pos[s, 0] + vel[s, 0] * t_mid
        p1 = pos[s, 1] + vel[s, 1] * t_mid
        p2 = pos[s, 2] + vel[s, 2] * t_mid
        r_ref[s] = np.sqrt(p0 * p0 + p1 * p1 + p2 * p2)
        # v_r = p(t_mid) . v / |p(t_mid)|
        v_ref[s] = (p0 * vel[s, 0] + p1 * vel[s, 1] + p2 * vel[s, 2]) / r_ref[s]
    for i in range(n):
        best = np.inf
        for s in range(n_s):
            dr = (range_m[i] - r_ref[s]) / res_r
            # radial velocities compared modulo 2 v_max (Doppler aliasing)
            dv = ((vr_m[i] - v_ref[s]) + span / 2) % span - span / 2
            dv /= res_v
            if abs(dr) <= 1.0 and abs(dv) <= 1.0:
                dist = dr * dr + dv * dv
                if dist < best:
                    best = dist
                    out[i] = source[s]
    return out


@numba.njit(cache=True, nogil=True, error_model="numpy")
def point_rows(
    rd, r, d, nz, x, n_tx, n_rx, row_ch, row_pos, upper, lower, tw_a, elevation, pos, vel,
    source, t_mid, res_r, res_v, span,
):  # fmt: skip  # pragma: no cover
    """Points of detections ``(r, d)`` with range-stage noise ``nz`` and channel values ``x``.

    Returns ``f64`` ``(n, 8)`` (range, azimuth, elevation, radial velocity, SNR, x, y, z) and
    the labels ``(n,)`` int32 from the reflectors ``pos``/``vel``/``source`` at ``t_mid``.
    A zero noise estimate (noise-free maps) gives an infinite SNR, as numpy's division does.
    """
    n_det = r.shape[0]
    f64 = np.empty((n_det, 8))
    r_bin, d_bin, az, el = points_kernel(
        rd, r, d, x, n_tx, n_rx, row_ch, row_pos, upper, lower, tw_a, elevation
    )
    for i in range(n_det):
        rng_m = r_bin[i] * res_r
        horiz = rng_m * np.cos(el[i])
        f64[i, 0] = rng_m
        f64[i, 1] = az[i]
        f64[i, 2] = el[i]
        f64[i, 3] = d_bin[i] * res_v
        # SNR = 10 log10(P / noise estimate)
        f64[i, 4] = 10 * np.log10(np.float64(rd[r[i], d[i]]) / nz[i])
        f64[i, 5] = horiz * np.sin(az[i])
        f64[i, 6] = horiz * np.cos(az[i])
        f64[i, 7] = rng_m * np.sin(el[i])
    src = _label_kernel(f64[:, 0], f64[:, 3], pos, vel, source, t_mid, res_r, res_v, span)
    return f64, src


def cloud_from_rows(f64: np.ndarray, source: np.ndarray) -> PointCloud:
    """The :class:`PointCloud` of :func:`point_rows` output: ``f64`` ``(n, 8)`` (range, azimuth,
    elevation, radial velocity, SNR, x, y, z) and ``source`` ``(n,)`` int32 (copied)."""
    c = [f64[:, k].copy() for k in range(8)]
    return PointCloud(
        range_m=c[0], azimuth_rad=c[1], elevation_rad=c[2], radial_velocity_mps=c[3],
        snr_db=c[4], x_m=c[5], y_m=c[6], z_m=c[7], source=np.array(source, dtype=np.int32),
    )  # fmt: skip


def labelled_points(
    rd_map: np.ndarray,
    det: Detections,
    channels: np.ndarray,
    radar: RadarConfig,
    settings: ProcessingSettings = DEFAULT_PROCESSING,
    *,
    elevation: bool = False,
    reflector_position_m: np.ndarray | None = None,
    reflector_velocity_mps: np.ndarray | None = None,
    reflector_source: np.ndarray | None = None,
    t_mid_s: float = 0.0,
) -> PointCloud:
    """:func:`build_point_cloud` and :func:`label_sources` in one compiled call.

    Parameters
    ----------
    channels
        ``(n_det, n_virtual)`` complex channel values of the detected cells.
    reflector_position_m, reflector_velocity_mps
        ``(N, 3)`` reflectors at the frame's start; they are labelled at ``t_mid_s`` (the
        middle of the frame's chirps), ``source`` ``(N,)`` their labels. None: no reflectors
        (every point ``SOURCE_OTHER``).

    The same arithmetic as the numpy functions up to floating-point order (tested: 1e-9 and
    the same labels).
    """
    if len(det) == 0:
        return PointCloud.empty()
    if reflector_position_m is None:
        pos = vel = np.zeros((0, 3))
        source = np.zeros(0, dtype=np.int32)
    else:
        pos = np.ascontiguousarray(reflector_position_m, dtype=np.float64)
        vel = np.ascontiguousarray(reflector_velocity_mps, dtype=np.float64)
        source = np.ascontiguousarray(reflector_source, dtype=np.int32)
    f64, src = point_rows(
        rd_map, det.range_bin, det.doppler_index, det.noise_power,
        np.ascontiguousarray(channels, dtype=np.complex128), radar.n_tx, radar.n_rx,
        *detection_rows(radar, bool(elevation)), angle_twiddles(radar, settings.angle_fft_size),
        bool(elevation),
        pos, vel, source, float(t_mid_s), radar.range_resolution_m,
        radar.velocity_resolution_mps, 2 * radar.max_velocity_mps,
    )  # fmt: skip
    return cloud_from_rows(f64, src)

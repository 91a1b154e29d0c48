"""TI's detection chains as recipes over the shared stages (docs/radar-chain.md, "Chains").

- ``paper``: section 3 (:func:`core.simulation.frame.process_windowed_cube`), unchanged.
- ``oob`` (:func:`oob_points`), TI's out-of-box demo: range and Doppler FFTs
  (:mod:`core.processing.spectrum`), static clutter removal if ``clutterRemoval`` asks, the
  non-coherent range-Doppler map, CFAR along range and along Doppler in dB
  (:func:`core.processing.db_cfar.db_cfar`, ``cfarCfg``) with peak grouping, range and
  Doppler limits (``cfarFovCfg``), the azimuth FFT and the elevation phase at each detection
  (:mod:`core.processing.angle`), a second point where the azimuth spectrum has a second peak
  (``multiObjBeamForming``), angle limits (``aoaFovCfg``).
- ``people-counting`` (:func:`people_counting_points`), TI's 3-D people counting: range FFT,
  static clutter removal, Capon beamforming of the azimuth row into a range-azimuth map
  (:mod:`core.processing.capon`, ``dynamicRangeAngleCfg``), two-pass CFAR on it
  (:func:`core.processing.db_cfar.ra_cfar`, ``dynamicRACfarCfg``), per point a Capon search
  over elevation on the whole array (``dynamic2DAngleCfg``) and the Doppler of the MVDR beam
  (Doppler FFT of the beamformed range bin, its peak); plus the static chain
  (``staticRangeAngleCfg``, ``staticRACfarCfg``): the mean over the frame's chirps, without
  clutter removal, Bartlett beamformed on a coarser grid, CFAR, points with zero Doppler.
"""

from __future__ import annotations

import numpy as np

from core.config import OobSettings, PeopleCountingSettings, ProcessingSettings, RadarConfig
from core.pointcloud import SOURCE_OTHER, PointCloud
from core.processing.angle import (
    azimuth_power,
    azimuth_row,
    elevation_sines,
    log_parabolic_offset,
    tdm_compensate,
)
from core.processing.capon import (
    capon_spectrum_lags,
    capon_weights,
    covariance_and_mean,
    loaded_inverse,
    spatial_covariance,
    steering,
)
from core.processing.cfar import Detections
from core.processing.db_cfar import db_cfar, ra_cfar
from core.processing.points import label_sources, refine_bins
from core.processing.spectrum import doppler_matrix

__all__ = ["ChainPoints", "label_points", "oob_points", "people_counting_points"]

#: What a chain recipe returns: the points (``source`` not yet labelled) and the detected
#: cells ``(n_det, 2)`` int64 (range bin, Doppler index for ``oob``; range bin, angle index
#: for ``people-counting``).
ChainPoints = tuple[PointCloud, np.ndarray]


def _range_limits(radar: RadarConfig, n_r: int, lo_m: float, hi_m: float) -> tuple[int, int]:
    k = np.arange(n_r) * radar.range_resolution_m
    inside = np.flatnonzero((k >= lo_m) & (k <= hi_m))
    if inside.size == 0:
        return 1, 0
    return int(inside[0]), int(inside[-1])


def _cloud(rng_m, az, el, vr, snr_db) -> PointCloud:
    rng_m = np.asarray(rng_m, dtype=np.float64)
    az, el = np.asarray(az, dtype=np.float64), np.asarray(el, dtype=np.float64)
    horiz = rng_m * np.cos(el)
    return PointCloud(
        range_m=rng_m,
        azimuth_rad=az,
        elevation_rad=el,
        radial_velocity_mps=np.asarray(vr, dtype=np.float64),
        snr_db=np.asarray(snr_db, dtype=np.float64),
        x_m=horiz * np.sin(az),
        y_m=horiz * np.cos(az),
        z_m=rng_m * np.sin(el),
        source=np.full(len(rng_m), SOURCE_OTHER, dtype=np.int32),
    )


# ---- oob ----------------------------------------------------------------------------------------
def oob_points(
    doppler_cube: np.ndarray,
    rd_map: np.ndarray,
    radar: RadarConfig,
    oob: OobSettings,
    settings: ProcessingSettings,
    *,
    elevation: bool,
) -> ChainPoints:
    """The out-of-box demo's detection half on a Doppler cube and its range-Doppler map.

    Parameters
    ----------
    doppler_cube
        ``[virtual channel, range bin, Doppler bin]``, zero velocity centred (with static
        clutter removal if ``oob.static_clutter_removal``).
    rd_map
        ``[range bin, Doppler bin]`` non-coherent power sum.
    settings
        Range limits (``min_range_m``, ``max_range_m``: the scene's) and the azimuth FFT size.
    """
    rd = np.asarray(rd_map, dtype=np.float64)
    n_r, n_d = rd.shape
    rd_db = 10 * np.log10(np.maximum(rd, np.finfo(np.float64).tiny))
    range_ok, noise_db = db_cfar(rd_db, 0, oob.range_cfar)
    doppler_ok, _ = db_cfar(rd_db, 1, oob.doppler_cfar)
    mask = range_ok & doppler_ok
    lo, hi = _range_limits(
        radar,
        n_r,
        max(settings.min_range_m, oob.min_range_m),
        min(settings.max_range_m, oob.max_range_m),
    )
    keep = np.zeros_like(mask)
    if hi >= lo:
        keep[lo : hi + 1] = True
    vel = (np.arange(n_d) - n_d // 2) * radar.velocity_resolution_mps
    keep &= ((vel >= oob.min_velocity_mps) & (vel <= oob.max_velocity_mps))[None, :]
    r, d = np.nonzero(mask & keep)
    if r.size == 0:
        return PointCloud.empty(), np.zeros((0, 2), dtype=np.int64)
    det = Detections(
        range_bin=r, doppler_index=d, power=rd[r, d], noise_power=10 ** (noise_db[r, d] / 10)
    )
    r_bin, d_bin = refine_bins(rd, det)
    x = np.asarray(doppler_cube)[:, r, d].T.astype(np.complex128)
    x = tdm_compensate(x, d_bin, radar)
    n_fft = settings.angle_fft_size
    power = azimuth_power(x, radar, n_fft)
    idx = np.arange(len(r))
    w = elevation_sines(x, radar) if elevation else np.zeros(len(r))
    el = np.arcsin(w)

    def azimuth_at(k: np.ndarray) -> np.ndarray:
        delta = log_parabolic_offset(
            power[idx, (k - 1) % n_fft], power[idx, k], power[idx, (k + 1) % n_fft]
        )
        k_signed = np.where(k >= n_fft // 2, k - n_fft, k)
        # u = sin(az) cos(el) = 2 (k + delta) / N
        u = 2.0 * (k_signed + delta) / n_fft
        return np.arcsin(np.clip(u / np.cos(el), -1.0, 1.0))

    k1 = np.argmax(power, axis=1)
    rows = [(idx, azimuth_at(k1))]
    if oob.multi_object_threshold is not None:
        # the second peak: the strongest local maximum other than the first
        peaks = (power >= np.roll(power, 1, axis=1)) & (power >= np.roll(power, -1, axis=1))
        peaks[idx, k1] = False
        masked = np.where(peaks, power, -np.inf)
        k2 = np.argmax(masked, axis=1)
        second = masked[idx, k2] >= oob.multi_object_threshold * power[idx, k1]
        if second.any():
            rows.append((idx[second], azimuth_at(k2)[second]))
    sel = np.concatenate([i for i, _ in rows])
    az = np.concatenate([a for _, a in rows])
    snr = rd_db[r, d] - noise_db[r, d]
    pc = _cloud(
        r_bin[sel] * radar.range_resolution_m,
        az,
        el[sel],
        d_bin[sel] * radar.velocity_resolution_mps,
        snr[sel],
    )
    az_deg, el_deg = np.degrees(pc.azimuth_rad), np.degrees(pc.elevation_rad)
    fov = (
        (az_deg >= oob.azimuth_fov_deg[0])
        & (az_deg <= oob.azimuth_fov_deg[1])
        & (el_deg >= oob.elevation_fov_deg[0])
        & (el_deg <= oob.elevation_fov_deg[1])
    )
    cells = np.column_stack((r[sel], d[sel])).astype(np.int64)
    return _subset(pc, fov), cells[fov]


def _subset(pc: PointCloud, keep: np.ndarray) -> PointCloud:
    if keep.all():
        return pc
    return PointCloud(
        **{
            f: getattr(pc, f)[keep]
            for f in (
                "range_m",
                "azimuth_rad",
                "elevation_rad",
                "radial_velocity_mps",
                "snr_db",
                "x_m",
                "y_m",
                "z_m",
                "source",
            )
        }
    )


# ---- people counting ----------------------------------------------------------------------------
def angle_grid(half_width_deg: float, step_deg: float) -> np.ndarray:
    """Angles ``-h, -h + step, ..., <= h`` in radians (a grid symmetric about 0 when ``h`` is a
    multiple of ``step``)."""
    n = int(np.floor(half_width_deg / step_deg + 1e-9))
    return np.radians(np.arange(-n, n + 1) * step_deg)


def _refine(p_left: np.ndarray, p_peak: np.ndarray, p_right: np.ndarray) -> np.ndarray:
    return log_parabolic_offset(p_left, p_peak, p_right)


def _grid_peak(spec: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """Interpolated location of each row's maximum on a uniform ``grid`` (rows of ``spec``)."""
    n = spec.shape[1]
    if n == 1:
        return np.full(spec.shape[0], grid[0])
    i = np.argmax(spec, axis=1)
    rows = np.arange(spec.shape[0])
    inner = (i > 0) & (i < n - 1)
    il, ih = np.clip(i - 1, 0, n - 1), np.clip(i + 1, 0, n - 1)
    delta = np.where(inner, _refine(spec[rows, il], spec[rows, i], spec[rows, ih]), 0.0)
    return grid[i] + delta * (grid[1] - grid[0])


def _elevation_search(
    cov: np.ndarray,
    radar: RadarConfig,
    u: np.ndarray,
    el_grid: np.ndarray,
    loading: float | None,
) -> np.ndarray:
    """Elevation of each detection: the peak over ``el_grid`` of the Capon (``loading`` given)
    or Bartlett (None) spectrum of the whole array at fixed ``u = sin(az) cos(el)``.

    ``cov``: ``(n_det, N, N)``; returns ``(n_det,)`` radians."""
    a = np.asarray(radar.azimuth_positions, dtype=np.float64)
    e = np.asarray(radar.elevation_positions, dtype=np.float64)
    w = np.sin(el_grid)
    # s[d, j, v] = exp(j pi (a_v u_d + e_v w_j))
    s = np.exp(1j * np.pi * (u[:, None, None] * a[None, None, :] + w[None, :, None] * e))
    q_mat = cov if loading is None else loaded_inverse(cov, loading)
    # s^H Q s for every detection d and elevation j
    q = np.sum(np.matmul(np.conj(s), q_mat) * s, axis=2).real
    spec = q if loading is None else 1.0 / np.maximum(q, np.finfo(np.float64).tiny)
    return _grid_peak(spec, el_grid)


def people_counting_points(
    range_cube: np.ndarray,
    radar: RadarConfig,
    pc: PeopleCountingSettings,
    settings: ProcessingSettings,
    *,
    elevation: bool,
) -> ChainPoints:
    """TI's 3-D people counting detection on a range cube: dynamic points, then static ones.

    Parameters
    ----------
    range_cube
        ``[virtual channel, loop, range bin]`` complex, no clutter removal (range bins from 0;
        those beyond ``settings.max_range_m`` plus the CFAR window are not looked at).
    settings
        Range limits (the scene's), the Doppler window of the per-point Doppler FFT.
    elevation
        Search elevation (non-planar scenes on an array with elevated channels).
    """
    x = np.asarray(range_cube)
    n_v, n_loops, n_all = x.shape
    cf = pc.dynamic_cfar
    last = int(np.floor(settings.max_range_m / radar.range_resolution_m))
    margin = max(
        cf.ref_range + cf.guard_range, pc.static_cfar.ref_range + pc.static_cfar.guard_range
    )
    n_r = int(min(n_all, last + 1 + margin))
    x = x[:, :, :n_r]
    lo, hi = _range_limits(radar, n_r, settings.min_range_m, settings.max_range_m)
    row_ch, row_pos = azimuth_row(radar)
    row_zero = np.zeros(len(row_pos))
    search_el = elevation and radar.has_elevation and pc.elevation_fov_deg > 0
    clouds, cells = [], []
    # the azimuth row's clutter-removed covariance per range bin; every channel's mean
    cov_row, _ = covariance_and_mean(x[row_ch])
    mean = x.mean(axis=1, dtype=np.complex128).T  # [range, channel]

    # -- dynamic: Capon range-azimuth map of the azimuth row, CFAR, elevation, Doppler --
    u_grid = np.sin(angle_grid(pc.azimuth_fov_deg, pc.angle_step_deg))
    ra = capon_spectrum_lags(cov_row, tuple(int(p) for p in row_pos), u_grid, pc.diagonal_loading)
    det = ra_cfar(ra, cf, lo, hi)
    if len(det):
        r, a = det.range_bin, det.angle_index
        u = _grid_peak_at(ra, r, a, u_grid)
        if search_el:
            el_grid = angle_grid(pc.elevation_fov_deg, pc.elevation_step_deg)
            # the whole array's clutter-removed covariance at the detected range bins
            xr_all = x[:, :, r] - mean[r].T[:, None, :]  # [ch, loop, det]
            cov = spatial_covariance(xr_all)
            el = _elevation_search(cov, radar, u, el_grid, pc.elevation_loading)
        else:
            el = np.zeros(len(r))
        az = np.arcsin(np.clip(u / np.cos(el), -1.0, 1.0))
        # Doppler of the MVDR beam: y[m] = w^H (x[:, m, k] - xbar_k); its Doppler FFT and peak
        inv = loaded_inverse(cov_row[r], pc.diagonal_loading)
        wts = capon_weights(inv, steering(row_pos, row_zero, u, np.zeros(len(u))))
        xr = x[row_ch][:, :, r] - mean[r][:, row_ch].T[:, None, :]  # [ch, loop, det]
        y = np.einsum("dc,cmd->dm", np.conj(wts), xr)
        m = doppler_matrix(settings.doppler_window, n_loops, False)
        spec = np.abs(y @ m.T.astype(np.complex128)) ** 2  # (n_det, Doppler index)
        j = np.argmax(spec, axis=1)
        rows = np.arange(len(r))
        dd = _refine(spec[rows, (j - 1) % n_loops], spec[rows, j], spec[rows, (j + 1) % n_loops])
        vr = (j - n_loops // 2 + dd) * radar.velocity_resolution_mps
        rr = _range_refine(ra, r, a)
        clouds.append(_cloud(rr * radar.range_resolution_m, az, el, vr, det.snr_db))
        cells.append(np.column_stack((r, a)))

    # -- static: the frame's mean (zero Doppler), Bartlett on a coarser grid, CFAR --
    if pc.static_enabled:
        us = np.sin(
            angle_grid(pc.azimuth_fov_deg, pc.angle_step_deg * pc.static_azimuth_decimation)
        )
        ss = steering(row_pos, row_zero, us, np.zeros(len(us)))
        # P[k, i] = |s_i^H xbar_k|^2 / N^2
        beam = mean[:, row_ch] @ np.conj(ss).T  # [range, angle]
        ra_s = np.abs(beam) ** 2 / len(row_pos) ** 2
        det_s = ra_cfar(ra_s, pc.static_cfar, lo, hi)
        if len(det_s):
            r, a = det_s.range_bin, det_s.angle_index
            u = _grid_peak_at(ra_s, r, a, us)
            if search_el:
                v = mean[r]  # (n_det, N)
                cov = v[:, :, None] * np.conj(v[:, None, :])
                step = pc.elevation_step_deg * pc.static_elevation_decimation
                el = _elevation_search(cov, radar, u, angle_grid(pc.elevation_fov_deg, step), None)
            else:
                el = np.zeros(len(r))
            az = np.arcsin(np.clip(u / np.cos(el), -1.0, 1.0))
            rr = _range_refine(ra_s, r, a)
            clouds.append(
                _cloud(rr * radar.range_resolution_m, az, el, np.zeros(len(r)), det_s.snr_db)
            )
            cells.append(np.column_stack((r, a)))
    if not clouds:
        return PointCloud.empty(), np.zeros((0, 2), dtype=np.int64)
    return PointCloud.concatenate(clouds), np.concatenate(cells).astype(np.int64)


def _grid_peak_at(spec: np.ndarray, r: np.ndarray, a: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """Interpolated grid value at detected cells ``(r, a)`` of ``spec[range, angle]``."""
    n = spec.shape[1]
    inner = (a > 0) & (a < n - 1)
    al, ah = np.clip(a - 1, 0, n - 1), np.clip(a + 1, 0, n - 1)
    delta = np.where(inner, _refine(spec[r, al], spec[r, a], spec[r, ah]), 0.0)
    step = grid[1] - grid[0] if len(grid) > 1 else 0.0
    return grid[a] + delta * step


def _range_refine(spec: np.ndarray, r: np.ndarray, a: np.ndarray) -> np.ndarray:
    """Fractional range bin of detected cells: log-parabola along range."""
    n = spec.shape[0]
    inner = (r > 0) & (r < n - 1)
    rl, rh = np.clip(r - 1, 0, n - 1), np.clip(r + 1, 0, n - 1)
    return r + np.where(inner, _refine(spec[rl, a], spec[r, a], spec[rh, a]), 0.0)


def label_points(
    pc: PointCloud,
    radar: RadarConfig,
    position_m: np.ndarray,
    velocity_mps: np.ndarray,
    source: np.ndarray,
) -> PointCloud:
    """``pc`` with ``source`` set from the reflectors at the middle of the frame's chirps
    (:func:`core.processing.points.label_sources`)."""
    if len(pc) == 0:
        return pc
    t_mid = 0.5 * radar.n_loops * radar.n_tx * radar.chirp_period_s
    p = np.asarray(position_m, dtype=np.float64) + np.asarray(velocity_mps) * t_mid
    rng = np.sqrt(np.sum(p**2, axis=1))
    with np.errstate(invalid="ignore", divide="ignore"):
        vr = np.where(rng > 0, np.sum(p * velocity_mps, axis=1) / rng, 0.0)
    labels = label_sources(pc.range_m, pc.radial_velocity_mps, rng, vr, source, radar)
    return PointCloud(
        **{
            f: getattr(pc, f)
            for f in (
                "range_m",
                "azimuth_rad",
                "elevation_rad",
                "radial_velocity_mps",
                "snr_db",
                "x_m",
                "y_m",
                "z_m",
            )
        },
        source=labels,
    )

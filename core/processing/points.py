"""Point cloud from detections (SPEC §3, steps 6-7) and ground-truth labels."""

from __future__ import annotations

import numpy as np

from core.config import DEFAULT_PROCESSING, ProcessingSettings, RadarConfig
from core.pointcloud import SOURCE_OTHER, PointCloud
from core.processing.angle import estimate_angles, log_parabolic_offset
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

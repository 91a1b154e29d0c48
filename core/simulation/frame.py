"""One radar frame through the whole exact chain: scatterers -> point cloud."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from core.config import DEFAULT_PROCESSING, ProcessingSettings, RadarConfig
from core.pointcloud import PointCloud
from core.processing import (
    build_point_cloud,
    doppler_fft,
    label_sources,
    range_doppler_map,
    range_fft,
    remove_static_clutter,
    two_stage_cfar,
)
from core.simulation.antenna import AntennaGain
from core.simulation.baseband import synthesize_noise, synthesize_signal
from core.simulation.scatterers import Scatterers


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class FrameOutput:
    """Result of :func:`simulate_frame`.

    Attributes
    ----------
    point_cloud
        Detections with ground-truth ``source`` labels.
    rd_map_db
        ``[range bin (n_samples), Doppler bin (n_loops)]`` float32, ``10 log10`` of the
        non-coherent sum (V²), zero velocity centred; None unless ``keep_rd_map=True``.
    detections
        ``(n_det, 2)`` int: range bin, Doppler index into ``rd_map_db``.
    """

    point_cloud: PointCloud
    rd_map_db: np.ndarray | None
    detections: np.ndarray


def needs_elevation(radar: RadarConfig, scatterers: Scatterers) -> bool:
    """Elevation processing runs only for non-planar scenes on an array that can measure it."""
    return radar.has_elevation and not scatterers.is_planar


def simulate_frame(
    radar: RadarConfig,
    scatterers: Scatterers,
    rng: np.random.Generator,
    *,
    antenna: AntennaGain,
    settings: ProcessingSettings = DEFAULT_PROCESSING,
    keep_rd_map: bool = False,
    elevation: bool | None = None,
    noise: bool = True,
) -> FrameOutput:
    """Simulate one frame: exact baseband, range FFT, clutter removal, Doppler FFT, CFAR, angles.

    Parameters
    ----------
    radar, scatterers, rng, antenna
        Configuration, reflectors of the frame, noise source, antenna gain realisation.
    settings
        Processing settings (windows, CFAR, range limits).
    keep_rd_map
        Return the range-Doppler map in dB (for the GUI); otherwise None.
    elevation
        Estimate elevation; None decides from the scene (:func:`needs_elevation`).
    noise
        Add receiver noise (switch off only for noise-free tests).
    """
    cube = synthesize_signal(radar, scatterers, antenna)
    if noise:
        cube += synthesize_noise(radar, rng)
    rc = range_fft(cube, settings.range_window)
    if settings.static_clutter_removal:
        rc = remove_static_clutter(rc)
    dc = doppler_fft(rc, settings.doppler_window)
    rd = range_doppler_map(dc)
    det = two_stage_cfar(rd, radar, settings)
    if elevation is None:
        elevation = needs_elevation(radar, scatterers)
    pc = build_point_cloud(dc, rd, det, radar, settings, elevation=elevation)
    if len(pc) and len(scatterers):
        # truth at the middle of the frame's chirps
        t_mid = 0.5 * radar.n_loops * radar.n_tx * radar.chirp_period_s
        pos = scatterers.position_m + scatterers.velocity_mps * t_mid
        r_mid = np.linalg.norm(pos, axis=1)
        vr = np.einsum("ij,ij->i", pos, scatterers.velocity_mps) / r_mid
        src = label_sources(pc.range_m, pc.radial_velocity_mps, r_mid, vr, scatterers.source, radar)
        pc = PointCloud(
            range_m=pc.range_m,
            azimuth_rad=pc.azimuth_rad,
            elevation_rad=pc.elevation_rad,
            radial_velocity_mps=pc.radial_velocity_mps,
            snr_db=pc.snr_db,
            x_m=pc.x_m,
            y_m=pc.y_m,
            z_m=pc.z_m,
            source=src,
        )
    rd_db = None
    if keep_rd_map:
        rd_db = (10 * np.log10(np.maximum(rd, np.finfo(np.float32).tiny))).astype(np.float32)
    return FrameOutput(
        point_cloud=pc,
        rd_map_db=rd_db,
        detections=np.column_stack((det.range_bin, det.doppler_index)).astype(np.int64),
    )

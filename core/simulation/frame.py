"""One radar frame through the whole exact chain: scatterers -> point cloud."""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.fft

from core.config import DEFAULT_PROCESSING, ProcessingSettings, RadarConfig
from core.pointcloud import PointCloud
from core.processing import (
    doppler_fft,
    range_azimuth_map,
    range_doppler_map,
    two_stage_cfar,
)
from core.processing.points import labelled_points
from core.processing.spectrum import window
from core.simulation.antenna import AntennaGain
from core.simulation.baseband import synthesize_signal
from core.simulation.gaussian import add_complex_noise
from core.simulation.link import noise_power_v2
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
    ra_map_db
        ``[range bin, angle index]`` float32 range-azimuth map in dB
        (:func:`core.processing.range_azimuth.range_azimuth_map`, angle index centred), kept
        with ``rd_map_db`` by the levels that have a Doppler cube (exact); None otherwise.
    synthesis_s, processing_s
        Wall-clock seconds of the frame's two halves where the level runs them apart (exact:
        baseband synthesis with noise, then FFTs, CFAR, angles and points); NaN where one
        kernel does both (fast, measurement). Not part of the result (not compared).
    """

    point_cloud: PointCloud
    rd_map_db: np.ndarray | None
    detections: np.ndarray
    ra_map_db: np.ndarray | None = None
    synthesis_s: float = field(default=math.nan, compare=False)
    processing_s: float = field(default=math.nan, compare=False)


def processed_range_bins(radar: RadarConfig, settings: ProcessingSettings) -> int:
    """Range bins ``0 .. n-1`` that the detector needs: up to ``max_range_m`` plus the range
    CFAR's guard and training cells (the map beyond is never looked at)."""
    last = int(np.floor(settings.max_range_m / radar.range_resolution_m))
    margin = settings.range_cfar.n_train + settings.range_cfar.n_guard
    return int(min(radar.n_samples, last + 1 + margin))


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
    t0 = time.perf_counter()
    cube = windowed_cube(radar, scatterers, rng, antenna=antenna, settings=settings, noise=noise)
    if elevation is None:
        elevation = needs_elevation(radar, scatterers)
    t1 = time.perf_counter()
    out = process_windowed_cube(
        cube, radar, scatterers, settings=settings, keep_rd_map=keep_rd_map, elevation=elevation
    )
    return dataclasses.replace(out, synthesis_s=t1 - t0, processing_s=time.perf_counter() - t1)


def windowed_cube(
    radar: RadarConfig,
    scatterers: Scatterers,
    rng: np.random.Generator,
    *,
    antenna: AntennaGain,
    settings: ProcessingSettings = DEFAULT_PROCESSING,
    noise: bool = True,
) -> np.ndarray:
    """The received cube of a frame with the range window applied: what every chain starts
    from (``[virtual channel, loop, ADC sample]`` complex64, C-contiguous)."""
    cube = synthesize_signal(radar, scatterers, antenna)
    # the range window is applied while the noise is added (one pass over the cube); the
    # transform then runs on the windowed cube
    w = window(settings.range_window, radar.n_samples)
    if noise:
        add_complex_noise(cube, noise_power_v2(radar), rng, window=w)
    elif settings.range_window != "rect":
        cube *= w
    return cube


def process_windowed_cube(
    cube: np.ndarray,
    radar: RadarConfig,
    scatterers: Scatterers,
    *,
    settings: ProcessingSettings = DEFAULT_PROCESSING,
    keep_rd_map: bool = False,
    elevation: bool = False,
) -> FrameOutput:
    """The processing half of the exact chain on a cube the range window was applied to.

    Range FFT (in place: ``cube`` is overwritten), static clutter removal and Doppler FFT, the
    range-Doppler map, then :func:`frame_from_spectrum`.

    Parameters
    ----------
    cube
        ``[virtual channel, loop, ADC sample]`` complex64, C-contiguous, windowed along samples.
    scatterers
        The frame's reflectors for the ``source`` labels (``Scatterers.empty()``: none known).
    """
    rc = scipy.fft.fft(cube, axis=-1, overwrite_x=True)
    if not keep_rd_map:
        # only the range bins the CFAR looks at (limits plus its training window)
        rc = rc[:, :, : processed_range_bins(radar, settings)]
    dc = doppler_fft(rc, settings.doppler_window, remove_static=settings.static_clutter_removal)
    rd = range_doppler_map(dc)
    return frame_from_spectrum(
        dc, rd, radar, scatterers, settings=settings, keep_rd_map=keep_rd_map, elevation=elevation
    )


def process_cube(
    cube: np.ndarray,
    radar: RadarConfig,
    *,
    settings: ProcessingSettings = DEFAULT_PROCESSING,
    keep_rd_map: bool = False,
    elevation: bool = False,
    scatterers: Scatterers | None = None,
) -> FrameOutput:
    """The processing half of the exact chain on a received (e.g. recorded) baseband cube.

    The range window, then :func:`process_windowed_cube`: what :func:`simulate_frame` does after
    synthesising the cube, one definition for both.

    Parameters
    ----------
    cube
        ``[virtual channel, loop, ADC sample]`` complex (volts or ADC counts: the chain is
        scale-free), not modified.
    scatterers
        Reflectors for the ``source`` labels; None: every point ``SOURCE_OTHER``.
    """
    # x_w[v, m, n] = x[v, m, n] w[n]
    w = window(settings.range_window, radar.n_samples)
    windowed = np.multiply(cube, w, dtype=np.complex64)
    return process_windowed_cube(
        windowed,
        radar,
        Scatterers.empty() if scatterers is None else scatterers,
        settings=settings,
        keep_rd_map=keep_rd_map,
        elevation=elevation,
    )


def frame_from_spectrum(
    doppler_cube: np.ndarray,
    rd_map: np.ndarray,
    radar: RadarConfig,
    scatterers: Scatterers,
    *,
    settings: ProcessingSettings = DEFAULT_PROCESSING,
    keep_rd_map: bool = False,
    elevation: bool = False,
) -> FrameOutput:
    """The detection half of the chain: CFAR, angles, point cloud and ground-truth labels.

    For frame simulators that produce the spectrum another way (cheaper fidelity levels).

    Parameters
    ----------
    doppler_cube
        ``[virtual channel, range bin, Doppler bin]`` complex, zero velocity centred; range bins
        ``0 .. n-1`` (may stop at :func:`processed_range_bins`).
    rd_map
        ``[range bin, Doppler bin]`` non-coherent power sum of ``doppler_cube``.
    scatterers
        The frame's reflectors, for the ``source`` labels (truth at the middle of the chirps).
    """
    rd = rd_map
    det = two_stage_cfar(rd, radar, settings)
    pc = PointCloud.empty()
    if len(det):
        # channel values of the detected cells; refinement, angles, SNR and labels (truth at
        # the middle of the frame's chirps) in one compiled call (build_point_cloud and
        # label_sources to floating-point order, tested)
        channels = np.asarray(doppler_cube)[:, det.range_bin, det.doppler_index].T
        pc = labelled_points(
            rd,
            det,
            channels,
            radar,
            settings,
            elevation=elevation,
            reflector_position_m=scatterers.position_m,
            reflector_velocity_mps=scatterers.velocity_mps,
            reflector_source=scatterers.source,
            t_mid_s=0.5 * radar.n_loops * radar.n_tx * radar.chirp_period_s,
        )
    rd_db = ra_db = None
    if keep_rd_map:
        tiny = np.finfo(np.float32).tiny
        rd_db = (10 * np.log10(np.maximum(rd, tiny))).astype(np.float32)
        ra = range_azimuth_map(doppler_cube, radar, fft_size=settings.angle_fft_size)
        ra_db = (10 * np.log10(np.maximum(ra, tiny))).astype(np.float32)
    return FrameOutput(
        point_cloud=pc,
        rd_map_db=rd_db,
        detections=np.column_stack((det.range_bin, det.doppler_index)).astype(np.int64),
        ra_map_db=ra_db,
    )

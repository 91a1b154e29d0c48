"""One frame through a TI detection chain (``oob``, ``people-counting``) on the exact level.

The cube is the exact level's (:func:`core.simulation.frame.windowed_cube`: the same signal and
noise as the paper chain for the same generator), then the chain's recipe
(:mod:`core.processing.chains`); ``paper`` is :func:`core.simulation.frame.simulate_frame`
itself. Only the exact level has a cube, so the TI chains run there alone.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import scipy.fft

from core.config import DEFAULT_PROCESSING, ChainConfig, ProcessingSettings, RadarConfig
from core.processing import doppler_fft, range_azimuth_map, range_doppler_map
from core.processing.chains import label_points, oob_points, people_counting_points
from core.simulation.antenna import AntennaGain
from core.simulation.frame import (
    FrameOutput,
    needs_elevation,
    processed_range_bins,
    simulate_frame,
    windowed_cube,
)
from core.simulation.scatterers import Scatterers


def simulate_frame_chain(
    radar: RadarConfig,
    scatterers: Scatterers,
    rng: np.random.Generator,
    *,
    antenna: AntennaGain,
    chain: ChainConfig,
    settings: ProcessingSettings = DEFAULT_PROCESSING,
    keep_rd_map: bool = False,
    elevation: bool | None = None,
    noise: bool = True,
) -> FrameOutput:
    """Simulate one frame through ``chain`` (arguments as :func:`simulate_frame`).

    ``settings`` gives the range window, the Doppler window, the range limits and the azimuth
    FFT size; the chain's own settings come from ``chain``.
    """
    if chain.name == "paper":
        return simulate_frame(
            radar,
            scatterers,
            rng,
            antenna=antenna,
            settings=settings,
            keep_rd_map=keep_rd_map,
            elevation=elevation,
            noise=noise,
        )
    t0 = time.perf_counter()
    cube = windowed_cube(radar, scatterers, rng, antenna=antenna, settings=settings, noise=noise)
    if elevation is None:
        elevation = needs_elevation(radar, scatterers)
    t1 = time.perf_counter()
    rc = scipy.fft.fft(cube, axis=-1, overwrite_x=True)  # [v, loop, range bin]
    rd = dc = None
    if chain.name == "oob":
        oob = chain.oob
        assert oob is not None
        limited = rc if keep_rd_map else rc[:, :, : processed_range_bins(radar, settings)]
        dc = doppler_fft(limited, settings.doppler_window, remove_static=oob.static_clutter_removal)
        rd = range_doppler_map(dc)
        pc, cells = oob_points(dc, rd, radar, oob, settings, elevation=elevation)
    else:
        people = chain.people_counting
        assert people is not None
        pc, cells = people_counting_points(rc, radar, people, settings, elevation=elevation)
    pc = label_points(pc, radar, scatterers.position_m, scatterers.velocity_mps, scatterers.source)
    rd_db = ra_db = None
    if keep_rd_map:
        tiny = np.finfo(np.float32).tiny
        if dc is None:
            dc = doppler_fft(rc, settings.doppler_window, remove_static=True)
            rd = range_doppler_map(dc)
        rd_db = (10 * np.log10(np.maximum(rd, tiny))).astype(np.float32)
        ra = range_azimuth_map(dc, radar, fft_size=settings.angle_fft_size)
        ra_db = (10 * np.log10(np.maximum(ra, tiny))).astype(np.float32)
    out = FrameOutput(point_cloud=pc, rd_map_db=rd_db, detections=cells, ra_map_db=ra_db)
    return dataclasses.replace(out, synthesis_s=t1 - t0, processing_s=time.perf_counter() - t1)

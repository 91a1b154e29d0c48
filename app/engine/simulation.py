"""Simulation: a scene through the radar chain frame by frame, as the views' snapshots."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from app.data import FrameData
from core.config import RadarConfig


def simulate(scene, *, fidelity: str = "exact", chain=None) -> Iterator[FrameData]:
    """Simulate the scene frame by frame through the radar chain (GUI plan: range-Doppler
    maps kept), yielding snapshots as they are ready. ``chain``: a ``ChainConfig`` (None: the
    paper's)."""
    from core import pipeline
    from core.config import PAPER_CHAIN

    the_plan = pipeline.plan(scene, fidelity=fidelity, consumer="gui", chain=chain or PAPER_CHAIN)
    settings = pipeline.processing_settings(scene)
    for fr in pipeline.iter_frames(scene, the_plan=the_plan):
        truth = np.asarray(fr.truth_xy_m, dtype=float).reshape(-1, 2)
        yield FrameData(
            index=fr.index,
            t_s=fr.t_s,
            cloud=fr.point_cloud,
            truth_xy_m=truth,
            rd_map_db=fr.rd_map_db,
            detections=np.asarray(fr.detections).reshape(-1, 2),
            ra_map_db=fr.ra_map_db,
            synthesis_s=fr.synthesis_s,
            processing_s=fr.processing_s,
            **frame_views(fr.rd_map_db, truth, scene.radar, settings),
        )


def frame_views(rd_map_db, truth_xy_m: np.ndarray, radar: RadarConfig, settings) -> dict:
    """What the range profile and the micro-Doppler views draw of one frame's map
    (:func:`core.pipeline.views.map_views`) as :class:`FrameData` fields: the CFAR threshold of
    every cell in dB (``cfar_threshold_db``) and the Doppler spectrum at each person's range
    (``person_doppler_db``); both ``None`` without a map."""
    if rd_map_db is None:
        return {"cfar_threshold_db": None, "person_doppler_db": None}
    from core.pipeline.views import map_views

    th_db, person_db = map_views(rd_map_db, truth_xy_m, radar, settings)
    return {"cfar_threshold_db": th_db, "person_doppler_db": person_db}


def fidelity_levels() -> list[str]:
    """Simulator levels, most faithful first (the keys of ``core.simulation.LEVELS``)."""
    from core.simulation import LEVELS

    return list(LEVELS)


def processing_settings(scene) -> dict:
    """The processing chain's settings for ``scene`` (windows, CFAR stages, ranges) as JSON."""
    from core.pipeline import processing_settings as _settings

    return _settings(scene).to_dict()

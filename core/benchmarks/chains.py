"""TI's detection chains against the paper's, timed on the same frames (``radartune bench sim``).

The paper scene's frames (a person walking a straight line, clutter) are simulated through the
exact level with each chain's own radar (``resources/radar/*.cfg``: the cube differs, 12 x 32 x
256 for the paper, 12 x 96 x 96 for people counting, 12 x 16 x 256 for the out-of-box demo),
in interleaved blocks so that every chain sees the same load; frames per second by wall clock
and by this process's CPU time, each chain's ratio to the paper chain in the same run.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from core.config import ProcessingSettings, RadarConfig

RADAR_DIR = Path(__file__).resolve().parents[2] / "resources" / "radar"
#: chain label -> the .cfg it is read from (None: the paper chain on the paper radar)
CHAIN_CFGS = {
    "paper": None,
    "oob (oob_isk.cfg)": "oob_isk.cfg",
    "people-counting (people_counting_isk.cfg)": "people_counting_isk.cfg",
    "people-counting + static (people_counting_isk_static.cfg)": "people_counting_isk_static.cfg",
    "people-counting AOP (people_counting_aop.cfg)": "people_counting_aop.cfg",
}
#: frames per block and chain in one interleaved pass
BLOCK = 10


def run(quick: bool = False, *, scene_frames: Callable[..., list]) -> dict:
    """Time every chain of :data:`CHAIN_CFGS`; ``scene_frames(radar, n, rng, antenna)`` gives the
    frames' scatterers (``core.benchmarks.sim.paper_scene_frames``)."""
    from core.config import PAPER_CHAIN
    from core.formats.ti_cfg import read_ti_cfg, read_ti_chain
    from core.simulation import AntennaGain
    from core.simulation.chain_frame import simulate_frame_chain

    n_frames = 60 if quick else 600
    setups = {}
    for label, cfg in CHAIN_CFGS.items():
        if cfg is None:
            radar, chain = RadarConfig(), PAPER_CHAIN
        else:
            radar, chain = read_ti_cfg(RADAR_DIR / cfg), read_ti_chain(RADAR_DIR / cfg)
        # detections up to 7.5 m (the people-counting radar reaches 8.08 m)
        settings = dataclasses.replace(ProcessingSettings(), max_range_m=7.5)
        rng = np.random.default_rng(2024)
        antenna = AntennaGain.draw(radar, rng)
        frames = scene_frames(radar, n_frames, rng, antenna)
        setups[label] = (radar, chain, settings, antenna, frames)

    def frame(label: str, i: int, rng: np.random.Generator):
        radar, chain, settings, antenna, frames = setups[label]
        return simulate_frame_chain(
            radar, frames[i], rng, antenna=antenna, chain=chain, settings=settings, elevation=True
        )

    rngs = {label: np.random.default_rng(1) for label in setups}
    for label in setups:  # warm up: compilation, FFT plans, caches
        frame(label, 0, np.random.default_rng(0))
    wall = dict.fromkeys(setups, 0.0)
    cpu = dict.fromkeys(setups, 0.0)
    points = {label: [] for label in setups}
    person = {label: [] for label in setups}
    for start in range(0, n_frames, BLOCK):
        for label in setups:
            t0, c0 = time.perf_counter(), time.process_time()
            outs = [frame(label, i, rngs[label]) for i in range(start, start + BLOCK)]
            wall[label] += time.perf_counter() - t0
            cpu[label] += time.process_time() - c0
            points[label] += [len(o.point_cloud) for o in outs]
            person[label] += [int(np.sum(o.point_cloud.source == 0)) for o in outs]
    out: dict = {"frames": n_frames, "chains": {}}
    for label in setups:
        fps, fps_cpu = n_frames / wall[label], n_frames / cpu[label]
        out["chains"][label] = {
            "fps": fps,
            "fps_cpu": fps_cpu,
            "over_paper": fps / (n_frames / wall["paper"]),
            "over_paper_cpu": fps_cpu / (n_frames / cpu["paper"]),
            "points_per_frame": float(np.mean(points[label])),
            "person_points_per_frame": float(np.mean(person[label])),
            "cube": list(_cube_shape(setups[label][0])),
        }
    out["goal"] = {"people_counting_fps": 100.0}
    return out


def _cube_shape(radar: RadarConfig) -> tuple[int, int, int]:
    return radar.n_virtual, radar.n_loops, radar.n_samples


def summary_lines(result: dict) -> list[str]:
    lines = [f"  detection chains, the same {result['frames']} paper-scene frames each:"]
    for label, c in result["chains"].items():
        lines.append(
            f"    {label:58s} {c['fps']:6.0f} frames/s ({c['over_paper']:.2f}x paper; CPU "
            f"{c['fps_cpu']:.0f}, {c['over_paper_cpu']:.2f}x), {c['points_per_frame']:.1f} "
            f"points/frame, {c['person_points_per_frame']:.1f} on the person"
        )
    return lines

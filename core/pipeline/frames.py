"""Simulating a scene: frame by frame (the GUI) or every frame in one batch call (data sets)."""

from __future__ import annotations

import dataclasses
import functools
import json
import math
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from core.dataset import Dataset
from core.errors import InputError
from core.pipeline.plan import Plan, plan, processing_settings, simulator
from core.pipeline.reflectors import Reflectors
from core.pipeline.streams import stage_rng
from core.pointcloud import PointCloud
from core.scene import Scene

ProgressCallback = Callable[[int, int], None]


@dataclass(frozen=True, slots=True, kw_only=True)
class FrameResult:
    """One simulated frame.

    ``rd_map_db``: shape ``(range bins, Doppler bins)``, zero velocity centred, or ``None``
    when the plan does not keep it. ``n_clutter``: clutter reflectors drawn in this frame.
    ``ra_map_db``: ``(range bins, angle bins)`` range-azimuth map in dB, kept with the
    range-Doppler map by the levels that have a Doppler cube, else ``None``.
    """

    index: int
    t_s: float
    truth_xy_m: np.ndarray  # (n_persons, 2)
    truth_v_mps: np.ndarray  # (n_persons, 2)
    point_cloud: PointCloud
    rd_map_db: np.ndarray | None
    detections: np.ndarray
    n_clutter: int
    ra_map_db: np.ndarray | None = None
    #: wall-clock seconds of the frame's synthesis and processing where the level runs them
    #: apart (:class:`core.simulation.frame.FrameOutput`), else NaN; not compared
    synthesis_s: float = field(default=math.nan, compare=False)
    processing_s: float = field(default=math.nan, compare=False)


@dataclass(frozen=True, slots=True, kw_only=True)
class SceneRun:
    """All frames of a simulated scene.

    ``truth_xy_m``/``truth_v_mps``: shape ``(F, n_persons, 2)`` (NaN once a trajectory ended);
    ``rd_maps_db``: ``(F, range bins, Doppler bins)`` or ``None``; ``n_clutter``: ``(F,)``.
    """

    scene: Scene
    plan: Plan
    seed: int
    clouds: tuple[PointCloud, ...]
    truth_t_s: np.ndarray
    truth_xy_m: np.ndarray
    truth_v_mps: np.ndarray
    n_clutter: np.ndarray
    rd_maps_db: np.ndarray | None = None
    elapsed_s: float = field(default=0.0, compare=False)

    def to_dataset(self) -> Dataset:
        """The run as a one-trajectory data set (SPEC §6)."""
        return Dataset.from_frames(
            clouds=list(self.clouds),
            trajectory=np.zeros(len(self.clouds), dtype=np.int32),
            truth_t_s=self.truth_t_s,
            truth_xy_m=self.truth_xy_m,
            truth_v_mps=self.truth_v_mps,
            trajectory_class=[self.scene.trajectory_class],
            scene_json=self.scene.to_json(),
            radar_json=json.dumps(self.scene.radar.to_dict()),
            fidelity=self.plan.fidelity,
            seed=self.seed,
        )


def iter_frames(
    scene: Scene,
    *,
    seed: int | None = None,
    fidelity: str = "exact",
    keep_rd_maps: bool = False,
    the_plan: Plan | None = None,
    frames: Sequence[int] | None = None,
) -> Iterator[FrameResult]:
    """Simulate a scene frame by frame (the GUI consumes this live).

    Parameters
    ----------
    scene
        What is simulated.
    seed
        Seed of every random stream; default ``scene.seed``.
    fidelity, keep_rd_maps
        As for :func:`plan` (ignored when ``the_plan`` is given).
    the_plan
        A ready plan (e.g. with forced stages).
    frames
        Frame indices to simulate (default all); every frame has its own random streams, so a
        frame simulated alone equals the same frame of a full run.
    """
    p = the_plan or plan(scene, keep_rd_maps=keep_rd_maps, fidelity=fidelity)
    if p.consumer == "study":
        raise InputError("a study trial never simulates: load the cached data set instead")
    seed = scene.seed if seed is None else int(seed)
    radar = scene.radar
    settings = processing_settings(scene)
    simulate = simulator(p.fidelity)
    if p.chain.name != "paper":
        from core.simulation.chain_frame import simulate_frame_chain

        simulate = functools.partial(simulate_frame_chain, chain=p.chain)
    for fi in frame_inputs(scene, p, seed, frames):
        out = simulate(
            radar,
            fi.scatterers,
            fi.rng,
            antenna=fi.antenna,
            settings=settings,
            keep_rd_map=p.keep_rd_maps,
            elevation=p.elevation,
        )
        yield FrameResult(
            index=fi.index,
            t_s=fi.t_s,
            truth_xy_m=fi.truth_xy_m,
            truth_v_mps=fi.truth_v_mps,
            point_cloud=in_room(scene, out.point_cloud),
            rd_map_db=out.rd_map_db if p.keep_rd_maps else None,
            detections=out.detections,
            n_clutter=fi.n_clutter,
            ra_map_db=out.ra_map_db if p.keep_rd_maps else None,
            synthesis_s=out.synthesis_s,
            processing_s=out.processing_s,
        )


def in_room(scene: Scene, cloud: PointCloud) -> PointCloud:
    """A simulated cloud of a scene in a room: ``x_m``, ``y_m``, ``z_m`` in room coordinates
    (range, angles and radial velocity stay the sensor's), ``source`` and ``path_order`` split
    from the path labels (:func:`core.simulation.multipath.split_labels`). Without a room: the
    cloud as it is."""
    if scene.room is None:
        return cloud
    from core.simulation.multipath import split_labels

    source, order = split_labels(cloud.source)
    xyz = scene.room.sensor.to_room(np.column_stack((cloud.x_m, cloud.y_m, cloud.z_m)))
    return dataclasses.replace(
        cloud, x_m=xyz[:, 0], y_m=xyz[:, 1], z_m=xyz[:, 2], source=source, path_order=order
    )


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class FrameInput:
    """What a frame simulator is given for one frame: reflectors, antenna, noise generator."""

    index: int
    t_s: float
    truth_xy_m: np.ndarray  # (n_persons, 2)
    truth_v_mps: np.ndarray  # (n_persons, 2)
    scatterers: Any  # core.simulation.Scatterers
    antenna: Any  # core.simulation.AntennaGain
    rng: np.random.Generator
    n_clutter: int


def frame_inputs(
    scene: Scene, p: Plan, seed: int, frames: Sequence[int] | None = None
) -> Iterator[FrameInput]:
    """Each asked frame's simulator inputs, as :func:`iter_frames` simulates them (one definition:
    the DCA1000 writer synthesises the same frames' ADC samples from these)."""
    from core import simulation as sim  # heavy import, and the radar chain is another branch

    settings = processing_settings(scene)
    antenna = sim.AntennaGain.draw(scene.radar, stage_rng(seed, "antenna"))
    reflectors = Reflectors.build(scene, p, seed, antenna, settings)
    t_s, xy, v = reflectors.truth_t_s, reflectors.truth_xy_m, reflectors.truth_v_mps
    idx = np.asarray(frames if frames is not None else range(scene.n_frames), dtype=np.int64)
    # every asked frame's reflectors at once (each frame on its own streams, the same bits)
    every, clutter_counts = reflectors.frames_at(idx)
    for f, scatterers, n_clutter in zip(idx.tolist(), every, clutter_counts.tolist()):
        yield FrameInput(
            index=f,
            t_s=float(t_s[f]),
            truth_xy_m=xy[f],
            truth_v_mps=v[f],
            scatterers=scatterers,
            antenna=antenna,
            rng=stage_rng(seed, "noise", f),
            n_clutter=n_clutter,
        )


def simulate_scene(
    scene: Scene,
    *,
    fidelity: str = "exact",
    keep_rd_maps: bool = False,
    seed: int | None = None,
    progress: ProgressCallback | None = None,
    the_plan: Plan | None = None,
) -> SceneRun:
    """Simulate every frame of a scene through the radar chain.

    Returns
    -------
    SceneRun
        Point clouds, truth, clutter counts and (if asked) range-Doppler maps.
    """
    t0 = time.perf_counter()
    p = the_plan or plan(scene, keep_rd_maps=keep_rd_maps, fidelity=fidelity)
    seed = scene.seed if seed is None else int(seed)
    from core.simulation.levels import fidelity_level

    batch = fidelity_level(p.fidelity).simulate_frames is not None and scene.n_frames > 0
    batch = batch and p.chain.name == "paper"
    if batch and not p.keep_rd_maps and p.consumer != "study":
        return _simulate_scene_batch(scene, p, seed, progress, t0)
    clouds, maps, n_clutter = [], [], []
    total = scene.n_frames
    for fr in iter_frames(scene, seed=seed, the_plan=p):
        clouds.append(fr.point_cloud)
        n_clutter.append(fr.n_clutter)
        if fr.rd_map_db is not None:
            maps.append(fr.rd_map_db)
        if progress is not None:
            progress(fr.index + 1, total)
    t_s, xy, v = scene.truth()
    return SceneRun(
        scene=scene,
        plan=p,
        seed=seed,
        clouds=tuple(clouds),
        truth_t_s=t_s,
        truth_xy_m=xy,
        truth_v_mps=v,
        n_clutter=np.array(n_clutter, dtype=np.int64),
        rd_maps_db=np.stack(maps) if maps else None,
        elapsed_s=time.perf_counter() - t0,
    )


def _simulate_scene_batch(
    scene: Scene, p: Plan, seed: int, progress: ProgressCallback | None, t0: float
) -> SceneRun:
    """:func:`simulate_scene` through the level's batch simulator: every frame's reflectors
    and noise generator as :func:`iter_frames` builds them, then one call for all frames."""
    from core import simulation as sim

    simulate = sim.fidelity_level(p.fidelity).simulate_frames
    assert simulate is not None, "the plan chose the batch path only for a level that has one"
    radar = scene.radar
    settings = processing_settings(scene)
    antenna = sim.AntennaGain.draw(radar, stage_rng(seed, "antenna"))
    reflectors = Reflectors.build(scene, p, seed, antenna, settings)
    frames, n_clutter = reflectors.frames()
    rngs = [stage_rng(seed, "noise", f) for f in range(scene.n_frames)]
    out = simulate(radar, frames, rngs, antenna=antenna, settings=settings, elevation=p.elevation)
    if progress is not None:
        progress(scene.n_frames, scene.n_frames)
    return SceneRun(
        scene=scene,
        plan=p,
        seed=seed,
        clouds=tuple(in_room(scene, c) for c in out.clouds()),
        truth_t_s=reflectors.truth_t_s,
        truth_xy_m=reflectors.truth_xy_m,
        truth_v_mps=reflectors.truth_v_mps,
        n_clutter=n_clutter,
        rd_maps_db=None,
        elapsed_s=time.perf_counter() - t0,
    )

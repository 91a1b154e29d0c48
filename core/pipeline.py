"""Scene → frames → point clouds → data set: the only orchestration of the radar chain.

The pipeline first builds a :class:`Plan` from the scene and from what the consumer asks for:
every stage declares what it needs and what it produces, and is run or skipped with a reason
(no clutter draws when λ = 0, no elevation on a planar scene, no range-Doppler map kept unless
asked, no simulation at all inside a study trial). ``radartune simulate --explain`` prints it.

Randomness: every random stage draws from its own stream,
``SeedSequence(seed, spawn_key=(stage, frame))``, so skipping a stage (or running one more)
leaves every other stage's numbers bit for bit unchanged, and any frame can be simulated alone.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import importlib
import json
import multiprocessing
import os
import time
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from core.config import DEFAULT_PROCESSING, ProcessingSettings, RadarConfig
from core.dataset import Dataset
from core.errors import InputError
from core.pointcloud import PointCloud
from core.scene import Scene, draw_clutter, expected_clutter_count, paper_scenes
from core.scene.body import body_scatterers, walking_headings

#: eq. (5): σ_dBsm ~ N(−8, 16): mean −8 dBsm, variance 16 dB² (standard deviation 4 dB)
PERSON_RCS_MEAN_DBSM = -8.0
PERSON_RCS_STD_DB = 4.0

#: Frame simulators by fidelity level: name -> "module:function", all with the signature of
#: ``core.simulation.simulate_frame``. Adding a level is one line.
SIMULATORS: dict[str, str] = {
    "exact": "core.simulation:simulate_frame",
    "fast": "core.simulation:simulate_frame_fast",
    "measurement": "core.simulation:simulate_frame_measurement",
}

#: Levels that can also simulate all frames of a scene in one call (the data-set path):
#: name -> "module:function" with the signature of
#: ``core.simulation.measurement.simulate_frames_measurement``. They must give the same frames
#: as the per-frame simulator with the same per-frame generators (tested).
BATCH_SIMULATORS: dict[str, str] = {
    "fast": "core.simulation.fast:simulate_frames_fast",
    "measurement": "core.simulation.measurement:simulate_frames_measurement",
}

#: Bump when the simulation changes in a way that invalidates cached data sets.
CACHE_VERSION = 1

ProgressCallback = Callable[[int, int], None]

# Stage keys of the per-stage random streams (never renumber: they define the data).
_STREAM = {"antenna": 0, "person_rcs": 1, "clutter": 2, "noise": 3}


def stage_rng(seed: int, stage: str, frame: int = 0) -> np.random.Generator:
    """The random stream of one stage in one frame: ``SeedSequence(seed, spawn_key=(s, f))``.

    (``Generator(PCG64(seq))`` is ``default_rng(seq)`` without its dispatch: ~10 µs less per
    call, and data sets make two calls per frame.)
    """
    return np.random.Generator(
        np.random.PCG64(np.random.SeedSequence(seed, spawn_key=(_STREAM[stage], frame)))
    )


# ---- the plan ----------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True, kw_only=True)
class Stage:
    """One step of the pipeline: what it needs, what it produces, whether it runs and why."""

    name: str
    needs: tuple[str, ...]
    produces: tuple[str, ...]
    run: bool
    reason: str


@dataclass(frozen=True, slots=True, kw_only=True)
class Plan:
    """The stages of a simulation, in order, each run or skipped with the reason."""

    stages: tuple[Stage, ...]
    fidelity: str = "exact"
    consumer: str = "simulate"

    def runs(self, name: str) -> bool:
        """Whether the stage ``name`` runs (KeyError for an unknown stage)."""
        for s in self.stages:
            if s.name == name:
                return s.run
        raise KeyError(name)

    @property
    def keep_rd_maps(self) -> bool:
        return self.runs("keep_rd_map")

    @property
    def elevation(self) -> bool:
        return self.runs("elevation")

    def explain(self) -> str:
        """One line per stage: ``run``/``skip``, name, needs → produces, reason."""
        width = max(len(s.name) for s in self.stages)
        lines = [f"plan ({self.consumer}, fidelity {self.fidelity}):"]
        for s in self.stages:
            flow = f"{', '.join(s.needs) or '-'} -> {', '.join(s.produces)}"
            lines.append(
                f"  {'run ' if s.run else 'skip'}  {s.name:<{width}}  {flow}  ({s.reason})"
            )
        return "\n".join(lines)


CONSUMERS = ("simulate", "gui", "study")


def plan(
    scene: Scene,
    *,
    keep_rd_maps: bool = False,
    fidelity: str = "exact",
    consumer: str = "simulate",
    force: Sequence[str] = (),
) -> Plan:
    """Decide which stages run for this scene and this consumer.

    Parameters
    ----------
    scene
        What is simulated.
    keep_rd_maps
        Keep the range-Doppler map of every frame (the GUI asks; a study does not).
    fidelity
        Simulator level (a key of :data:`SIMULATORS`).
    consumer
        ``"simulate"`` (CLI, data sets), ``"gui"`` (keeps range-Doppler maps) or ``"study"``
        (an optimisation trial: tracks cached point clouds, simulates nothing).
    force
        Stage names to run even where the plan would skip them (for tests and comparisons).
    """
    _simulator_path(fidelity)
    if consumer not in CONSUMERS:
        raise InputError(f"consumer must be one of {list(CONSUMERS)}, got {consumer!r}")
    keep = keep_rd_maps or consumer == "gui"
    study = consumer == "study"
    has_clutter = scene.clutter_density_per_m2 > 0
    drawn_rcs = [i for i, p in enumerate(scene.persons) if p.rcs_dbsm is None]
    extended = [i for i, p in enumerate(scene.persons) if p.model == "extended"]
    needs_el = scene.radar.has_elevation and not scene.is_planar

    def stage(name, needs, produces, run, why_run, why_skip):
        run = bool(run) or name in force
        if study and name not in ("load_point_clouds",):
            run, why = False, "a study trial only tracks cached point clouds; it never simulates"
        else:
            why = why_run if run else why_skip
            if name in force and why is why_skip:
                why = "forced"
        return Stage(name=name, needs=needs, produces=produces, run=run, reason=why)

    lam = scene.clutter_density_per_m2
    stages = (
        stage(
            "truth", ("trajectories",), ("truth_xy", "truth_v"), True,
            f"{scene.n_persons} person(s), {scene.n_frames} frames of eq. (6)", "",
        ),
        stage(
            "antenna", ("seed",), ("antenna_gain",), True,
            "eq. (1): one gain realisation per simulated radar", "",
        ),
        stage(
            "person_rcs", ("truth_xy",), ("person_rcs",), drawn_rcs,
            f"eq. (5) N(-8, 16) dBsm every frame for person(s) {drawn_rcs}",
            "every person has a fixed rcs_dbsm",
        ),
        stage(
            "body_model", ("truth_xy", "person_rcs"), ("body_scatterers",), extended,
            f"extended model (torso, arms, legs, micro-Doppler) for person(s) {extended}",
            "point-scatterer persons (the paper's model)",
        ),
        stage(
            "clutter", ("antenna_gain",), ("clutter_reflectors",), has_clutter,
            f"Poisson, mean lambda*area = {expected_clutter_count(scene.aoi, lam):.3f} per frame",
            "clutter_density_per_m2 = 0: no clutter draws",
        ),
        stage(
            "static_reflectors", (), ("static_reflectors",), scene.static_reflectors,
            f"{len(scene.static_reflectors)} fixed reflector(s), v = 0",
            "the scene has no static reflectors",
        ),
        stage(
            "scatterers",
            ("truth_xy", "person_rcs", "body_scatterers", "clutter_reflectors",
             "static_reflectors"),
            ("scatterers",), True, "reflectors of each frame", "",
        ),
        stage(
            "baseband", ("scatterers", "antenna_gain"), ("cube",), True,
            f"{fidelity} synthesis [virtual, loop, sample] + receiver noise", "",
        ),
        stage(
            "range_fft", ("cube",), ("range_profiles",), True, "along samples", "",
        ),
        stage(
            "static_clutter_removal", ("range_profiles",), ("range_profiles",), True,
            "subtract the mean over loops", "",
        ),
        stage(
            "doppler_fft", ("range_profiles",), ("rd_cube",), True, "along loops", "",
        ),
        stage(
            "rd_map", ("rd_cube",), ("rd_map",), True,
            "non-coherent sum over virtual channels (CFAR input)", "",
        ),
        stage(
            "keep_rd_map", ("rd_map",), ("rd_maps",), keep,
            "the consumer displays range-Doppler maps",
            "no consumer asked for range-Doppler maps",
        ),
        stage(
            "cfar", ("rd_map",), ("detections",), True, "two-stage CFAR (range, Doppler)", "",
        ),
        stage(
            "azimuth", ("rd_cube", "detections"), ("azimuth",), True,
            "angle FFT at detected cells only", "",
        ),
        stage(
            "elevation", ("rd_cube", "detections"), ("elevation",), needs_el,
            "the scene has reflectors off the z = 0 plane",
            "planar scene (all z = 0)" if scene.radar.has_elevation
            else "the radar has no elevated antennas",
        ),
        stage(
            "point_cloud", ("detections", "azimuth", "elevation"), ("point_cloud",), True,
            "points with SNR and ground-truth labels", "",
        ),
        stage(
            "load_point_clouds", ("dataset_cache",), ("point_cloud",), study,
            "point clouds simulated once and cached for every trial",
            "point clouds are simulated here",
        ),
    )  # fmt: skip
    unknown = sorted(set(force) - {s.name for s in stages})
    if unknown:
        raise InputError(f"force: unknown stage(s) {unknown}")
    return Plan(stages=stages, fidelity=fidelity, consumer=consumer)


# ---- simulating a scene --------------------------------------------------------------------------


def _simulator_path(fidelity: str) -> str:
    try:
        return SIMULATORS[fidelity]
    except KeyError:
        raise InputError(
            f"fidelity must be one of {sorted(SIMULATORS)}, got fidelity={fidelity!r}"
        ) from None


def simulator(fidelity: str = "exact") -> Callable[..., Any]:
    """The frame simulator of a fidelity level (signature of ``simulate_frame``)."""
    module, name = _simulator_path(fidelity).split(":")
    return getattr(importlib.import_module(module), name)


@dataclass(frozen=True, slots=True, kw_only=True)
class FrameResult:
    """One simulated frame.

    ``rd_map_db``: shape ``(range bins, Doppler bins)``, zero velocity centred, or ``None``
    when the plan does not keep it. ``n_clutter``: clutter reflectors drawn in this frame.
    """

    index: int
    t_s: float
    truth_xy_m: np.ndarray  # (n_persons, 2)
    truth_v_mps: np.ndarray  # (n_persons, 2)
    point_cloud: PointCloud
    rd_map_db: np.ndarray | None
    detections: np.ndarray
    n_clutter: int


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


def processing_settings(scene: Scene) -> ProcessingSettings:
    """The chain's default processing, with detections limited to the scene's AOI range."""
    return dataclasses.replace(DEFAULT_PROCESSING, max_range_m=scene.aoi.max_range_m)


@dataclass(frozen=True, slots=True, kw_only=True)
class _Reflectors:
    """Builds the scatterers of any frame of a scene (stages truth … scatterers of the plan)."""

    scene: Scene
    seed: int
    antenna: Any
    settings: ProcessingSettings
    truth_t_s: np.ndarray  # (F,)
    truth_xy_m: np.ndarray  # (F, n_persons, 2)
    truth_v_mps: np.ndarray  # (F, n_persons, 2)
    fixed_rcs: np.ndarray  # (n_persons,), NaN where drawn
    extended: np.ndarray  # (n_persons,) bool: body model applies
    headings: dict[int, np.ndarray]
    run_rcs: bool
    run_clutter: bool
    run_static: bool
    _consts: _FrameConstants

    @classmethod
    def build(cls, scene: Scene, p: Plan, seed: int, antenna, settings) -> _Reflectors:
        t_s, xy, v = scene.truth()
        extended = np.array([q.model == "extended" for q in scene.persons], dtype=bool)
        if not p.runs("body_model"):
            extended[:] = False
        fixed_rcs = np.array([np.nan if q.rcs_dbsm is None else q.rcs_dbsm for q in scene.persons])
        return cls(
            scene=scene,
            seed=seed,
            antenna=antenna,
            settings=settings,
            truth_t_s=t_s,
            truth_xy_m=xy,
            truth_v_mps=v,
            fixed_rcs=fixed_rcs,
            extended=extended,
            headings={
                i: walking_headings(q.trajectory.velocity_mps)
                for i, q in enumerate(scene.persons)
                if extended[i]
            },
            run_rcs=p.runs("person_rcs"),
            run_clutter=p.runs("clutter"),
            run_static=p.runs("static_reflectors"),
            _consts=cls._constants(scene, fixed_rcs, p.runs("static_reflectors"), settings),
        )

    def frame(self, f: int) -> tuple[Any, int]:
        """Scatterers of frame ``f`` and the number of clutter reflectors among them.

        Bit for bit the reflectors of the straightforward construction (persons, body parts,
        clutter, static reflectors, in this order) with the same per-frame streams (tested).
        """
        out, n_clutter = self._build(np.array([f], dtype=np.int64))
        return out[0], int(n_clutter[0])

    def frames(self, n_frames: int | None = None) -> tuple[list[Any], np.ndarray]:
        """The scatterers of frames ``0 .. n_frames - 1`` and their clutter counts, at once.

        Bit for bit ``[self.frame(f) for f in range(n_frames)]`` (tested): every frame draws
        from its own streams in the same order; what follows the draws (persons' RCS, clutter
        velocities and RCS, assembly, validation) runs once over all frames instead of once per
        frame. The frames are views into shared arrays.
        """
        n_f = len(self.truth_t_s) if n_frames is None else int(n_frames)
        return self._build(np.arange(n_f, dtype=np.int64))

    def _build(self, idx: np.ndarray) -> tuple[list[Any], np.ndarray]:
        """Scatterers and clutter counts of the frames ``idx`` (see :meth:`frames`)."""
        from core import simulation as sim

        scene = self.scene
        k = self._consts
        n_f = len(idx)
        n_p = scene.n_persons
        if n_f == 0:
            return [], np.zeros(0, dtype=np.int64)
        rcs = np.broadcast_to(self.fixed_rcs, (n_f, n_p))
        if self.run_rcs:
            # σ_dBsm ~ N(−8, 16), eq. (5), drawn afresh every frame
            drawn = np.empty((n_f, n_p))
            for row, f in enumerate(idx):
                drawn[row] = stage_rng(self.seed, "person_rcs", int(f)).normal(
                    PERSON_RCS_MEAN_DBSM, PERSON_RCS_STD_DB, n_p
                )
            rcs = np.where(k.drawn_rcs[None, :], drawn, self.fixed_rcs[None, :])
        xy, v = self.truth_xy_m[idx], self.truth_v_mps[idx]
        active = ~np.isnan(xy[:, :, 0])  # (F, n_p)
        point = active & ~self.extended[None, :]
        n_point = point.sum(axis=1)
        # extended persons: the body model per frame and person (frame order, person order)
        body_pos, body_vel, body_rcs, body_src = [], [], [], []
        n_body = np.zeros(n_f, dtype=np.int64)
        if self.extended.any():
            for row, f in enumerate(idx):
                for i in np.flatnonzero(active[row] & self.extended):
                    bp, bv, frac = body_scatterers(
                        xy[row, i], v[row, i], self.headings[i][f], self.truth_t_s[f]
                    )
                    body_pos.append(bp)
                    body_vel.append(bv)
                    # σ_part = σ · share (linear power)
                    body_rcs.append(rcs[row, i] + 10 * np.log10(frac))
                    body_src.append(np.full(len(bp), i, dtype=np.int32))
                    n_body[row] += len(bp)
        n_clutter = np.zeros(n_f, dtype=np.int64)
        c_pos, c_vr, c_snr = [], [], []
        if self.run_clutter:
            for row, f in enumerate(idx):
                c = draw_clutter(
                    scene.aoi,
                    scene.clutter_density_per_m2,
                    scene.radar,
                    stage_rng(self.seed, "clutter", int(f)),
                )
                n_clutter[row] = len(c)
                c_pos.append(c.position_m)
                c_vr.append(c.radial_velocity_mps)
                c_snr.append(c.snr_db)
        n_static = len(k.static_rcs)
        per_frame = n_point + n_body + n_clutter + n_static
        start = np.zeros(n_f + 1, dtype=np.int64)
        np.cumsum(per_frame, out=start[1:])
        n = int(start[-1])
        position = np.zeros((n, 3))
        velocity = np.zeros((n, 3))
        rcs_all = np.empty(n)
        source = np.empty(n, dtype=np.int32)
        # persons as points: frame f's j-th active point person at start[f] + j
        ff, ii = np.nonzero(point)
        at = start[ff] + (np.cumsum(point, axis=1) - 1)[ff, ii]
        position[at, :2] = xy[ff, ii]
        velocity[at, :2] = v[ff, ii]
        rcs_all[at] = rcs[ff, ii]
        source[at] = ii
        # then the body parts, the clutter and the static reflectors of each frame
        frame_of = np.repeat(np.arange(n_f), per_frame)
        slot = np.arange(n) - start[frame_of]  # position within the frame
        first = n_point[frame_of]
        if body_pos:
            at = np.flatnonzero((slot >= first) & (slot < first + n_body[frame_of]))
            position[at, :2] = np.concatenate(body_pos)
            velocity[at, :2] = np.concatenate(body_vel)
            rcs_all[at] = np.concatenate(body_rcs)
            source[at] = np.concatenate(body_src)
        first = first + n_body[frame_of]
        if n_clutter.any():
            at = np.flatnonzero((slot >= first) & (slot < first + n_clutter[frame_of]))
            pos = np.concatenate(c_pos)
            vr = np.concatenate(c_vr)
            # v = vr p / |p|  (ClutterDraw.velocity_mps)
            r = np.hypot(pos[:, 0], pos[:, 1])
            position[at, :2] = pos
            velocity[at, :2] = pos / r[:, None] * vr[:, None]
            rcs_all[at] = self._clutter_rcs_dbsm(pos, np.concatenate(c_snr))
            source[at] = -1
        if n_static:
            at = np.flatnonzero(slot >= first + n_clutter[frame_of])
            j = slot[at] - (first + n_clutter[frame_of])[at]
            position[at] = k.static_position[j]
            rcs_all[at] = k.static_rcs[j]
            source[at] = k.static_source[j]
        whole_ok = _arrays_ok(position, velocity, rcs_all)
        out = []
        for row in range(n_f):
            s = slice(start[row], start[row + 1])
            part = (position[s], velocity[s], rcs_all[s], source[s])
            # an invalid reflector: the frame's validating constructor names the field
            out.append(_checked_scatterers(sim, *part) if whole_ok else _scatterers(sim, *part))
        return out, n_clutter

    @staticmethod
    def _constants(scene: Scene, fixed_rcs, run_static: bool, settings) -> _FrameConstants:
        """What does not change from frame to frame."""
        from core import simulation as sim

        radar, static = scene.radar, scene.static_reflectors
        run_static = run_static and bool(static)
        return _FrameConstants(
            drawn_rcs=np.isnan(fixed_rcs),
            pt_w=10 ** ((radar.tx_power_dbm - 30.0) / 10),
            wavelength2_m2=radar.wavelength_m**2,
            noise_power_w=radar.noise_power_w,
            processing_gain_db=sim.processing_gain_db(radar, settings),
            static_position=np.array([[q.x_m, q.y_m, q.z_m] for q in static], dtype=np.float64)
            if run_static
            else np.zeros((0, 3)),
            static_rcs=np.array([q.rcs_dbsm for q in static], dtype=np.float64)
            if run_static
            else np.zeros(0),
            static_source=np.full(len(static) if run_static else 0, -1, dtype=np.int32),
        )

    def _clutter_rcs_dbsm(self, xy_m: np.ndarray, snr_db: np.ndarray) -> np.ndarray:
        """RCS giving each clutter reflector its drawn SNR: ``core.simulation.rcs_for_snr_db``
        with the frame-independent factors cached (same operations, same bits; tested)."""
        k = self._consts
        r = np.hypot(xy_m[:, 0], xy_m[:, 1])
        az = np.arctan2(xy_m[:, 0], xy_m[:, 1])
        g = 10 ** (self.antenna.gain_db(az) / 10)  # Gt = Gr
        # Pr = Pt Gt Gr lambda^2 sigma / ((4 pi)^3 R^4), sigma = 1 m² (0 dBsm)
        pr = k.pt_w * g * g * k.wavelength2_m2 / ((4 * np.pi) ** 3 * r**4)
        # SNR(0 dBsm) = 10 log10(Pr / (k T F Be)) + G_proc;  σ_dBsm = SNR - SNR(0 dBsm)
        return np.asarray(snr_db) - (10 * np.log10(pr / k.noise_power_w) + k.processing_gain_db)


@dataclass(frozen=True, slots=True, kw_only=True)
class _FrameConstants:
    """Frame-independent inputs of :meth:`_Reflectors.frame`."""

    drawn_rcs: np.ndarray  # (n_persons,) bool: RCS drawn every frame
    pt_w: float
    wavelength2_m2: float
    noise_power_w: float
    processing_gain_db: float
    static_position: np.ndarray  # (S, 3)
    static_rcs: np.ndarray  # (S,)
    static_source: np.ndarray  # (S,) int32, -1


def _arrays_ok(position, velocity, rcs_dbsm) -> bool:
    """What the ``Scatterers`` constructor checks, in one pass: finite, off the radar."""
    return bool(
        np.isfinite(position).all()
        and np.isfinite(velocity).all()
        and np.isfinite(rcs_dbsm).all()
        and (len(position) == 0 or np.einsum("ij,ij->i", position, position).min() > 0)
    )


def _scatterers(sim, position, velocity, rcs_dbsm, source):
    """``Scatterers`` of arrays checked here in one pass (finite, off the radar); arrays that
    fail go through the validating constructor, which names the field."""
    if not _arrays_ok(position, velocity, rcs_dbsm):
        return sim.Scatterers(
            position_m=position, velocity_mps=velocity, rcs_dbsm=rcs_dbsm, source=source
        )
    return _checked_scatterers(sim, position, velocity, rcs_dbsm, source)


def _checked_scatterers(sim, position, velocity, rcs_dbsm, source):
    """``Scatterers`` of arrays already checked (:func:`_arrays_ok`), without the constructor."""
    s = object.__new__(sim.Scatterers)
    for name, value in (
        ("position_m", position),
        ("velocity_mps", velocity),
        ("rcs_dbsm", rcs_dbsm),
        ("source", source),
    ):
        object.__setattr__(s, name, value)
    return s


def frame_scatterers(scene: Scene, frame: int, *, seed: int | None = None, the_plan=None):
    """The reflectors of one frame (persons, clutter, static reflectors) as the chain sees them.

    Returns
    -------
    core.simulation.Scatterers
        ``source``: person index, or −1 for clutter and static reflectors.
    """
    from core import simulation as sim

    p = the_plan or plan(scene)
    seed = scene.seed if seed is None else int(seed)
    antenna = sim.AntennaGain.draw(scene.radar, stage_rng(seed, "antenna"))
    settings = processing_settings(scene)
    return _Reflectors.build(scene, p, seed, antenna, settings).frame(frame)[0]


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
    from core import simulation as sim  # heavy import, and the radar chain is another branch

    p = the_plan or plan(scene, keep_rd_maps=keep_rd_maps, fidelity=fidelity)
    if p.consumer == "study":
        raise InputError("a study trial never simulates: load the cached data set instead")
    seed = scene.seed if seed is None else int(seed)
    radar = scene.radar
    settings = processing_settings(scene)
    simulate = simulator(p.fidelity)
    antenna = sim.AntennaGain.draw(radar, stage_rng(seed, "antenna"))
    reflectors = _Reflectors.build(scene, p, seed, antenna, settings)
    t_s, xy, v = reflectors.truth_t_s, reflectors.truth_xy_m, reflectors.truth_v_mps
    idx = np.asarray(frames if frames is not None else range(scene.n_frames), dtype=np.int64)
    # every asked frame's reflectors at once (each frame on its own streams, the same bits)
    every, clutter_counts = reflectors._build(idx)
    for f, scatterers, n_clutter in zip(idx.tolist(), every, clutter_counts.tolist()):
        out = simulate(
            radar,
            scatterers,
            stage_rng(seed, "noise", f),
            antenna=antenna,
            settings=settings,
            keep_rd_map=p.keep_rd_maps,
            elevation=p.elevation,
        )
        yield FrameResult(
            index=f,
            t_s=float(t_s[f]),
            truth_xy_m=xy[f],
            truth_v_mps=v[f],
            point_cloud=out.point_cloud,
            rd_map_db=out.rd_map_db if p.keep_rd_maps else None,
            detections=out.detections,
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
    batch = p.fidelity in BATCH_SIMULATORS and scene.n_frames > 0
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

    module, name = BATCH_SIMULATORS[p.fidelity].split(":")
    simulate = getattr(importlib.import_module(module), name)
    radar = scene.radar
    settings = processing_settings(scene)
    antenna = sim.AntennaGain.draw(radar, stage_rng(seed, "antenna"))
    reflectors = _Reflectors.build(scene, p, seed, antenna, settings)
    frames, n_clutter = reflectors.frames()
    rngs = [stage_rng(seed, "noise", f) for f in range(scene.n_frames)]
    out = simulate(radar, frames, rngs, antenna=antenna, settings=settings, elevation=p.elevation)
    if progress is not None:
        progress(scene.n_frames, scene.n_frames)
    return SceneRun(
        scene=scene,
        plan=p,
        seed=seed,
        clouds=tuple(out.clouds()),
        truth_t_s=reflectors.truth_t_s,
        truth_xy_m=reflectors.truth_xy_m,
        truth_v_mps=reflectors.truth_v_mps,
        n_clutter=n_clutter,
        rd_maps_db=None,
        elapsed_s=time.perf_counter() - t0,
    )


# ---- data sets -----------------------------------------------------------------------------------


def default_cache_dir() -> Path:
    """``$RADARTUNE_CACHE`` or ``~/.cache/radartune``."""
    env = os.environ.get("RADARTUNE_CACHE")
    return Path(env) if env else Path.home() / ".cache" / "radartune"


#: Sources whose code determines a simulated data set (their text is part of the cache key).
_SIMULATION_SOURCES = ("config.py", "pipeline.py", "pointcloud.py", "dataset.py")
_SIMULATION_PACKAGES = ("scene", "simulation", "processing")


@functools.cache
def code_fingerprint() -> str:
    """Hash of the source of every module that shapes a simulated data set.

    Part of the cache key, so a change to the radar chain, the scenes or this pipeline never
    serves a stale cached data set.
    """
    root = Path(__file__).resolve().parent
    files = [root / name for name in _SIMULATION_SOURCES]
    for pkg in _SIMULATION_PACKAGES:
        files += sorted((root / pkg).rglob("*.py"))
    h = hashlib.sha256()
    for f in files:
        if f.is_file():
            h.update(f.relative_to(root).as_posix().encode() + b"\0" + f.read_bytes() + b"\0")
    return h.hexdigest()[:16]


def dataset_key(
    scenes: Sequence[Scene], *, fidelity: str, seed: int, seeds: Sequence[int] | None = None
) -> str:
    """Hash of the scenes (with their resolved radar), the fidelity level, the seed(s), the code.

    The code part is :func:`code_fingerprint` (the simulation's source) and
    :data:`CACHE_VERSION`.
    """
    seeds = list(seeds) if seeds is not None else trajectory_seeds(seed, len(scenes))
    h = hashlib.sha256()
    h.update(
        f"radartune-dataset v{CACHE_VERSION} code={code_fingerprint()} "
        f"fidelity={fidelity} seed={seed} seeds={seeds}\n".encode()
    )
    for s in scenes:
        h.update(s.canonical_json().encode())
        h.update(b"\n")
    return h.hexdigest()[:32]


def trajectory_seeds(seed: int, n: int) -> list[int]:
    """Simulation seed of each of ``n`` scenes: ``SeedSequence([seed, 1]).spawn(n)``.

    (Entropy ``[seed, 1]`` keeps them apart from :func:`core.scene.paper_scenes`, which spawns
    trajectory seeds from ``SeedSequence(seed)``.)
    """
    return [int(c.generate_state(1)[0]) for c in np.random.SeedSequence([seed, 1]).spawn(n)]


def _simulate_task(args: tuple[str, int, str]) -> dict[str, Any]:
    """Worker process: one scene → plain arrays (picklable, small)."""
    scene_json, seed, fidelity = args
    scene = Scene.from_json_text(scene_json)
    run = simulate_scene(scene, fidelity=fidelity, seed=seed)
    merged = PointCloud.concatenate(list(run.clouds))
    return {
        "counts": np.array([len(c) for c in run.clouds], dtype=np.int64),
        "cloud": merged,
        "truth_t_s": run.truth_t_s,
        "truth_xy_m": run.truth_xy_m,
        "truth_v_mps": run.truth_v_mps,
        "n_clutter": run.n_clutter,
    }


def build_dataset(
    scenes: Sequence[Scene],
    *,
    fidelity: str = "exact",
    seed: int = 0,
    jobs: int | None = None,
    cache_dir: str | os.PathLike | None = None,
    progress: ProgressCallback | None = None,
    use_cache: bool = True,
    seeds: Sequence[int] | None = None,
) -> Dataset:
    """Simulate scenes into one data set, cached by hash and written atomically.

    Scene ``k`` is simulated with seed ``seeds[k]`` (default ``trajectory_seeds(seed, K)[k]``),
    one scene per task in a process pool of ``jobs`` workers (default: all cores; ``1`` runs in
    this process), so the result does not depend on ``jobs``.

    Parameters
    ----------
    seed
        Seed of the whole set (recorded in the data set).
    seeds
        Explicit per-scene simulation seeds (the paper set uses each scene's own seed, so any
        trajectory re-simulated alone with :func:`simulate_scene` gives the same frames).
    progress
        Called as ``progress(done, total)`` after each scene.
    use_cache
        Read and write ``<cache_dir>/datasets/<key>.npz`` (key: :func:`dataset_key`).
    """
    if not scenes:
        raise InputError("a data set needs at least one scene")
    _simulator_path(fidelity)
    radar: RadarConfig = scenes[0].radar
    if any(s.radar != radar for s in scenes):
        raise InputError("all scenes of a data set must use the same radar configuration")
    cache_file = None
    if use_cache:
        root = Path(cache_dir) if cache_dir is not None else default_cache_dir()
        key = dataset_key(scenes, fidelity=fidelity, seed=seed, seeds=seeds)
        cache_file = root / "datasets" / f"{key}.npz"
        if cache_file.is_file():
            try:
                ds = Dataset.load(cache_file)
                if progress is not None:
                    progress(len(scenes), len(scenes))
                return ds
            except InputError:
                cache_file.unlink(missing_ok=True)  # corrupt cache entry: simulate again
    if seeds is None:
        seeds = trajectory_seeds(seed, len(scenes))
    elif len(seeds) != len(scenes):
        raise InputError(f"seeds: {len(seeds)} given for {len(scenes)} scenes")
    # self-contained scenes (radar as fields): workers may not see a .cfg relative to a file
    tasks = [
        (json.dumps(s.to_dict(resolve_radar=True)), sd, fidelity) for s, sd in zip(scenes, seeds)
    ]
    jobs = (os.cpu_count() or 1) if jobs is None else max(1, int(jobs))
    results: list[dict[str, Any]] = []
    if jobs == 1 or len(tasks) == 1:
        for i, t in enumerate(tasks):
            results.append(_simulate_task(t))
            if progress is not None:
                progress(i + 1, len(tasks))
    else:
        # workers fork from a single-threaded server that has imported the chain once: safe when
        # the caller has threads (GUI, FFT pools: forking a threaded process can deadlock) and
        # cheaper than "spawn", which imports the chain in every worker
        ctx = _worker_context()
        with ProcessPoolExecutor(max_workers=min(jobs, len(tasks)), mp_context=ctx) as pool:
            for i, r in enumerate(pool.map(_simulate_task, tasks)):
                results.append(r)
                if progress is not None:
                    progress(i + 1, len(tasks))
    ds = _assemble(scenes, results, fidelity=fidelity, seed=seed)
    if cache_file is not None:
        ds.save(cache_file)
    return ds


def _worker_context() -> multiprocessing.context.BaseContext:
    if "forkserver" in multiprocessing.get_all_start_methods():
        ctx = multiprocessing.get_context("forkserver")
        ctx.set_forkserver_preload(["core.pipeline", "core.simulation"])
        return ctx
    return multiprocessing.get_context("spawn")


def _assemble(
    scenes: Sequence[Scene], results: list[dict[str, Any]], *, fidelity: str, seed: int
) -> Dataset:
    n_persons = max(max(s.n_persons for s in scenes), 1)
    traj, t, xy, v = [], [], [], []
    for k, r in enumerate(results):
        f = len(r["counts"])
        traj.append(np.full(f, k, dtype=np.int32))
        t.append(r["truth_t_s"])
        pad = np.full((f, n_persons, 2), np.nan)
        pad[:, : r["truth_xy_m"].shape[1]] = r["truth_xy_m"]
        xy.append(pad)
        pad = np.full((f, n_persons, 2), np.nan)
        pad[:, : r["truth_v_mps"].shape[1]] = r["truth_v_mps"]
        v.append(pad)
    scene_json = (
        scenes[0].to_json()
        if len(scenes) == 1
        else json.dumps([s.to_dict() for s in scenes], indent=1)
    )
    return Dataset.from_cloud(
        cloud=PointCloud.concatenate([r["cloud"] for r in results]),
        counts=np.concatenate([r["counts"] for r in results]),
        trajectory=np.concatenate(traj),
        truth_t_s=np.concatenate(t),
        truth_xy_m=np.concatenate(xy),
        truth_v_mps=np.concatenate(v),
        trajectory_class=[s.trajectory_class for s in scenes],
        scene_json=scene_json,
        radar_json=json.dumps(scenes[0].radar.to_dict()),
        fidelity=fidelity,
        seed=seed,
    )


def paper_dataset(
    seed: int = 0,
    n_trajectories: int = 35,
    *,
    fidelity: str = "exact",
    cache_dir: str | os.PathLike | None = None,
    jobs: int | None = None,
    progress: ProgressCallback | None = None,
    use_cache: bool = True,
    person_model: str = "point",
) -> Dataset:
    """The paper's data set: :func:`core.scene.paper_scenes` simulated (cached).

    Each trajectory is simulated with its scene's own seed, so ``simulate_scene(scene)`` of any
    of the scenes reproduces its frames of the data set bit for bit. ``person_model``
    (``"point"`` or ``"extended"``) changes only the person's scattering model.
    """
    scenes = paper_scenes(seed, n_trajectories, person_model=person_model)
    return build_dataset(
        scenes,
        seeds=[s.seed for s in scenes],
        fidelity=fidelity,
        seed=seed,
        jobs=jobs,
        cache_dir=cache_dir,
        progress=progress,
        use_cache=use_cache,
    )


# ---- clutter density for the tracker ----------------------------------------------------------


def scene_clutter_density(scene: Scene, settings: ProcessingSettings | None = None) -> float:
    """Clutter density ρ for the tracker, per m · rad · m/s.

    ``ρ = (λ·area(AOI) + N_fa) / ((r_max − r_min) · 2 az_max · 2 v_max)``: the expected false
    points per frame — clutter reflectors plus the chain's own noise detections ``N_fa``
    (:func:`core.processing.expected_false_alarms_per_frame`: the two CFAR stages test the same
    cell, so their joint false-alarm probability is far above ``Pfa_r · Pfa_d``; about 0.20 per
    frame for the paper chain) — spread over the measurement-space volume of the AOI.
    Paper scene: (2.089 + 0.200) / 288.1 = 0.00795. SPEC §4's "about 0.0073" is the clutter
    term alone (2.089 / 288.1 = 0.00725); see docs/decisions/scene-05.
    """
    from core.processing import expected_false_alarms_per_frame

    aoi = scene.aoi
    settings = settings or processing_settings(scene)
    # N = λ·A + N_fa
    n_false = expected_clutter_count(aoi, scene.clutter_density_per_m2)
    n_false += expected_false_alarms_per_frame(scene.radar, settings)
    # V = (r_max − r_min) · 2 az_max · 2 v_max
    volume = (
        (aoi.max_range_m - aoi.min_range_m)
        * 2
        * aoi.max_azimuth_rad
        * 2
        * scene.radar.max_velocity_mps
    )
    return n_false / volume


def paper_dataset_file(
    seed: int = 0,
    n_trajectories: int = 35,
    *,
    fidelity: str = "exact",
    cache_dir: str | os.PathLike | None = None,
    jobs: int | None = None,
    progress: ProgressCallback | None = None,
    person_model: str = "point",
) -> Path:
    """Path of the cached paper data set (simulated first if not cached).

    For study workers, which should receive a file path rather than an in-memory data set: the
    file lives in the cache under its content key, so it is never stale. ``person_model`` as in
    :func:`paper_dataset`.
    """
    scenes = paper_scenes(seed, n_trajectories, person_model=person_model)
    seeds = [s.seed for s in scenes]
    root = Path(cache_dir) if cache_dir is not None else default_cache_dir()
    key = dataset_key(scenes, fidelity=fidelity, seed=seed, seeds=seeds)
    path = root / "datasets" / f"{key}.npz"
    if not path.is_file():
        build_dataset(
            scenes,
            seeds=seeds,
            fidelity=fidelity,
            seed=seed,
            jobs=jobs,
            cache_dir=root,
            progress=progress,
        )
    return path

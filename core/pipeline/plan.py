"""The plan of a simulation: which stages run for a scene and a consumer, and why.

The pipeline first builds a :class:`Plan` from the scene and from what the consumer asks for:
every stage declares what it needs and what it produces, and is run or skipped with a reason
(no clutter draws when λ = 0, no elevation on a planar scene, no range-Doppler map kept unless
asked, no simulation at all inside a study trial). ``radartune simulate --explain`` prints it.
Also here: the processing settings a scene is simulated with and the clutter density the
tracker assumes for it.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from core.config import DEFAULT_PROCESSING, PAPER_CHAIN, ChainConfig, ProcessingSettings
from core.errors import InputError
from core.scene import Scene, expected_clutter_count

if TYPE_CHECKING:
    from core.simulation.levels import FrameSimulator

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
    #: the detection chain (``paper``: section 3; ``oob``, ``people-counting``: TI's)
    chain: ChainConfig = PAPER_CHAIN

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
        head = f"plan ({self.consumer}, fidelity {self.fidelity}"
        head += "):" if self.chain.name == "paper" else f", chain {self.chain.name}):"
        lines = [head]
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
    chain: ChainConfig = PAPER_CHAIN,
) -> Plan:
    """Decide which stages run for this scene and this consumer.

    Parameters
    ----------
    scene
        What is simulated.
    keep_rd_maps
        Keep the range-Doppler map of every frame (the GUI asks; a study does not).
    fidelity
        Simulator level (a key of :data:`core.simulation.LEVELS`).
    consumer
        ``"simulate"`` (CLI, data sets), ``"gui"`` (keeps range-Doppler maps) or ``"study"``
        (an optimisation trial: tracks cached point clouds, simulates nothing).
    force
        Stage names to run even where the plan would skip them (for tests and comparisons).
    chain
        The detection chain; TI's chains (``oob``, ``people-counting``) need a baseband cube,
        so they run on the exact level only.
    """
    _check_plan_args(fidelity, consumer, chain)
    keep = keep_rd_maps or consumer == "gui"
    study = consumer == "study"
    needs_el = scene.radar.has_elevation and not scene.is_planar
    stage = _stage_maker(force, study)
    stages = _scene_stages(scene, stage) + _processing_stages(
        scene, stage, fidelity=fidelity, keep=keep, needs_el=needs_el, study=study
    )
    unknown = sorted(set(force) - {s.name for s in stages})
    if unknown:
        raise InputError(f"force: unknown stage(s) {unknown}")
    all_stages: tuple[Stage, ...] = stages
    if chain.name != "paper":
        all_stages = _chain_stages(stages, chain, study)
    return Plan(stages=all_stages, fidelity=fidelity, consumer=consumer, chain=chain)


def _check_plan_args(fidelity: str, consumer: str, chain: ChainConfig) -> None:
    """InputError for an unknown level or consumer, or a TI chain off the exact level."""
    # the registry is imported here, not at load: ``import core.pipeline`` stays light
    from core.simulation.levels import fidelity_level

    fidelity_level(fidelity)  # InputError for an unknown level
    if chain.name != "paper" and fidelity != "exact":
        raise InputError(
            f"chain {chain.name!r} runs on the exact level only (it needs the baseband cube), "
            f"got fidelity={fidelity!r}"
        )
    if consumer not in CONSUMERS:
        raise InputError(f"consumer must be one of {list(CONSUMERS)}, got {consumer!r}")


def _stage_maker(force: Sequence[str], study: bool):
    """``stage(name, needs, produces, run, why_run, why_skip)``: a :class:`Stage` whose run
    flag and reason follow the plan's rules (forced stages run; a study trial runs only the
    loading of cached point clouds)."""

    def stage(name, needs, produces, run, why_run, why_skip):
        run = bool(run) or name in force
        if study and name not in ("load_point_clouds",):
            run, why = False, "a study trial only tracks cached point clouds; it never simulates"
        else:
            why = why_run if run else why_skip
            if name in force and why is why_skip:
                why = "forced"
        return Stage(name=name, needs=needs, produces=produces, run=run, reason=why)

    return stage


def _body_why(scene: Scene) -> str:
    """Why the body model runs: which persons are extended blobs and which walking bodies."""
    extended = [i for i, p in enumerate(scene.persons) if p.kind != "point"]
    walking = [i for i, p in enumerate(scene.persons) if p.kind == "walking"]
    blob = [i for i in extended if i not in walking]
    return " and ".join(
        (
            [f"extended model (torso, arms, legs, micro-Doppler) for person(s) {blob}"]
            if blob
            else []
        )
        + ([f"walking body (17 segments, Boulic gait) for person(s) {walking}"] if walking else [])
    )


def _scene_stages(scene: Scene, stage) -> tuple[Stage, ...]:
    """The stages that build each frame's reflectors: truth to scatterers."""
    has_clutter = scene.clutter_density_per_m2 > 0
    drawn_rcs = [i for i, p in enumerate(scene.persons) if p.rcs_dbsm is None]
    extended = [i for i, p in enumerate(scene.persons) if p.kind != "point"]
    body_why = _body_why(scene)
    lam = scene.clutter_density_per_m2
    room = scene.room
    return (
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
            body_why,
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
            "multipath", ("body_scatterers", "static_reflectors"), ("multipath_paths",),
            room is not None and room.has_multipath,
            "image method over "
            f"{sum(w.reflection > 0 for w in room.walls) if room else 0} reflecting wall(s): "
            "first order (both paths of a bounce), second order (a bounce out and back)",
            "the scene has no reflecting walls: no multipath"
            if room is None or not room.walls
            else "every wall absorbs (reflection_db = -inf): no multipath",
        ),
        stage(
            "scatterers",
            ("truth_xy", "person_rcs", "body_scatterers", "clutter_reflectors",
             "static_reflectors", "multipath_paths"),
            ("scatterers",), True, "reflectors of each frame", "",
        ),
    )  # fmt: skip


def _processing_stages(
    scene: Scene, stage, *, fidelity: str, keep: bool, needs_el: bool, study: bool
) -> tuple[Stage, ...]:
    """The radar's stages: baseband synthesis to the point cloud, and the study's loading."""
    return (
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


#: What TI's chains run instead of the paper's detection stages (docs/radar-chain.md, "Chains").
_CHAIN_STAGES = {
    "oob": (
        ("static_clutter_removal", "clutterRemoval: subtract the mean over loops"),
        ("cfar", "cfarCfg: CFAR in dB along range and along Doppler, peak grouping, cfarFovCfg"),
        ("azimuth", "azimuth FFT at detections; multiObjBeamForming second peaks; aoaFovCfg"),
    ),
    "people-counting": (
        ("static_clutter_removal", "dynamic chain only; the static chain keeps the mean"),
        ("doppler_fft", "per detected point, of its MVDR beam (not a Doppler cube)"),
        ("rd_map", "replaced by the Capon range-azimuth map (dynamicRangeAngleCfg)"),
        ("cfar", "dynamicRACfarCfg on the Capon map; staticRACfarCfg on the static map"),
        ("azimuth", "Capon range-azimuth map peaks; elevation by Capon (dynamic2DAngleCfg)"),
    ),
}


def _chain_stages(stages: tuple[Stage, ...], chain: ChainConfig, study: bool) -> tuple[Stage, ...]:
    why = dict(_CHAIN_STAGES[chain.name])
    out = []
    for s in stages:
        if s.name in why and s.run and not study:
            run: bool = s.run
            if s.name == "static_clutter_removal" and chain.oob is not None:
                run = chain.oob.static_clutter_removal
            reason = why[s.name] if run else "clutterRemoval is off in the chain's .cfg"
            s = dataclasses.replace(s, run=run, reason=reason)
        out.append(s)
    return tuple(out)


def simulator(fidelity: str = "exact") -> FrameSimulator:
    """The frame simulator of a fidelity level (:data:`core.simulation.LEVELS`)."""
    from core.simulation.levels import fidelity_level

    return fidelity_level(fidelity).simulate_frame


def processing_settings(scene: Scene) -> ProcessingSettings:
    """The chain's default processing, with detections limited to the scene's AOI range."""
    return dataclasses.replace(DEFAULT_PROCESSING, max_range_m=scene.aoi.max_range_m)


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

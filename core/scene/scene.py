"""Scene: radar, AOI, clutter, static reflectors and persons; JSON in and out (SPEC §6)."""

from __future__ import annotations

import dataclasses
import json
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from core.config import PAPER_CLUTTER_DENSITY_PER_M2, PAPER_RADAR, RadarConfig
from core.errors import InputError
from core.files import check_text_field, parse_json, read_json, write_text_atomic
from core.formats.ti_cfg import read_ti_cfg
from core.limits import (
    MAX_FRAMES,
    MAX_PERSON_DISTANCE_M,
    MAX_PERSON_FRAMES,
    MAX_PERSONS,
    MAX_SCATTERER_FRAMES,
    MAX_SIMULATED_SAMPLES,
    MAX_STATIC_REFLECTORS,
    PERSON_HEIGHT_RANGE_M,
)
from core.scene.aoi import AOI
from core.scene.body import N_BODY_SCATTERERS
from core.scene.clutter import check_clutter_radar, expected_clutter_count
from core.scene.room import N_FURNITURE_SCATTERERS, ROOM_KEYS, Room, parse_room
from core.scene.trajectory import (
    TRAJECTORY_CLASSES,
    Trajectory,
    generate_trajectory,
    profile_trajectory,
    stopping_waypoint_trajectory,
    validate_class_parameters,
    waypoint_duration_s,
    waypoint_trajectory,
)
from core.scene.walking import (
    DEFAULT_HEIGHT_M,
    MAX_RELATIVE_VELOCITY,
    N_SEGMENTS,
    max_walking_speed_mps,
)

SCHEMA_VERSION = 1
SCENE_KEYS = (
    "schema_version",
    "radar",
    "seed",
    "clutter_density_per_m2",
    "aoi",
    "static_reflectors",
    "persons",
    # a room (docs/rooms.md): written only when the scene has one
    "walls",
    "furniture",
    "sensor",
)
PERSON_KEYS = ("trajectory", "rcs_dbsm", "model", "height_m", "gait_phase")
#: Person models: the paper's point, the 5-scatterer blob (:mod:`core.scene.body`) and the
#: walking body of segments (:mod:`core.scene.walking`). ``"extended"`` is the blob's former
#: name, still read (and written back as given, so old files and results stay identical).
PERSON_MODELS = ("point", "blob", "walking")
PERSON_MODEL_ALIASES = {"extended": "blob"}
#: The person model ``radartune dataset`` and the app's new persons use unless told otherwise
#: (docs/decisions/scene-07-default-person-model.md). A person without ``"model"`` in a scene
#: file stays ``"point"``, so existing scene files keep their meaning.
DEFAULT_PERSON_MODEL = "walking"


def person_model_kind(name: str) -> str:
    """The model a person-model name stands for (``"extended"`` -> ``"blob"``).

    :class:`InputError` for an unknown name.
    """
    kind = PERSON_MODEL_ALIASES.get(name, name) if isinstance(name, str) else name
    if kind not in PERSON_MODELS:
        raise InputError(f"model must be one of {list(PERSON_MODELS)}, got {name!r}")
    return kind


def scatterers_per_person(name: str) -> int:
    """Scatterers a person of model ``name`` contributes to a frame."""
    kind = person_model_kind(name)
    return {"point": 1, "blob": N_BODY_SCATTERERS, "walking": N_SEGMENTS}[kind]


REFLECTOR_KEYS = ("x_m", "y_m", "z_m", "rcs_dbsm")
RCS_RANGE_DBSM = (-60.0, 60.0)
WAYPOINT_SPEED_RANGE_MPS = (0.05, 3.0)
#: A stop waypoint ``[x_m, y_m, 0, hold_s]`` holds for this long, s.
WAYPOINT_HOLD_RANGE_S = (0.08, 600.0)
#: A stop waypoint's 5th element ``[x_m, y_m, 0, hold_s, "sit"]``: the person sits for the hold.
WAYPOINT_SIT = "sit"
MAX_PROFILE_FRAMES = MAX_FRAMES
MIN_SCATTERER_RANGE_M = 0.1
#: The longest a class trajectory without ``duration_s`` lasts (classes c-e draw 6-20 s).
CLASS_MAX_DEFAULT_DURATION_S = 20.0


@dataclass(frozen=True, slots=True, kw_only=True)
class StaticReflector:
    """A fixed point reflector (wall, furniture): v = 0, so static clutter removal removes it."""

    x_m: float
    y_m: float
    z_m: float = 0.0
    rcs_dbsm: float = 10.0

    def to_dict(self) -> dict:
        d = {"x_m": self.x_m, "y_m": self.y_m, "rcs_dbsm": self.rcs_dbsm}
        if self.z_m != 0.0:
            d["z_m"] = self.z_m
        return d


@dataclass(frozen=True, slots=True, kw_only=True)
class Person:
    """One walking person on a trajectory.

    ``rcs_dbsm`` fixes the RCS; ``None`` draws it from eq. (5), N(−8, 16) dBsm, every frame.
    ``model``: ``"point"`` (the paper's, default: one scatterer at z = 0), ``"blob"`` (torso,
    arms and legs as 5 scatterers in the z = 0 plane, :mod:`core.scene.body`; ``"extended"`` is
    its former name) or ``"walking"`` (17 articulated segments at their heights driven by
    Boulic's gait model, :mod:`core.scene.walking`); the RCS is split over the scatterers.
    ``height_m`` (walking model: body height, default 1.75 m) and ``gait_phase`` (walking model:
    phase of the gait cycle at the first frame in cycles, default drawn from the scene seed).
    ``spec`` is the trajectory's JSON description (kept so that the scene saves as written).
    """

    trajectory: Trajectory
    rcs_dbsm: float | None = None
    model: str = "point"
    height_m: float | None = None
    gait_phase: float | None = None
    spec: Mapping[str, Any] = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        kind = person_model_kind(self.model)
        if self.height_m is not None:
            _number(self.height_m, "height_m", *PERSON_HEIGHT_RANGE_M)
        if self.gait_phase is not None:
            _number(self.gait_phase, "gait_phase", 0.0, 1.0)
        if kind == "walking":
            v_max = max_walking_speed_mps(self.body_height_m)
            fastest = float(self.trajectory.speed_mps.max(initial=0.0))
            if fastest > v_max:
                raise InputError(
                    f"trajectory speed {fastest:.3g} m/s exceeds the walking model's "
                    f"{v_max:.3g} m/s for height_m={self.body_height_m} (RV = v / H_t <= "
                    f"{MAX_RELATIVE_VELOCITY}); use a slower trajectory or model 'point'/'blob'"
                )

    @property
    def kind(self) -> str:
        """The person model (``"point"``, ``"blob"`` or ``"walking"``; aliases resolved)."""
        return person_model_kind(self.model)

    @property
    def body_height_m(self) -> float:
        """Body height of the walking model (m)."""
        return DEFAULT_HEIGHT_M if self.height_m is None else float(self.height_m)

    def to_dict(self) -> dict:
        d: dict[str, Any] = {"trajectory": dict(self.spec)}
        if self.rcs_dbsm is not None:
            d["rcs_dbsm"] = self.rcs_dbsm
        if self.model != "point":
            d["model"] = self.model
        if self.height_m is not None:
            d["height_m"] = self.height_m
        if self.gait_phase is not None:
            d["gait_phase"] = self.gait_phase
        return d


@dataclass(frozen=True, slots=True, kw_only=True)
class Scene:
    """Everything the radar sees over a run of frames.

    ``radar_spec`` is how the radar was given in JSON (``"paper"``, a ``.cfg`` path relative to
    the scene file, or a dict of fields); ``radar`` is the resolved configuration.
    """

    seed: int = 0
    radar: RadarConfig = PAPER_RADAR
    radar_spec: str | Mapping[str, Any] = "paper"
    clutter_density_per_m2: float = PAPER_CLUTTER_DENSITY_PER_M2
    aoi: AOI = field(default_factory=AOI)
    static_reflectors: tuple[StaticReflector, ...] = ()
    persons: tuple[Person, ...] = ()
    #: walls, furniture and sensor pose (docs/rooms.md); ``None``: the paper's open field
    room: Room | None = None

    def __post_init__(self) -> None:
        if not (isinstance(self.seed, int) and not isinstance(self.seed, bool) and self.seed >= 0):
            raise InputError(f"seed must be an integer >= 0, got seed={self.seed!r}")
        d = self.clutter_density_per_m2
        if not (isinstance(d, int | float) and math.isfinite(d) and 0 <= d <= 1):
            raise InputError(
                f"clutter_density_per_m2 must be in [0, 1] m^-2, got clutter_density_per_m2={d!r}"
            )
        check_clutter_radar(self.radar, d)

    # ---- derived -----------------------------------------------------------------------------
    @property
    def n_frames(self) -> int:
        """Frames simulated: the longest trajectory (1 for a scene without persons)."""
        return max((p.trajectory.n_frames for p in self.persons), default=1)

    @property
    def n_persons(self) -> int:
        return len(self.persons)

    @property
    def is_planar(self) -> bool:
        """True when every reflector has z = 0 (point and blob persons are at z = 0; walking
        bodies have their segments at their heights)."""
        return (
            all(r.z_m == 0.0 for r in self.static_reflectors)
            and not any(p.kind == "walking" for p in self.persons)
            and self.room is None
        )

    @property
    def trajectory_class(self) -> str:
        """The class of the first person's trajectory (``"drawn"`` for waypoints/profiles)."""
        if not self.persons:
            return "drawn"
        c = self.persons[0].trajectory.trajectory_class
        return c if c in TRAJECTORY_CLASSES else "drawn"

    def truth(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Ground truth per frame.

        Returns
        -------
        t_s
            Frame times, shape ``(F,)``, s.
        xy_m, v_mps
            Shape ``(F, n_persons, 2)``; NaN after a person's trajectory has ended.
        """
        f = self.n_frames
        xy = np.full((f, self.n_persons, 2), np.nan)
        v = np.full((f, self.n_persons, 2), np.nan)
        for i, p in enumerate(self.persons):
            n = p.trajectory.n_frames
            xy[:n, i] = p.trajectory.position_m
            v[:n, i] = p.trajectory.velocity_mps
        return np.arange(f) * self.radar.frame_period_s, xy, v

    # ---- JSON --------------------------------------------------------------------------------
    def to_dict(self, *, resolve_radar: bool = False) -> dict:
        """The scene as JSON-ready data; ``resolve_radar`` writes the radar as its fields
        (self-contained: no ``.cfg`` path relative to a scene file)."""
        if resolve_radar:
            radar: Any = self.radar.to_dict()
        elif isinstance(self.radar_spec, str):
            radar = self.radar_spec
        else:
            radar = dict(self.radar_spec)
        d = {
            "schema_version": SCHEMA_VERSION,
            "radar": radar,
            "seed": self.seed,
            "clutter_density_per_m2": self.clutter_density_per_m2,
            "aoi": self.aoi.to_dict(),
            "static_reflectors": [r.to_dict() for r in self.static_reflectors],
            "persons": [p.to_dict() for p in self.persons],
        }
        if self.room is not None:
            d.update(self.room.to_dict())
        return d

    def to_json(self, path: str | os.PathLike | None = None) -> str:
        """The scene as JSON text; with ``path``, also written atomically (temp file + rename)."""
        text = json.dumps(self.to_dict(), indent=2) + "\n"
        if path is not None:
            write_text_atomic(Path(path), text)
        return text

    def canonical_json(self) -> str:
        """Compact, key-sorted JSON including the resolved radar (for hashing)."""
        return json.dumps(self.to_dict(resolve_radar=True), sort_keys=True, separators=(",", ":"))

    @classmethod
    def from_json(cls, path: str | os.PathLike) -> Scene:
        """Load a scene file; errors name the file and the line (syntax) or the field."""
        path = Path(path)
        data = read_json(path, what="scene file")
        return cls.from_dict(data, source=str(path), base_dir=path.parent)

    @classmethod
    def from_json_text(cls, text: str, source: str = "<scene>") -> Scene:
        return cls.from_dict(parse_json(text, source, what="scene"), source=source)

    @classmethod
    def from_dict(
        cls, data: Any, *, source: str | None = None, base_dir: str | os.PathLike | None = None
    ) -> Scene:
        """Build from parsed JSON (SPEC §6). Errors name ``source`` and the field."""
        try:
            return _parse_scene(data, Path(base_dir) if base_dir else Path.cwd())
        except InputError as exc:
            if exc.source is None and source is not None:
                raise InputError(exc.message, source) from None
            raise


# ---- parsing -----------------------------------------------------------------------------------


def _check_keys(obj: Any, allowed: tuple[str, ...], where: str) -> dict:
    if not isinstance(obj, dict):
        raise InputError(f"{where} must be a JSON object, got {type(obj).__name__}")
    unknown = sorted(set(obj) - set(allowed))
    if unknown:
        raise InputError(f"{where}: unknown key(s) {unknown}; expected some of {list(allowed)}")
    return obj


def _all_numbers(d: dict) -> bool:
    return all(
        isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
        for k, v in d.items()
        if k in ("x_m", "y_m", "z_m")
    )


def _number(value: Any, where: str, lo: float | None = None, hi: float | None = None) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise InputError(f"{where} must be a finite number, got {value!r}")
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        raise InputError(f"{where} must be in [{lo}, {hi}], got {value!r}")
    return float(value)


def _integer(value: Any, where: str, lo: int = 0, hi: int | None = None) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise InputError(f"{where} must be an integer, got {value!r}")
    if value < lo or (hi is not None and value > hi):
        raise InputError(f"{where} must be in [{lo}, {hi}], got {value!r}")
    return value


def _vector(value: Any, where: str, lo: float | None = None, hi: float | None = None) -> np.ndarray:
    if not isinstance(value, list) or len(value) != 2:
        raise InputError(f"{where} must be a list [x, y], got {value!r}")
    return np.array([_number(v, f"{where}[{i}]", lo, hi) for i, v in enumerate(value)])


def _parse_radar(spec: Any, base_dir: Path) -> RadarConfig:
    if spec == "paper":
        return PAPER_RADAR
    if isinstance(spec, str):
        check_text_field(spec, "radar")
        try:
            cfg = (base_dir / spec).resolve()
            found = cfg.is_file()
        except (OSError, ValueError) as exc:
            raise InputError(f"radar: cannot use {spec!r} as a TI .cfg path ({exc})") from None
        if not found:
            raise InputError(f"radar: TI .cfg file {spec!r} not found (looked for {str(cfg)!r})")
        return read_ti_cfg(cfg)
    if isinstance(spec, dict):
        try:
            return RadarConfig.from_dict(spec)
        except InputError as exc:
            raise InputError(f"radar: {exc.message}") from None
    raise InputError(
        f"radar must be 'paper', a path to a TI .cfg or an object of fields, got {spec!r}"
    )


def _parse_trajectory(
    spec: Any, where: str, scene_seed: int, index: int, aoi: AOI, dt: float
) -> Trajectory:
    """A person's trajectory from its JSON: a class a-e, waypoints or an explicit profile."""
    if not isinstance(spec, dict):
        raise InputError(f"{where} must be a JSON object, got {type(spec).__name__}")
    if "class" in spec:
        return _parse_class_trajectory(spec, where, scene_seed, index, aoi, dt)
    if "waypoints" in spec:
        return _parse_waypoint_trajectory(spec, where, aoi, dt)
    if "initial_position_m" in spec:
        return _parse_profile_trajectory(spec, where, dt)
    raise InputError(
        f"{where} needs 'class' (a-e), 'waypoints' or 'initial_position_m' "
        f"(explicit profile), got keys {sorted(spec)}"
    )


def _parse_class_trajectory(
    spec: dict, where: str, scene_seed: int, index: int, aoi: AOI, dt: float
) -> Trajectory:
    """``{"class": "a".."e", "seed"?, class parameters...}``: a random walk of that class."""
    params = {k: v for k, v in spec.items() if k not in ("class", "seed")}
    cls = spec["class"]
    if not isinstance(cls, str) or cls not in TRAJECTORY_CLASSES:
        raise InputError(
            f"{where}.class: unknown trajectory class {cls!r}; "
            f"expected one of {list(TRAJECTORY_CLASSES)}"
        )
    checked = validate_class_parameters(cls, params, where)
    _check_frames(checked.get("duration_s", CLASS_MAX_DEFAULT_DURATION_S) / dt, where)
    if "seed" in spec:
        seed = _integer(spec["seed"], f"{where}.seed")
    else:
        seed = person_seed(scene_seed, index)
    try:
        return generate_trajectory(
            cls, np.random.default_rng(seed), aoi=aoi, frame_period_s=dt, **params
        )
    except InputError as exc:
        raise InputError(f"{where}: {exc.message}") from None


def _parse_waypoint_row(
    row: Any, f: str, aoi: AOI
) -> tuple[tuple[float, float, float], float, bool]:
    """One waypoint ``[x_m, y_m, speed_mps]``, stop ``[x_m, y_m, 0, hold_s]`` or seated stop
    ``[x_m, y_m, 0, hold_s, "sit"]``: ``((x, y, speed), hold_s, sit)``."""
    if not isinstance(row, list) or len(row) not in (3, 4, 5):
        raise InputError(
            f"{f} must be [x_m, y_m, speed_mps] or a stop [x_m, y_m, 0, hold_s] "
            f'(+ "{WAYPOINT_SIT}" to sit), got {row!r}'
        )
    x, y = _number(row[0], f"{f}[0]"), _number(row[1], f"{f}[1]")
    sit = False
    if len(row) >= 4:
        _number(row[2], f"{f}[2] (speed_mps of a stop)", 0.0, 0.0)
        s, hold = 0.0, _number(row[3], f"{f}[3] (hold_s)", *WAYPOINT_HOLD_RANGE_S)
        if len(row) == 5:
            if row[4] != WAYPOINT_SIT:
                raise InputError(f'{f}[4] (posture) must be "{WAYPOINT_SIT}", got {row[4]!r}')
            sit = True
    else:
        s = _number(row[2], f"{f}[2] (speed_mps)", *WAYPOINT_SPEED_RANGE_MPS)
        hold = 0.0
    if not aoi.contains(np.array([x, y])):
        raise InputError(f"{f}: point ({x}, {y}) lies outside the AOI")
    return (x, y, s), hold, sit


def _parse_waypoint_trajectory(spec: dict, where: str, aoi: AOI, dt: float) -> Trajectory:
    """``{"waypoints": [[x, y, speed] | [x, y, 0, hold_s(, "sit")], ...]}``: straight legs and
    stops (standing or seated)."""
    _check_keys(spec, ("waypoints",), where)
    w = spec["waypoints"]
    if not isinstance(w, list) or len(w) < 2:
        raise InputError(f"{where}.waypoints must list at least 2 [x_m, y_m, speed_mps]")
    if len(w) > MAX_FRAMES:
        raise InputError(f"{where}.waypoints lists {len(w)} points, more than {MAX_FRAMES}")
    rows, holds, sits = [], [], []
    for i, row in enumerate(w):
        point, hold, sit = _parse_waypoint_row(row, f"{where}.waypoints[{i}]", aoi)
        rows.append(point)
        holds.append(hold)
        sits.append(sit)
    if all(s == 0 for _, _, s in rows):
        raise InputError(f"{where}.waypoints: stops only; give some waypoint a speed")
    # the stops walked at the slowest speed given: an upper bound of the walking time
    slowest = min(s for _, _, s in rows if s > 0)
    walk = [r if r[2] > 0 else (r[0], r[1], slowest) for r in rows]
    _check_frames((waypoint_duration_s(np.array(walk)) + sum(holds)) / dt, where)
    try:
        if any(holds):
            return stopping_waypoint_trajectory(
                np.array(rows),
                np.array(holds),
                frame_period_s=dt,
                sit=np.array(sits) if any(sits) else None,
            )
        return waypoint_trajectory(np.array(rows), frame_period_s=dt)
    except InputError as exc:
        raise InputError(f"{where}: {exc.message}") from None


def _parse_profile_trajectory(spec: dict, where: str, dt: float) -> Trajectory:
    """``{"initial_position_m", "initial_velocity_mps", "acceleration_mps2", "frames"?}``: an
    explicit acceleration profile (one vector, or one row per frame)."""
    keys = ("initial_position_m", "initial_velocity_mps", "acceleration_mps2", "frames")
    _check_keys(spec, keys, where)
    for k in keys[:3]:
        if k not in spec:
            raise InputError(f"{where}: missing key {k!r}")
    # components bounded so that the integrated walk stays finite (checked whole below)
    bound = (-MAX_PERSON_DISTANCE_M, MAX_PERSON_DISTANCE_M)
    p0 = _vector(spec["initial_position_m"], f"{where}.initial_position_m", *bound)
    v0 = _vector(spec["initial_velocity_mps"], f"{where}.initial_velocity_mps", *bound)
    acc = spec["acceleration_mps2"]
    if isinstance(acc, list) and len(acc) > MAX_PROFILE_FRAMES:
        raise InputError(
            f"{where}.acceleration_mps2 lists {len(acc)} rows, more than {MAX_PROFILE_FRAMES}"
        )
    if isinstance(acc, list) and acc and isinstance(acc[0], list):
        a = np.array(
            [_vector(row, f"{where}.acceleration_mps2[{i}]", *bound) for i, row in enumerate(acc)]
        )
    else:
        a = _vector(acc, f"{where}.acceleration_mps2", *bound)
    frames = spec.get("frames")
    if frames is not None:
        frames = _integer(frames, f"{where}.frames", 1, MAX_PROFILE_FRAMES)
    try:
        return profile_trajectory(
            initial_position_m=p0,
            initial_velocity_mps=v0,
            acceleration_mps2=a,
            frames=frames,
            frame_period_s=dt,
        )
    except InputError as exc:
        raise InputError(f"{where}: {exc.message}") from None


def _check_frames(n_frames: float, where: str) -> None:
    """Refuse a trajectory that would last more than :data:`MAX_FRAMES` frames (before it is
    built: its arrays have one row per frame)."""
    if not n_frames <= MAX_FRAMES:
        raise InputError(
            f"{where} would last {n_frames:.0f} frames, more than the limit {MAX_FRAMES}"
        )


def person_seed(scene_seed: int, index: int) -> int:
    """Trajectory seed of person ``index`` when its JSON gives none."""
    return int(np.random.SeedSequence([scene_seed, index]).generate_state(1)[0])


def _parse_scene(data: Any, base_dir: Path) -> Scene:
    """A scene from its JSON object, every field checked (the first fault names its field)."""
    _check_keys(data, SCENE_KEYS, "scene")
    if data.get("schema_version") != SCHEMA_VERSION:
        raise InputError(
            f"schema_version must be {SCHEMA_VERSION}, got {data.get('schema_version')!r}"
        )
    radar_spec = data.get("radar", "paper")
    radar = _parse_radar(radar_spec, base_dir)
    seed = _integer(data.get("seed", 0), "seed")
    # a file without a clutter density has the paper's, as Scene() and the editor do
    density = _number(
        data.get("clutter_density_per_m2", PAPER_CLUTTER_DENSITY_PER_M2),
        "clutter_density_per_m2",
        0,
        1,
    )
    aoi = _parse_aoi(data.get("aoi", {}), radar)
    reflectors = _parse_static_reflectors(data.get("static_reflectors", []), radar)
    room = parse_room(data) if any(k in data for k in ROOM_KEYS) else None
    persons = _parse_persons(data.get("persons", []), seed, aoi, radar)
    _check_scene_work(persons, reflectors, room, aoi, density, radar)
    return Scene(
        seed=seed,
        radar=radar,
        radar_spec=radar_spec,
        clutter_density_per_m2=density,
        aoi=aoi,
        static_reflectors=tuple(reflectors),
        persons=tuple(persons),
        room=room,
    )


def _parse_aoi(spec: Any, radar: RadarConfig) -> AOI:
    """The area of interest, within the radar's maximum range."""
    aoi_d = _check_keys(spec, ("min_range_m", "max_range_m", "max_azimuth_deg"), "aoi")
    aoi = AOI(**{k: _number(v, f"aoi.{k}") for k, v in aoi_d.items()})
    if aoi.max_range_m > radar.max_range_m:
        raise InputError(
            f"aoi.max_range_m={aoi.max_range_m} exceeds the radar's maximum range "
            f"{radar.max_range_m:.3f} m"
        )
    return aoi


def _parse_static_reflectors(refl: Any, radar: RadarConfig) -> list[StaticReflector]:
    """``static_reflectors``: points at a range the radar sees."""
    if not isinstance(refl, list):
        raise InputError("static_reflectors must be a list")
    if len(refl) > MAX_STATIC_REFLECTORS:
        raise InputError(
            f"static_reflectors lists {len(refl)}, more than the limit {MAX_STATIC_REFLECTORS}"
        )
    reflectors = []
    for i, r in enumerate(refl):
        where = f"static_reflectors[{i}]"
        _check_keys(r, REFLECTOR_KEYS, where)
        for k in ("x_m", "y_m"):
            if k not in r:
                raise InputError(f"{where}: missing key {k!r}")
        r_m = math.hypot(r["x_m"], r["y_m"], r.get("z_m", 0.0)) if _all_numbers(r) else None
        if r_m is not None and not MIN_SCATTERER_RANGE_M <= r_m <= radar.max_range_m:
            raise InputError(
                f"{where}: range {r_m:.3g} m must be in [{MIN_SCATTERER_RANGE_M}, "
                f"{radar.max_range_m:.3f}] m (the radar's maximum range)"
            )
        reflectors.append(
            StaticReflector(
                x_m=_number(r["x_m"], f"{where}.x_m"),
                y_m=_number(r["y_m"], f"{where}.y_m"),
                z_m=_number(r.get("z_m", 0.0), f"{where}.z_m", -10, 10),
                rcs_dbsm=_number(r.get("rcs_dbsm", 10.0), f"{where}.rcs_dbsm", *RCS_RANGE_DBSM),
            )
        )
    return reflectors


def _parse_persons(persons_d: Any, seed: int, aoi: AOI, radar: RadarConfig) -> list[Person]:
    """``persons``: 1 to :data:`MAX_PERSONS`, each a trajectory and its body."""
    if not isinstance(persons_d, list):
        raise InputError("persons must be a list")
    if len(persons_d) > MAX_PERSONS:
        raise InputError(f"persons lists {len(persons_d)}, more than the limit {MAX_PERSONS}")
    if not persons_d:
        raise InputError(f"persons lists none; a scene holds 1 to {MAX_PERSONS} persons")
    return [_parse_person(p, f"persons[{i}]", seed, i, aoi, radar) for i, p in enumerate(persons_d)]


def _parse_person(
    p: Any, where: str, seed: int, index: int, aoi: AOI, radar: RadarConfig
) -> Person:
    """One person: the trajectory (kept in the radar's reach) and the optional body fields."""
    _check_keys(p, PERSON_KEYS, where)
    if "trajectory" not in p:
        raise InputError(f"{where}: missing key 'trajectory'")
    traj = _parse_trajectory(
        p["trajectory"], f"{where}.trajectory", seed, index, aoi, radar.frame_period_s
    )
    _check_person_distance(traj, where)
    rcs = p.get("rcs_dbsm")
    if rcs is not None:
        rcs = _number(rcs, f"{where}.rcs_dbsm", *RCS_RANGE_DBSM)
    model = p.get("model", "point")
    try:
        person_model_kind(model)
    except InputError as exc:
        raise InputError(f"{where}.{exc.message}") from None
    height = p.get("height_m")
    if height is not None:
        height = _number(height, f"{where}.height_m", *PERSON_HEIGHT_RANGE_M)
    phase = p.get("gait_phase")
    if phase is not None:
        phase = _number(phase, f"{where}.gait_phase", 0.0, 1.0)
    try:
        return Person(
            trajectory=traj,
            rcs_dbsm=rcs,
            model=model,
            height_m=height,
            gait_phase=phase,
            spec=dict(p["trajectory"]),
        )
    except InputError as exc:
        raise InputError(f"{where}: {exc.message}") from None


def _check_person_distance(traj: Trajectory, where: str) -> None:
    """Refuse a walk that leaves :data:`MAX_PERSON_DISTANCE_M` or comes closer than
    :data:`MIN_SCATTERER_RANGE_M` to the radar."""
    r = np.hypot(*traj.position_m.T)
    r_min = float(r.min())
    if not r.max() <= MAX_PERSON_DISTANCE_M:
        far = int(np.argmax(~(r <= MAX_PERSON_DISTANCE_M)))
        raise InputError(
            f"{where}.trajectory is {r[far]:.3g} m from the radar at frame {far} "
            f"(at most {MAX_PERSON_DISTANCE_M:g} m)"
        )
    if r_min < MIN_SCATTERER_RANGE_M:
        raise InputError(
            f"{where}.trajectory passes within {r_min:.3g} m of the radar "
            f"(at least {MIN_SCATTERER_RANGE_M} m)"
        )


def _check_scene_work(
    persons: list[Person],
    reflectors: list[StaticReflector],
    room: Room | None,
    aoi: AOI,
    density: float,
    radar: RadarConfig,
) -> None:
    """Refuse a scene whose simulation would exceed one scene's work (frames x persons,
    frames x scatterers, frames x radar cube)."""
    n_frames = max((p.trajectory.n_frames for p in persons), default=1)
    if len(persons) * n_frames > MAX_PERSON_FRAMES:
        raise InputError(
            f"persons x frames = {len(persons)} x {n_frames} exceeds the limit "
            f"{MAX_PERSON_FRAMES} of one scene's work"
        )
    scatterers = (
        sum(scatterers_per_person(p.model) for p in persons)
        + len(reflectors)
        + (N_FURNITURE_SCATTERERS * len(room.furniture) if room is not None else 0)
        + expected_clutter_count(aoi, density)
    )
    if n_frames * scatterers > MAX_SCATTERER_FRAMES:
        raise InputError(
            f"frames x scatterers = {n_frames} x {scatterers:.0f} (persons' scatterers, static "
            f"reflectors and expected clutter points) exceeds the limit {MAX_SCATTERER_FRAMES} "
            "of one scene's work"
        )
    cube = radar.n_tx * radar.n_rx * radar.n_loops * radar.n_samples
    if n_frames * cube > MAX_SIMULATED_SAMPLES:
        raise InputError(
            f"frames x radar cube = {n_frames} x {cube} samples exceeds the limit "
            f"{MAX_SIMULATED_SAMPLES:.3g} of one scene's work"
        )


def class_scene(
    trajectory_class: str,
    trajectory_seed: int,
    *,
    seed: int = 0,
    clutter_density_per_m2: float = PAPER_CLUTTER_DENSITY_PER_M2,
    radar: RadarConfig = PAPER_RADAR,
    aoi: AOI | None = None,
    **class_params: Any,
) -> Scene:
    """A one-person scene whose trajectory is of a class a–e (the paper's set-up)."""
    aoi = aoi or AOI()
    traj = generate_trajectory(
        trajectory_class,
        np.random.default_rng(trajectory_seed),
        aoi=aoi,
        frame_period_s=radar.frame_period_s,
        **class_params,
    )
    spec = {"class": trajectory_class, "seed": int(trajectory_seed), **class_params}
    return Scene(
        seed=seed,
        radar=radar,
        radar_spec="paper" if radar == PAPER_RADAR else radar.to_dict(),
        clutter_density_per_m2=clutter_density_per_m2,
        aoi=aoi,
        persons=(Person(trajectory=traj, spec=spec),),
    )


def paper_scenes(
    seed: int, n_trajectories: int = 35, *, person_model: str = "point", n_persons: int = 1
) -> list[Scene]:
    """The paper's data set: 7 trajectories per class, ordered round-robin a, b, c, d, e, a, …

    Trajectory ``k`` has class ``"abcde"[k % 5]``; its trajectory seed and its scene seed come
    from ``numpy.random.SeedSequence(seed).spawn(n_trajectories)`` (child ``k`` →
    two 32-bit words), so the set depends on ``seed`` only.

    ``person_model`` (``"point"``, the paper's, ``"blob"`` (or its former name
    ``"extended"``) or ``"walking"``) changes only the person's scattering model
    (:class:`Person` ``model``): trajectories, scene seeds and everything else are those of the
    point-model set of the same ``seed``.

    ``n_persons`` > 1 (at most :data:`core.limits.MAX_PERSONS`) adds persons 1 … N−1 to every
    scene: person j walks a trajectory of class ``"abcde"[(k + j) % 5]`` drawn with the seed
    ``child_k.spawn(N − 1)[j − 1]`` (one 32-bit word). Person 0, the scene seed and the class of
    the trajectory are those of the one-person set of the same ``seed``; each person leaves the
    scene when its trajectory ends (the scene lasts as long as the longest).
    """
    if n_trajectories < 1:
        raise InputError(f"n_trajectories must be >= 1, got {n_trajectories}")
    try:
        person_model_kind(person_model)
    except InputError as exc:
        raise InputError(f"person_{exc.message}") from None
    if not (isinstance(n_persons, int) and 1 <= n_persons <= MAX_PERSONS):
        raise InputError(f"n_persons must be in [1, {MAX_PERSONS}], got {n_persons!r}")
    scenes = []
    for k, child in enumerate(np.random.SeedSequence(seed).spawn(n_trajectories)):
        traj_seed, scene_seed = (int(s) for s in child.generate_state(2))
        scene = class_scene(TRAJECTORY_CLASSES[k % 5], traj_seed, seed=scene_seed)
        if n_persons > 1:
            extra = []
            for j, sub in enumerate(child.spawn(n_persons - 1), start=1):
                cls, s = TRAJECTORY_CLASSES[(k + j) % 5], int(sub.generate_state(1)[0])
                traj = generate_trajectory(
                    cls,
                    np.random.default_rng(s),
                    aoi=scene.aoi,
                    frame_period_s=scene.radar.frame_period_s,
                )
                extra.append(Person(trajectory=traj, spec={"class": cls, "seed": s}))
            scene = dataclasses.replace(scene, persons=(*scene.persons, *extra))
        if person_model != "point":
            scene = dataclasses.replace(
                scene,
                persons=tuple(dataclasses.replace(p, model=person_model) for p in scene.persons),
            )
        scenes.append(scene)
    return scenes

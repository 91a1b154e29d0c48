"""gtrack's parameters (:class:`GtrackParams`), their one mapping to and from TI's ``.cfg`` lines.

Every field of TI's tracker lines (``trackingCfg``, ``sensorPosition``, ``boundaryBox``,
``staticBoundaryBox``, ``presenceBoundaryBox``, ``gatingParam``, ``stateParam``,
``allocationParam``, ``maxAcceleration``) has one row in :data:`CFG_MAP`: the line, the field's
position there, the :class:`GtrackParams` attribute and the line's units in one SI unit
(``trackingCfg`` gives the maximum radial velocity in 0.1 m/s, the radial velocity resolution in
mm/s and the frame period in ms; ``sensorPosition`` its tilts in degrees). The line syntax (field
names, integer or number) is :data:`core.formats.ti_cfg.TRACKER_COMMAND_FIELDS`; the reading and
writing of the lines is :func:`params_from_cfg` and :func:`cfg_lines`. Fields not carried by the
lines (the measurement noise of one point) keep their defaults and are named in the docs.
"""

from __future__ import annotations

import math
import os
from dataclasses import asdict, dataclass, fields, replace
from pathlib import Path

from core.errors import InputError
from core.files import read_json, write_json_atomic
from core.formats.ti_cfg import TRACKER_COMMAND_FIELDS, TiCommand, tracker_fields
from core.limits import FRAME_PERIOD_RANGE_S, MAX_TRACKS
from core.tracking.space import GTRACK_LEGACY_NAMES as LEGACY_NAMES

__all__ = [
    "GtrackParams",
    "CFG_MAP",
    "params_from_cfg",
    "cfg_lines",
    "BOX_NAMES",
    "LEGACY_NAMES",
]

#: The three boxes: attribute prefix -> cfg line.
BOX_NAMES = {
    "boundary": "boundaryBox",
    "static": "staticBoundaryBox",
    "presence": "presenceBoundaryBox",
}
#: Upper bound of the counters and point counts (frames or points).
MAX_COUNT = 1_000_000
#: Upper bound of the lengths, speeds and accelerations (m, m/s, m/s²): far beyond any room.
MAX_SCALE = 1e4
_BOX_SUFFIX = ("x_min_m", "x_max_m", "y_min_m", "y_max_m", "z_min_m", "z_max_m")


@dataclass(frozen=True, slots=True, kw_only=True)
class GtrackParams:
    """Parameters of the gtrack-compatible tracker (SI units; the cfg's units in :data:`CFG_MAP`).

    Defaults are TI's published people-counting values (``resources/gtrack/ti_people_counting
    .cfg``; docs/tracking/gtrack.md cites them); ``dims`` and the point noise are RadarTune's.

    Attributes
    ----------
    dims
        3 (state ``[x, y, z, vx, vy, vz, ax, ay, az]``, measurement ``[r, az, el, vr]``) or 2
        (``[x, y, vx, vy, ax, ay]``, ``[r, az, vr]``).
    tracker_enabled, param_set, max_points, max_tracks
        ``trackingCfg`` fields 1–4: tracker on, TI's parameter-set index (kept, not used), the
        point and track capacities.
    max_radial_velocity_mps, radial_velocity_resolution_mps, frame_period_s
        ``trackingCfg`` fields 5–7: the chirp configuration's unambiguous radial velocity, its
        resolution (points with |vr| below half of it are static) and the frame period T.
    sensor_height_m, sensor_azimuth_tilt_deg, sensor_elevation_tilt_deg
        ``sensorPosition``: height above the floor, rotation about z, downward tilt.
    boundary_*, static_*, presence_*
        The boxes (world x, y, z limits in m): points outside the boundary box are not used; the
        static box selects the miss rules; the presence box the presence flag.
    gating_gain, gating_width_m, gating_depth_m, gating_height_m, gating_velocity_mps
        ``gatingParam``: the gate's size in standard deviations and its limits (full extents in
        world x, y, z and radial velocity; velocity 0: no limit).
    det2act, det2free, active2free, static2free, exit2free, sleep2free
        ``stateParam``: the state counters (frames).
    snr_thre, snr_thre_obscured, velocity_thre_mps, points_thre, max_distance_thre_m2,
    max_vel_thre_mps
        ``allocationParam``: a new track needs a set of at least ``points_thre`` points, each
        within ``max_distance_thre_m2`` (squared distance, m²) and ``max_vel_thre_mps`` of
        the set's centroid, with centroid |vr| ≥ ``velocity_thre_mps`` and an SNR sum ≥
        ``snr_thre`` (≥ ``snr_thre_obscured`` behind another track).
    max_accel_x_mps2, max_accel_y_mps2, max_accel_z_mps2
        ``maxAcceleration``: the process noise's acceleration-increment standard deviations.
    range_sigma_m, angle_sigma_rad, doppler_sigma_mps
        Measurement noise of one point (not in the cfg lines; RadarTune's choice).
    """

    dims: int = 3
    tracker_enabled: int = 1
    param_set: int = 2
    max_points: int = 800
    max_tracks: int = 30
    max_radial_velocity_mps: float = 4.6
    radial_velocity_resolution_mps: float = 0.096
    frame_period_s: float = 0.055
    sensor_height_m: float = 2.0
    sensor_azimuth_tilt_deg: float = 0.0
    sensor_elevation_tilt_deg: float = 15.0
    boundary_x_min_m: float = -4.0
    boundary_x_max_m: float = 4.0
    boundary_y_min_m: float = 0.0
    boundary_y_max_m: float = 8.0
    boundary_z_min_m: float = 0.0
    boundary_z_max_m: float = 3.0
    static_x_min_m: float = -3.0
    static_x_max_m: float = 3.0
    static_y_min_m: float = 0.5
    static_y_max_m: float = 7.5
    static_z_min_m: float = 0.0
    static_z_max_m: float = 3.0
    presence_x_min_m: float = -3.0
    presence_x_max_m: float = 3.0
    presence_y_min_m: float = 0.5
    presence_y_max_m: float = 7.5
    presence_z_min_m: float = 0.0
    presence_z_max_m: float = 3.0
    gating_gain: float = 3.0
    gating_width_m: float = 2.0
    gating_depth_m: float = 2.0
    gating_height_m: float = 2.0
    gating_velocity_mps: float = 4.0
    det2act: int = 3
    det2free: int = 3
    active2free: int = 12
    static2free: int = 500
    exit2free: int = 5
    sleep2free: int = 6000
    snr_thre: float = 40.0
    snr_thre_obscured: float = 100.0
    velocity_thre_mps: float = 0.1
    points_thre: int = 20
    max_distance_thre_m2: float = 0.5
    max_vel_thre_mps: float = 20.0
    max_accel_x_mps2: float = 0.1
    max_accel_y_mps2: float = 0.1
    max_accel_z_mps2: float = 0.1
    range_sigma_m: float = 0.05
    angle_sigma_rad: float = 0.03
    doppler_sigma_mps: float = 0.1

    def __post_init__(self) -> None:
        if self.dims not in (2, 3):
            raise InputError(f"dims must be 2 or 3, got dims={self.dims!r}")
        for f in fields(self):
            v = getattr(self, f.name)
            if f.type == "int":
                if isinstance(v, bool) or not isinstance(v, int):
                    raise InputError(f"{f.name} must be an integer, got {f.name}={v!r}")
            elif isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
                raise InputError(f"{f.name} must be a finite number, got {f.name}={v!r}")
        for name in ("tracker_enabled",):
            if getattr(self, name) not in (0, 1):
                raise InputError(f"{name} must be 0 or 1, got {getattr(self, name)}")
        for name in (
            "max_points",
            "max_tracks",
            "det2act",
            "det2free",
            "active2free",
            "static2free",
            "exit2free",
            "sleep2free",
        ):
            if getattr(self, name) < 1:
                raise InputError(f"{name} must be >= 1, got {name}={getattr(self, name)}")
        for name in (
            "max_radial_velocity_mps",
            "radial_velocity_resolution_mps",
            "frame_period_s",
            "gating_gain",
            "gating_width_m",
            "gating_depth_m",
            "gating_height_m",
            "max_distance_thre_m2",
            "max_vel_thre_mps",
            "range_sigma_m",
            "angle_sigma_rad",
            "doppler_sigma_mps",
        ):
            if not getattr(self, name) > 0:
                raise InputError(f"{name} must be > 0, got {name}={getattr(self, name)}")
        for name in (
            "points_thre",  # more than pointsThre points: 0 lets one point start a track
            "gating_velocity_mps",
            "snr_thre",
            "snr_thre_obscured",
            "velocity_thre_mps",
            "max_accel_x_mps2",
            "max_accel_y_mps2",
            "max_accel_z_mps2",
            "sensor_height_m",
        ):
            if getattr(self, name) < 0:
                raise InputError(f"{name} must be >= 0, got {name}={getattr(self, name)}")
        if self.max_tracks > MAX_TRACKS:
            raise InputError(
                f"max_tracks must be <= {MAX_TRACKS}, got max_tracks={self.max_tracks}"
            )
        for name in ("max_points", "det2act", "det2free", "active2free", "static2free",
                     "exit2free", "sleep2free", "points_thre"):  # fmt: skip
            if getattr(self, name) > MAX_COUNT:
                raise InputError(f"{name} must be <= {MAX_COUNT}, got {name}={getattr(self, name)}")
        lo, hi = FRAME_PERIOD_RANGE_S
        if not lo <= self.frame_period_s <= hi:
            raise InputError(f"frame_period_s must be in [{lo}, {hi}] s, got {self.frame_period_s}")
        for name in ("sensor_height_m", "gating_width_m", "gating_depth_m", "gating_height_m",
                     "gating_velocity_mps", "max_radial_velocity_mps",
                     "radial_velocity_resolution_mps", "velocity_thre_mps",
                     "max_vel_thre_mps", "max_accel_x_mps2", "max_accel_y_mps2",
                     "max_accel_z_mps2", "range_sigma_m", "doppler_sigma_mps"):  # fmt: skip
            if getattr(self, name) > MAX_SCALE:
                raise InputError(f"{name} must be <= {MAX_SCALE:g}, got {getattr(self, name)}")
        if not -90.0 < self.sensor_elevation_tilt_deg < 90.0:
            raise InputError(
                "sensor_elevation_tilt_deg must be in (-90, 90), "
                f"got {self.sensor_elevation_tilt_deg}"
            )
        for prefix in BOX_NAMES:
            for axis in "xyz":
                lo = getattr(self, f"{prefix}_{axis}_min_m")
                hi = getattr(self, f"{prefix}_{axis}_max_m")
                if not lo < hi:
                    raise InputError(
                        f"{prefix}_{axis}_min_m must be < {prefix}_{axis}_max_m, got {lo}, {hi}"
                    )

    def box(self, prefix: str) -> tuple[float, float, float, float, float, float]:
        """``(x_min, x_max, y_min, y_max, z_min, z_max)`` of the box ``prefix`` (m)."""
        return tuple(getattr(self, f"{prefix}_{s}") for s in _BOX_SUFFIX)

    @property
    def max_acceleration_mps2(self) -> tuple[float, float, float]:
        return (self.max_accel_x_mps2, self.max_accel_y_mps2, self.max_accel_z_mps2)

    def to_dict(self) -> dict[str, float | int]:
        """Flat JSON document (every field)."""
        return asdict(self)

    @classmethod
    def from_dict(cls, doc: object, source: str = "<params>") -> GtrackParams:
        """From a flat JSON object; missing keys take the defaults, unknown keys are an error."""
        if not isinstance(doc, dict):
            raise InputError("gtrack parameters must be a JSON object", source)
        names = {f.name: f for f in fields(cls)}
        doc = {LEGACY_NAMES.get(str(k), str(k)): v for k, v in doc.items()}
        unknown = sorted(set(doc) - set(names))
        if unknown:
            raise InputError(f"unknown gtrack parameter(s): {', '.join(map(str, unknown))}", source)
        values: dict[str, float | int] = {}
        for key, v in doc.items():
            if names[key].type == "int" and isinstance(v, float) and v.is_integer():
                v = int(v)
            values[key] = v
        try:
            return cls(**values)
        except InputError as exc:
            raise InputError(exc.message, source) from None

    @classmethod
    def load(cls, path: str | os.PathLike) -> GtrackParams:
        return cls.from_dict(read_json(Path(path), what="gtrack parameters"), str(path))

    def save(self, path: str | os.PathLike) -> None:
        write_json_atomic(Path(path), self.to_dict())


def _map() -> tuple[tuple[str, int, str, float], ...]:
    rows: list[tuple[str, int, str, float]] = []
    tracking = (
        "tracker_enabled",
        "param_set",
        "max_points",
        "max_tracks",
        "max_radial_velocity_mps",
        "radial_velocity_resolution_mps",
        "frame_period_s",
    )
    scale = (1.0, 1.0, 1.0, 1.0, 10.0, 1000.0, 1000.0)
    rows += [("trackingCfg", i, a, s) for i, (a, s) in enumerate(zip(tracking, scale))]
    rows += [
        ("sensorPosition", i, a, 1.0)
        for i, a in enumerate(
            ("sensor_height_m", "sensor_azimuth_tilt_deg", "sensor_elevation_tilt_deg")
        )
    ]
    for prefix, line in BOX_NAMES.items():
        rows += [(line, i, f"{prefix}_{s}", 1.0) for i, s in enumerate(_BOX_SUFFIX)]
    rows += [
        ("gatingParam", i, a, 1.0)
        for i, a in enumerate(
            (
                "gating_gain",
                "gating_width_m",
                "gating_depth_m",
                "gating_height_m",
                "gating_velocity_mps",
            )
        )
    ]
    rows += [
        ("stateParam", i, a, 1.0)
        for i, a in enumerate(
            ("det2act", "det2free", "active2free", "static2free", "exit2free", "sleep2free")
        )
    ]
    rows += [
        ("allocationParam", i, a, 1.0)
        for i, a in enumerate(
            (
                "snr_thre",
                "snr_thre_obscured",
                "velocity_thre_mps",
                "points_thre",
                "max_distance_thre_m2",
                "max_vel_thre_mps",
            )
        )
    ]
    rows += [
        ("maxAcceleration", i, a, 1.0)
        for i, a in enumerate(("max_accel_x_mps2", "max_accel_y_mps2", "max_accel_z_mps2"))
    ]
    return tuple(rows)


#: (cfg line, field index, GtrackParams attribute, cfg units per SI unit): the one mapping.
CFG_MAP: tuple[tuple[str, int, str, float], ...] = _map()


def params_from_cfg(
    commands: list[TiCommand], source: str = "<cfg>", base: GtrackParams | None = None
) -> GtrackParams:
    """gtrack parameters from a parsed TI cfg; lines it lacks keep ``base``'s (default) values.

    Raises :class:`InputError` naming file, line and field of a malformed or out-of-range field.
    """
    base = base or GtrackParams()
    found = tracker_fields(commands, source)
    values: dict[str, float | int] = {}
    where: dict[str, tuple[TiCommand, int]] = {}
    for line, index, attr, scale in CFG_MAP:
        if line not in found:
            continue
        cmd, vals = found[line]
        v = vals[index]
        values[attr] = v if scale == 1.0 else v / scale
        where[attr] = (cmd, index)
    try:
        return replace(base, **values)
    except InputError as exc:
        attr = exc.message.split(" ", 1)[0]
        if attr in where:
            cmd, index = where[attr]
            name = TRACKER_COMMAND_FIELDS[cmd.name][index][0]
            raise InputError(
                f"{cmd.name} field {index + 1} {name!r}: {exc.message}", f"{source}:{cmd.line}"
            ) from None
        raise InputError(exc.message, source) from None


def _number(v: float | int) -> str:
    if isinstance(v, int):
        return str(v)
    text = f"{v:.10g}"
    return text


def cfg_lines(params: GtrackParams) -> dict[str, str]:
    """The tracker lines of ``params``, by command name (values back in the cfg's units)."""
    args: dict[str, dict[int, str]] = {}
    for line, index, attr, scale in CFG_MAP:
        v = getattr(params, attr)
        if scale != 1.0:
            v = v * scale
            if TRACKER_COMMAND_FIELDS[line][index][1] is int:
                v = round(v)
        args.setdefault(line, {})[index] = _number(v)
    return {line: " ".join([line, *(a[i] for i in sorted(a))]) for line, a in args.items()}

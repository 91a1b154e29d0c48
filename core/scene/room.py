"""Rooms: walls (vertical reflecting planes), furniture (static reflectors) and the sensor pose.

Room coordinates: x across, y along the radar's horizontal boresight, z up from the floor; the
radar sits at ``(0, 0, height_m)``, its boresight tilted down by ``tilt_deg``. A scene without a
room keeps the paper's frame (radar at the origin, boresight +y, no tilt). docs/rooms.md.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from core.errors import InputError
from core.files import read_json

ROOM_KEYS = ("walls", "furniture", "sensor")
WALL_KEYS = ("from_m", "to_m", "reflection_db")
FURNITURE_KEYS = ("x_m", "y_m", "width_m", "depth_m", "height_m", "rcs_dbsm")
SENSOR_KEYS = ("height_m", "tilt_deg")
#: A wall shorter than this is refused (its image is not defined).
MIN_WALL_LENGTH_M = 0.01
#: The radar may sit this close to a wall (mounted on it) and still be inside the room.
MOUNT_TOLERANCE_M = 0.05
MAX_WALLS = 32
MAX_FURNITURE = 100
SENSOR_HEIGHT_RANGE_M = (0.0, 10.0)
SENSOR_TILT_RANGE_DEG = (-90.0, 90.0)
FURNITURE_SIZE_RANGE_M = (0.01, 20.0)
FURNITURE_RCS_RANGE_DBSM = (-60.0, 60.0)
#: A wall without ``reflection_db`` loses this much power at a bounce: the effective loss fitted
#: to the ghost fraction of a real walking recording through the out-of-box chain
#: (``radartune bench chain_calibration``; docs/decisions/rooms-02-fitted-wall-loss.md).
DEFAULT_REFLECTION_DB = -33.0
#: The scatterers a piece of furniture is made of: its top face's four corners and centre.
N_FURNITURE_SCATTERERS = 5


@dataclass(frozen=True, slots=True, kw_only=True)
class Wall:
    """A vertical reflecting plane over the segment ``from_m`` → ``to_m`` (x, y in m).

    ``reflection_db``: power kept at a bounce, dB, at most 0 (0: a perfect mirror; ``-inf``,
    ``null`` in JSON: an absorber, no image).
    """

    from_m: tuple[float, float]
    to_m: tuple[float, float]
    reflection_db: float = DEFAULT_REFLECTION_DB

    def __post_init__(self) -> None:
        for name in ("from_m", "to_m"):
            v = getattr(self, name)
            if len(v) != 2 or not all(_finite(c) for c in v):
                raise InputError(f"{name} must be [x_m, y_m] of finite numbers, got {v!r}")
        if self.length_m < MIN_WALL_LENGTH_M:
            raise InputError(
                f"from_m/to_m: a wall must be at least {MIN_WALL_LENGTH_M} m long, got "
                f"{self.length_m:.3g} m ({list(self.from_m)} -> {list(self.to_m)})"
            )
        r = self.reflection_db
        if isinstance(r, bool) or not isinstance(r, int | float) or math.isnan(r) or r > 0:
            raise InputError(
                f"reflection_db must be <= 0 dB (0: a perfect mirror), got reflection_db={r!r}"
            )

    @property
    def length_m(self) -> float:
        return math.hypot(self.to_m[0] - self.from_m[0], self.to_m[1] - self.from_m[1])

    @property
    def reflection(self) -> float:
        """Linear power factor of a bounce, ``10^(reflection_db / 10)`` (0 for -inf)."""
        return 10.0 ** (self.reflection_db / 10.0)

    def to_dict(self) -> dict:
        return {
            "from_m": list(self.from_m),
            "to_m": list(self.to_m),
            "reflection_db": None if self.reflection_db == -math.inf else self.reflection_db,
        }


@dataclass(frozen=True, slots=True, kw_only=True)
class Furniture:
    """A box on the floor centred at (``x_m``, ``y_m``): an extended static reflector.

    Its RCS ``rcs_dbsm`` is split evenly over :data:`N_FURNITURE_SCATTERERS` point scatterers
    (the top face's corners and centre at ``height_m``).
    """

    x_m: float
    y_m: float
    width_m: float = 0.8
    depth_m: float = 0.6
    height_m: float = 0.75
    rcs_dbsm: float = 5.0

    def __post_init__(self) -> None:
        for name in ("x_m", "y_m"):
            if not _finite(getattr(self, name)):
                raise InputError(f"{name} must be a finite number, got {getattr(self, name)!r}")
        for name in ("width_m", "depth_m", "height_m"):
            _check_range(getattr(self, name), name, FURNITURE_SIZE_RANGE_M)
        _check_range(self.rcs_dbsm, "rcs_dbsm", FURNITURE_RCS_RANGE_DBSM)

    def scatterer_positions_m(self) -> np.ndarray:
        """``(5, 3)`` room coordinates: the top face's four corners, then its centre."""
        hx, hy = self.width_m / 2, self.depth_m / 2
        dx = np.array([-hx, hx, hx, -hx, 0.0])
        dy = np.array([-hy, -hy, hy, hy, 0.0])
        return np.column_stack((self.x_m + dx, self.y_m + dy, np.full(5, self.height_m)))

    def to_dict(self) -> dict:
        return {k: getattr(self, k) for k in FURNITURE_KEYS}


@dataclass(frozen=True, slots=True, kw_only=True)
class SensorPose:
    """Mounting height above the floor (m) and downward tilt of the boresight (degrees)."""

    height_m: float = 0.0
    tilt_deg: float = 0.0

    def __post_init__(self) -> None:
        _check_range(self.height_m, "height_m", SENSOR_HEIGHT_RANGE_M)
        _check_range(self.tilt_deg, "tilt_deg", SENSOR_TILT_RANGE_DEG)

    @property
    def position_m(self) -> np.ndarray:
        """``(3,)`` the radar in room coordinates."""
        return np.array([0.0, 0.0, self.height_m])

    def rotation(self) -> np.ndarray:
        """``(3, 3)`` room → sensor axes: ``d_sensor = M d_room``.

        A rotation about x by the tilt ``t``: ``y' = y cos t - z sin t``,
        ``z' = y sin t + z cos t``, so the room direction ``(0, cos t, -sin t)`` (down by
        ``t``) becomes the boresight ``(0, 1, 0)``.
        """
        t = math.radians(self.tilt_deg)
        c, s = math.cos(t), math.sin(t)
        return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])

    def to_sensor(
        self, position_m: np.ndarray, velocity_mps: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Room positions ``(N, 3)`` and velocities ``(N, 3)`` in sensor coordinates."""
        m = self.rotation()
        return (np.asarray(position_m) - self.position_m) @ m.T, np.asarray(velocity_mps) @ m.T

    def to_room(self, xyz_m: np.ndarray) -> np.ndarray:
        """Sensor-coordinate points ``(N, 3)`` in room coordinates (the inverse of
        :meth:`to_sensor` for positions)."""
        return np.asarray(xyz_m) @ self.rotation() + self.position_m

    def to_dict(self) -> dict:
        return {"height_m": self.height_m, "tilt_deg": self.tilt_deg}


@dataclass(frozen=True, slots=True, kw_only=True)
class Room:
    """Walls, furniture and the sensor pose of a scene (any may be empty)."""

    walls: tuple[Wall, ...] = ()
    furniture: tuple[Furniture, ...] = ()
    sensor: SensorPose = field(default_factory=SensorPose)

    def __post_init__(self) -> None:
        if len(self.walls) > MAX_WALLS:
            raise InputError(f"walls lists {len(self.walls)}, more than the limit {MAX_WALLS}")
        if len(self.furniture) > MAX_FURNITURE:
            raise InputError(
                f"furniture lists {len(self.furniture)}, more than the limit {MAX_FURNITURE}"
            )
        if self.walls and not _radar_inside(self.walls):
            raise InputError(
                "sensor: the radar at (0, 0) lies outside the room its walls enclose "
                f"(within {MOUNT_TOLERANCE_M} m of a wall counts as mounted on it)"
            )

    @property
    def has_multipath(self) -> bool:
        """True when some wall reflects (a finite ``reflection_db``)."""
        return any(w.reflection > 0 for w in self.walls)

    def wall_segments(self) -> tuple[tuple[float, float, float, float], ...]:
        """The reflecting walls (absorbers left out) as x–y segments ``(x0, y0, x1, y1)``, m."""
        return tuple(
            (float(w.from_m[0]), float(w.from_m[1]), float(w.to_m[0]), float(w.to_m[1]))
            for w in self.walls
            if w.reflection > 0
        )

    def furniture_scatterers(self) -> tuple[np.ndarray, np.ndarray]:
        """Room positions ``(5 K, 3)`` and RCS ``(5 K,)`` dBsm of the furniture's scatterers
        (each piece's RCS split evenly: ``sigma_k = sigma / 5``)."""
        if not self.furniture:
            return np.zeros((0, 3)), np.zeros(0)
        pos = np.concatenate([f.scatterer_positions_m() for f in self.furniture])
        share = 10 * math.log10(N_FURNITURE_SCATTERERS)
        rcs = np.repeat([f.rcs_dbsm - share for f in self.furniture], N_FURNITURE_SCATTERERS)
        return pos, rcs

    def to_dict(self) -> dict:
        d: dict[str, Any] = {}
        if self.walls:
            d["walls"] = [w.to_dict() for w in self.walls]
        if self.furniture:
            d["furniture"] = [f.to_dict() for f in self.furniture]
        d["sensor"] = self.sensor.to_dict()
        return d

    @classmethod
    def from_json(cls, path: str | os.PathLike) -> Room:
        """A room file: a JSON object with some of ``walls``, ``furniture``, ``sensor``."""
        path = Path(path)
        data = read_json(path, what="room file")
        try:
            if not isinstance(data, dict):
                raise InputError(f"room must be a JSON object, got {type(data).__name__}")
            unknown = sorted(set(data) - set(ROOM_KEYS))
            if unknown:
                raise InputError(f"room: unknown key(s) {unknown}; expected some of {ROOM_KEYS}")
            return parse_room(data)
        except InputError as exc:
            raise InputError(exc.message, str(path)) from None


def parse_room(data: dict) -> Room:
    """The room in a scene's (or a room file's) ``walls``/``furniture``/``sensor`` keys; errors
    name the field (``walls[2].reflection_db``)."""
    walls = []
    for i, w in enumerate(_list(data.get("walls", []), "walls")):
        where = f"walls[{i}]"
        w = _object(w, WALL_KEYS, where)
        for k in ("from_m", "to_m"):
            if k not in w:
                raise InputError(f"{where}: missing key {k!r}")
            if not (isinstance(w[k], list) and len(w[k]) == 2):
                raise InputError(f"{where}.{k} must be a list [x_m, y_m], got {w[k]!r}")
        walls.append(
            _build(
                Wall,
                where,
                from_m=tuple(w["from_m"]),
                to_m=tuple(w["to_m"]),
                # JSON has no -inf: null is an absorber
                reflection_db=-math.inf
                if "reflection_db" in w and w["reflection_db"] is None
                else w.get("reflection_db", DEFAULT_REFLECTION_DB),
            )
        )
    furniture = []
    for i, f in enumerate(_list(data.get("furniture", []), "furniture")):
        where = f"furniture[{i}]"
        f = _object(f, FURNITURE_KEYS, where)
        for k in ("x_m", "y_m"):
            if k not in f:
                raise InputError(f"{where}: missing key {k!r}")
        furniture.append(_build(Furniture, where, **f))
    sensor = SensorPose()
    if "sensor" in data:
        sensor = _build(SensorPose, "sensor", **_object(data["sensor"], SENSOR_KEYS, "sensor"))
    return Room(walls=tuple(walls), furniture=tuple(furniture), sensor=sensor)


# ---- helpers ------------------------------------------------------------------------------------


def _finite(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


def _check_range(v: Any, name: str, bounds: tuple[float, float]) -> None:
    if not _finite(v) or not bounds[0] <= v <= bounds[1]:
        raise InputError(f"{name} must be a number in [{bounds[0]}, {bounds[1]}], got {v!r}")


def _list(v: Any, where: str) -> list:
    if not isinstance(v, list):
        raise InputError(f"{where} must be a list, got {type(v).__name__}")
    return v


def _object(v: Any, keys: tuple[str, ...], where: str) -> dict:
    if not isinstance(v, dict):
        raise InputError(f"{where} must be a JSON object, got {type(v).__name__}")
    unknown = sorted(set(v) - set(keys))
    if unknown:
        raise InputError(f"{where}: unknown key(s) {unknown}; expected some of {list(keys)}")
    return v


def _build(cls: Any, where: str, **kw: Any) -> Any:
    """``cls(**kw)`` with its error prefixed by ``where`` (``walls[1].reflection_db ...``)."""
    try:
        return cls(**kw)
    except InputError as exc:
        raise InputError(f"{where}.{exc.message}") from None
    except TypeError as exc:  # a non-sequence coordinate
        raise InputError(f"{where}: {exc}") from None


def _radar_inside(walls: tuple[Wall, ...]) -> bool:
    """Whether the radar at the origin is inside the room (or mounted on a wall).

    On (within :data:`MOUNT_TOLERANCE_M` of) a wall: inside. Walls that close into a loop
    (every endpoint shared by two walls): the even-odd rule. Open walls (a corridor, a lone
    wall) enclose nothing: inside.
    """
    a = np.array([w.from_m for w in walls], dtype=np.float64)
    b = np.array([w.to_m for w in walls], dtype=np.float64)
    ab = b - a
    t = np.clip(-(a * ab).sum(axis=1) / (ab * ab).sum(axis=1), 0.0, 1.0)
    if np.min(np.hypot(*(a + t[:, None] * ab).T)) <= MOUNT_TOLERANCE_M:
        return True
    return bool(inside_walls(walls, np.zeros((1, 2)))[0])


def inside_walls(walls: tuple[Wall, ...], xy_m: np.ndarray) -> np.ndarray:
    """``(N,)`` whether each point ``xy_m`` ``(N, 2)`` is inside the room the walls enclose.

    Walls that close into a loop (every endpoint shared by two walls): the even-odd rule (a ray
    along +x crosses the walls an odd number of times). Open walls enclose nothing: all True.
    """
    xy = np.asarray(xy_m, dtype=np.float64).reshape(-1, 2)
    if not walls:
        return np.ones(len(xy), dtype=bool)
    a = np.array([w.from_m for w in walls], dtype=np.float64)
    b = np.array([w.to_m for w in walls], dtype=np.float64)
    _, counts = np.unique(np.round(np.concatenate((a, b)), 6), axis=0, return_counts=True)
    if not np.all(counts == 2):
        return np.ones(len(xy), dtype=bool)
    ay, by = a[None, :, 1], b[None, :, 1]
    py = xy[:, 1:2]
    crosses = (ay > py) != (by > py)
    with np.errstate(divide="ignore", invalid="ignore"):
        x = a[None, :, 0] + (py - ay) * (b[None, :, 0] - a[None, :, 0]) / (by - ay)
    return np.sum(crosses & (x > xy[:, 0:1]), axis=1) % 2 == 1

"""Zones of a room (the room tracker, SPEC §7): the boundary box, static boxes, presence boxes.

As TI's 3-D people-counting firmware has them (TI reference design TIDUE71D, the tracker's
configuration parameters; ``.cfg`` lines ``boundaryBox``, ``staticBoundaryBox``,
``presenceBoundaryBox``, each ``xmin xmax ymin ymax zmin zmax`` in m in the sensor's frame):

- **boundary box**: points outside it are not used (neither update nor start a track);
- **static boxes**: where a track may live on zero-Doppler points alone (a person who stopped or
  sits); outside them a track that only static points support is let go. None given: the
  boundary box;
- **presence boxes**: where a moving point means "someone is there" (occupancy, reported per
  frame by :func:`presence`).

A box is ``(xmin, xmax, ymin, ymax, zmin, zmax)``; every limit may be infinite. No boundary box
given: everything is inside. The functions marked jitable run as plain Python and inside the
compiled room kernel (numba ``register_jitable``).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, replace

import numpy as np
from numba.extending import register_jitable

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)
from core.errors import InputError
from core.files import read_text
from core.walls import wall_lines

__all__ = [
    "Box",
    "Zones",
    "in_box",
    "in_any_box",
    "zones_from_cfg",
    "presence",
    "with_scene_walls",
]

Box = tuple[float, float, float, float, float, float]
#: Everything: no limit on x, y, z.
_ALL: Box = (-math.inf, math.inf, -math.inf, math.inf, -math.inf, math.inf)
_CFG_LINES = {
    "boundaryBox": "boundary",
    "staticBoundaryBox": "static",
    "presenceBoundaryBox": "presence",
}


def _check_box(box: object, name: str) -> Box:
    try:
        b = tuple(float(v) for v in box)  # type: ignore[attr-defined]
    except (TypeError, ValueError):
        raise InputError(f"{name} must be 6 numbers xmin xmax ymin ymax zmin zmax") from None
    if len(b) != 6 or any(math.isnan(v) for v in b):
        raise InputError(f"{name} must be 6 numbers xmin xmax ymin ymax zmin zmax, got {box!r}")
    for i, axis in enumerate("xyz"):
        if not b[2 * i] < b[2 * i + 1]:
            raise InputError(
                f"{name}: {axis}min must be < {axis}max, got {b[2 * i]} and {b[2 * i + 1]}"
            )
    return b


@dataclass(frozen=True, slots=True, kw_only=True)
class Zones:
    """The zones of a room, in m in the sensor's frame (x right, y boresight, z up).

    Attributes
    ----------
    boundary
        The boundary box (points outside are not used); ``None``: no limit.
    static
        Static boxes (a track may live on zero-Doppler points inside one); empty: the boundary.
    presence
        Presence boxes (:func:`presence`).
    walls
        The room's reflecting walls, when known (``--room``), as x–y segments
        ``(x0, y0, x1, y1)`` in m, the radar at the origin (as :mod:`core.scene.room` has them):
        tentative tracks at their predicted ghost positions are ghost candidates
        (:mod:`core.tracking.ghosts`).
    sensor_height_m
        The radar's height in the frame of the points' z (m): 0 when z is measured from the
        sensor (a recording), the sensor's mounting height when z is the height above the floor
        (a data set simulated in a room); the predicted ghosts use z − this.
    """

    boundary: Box | None = None
    static: tuple[Box, ...] = ()
    presence: tuple[Box, ...] = ()
    walls: tuple[tuple[float, float, float, float], ...] = ()
    sensor_height_m: float = 0.0

    def __post_init__(self) -> None:
        if self.boundary is not None:
            object.__setattr__(self, "boundary", _check_box(self.boundary, "boundary"))
        for name in ("static", "presence"):
            boxes = tuple(_check_box(b, f"{name}[{i}]") for i, b in enumerate(getattr(self, name)))
            object.__setattr__(self, name, boxes)
        walls = []
        for i, w in enumerate(self.walls):
            try:
                seg = tuple(float(v) for v in w)
            except (TypeError, ValueError):
                seg = ()
            if len(seg) != 4 or not all(math.isfinite(v) for v in seg):
                raise InputError(f"walls[{i}] must be 4 finite numbers (x0, y0, x1, y1), got {w!r}")
            if math.hypot(seg[2] - seg[0], seg[3] - seg[1]) <= 0.0:
                raise InputError(f"walls[{i}] has zero length: {list(seg)}")
            walls.append(seg)
        object.__setattr__(self, "walls", tuple(walls))
        h = self.sensor_height_m
        if isinstance(h, bool) or not isinstance(h, int | float) or not math.isfinite(h):
            raise InputError(f"sensor_height_m must be a finite number (m), got {h!r}")

    def boundary_array(self) -> np.ndarray:
        """(6,) float64 boundary box, infinite limits when none."""
        return np.array(self.boundary if self.boundary is not None else _ALL, dtype=np.float64)

    def static_array(self) -> np.ndarray:
        """(k, 6) float64 static boxes; the boundary box when none is given (k ≥ 1)."""
        boxes = self.static or (self.boundary if self.boundary is not None else _ALL,)
        return np.array(boxes, dtype=np.float64).reshape(-1, 6)

    def wall_array(self) -> np.ndarray:
        """(W, 7) float64 lines of the walls (:func:`core.walls.wall_lines`)."""
        return wall_lines(np.array(self.walls, dtype=np.float64).reshape(-1, 4))

    def to_dict(self) -> dict:
        d = {
            "boundary": list(self.boundary) if self.boundary is not None else None,
            "static": [list(b) for b in self.static],
            "presence": [list(b) for b in self.presence],
        }
        if self.walls:
            d["walls"] = [list(w) for w in self.walls]
        if self.sensor_height_m:
            d["sensor_height_m"] = self.sensor_height_m
        return d


def with_scene_walls(
    zones: Zones | None,
    walls: tuple[tuple[float, float, float, float], ...],
    sensor_height_m: float = 0.0,
) -> Zones | None:
    """``zones`` with the walls of the data set's scene (:func:`core.walls.scene_walls`) when
    it gives none itself: a data set simulated in a room carries its room, so the room mode
    predicts its ghosts without ``--room``; walls given (``--room``) win; ``zones`` unchanged
    without walls."""
    if zones is not None and zones.walls:
        return zones
    if not walls:
        return zones
    kw = {"walls": walls, "sensor_height_m": sensor_height_m}
    return Zones(**kw) if zones is None else replace(zones, **kw)


@register_jitable
def in_box(x: float, y: float, z: float, box: np.ndarray) -> bool:
    """True when (x, y, z) lies in the closed box (6,) ``xmin xmax ymin ymax zmin zmax``."""
    return box[0] <= x <= box[1] and box[2] <= y <= box[3] and box[4] <= z <= box[5]


@register_jitable
def in_any_box(x: float, y: float, z: float, boxes: np.ndarray) -> bool:
    """True when (x, y, z) lies in one of the boxes (k, 6)."""
    for i in range(boxes.shape[0]):
        if in_box(x, y, z, boxes[i]):
            return True
    return False


def presence(
    x: np.ndarray, y: np.ndarray, z: np.ndarray, vr: np.ndarray, zones: Zones, v_static: float
) -> bool:
    """Someone is present: a moving point (|vr| > v_static) in a presence box (or, with none
    given, in the boundary box). Arrays (m,) of one frame, m and m/s."""
    boxes = (
        np.array(zones.presence, dtype=np.float64).reshape(-1, 6)
        if zones.presence
        else zones.boundary_array()[None, :]
    )
    for j in range(len(x)):
        if abs(vr[j]) > v_static and in_any_box(x[j], y[j], z[j], boxes):
            return True
    return False


def zones_from_cfg(path: str | os.PathLike) -> Zones:
    """The zones of a TI ``.cfg`` (its ``boundaryBox``, ``staticBoundaryBox`` and
    ``presenceBoundaryBox`` lines; every other line is left to the radar and tracker readers).

    A bad line gives :class:`InputError` naming the file and line.
    """
    from core.formats.ti_cfg import parse_ti_cfg

    source = str(path)
    found: dict[str, list[Box]] = {"boundary": [], "static": [], "presence": []}
    for cmd in parse_ti_cfg(read_text(path, what="TI .cfg"), source):
        key = _CFG_LINES.get(cmd.name)
        if key is None:
            continue
        where = f"{source}:{cmd.line}"
        if len(cmd.args) != 6:
            raise InputError(
                f"{cmd.name} needs 6 fields xmin xmax ymin ymax zmin zmax, got {len(cmd.args)}",
                where,
            )
        try:
            values = [float(a) for a in cmd.args]
        except ValueError:
            raise InputError(f"{cmd.name}: fields must be numbers, got {cmd.args}", where) from None
        try:
            found[key].append(_check_box(values, cmd.name))
        except InputError as exc:
            raise InputError(exc.message, where) from None
    if len(found["boundary"]) > 1:
        raise InputError("boundaryBox given more than once", source)
    return Zones(
        boundary=found["boundary"][0] if found["boundary"] else None,
        static=tuple(found["static"]),
        presence=tuple(found["presence"]),
    )

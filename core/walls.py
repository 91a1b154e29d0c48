"""Where a wall makes the radar see a point a second time: the first-order ghost geometry.

The one statement of it both the room tracker (predicted ghosts, :mod:`core.tracking.ghosts`)
and the rooms of the scenes may use: walls are vertical planes given by their x–y segments, the
radar at the origin of the x–y plane (as in :mod:`core.scene.room`). The image method's
derivation is in :mod:`core.simulation.multipath`; docs/tracker.md "Predicted ghosts".
"""

from __future__ import annotations

import math

import numpy as np
from numba.extending import register_jitable

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)
from core.errors import InputError

__all__ = [
    "WALL_LINE_COLUMNS",
    "GHOSTS_PER_WALL",
    "wall_lines",
    "ghost_points_xy",
    "scene_walls",
    "scene_sensor_height",
]

#: Columns of :func:`wall_lines`: a point on the wall, its unit normal, unit direction, length.
WALL_LINE_COLUMNS = ("ax", "ay", "nx", "ny", "ex", "ey", "length")
#: Predicted ghost points per wall (:func:`ghost_points_xy`).
GHOSTS_PER_WALL = 3


def scene_walls(scene: dict | list) -> tuple[tuple[float, float, float, float], ...]:
    """The reflecting walls a data set's stored scene JSON carries (``Dataset.scene()``: one
    scene or a list of them, as :class:`core.scene.room.Room` writes them), as x–y segments
    ``(x0, y0, x1, y1)``, absorbers (``reflection_db`` null) left out, as
    :meth:`core.scene.room.Room.wall_segments` gives them. ``()`` when the scene has no walls
    (a recording, the open field) or its scenes stand in different rooms (then only a room file
    given to the tracker gives the walls). A damaged wall: :class:`InputError` naming it."""
    scenes = scene if isinstance(scene, list) else [scene]
    found = set()
    for k, s in enumerate(scenes):
        walls = s.get("walls", []) if isinstance(s, dict) else []
        segments = []
        for i, w in enumerate(walls if isinstance(walls, list) else [walls]):
            try:
                if w.get("reflection_db", 0.0) is None:
                    continue
                seg = tuple(float(v) for v in (*w["from_m"], *w["to_m"]))
            except (AttributeError, KeyError, TypeError, ValueError):
                seg = ()
            if len(seg) != 4 or not all(math.isfinite(v) for v in seg):
                raise InputError(
                    f"data set scene {k}: walls[{i}] must have from_m and to_m [x_m, y_m], "
                    f"got {w!r}"
                )
            segments.append(seg)
        found.add(tuple(segments))
    return found.pop() if len(found) == 1 else ()


def scene_sensor_height(scene: dict | list) -> float:
    """The sensor's mounting height (m) in a data set's stored scene JSON (``sensor.height_m``
    of its room); 0 without one or when its scenes disagree."""
    scenes = scene if isinstance(scene, list) else [scene]
    found = set()
    for s in scenes:
        sensor = s.get("sensor", {}) if isinstance(s, dict) else {}
        h = sensor.get("height_m", 0.0) if isinstance(sensor, dict) else 0.0
        found.add(float(h) if isinstance(h, int | float) and math.isfinite(h) else 0.0)
    return found.pop() if len(found) == 1 else 0.0


def wall_lines(segments: np.ndarray) -> np.ndarray:
    """``(W, 7)`` float64 :data:`WALL_LINE_COLUMNS` of wall segments ``(W, 4)``
    ``(x0, y0, x1, y1)`` in m (each at least a few mm long; :class:`core.scene.room.Wall`
    checks it); ``(0, 7)`` without walls."""
    s = np.asarray(segments, dtype=np.float64).reshape(-1, 4)
    d = s[:, 2:4] - s[:, 0:2]
    length = np.hypot(d[:, 0], d[:, 1])
    e = d / length[:, None] if len(s) else d
    return np.column_stack((s[:, 0], s[:, 1], -e[:, 1], e[:, 0], e[:, 0], e[:, 1], length))


@register_jitable
def ghost_points_xy(x: float, y: float, lines: np.ndarray, out: np.ndarray) -> int:
    """:func:`ghost_points` of a point at the radar's height (h = 0)."""
    return ghost_points(x, y, 0.0, lines, out)


@register_jitable
def ghost_points(x: float, y: float, h: float, lines: np.ndarray, out: np.ndarray) -> int:
    """Where the radar at the origin sees the first-order wall ghosts of a point S.

    The tracker's position ``(x, y)`` is a range and a bearing: ``r = |(x, y)|`` is the slant
    range from the radar to S, and S lies ``h`` (m) above (below: h < 0) the radar, as the
    points' z gives it in the sensor's frame. S's ground position is then
    ``S_g = (ρ / r) (x, y)`` with ``ρ = √(r² − h²)`` (h = 0: S_g = (x, y)). With
    ``S'_g = S_g − 2 ((S_g − a)·n) n`` its image in wall (a, n) (walls are vertical, so the image
    keeps the height) and ``r' = √(|S'_g|² + h²)`` the image's slant range, the bounce paths are:

    - radar → wall → S → radar and its reverse: length ``L = r + r'``; the radar sees a point
      at range ``L / 2`` in the bearing of the last leg, so two points: ``(L / 2) S_g / |S_g|``
      (back from S) and ``(L / 2) S'_g / |S'_g|`` (back by the wall);
    - radar → wall → S → wall → radar: length ``2 r'``, seen at range ``r'`` in the bearing of
      S'_g (h = 0: S' itself).

    A wall contributes only where its bounce is specular (the radar and S strictly on the same
    side of its line, the reflection point's ground position ``t S'_g``,
    ``t = d_R / (d_R + d_S)`` with ``d`` the horizontal distances to the line, inside the
    segment). Writes the points, as the tracker's ``(x, y)`` (range times the bearing's unit
    vector), into ``out`` ``(≥ 3 W, 2)`` three per wall in wall order (back from S, back by the
    wall, double bounce); returns how many it wrote.
    """
    n_out = 0
    r = math.sqrt(x * x + y * y)
    if r == 0.0:
        return 0
    gx, gy = x, y
    if h != 0.0:
        rho = math.sqrt(max(r * r - h * h, 1e-12 * r * r))
        gx, gy = x * rho / r, y * rho / r
    for w in range(lines.shape[0]):
        ax, ay, nx, ny = lines[w, 0], lines[w, 1], lines[w, 2], lines[w, 3]
        d_r = -ax * nx - ay * ny  # the radar's signed distance to the wall's line
        d_s = (gx - ax) * nx + (gy - ay) * ny
        if d_r * d_s <= 0.0:
            continue
        ix, iy = gx - 2.0 * d_s * nx, gy - 2.0 * d_s * ny
        t = d_r / (d_r + d_s)
        u = (t * ix - ax) * lines[w, 4] + (t * iy - ay) * lines[w, 5]
        if u < 0.0 or u > lines[w, 6]:
            continue
        ri = math.sqrt(ix * ix + iy * iy)
        if h == 0.0:
            half = 0.5 * (r + ri)
            out[n_out + 2, 0], out[n_out + 2, 1] = ix, iy
        else:
            rs = math.sqrt(ri * ri + h * h)  # the image's slant range
            half = 0.5 * (r + rs)
            out[n_out + 2, 0], out[n_out + 2, 1] = rs * ix / ri, rs * iy / ri
        out[n_out, 0], out[n_out, 1] = half * x / r, half * y / r
        out[n_out + 1, 0], out[n_out + 1, 1] = half * ix / ri, half * iy / ri
        n_out += GHOSTS_PER_WALL
    return n_out

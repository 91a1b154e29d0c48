"""The ghost rule (the room tracker, SPEC §7): tracks on wall multipath are not counted.

A wall behind or beside a person returns the person a second time along a longer path: a cluster
one to three metres further in range, at a nearby bearing, moving with the person, weaker
(SPEC §7, measured on the walking recordings in docs/tracker.md). Track b is a *ghost candidate*
of track a when

- a is confirmed and not itself a candidate of another track,
- b is further: ``r_b − r_a ≥ Δr_ghost``,
- at a nearby bearing: ``|az_b − az_a| ≤ Δaz_ghost`` (wrapped),
- moving with a: ``|vr_b − vr_a| ≤ Δv_ghost`` (radial velocities of the states),
- weaker: its strength (the smoothed SNR sum of its points) is below a's.

Tracks are visited in range order (nearest first), so a person in front is decided before what
lies behind it. A candidate is neither confirmed nor counted while it is one (its existence runs
on; it may be confirmed later if the rule no longer holds). Runs as plain Python and inside the
compiled room kernel (``register_jitable``).

Where the room's walls are known (:attr:`core.tracking.zones.Zones.walls`), the walls predict
where each confirmed track's first-order ghosts appear (:func:`core.walls.ghost_points`:
three points per wall whose bounce is specular, from the track's range, bearing and height). A
track that is not confirmed (a newborn or a tentative one) within ``r_ghost`` of such a point
of a confirmed track that is no candidate itself is a ghost candidate too
(:func:`wall_ghost_candidates`). Without walls nothing changes.
"""

from __future__ import annotations

import math

import numpy as np
from numba.extending import register_jitable

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)
from core.tracking import ekf
from core.walls import ghost_points

__all__ = ["ghost_candidates", "wall_ghost_candidates"]


@register_jitable
def ghost_candidates(
    X: np.ndarray,
    confirmed: np.ndarray,
    strength: np.ndarray,
    nt: int,
    gap: float,
    bearing: float,
    velocity: float,
    ghost: np.ndarray,
    zm: np.ndarray,
    order: np.ndarray,
) -> None:
    """Flag the ghost candidates among the first ``nt`` tracks.

    Parameters
    ----------
    X
        (cap, d) states; confirmed (cap,) bool; strength (cap,) smoothed SNR sums (dB).
    nt
        Live tracks (slots 0 … nt − 1).
    gap, bearing, velocity
        Δr_ghost (m), Δaz_ghost (rad), Δv_ghost (m/s).
    ghost
        (cap,) bool output.
    zm, order
        Scratch: (cap, 3) float and (cap,) int64.
    """
    # zm: [r, az, vr] of each state; order: nearest first, ties in slot order (stable)
    for k in range(nt):
        x, y, r = ekf.safe_position(X[k, 0], X[k, 1])
        zm[k, 0], zm[k, 1], zm[k, 2] = r, math.atan2(x, y), (x * X[k, 2] + y * X[k, 3]) / r
        ghost[k] = False
        i = k
        while i > 0 and zm[order[i - 1], 0] > r:
            order[i] = order[i - 1]
            i -= 1
        order[i] = k
    for ib in range(nt):
        b = order[ib]
        for ia in range(ib):
            a = order[ia]
            if not confirmed[a] or ghost[a]:
                continue
            if zm[b, 0] - zm[a, 0] < gap:
                continue
            dz = ((zm[b, 1] - zm[a, 1] + math.pi) % (2.0 * math.pi)) - math.pi
            if abs(dz) > bearing or abs(zm[b, 2] - zm[a, 2]) > velocity:
                continue
            if strength[b] < strength[a]:
                ghost[b] = True
                break


@register_jitable
def wall_ghost_candidates(
    X: np.ndarray,
    confirmed: np.ndarray,
    height: np.ndarray,
    sensor_height: float,
    ghost: np.ndarray,
    nt: int,
    walls: np.ndarray,
    radius: float,
    pts: np.ndarray,
) -> None:
    """Flag the tracks that are not confirmed and lie within ``radius`` (m) of a predicted wall
    ghost of a confirmed track that is no ghost candidate (among the first ``nt``); ``height``
    (m): each track's z (the mean z of its latest group), ``sensor_height`` the radar's z in
    the same frame (:attr:`core.tracking.zones.Zones.sensor_height_m`).

    ``walls`` (W, 7) :func:`core.walls.wall_lines`; ``pts`` scratch (≥ 3 W, 2). Without
    walls (W = 0) nothing is touched.
    """
    if walls.shape[0] == 0:
        return
    r2 = radius * radius
    for a in range(nt):
        if not confirmed[a] or ghost[a]:
            continue
        n = ghost_points(X[a, 0], X[a, 1], height[a] - sensor_height, walls, pts)
        for b in range(nt):
            if confirmed[b] or ghost[b]:
                continue
            for i in range(n):
                dx, dy = X[b, 0] - pts[i, 0], X[b, 1] - pts[i, 1]
                if dx * dx + dy * dy <= r2:
                    ghost[b] = True
                    break

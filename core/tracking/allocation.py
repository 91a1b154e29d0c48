"""Group allocation (the room tracker, SPEC §7): new tracks start from groups of points.

A person gives many points a frame; a wall ghost or a static return gives a few, weaker ones. A
new track starts only from a *group* of points that no track explained, moving ones only
(|vr| > v_static: zero-Doppler points never start a track), following the allocation of TI's
gtrack (TI reference design TIDUE71D, the tracker's allocation parameters: a points threshold, an
SNR threshold, a maximum distance and a maximum velocity difference within a group):

1. the candidate points, strongest first (SNR descending, ties by index), each in turn a seed;
2. a seed gathers every later candidate not yet taken whose radial velocity is within
   ``v_alloc`` of the group's running mean and whose x–y position is within ``d_alloc`` of the
   group's running centroid (one pass: the running means move as points join);
3. the group is kept when it has at least ``n_alloc`` points and its SNR sum
   Σ max(SNRᵢ, 0) (dB, as TI's allocation sums the points' SNR) is at least ``SNR_alloc``; its
   points are then taken. A group that fails releases its points (they may join a later seed).

Why this seeded grouping rather than a density clustering (DBSCAN): docs/decisions/
tracker-08-room-mode.md.
"""

from __future__ import annotations

import numpy as np
from numba.extending import register_jitable

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)
from core.tracking.groups import COL_SNR, COL_VR, COL_X, COL_Y

__all__ = ["allocate"]


@register_jitable
def allocate(
    pts: np.ndarray,
    free: np.ndarray,
    n_alloc: float,
    snr_alloc: float,
    d_alloc: float,
    v_alloc: float,
    labels: np.ndarray,
    order: np.ndarray,
    member: np.ndarray,
) -> int:
    """Groups of free points that may start tracks.

    Parameters
    ----------
    pts
        (m, 7) points of a frame (:data:`core.tracking.groups.COLUMNS`).
    free
        (m,) bool: the candidates (used, moving, explained by no track).
    n_alloc, snr_alloc, d_alloc, v_alloc
        Minimum points, minimum SNR sum (dB), group radius (m), velocity spread (m/s).
    labels
        (m,) int64 output: the group of each point, −1 for none.
    order, member
        Scratch, (m,) int64 each.

    Returns
    -------
    int
        The number of groups (labels 0 … n − 1, in order of their seeds).
    """
    m = pts.shape[0]
    n_cand = 0
    for j in range(m):
        labels[j] = -1
        if free[j]:
            n_cand += 1
    if n_cand == 0:
        return 0
    # the candidates strongest first, ties in index order (a stable insertion sort: the
    # order a stable argsort of −SNR gives, without its temporaries; frames hold few candidates)
    n_sorted = 0
    for j in range(m):
        if not free[j]:
            continue
        key = pts[j, COL_SNR]
        i = n_sorted
        while i > 0 and pts[order[i - 1], COL_SNR] < key:
            order[i] = order[i - 1]
            i -= 1
        order[i] = j
        n_sorted += 1
    # a point is taken when it has a label (only kept groups label their points)
    n_groups = 0
    for a in range(n_cand):
        seed = order[a]
        if labels[seed] >= 0:
            continue
        n = 1
        member[0] = seed
        cx, cy, cv = pts[seed, COL_X], pts[seed, COL_Y], pts[seed, COL_VR]
        snr = max(pts[seed, COL_SNR], 0.0)
        for b in range(a + 1, n_cand):
            j = order[b]
            if labels[j] >= 0:
                continue
            if abs(pts[j, COL_VR] - cv) > v_alloc:
                continue
            dx, dy = pts[j, COL_X] - cx, pts[j, COL_Y] - cy
            if dx * dx + dy * dy > d_alloc * d_alloc:
                continue
            member[n] = j
            n += 1
            # running means: c ← c + (p − c)/n
            cx += (pts[j, COL_X] - cx) / n
            cy += (pts[j, COL_Y] - cy) / n
            cv += (pts[j, COL_VR] - cv) / n
            snr += max(pts[j, COL_SNR], 0.0)
        if n >= n_alloc and snr >= snr_alloc:
            for i in range(n):
                labels[member[i]] = n_groups
            n_groups += 1
    return n_groups

"""The ``measurement`` level's model of a many-scatterer person: scatterers merged per cell.

The measurement level turns every reflector into at most one detection. A body of many
scatterers (``blob``, ``walking``) puts several of them into one resolution cell of the chain,
where the exact chain sees one peak and makes one point; handing them to the measurement kernel
one by one gives too many points (measured: 4.5-5 points a frame for the 5-scatterer body where
the exact chain makes 2.2-2.8, ``radartune bench clouds``).

Model: per frame and person, the scatterers whose range, radial velocity and ``sin(azimuth)``
fall into the same cell of a grid ``k_r`` range bins by ``k_d`` Doppler bins by ``k_u`` azimuth
beam widths become one reflector: its power is the sum of theirs (the expected power of a sum
with random phases), its position and velocity their power-weighted means. The cell sizes
(:data:`MERGE_CELLS`) are fitted so that the measurement level's points per person and frame
match the exact level's per range band (``docs/person-models.md``). Persons of one scatterer and
clutter are never touched, so point-person results are the same bit for bit.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from core.config import RadarConfig

#: Merge cell size in (range bins, Doppler bins, azimuth beam widths 2/M), fitted against the
#: exact level (docs/person-models.md).
MERGE_CELLS = (3.0, 2.0, 1.0)


class MergedReflectors(NamedTuple):
    """Reflectors of several frames after merging: ``start`` (F+1,) frame offsets, ``position_m``
    and ``velocity_mps`` (N, 3), ``rcs_dbsm`` and ``source`` (N,)."""

    start: np.ndarray
    position_m: np.ndarray
    velocity_mps: np.ndarray
    rcs_dbsm: np.ndarray
    source: np.ndarray


def merge_person_cells(
    radar: RadarConfig,
    start: np.ndarray,
    position_m: np.ndarray,
    velocity_mps: np.ndarray,
    rcs_dbsm: np.ndarray,
    source: np.ndarray,
    cells: tuple[float, float, float] = MERGE_CELLS,
) -> MergedReflectors:
    """Merge each person's scatterers that share a cell (see the module docstring).

    Parameters
    ----------
    radar
        Range and velocity resolution, number of azimuth elements.
    start
        (F+1,) int: frame ``f`` holds reflectors ``start[f]:start[f+1]``.
    position_m, velocity_mps, rcs_dbsm, source
        (N, 3), (N, 3), (N,), (N,): the reflectors; ``source >= 0`` is a person.
    cells
        ``(k_r, k_d, k_u)``: cell size in range bins, Doppler bins and azimuth beam widths.

    Returns
    -------
    MergedReflectors
        The input arrays themselves when nothing merges (bit for bit); otherwise new arrays,
        each frame's reflectors in the order of their first scatterer.
    """
    start = np.asarray(start, dtype=np.int64)
    n = len(rcs_dbsm)
    source = np.asarray(source)
    person = source >= 0
    same = MergedReflectors(start, position_m, velocity_mps, rcs_dbsm, source)
    if n == 0 or np.count_nonzero(person) < 2:
        return same
    frame = np.repeat(np.arange(len(start) - 1), np.diff(start))
    pos = np.asarray(position_m, dtype=np.float64)
    vel = np.asarray(velocity_mps, dtype=np.float64)
    rng = np.linalg.norm(pos, axis=1)
    # v_r = v · r̂,  u = sin(az) = x / r_horizontal
    vr = np.einsum("ij,ij->i", vel, pos) / rng
    u = pos[:, 0] / np.maximum(np.hypot(pos[:, 0], pos[:, 1]), 1e-12)
    k_r, k_d, k_u = cells
    beam = 2.0 / len(radar.azimuth_positions)  # Δu = 2 / M (element spacing λ/2)
    # coordinates in cell units: a stronger scatterer closer than one cell in all three absorbs
    coord = np.column_stack(
        (
            rng / (k_r * radar.range_resolution_m),
            vr / (k_d * radar.velocity_resolution_mps),
            u / (k_u * beam),
        )
    )
    power = 10 ** (np.asarray(rcs_dbsm, dtype=np.float64) / 10)
    owner = np.arange(n)
    key = frame.astype(np.int64) * (int(source.max()) + 2) + source
    idx = np.flatnonzero(person)
    idx = idx[np.lexsort((-power[idx], key[idx]))]  # by person-frame, strongest first
    bounds = np.flatnonzero(np.diff(key[idx])) + 1
    for grp in np.split(idx, bounds):
        if len(grp) < 2:
            continue
        kept: list[int] = []
        for i in grp:
            for k in kept:
                if np.all(np.abs(coord[i] - coord[k]) < 1.0):
                    owner[i] = k
                    break
            else:
                kept.append(int(i))
    first = np.flatnonzero(owner == np.arange(n))
    if len(first) == n:
        return same
    group = np.searchsorted(first, owner)
    g = group
    m = len(first)
    # P = Σ_i 10^(σ_i / 10): random phases add in power on average
    total = np.bincount(g, weights=power, minlength=m)
    w = power / total[g]
    new_pos = np.stack([np.bincount(g, weights=w * pos[:, k], minlength=m) for k in range(3)], 1)
    new_vel = np.stack([np.bincount(g, weights=w * vel[:, k], minlength=m) for k in range(3)], 1)
    first_sorted = first
    # a reflector alone in its group keeps its values bit for bit
    alone = np.bincount(g, minlength=m) == 1
    new_pos[alone] = pos[first_sorted[alone]]
    new_vel[alone] = vel[first_sorted[alone]]
    new_rcs = 10 * np.log10(total)
    new_rcs[alone] = np.asarray(rcs_dbsm, dtype=np.float64)[first_sorted[alone]]
    new_frame = frame[first_sorted]
    new_start = np.searchsorted(new_frame, np.arange(len(start))).astype(np.int64)
    return MergedReflectors(
        start=new_start,
        position_m=new_pos,
        velocity_mps=new_vel,
        rcs_dbsm=new_rcs,
        source=np.asarray(source)[first_sorted],
    )

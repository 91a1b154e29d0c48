"""Tracking metrics besides the paper's loss: OSPA, GOSPA and the thresholds of the far-frame
count.

OSPA (Schuhmacher et al. 2008) with cut-off c = 1 m and order p = 2 compares the set of
confirmed track positions with the set of persons present in a frame; it is defined for every
pair of sets, empty or not, so for frames without a track, without a person and with several
persons (rows that are NaN — an absent person, a padded track slot — are not in the set).

GOSPA (Rahmathullah, García-Fernández & Svensson, "Generalized optimal sub-pattern assignment
metric", FUSION 2017) with α = 2 splits the same comparison into localisation error of the
assigned pairs, missed persons and false tracks (:func:`gospa`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = [
    "FAR_DISTANCE_M",
    "GOSPA_C_M",
    "GOSPA_P",
    "OSPA_C_M",
    "OSPA_P",
    "GospaTerms",
    "gospa",
    "ospa",
    "ospa_per_frame",
]

#: Distance (m) beyond which a confirmed track counts as far from the person.
FAR_DISTANCE_M = 1.0
#: OSPA cut-off c (m) and order p.
OSPA_C_M = 1.0
OSPA_P = 2
#: GOSPA cut-off c (m) and order p (α = 2 always).
GOSPA_C_M = 1.0
GOSPA_P = 2


def ospa(tracks_xy: np.ndarray, truth_xy: np.ndarray, c: float = OSPA_C_M, p: int = OSPA_P):
    """OSPA distance (Schuhmacher et al. 2008) between two finite sets of 2-D points (m).

    ``d = ((1/n) (min_π Σ min(d_i,π(i), c)^p + c^p (n − m)))^{1/p}``, n ≥ m the larger set
    size; 0 when both sets are empty, c when exactly one is. tracks_xy (m, 2), truth_xy (n, 2);
    rows with a NaN or infinite coordinate are left out of their set.
    """
    a = np.asarray(tracks_xy, dtype=np.float64).reshape(-1, 2)
    b = np.asarray(truth_xy, dtype=np.float64).reshape(-1, 2)
    a = a[np.all(np.isfinite(a), axis=1)]
    b = b[np.all(np.isfinite(b), axis=1)]
    if len(a) > len(b):
        a, b = b, a
    m, n = len(a), len(b)
    if n == 0:
        return 0.0
    if m == 0:
        return float(c)
    d = np.minimum(np.linalg.norm(a[:, None, :] - b[None, :, :], axis=2), c) ** p
    if m == 1:
        cost = float(d.min())
    else:
        from scipy.optimize import linear_sum_assignment  # 0.5 s to import: on use

        rows, cols = linear_sum_assignment(d)
        cost = float(d[rows, cols].sum())
    return float(((cost + c**p * (n - m)) / n) ** (1.0 / p))


def ospa_per_frame(
    tracks_xy: Sequence[np.ndarray],
    truth_xy: Sequence[np.ndarray],
    c: float = OSPA_C_M,
    p: int = OSPA_P,
) -> np.ndarray:
    """:func:`ospa` of every frame: ``tracks_xy[k]`` (m_k, 2) against ``truth_xy[k]`` (n_k, 2)
    in m (NaN rows, absent persons, left out); returns ``(F,)`` in m."""
    out = np.zeros(len(truth_xy))
    for k, (a, b) in enumerate(zip(tracks_xy, truth_xy, strict=True)):
        out[k] = ospa(a, b, c, p)
    return out


@dataclass(frozen=True, slots=True, kw_only=True)
class GospaTerms:
    """GOSPA of one frame (α = 2) and its decomposition.

    ``distance_m ** p == localisation + missed + false`` (all three in m^p).

    Attributes
    ----------
    distance_m
        d_p^(c,2)(X, Y) in m.
    localisation
        Σ ‖x_i − y_j‖^p over the assigned pairs (each closer than c), m^p.
    missed, false
        (c^p/2) × the number of persons without a track (``n_missed``) and of tracks without a
        person (``n_false``), m^p.
    n_missed, n_false
        Those counts.
    track_of_truth
        (n,) index into the tracks of the track assigned to each truth row (−1: missed; rows
        that are absent — NaN — are −1 too).
    """

    distance_m: float
    localisation: float
    missed: float
    false: float
    n_missed: int
    n_false: int
    track_of_truth: np.ndarray


def gospa(
    tracks_xy: np.ndarray, truth_xy: np.ndarray, c: float = GOSPA_C_M, p: float = GOSPA_P
) -> GospaTerms:
    """GOSPA (α = 2; Rahmathullah et al. 2017, Prop. 1) between tracks and persons of one frame.

    ``d = (min_γ Σ_{(i,j)∈γ} ‖x_i − y_j‖^p + (c^p/2)(|X| + |Y| − 2|γ|))^{1/p}``, γ an
    assignment of pairs closer than c. Defined for every pair of sets: 0 when both are empty,
    ``(c^p/2 · n)^{1/p}`` when one holds n points and the other none. Rows with a NaN or
    infinite coordinate are not in their set.

    Parameters
    ----------
    tracks_xy
        (m, 2) track positions, m.
    truth_xy
        (n, 2) person positions, m (NaN: absent).
    c, p
        Cut-off (m, > 0) and order (≥ 1).
    """
    if not (c > 0 and p >= 1):
        raise ValueError(f"GOSPA needs c > 0 and p >= 1, got {c=}, {p=}")
    a = np.asarray(tracks_xy, dtype=np.float64).reshape(-1, 2)
    b_all = np.asarray(truth_xy, dtype=np.float64).reshape(-1, 2)
    a = a[np.all(np.isfinite(a), axis=1)]
    rows_b = np.flatnonzero(np.all(np.isfinite(b_all), axis=1))
    b = b_all[rows_b]
    track_of_truth = np.full(len(b_all), -1, np.int64)
    loc, n_pairs = 0.0, 0
    if len(a) and len(b):
        d = np.linalg.norm(a[:, None, :] - b[None, :, :], axis=2)
        # a pair at or beyond c costs what leaving both unassigned costs: c^p/2 + c^p/2
        cost = np.minimum(d, c) ** p
        from scipy.optimize import linear_sum_assignment  # 0.5 s to import: on use

        ia, ib = linear_sum_assignment(cost)
        ok = d[ia, ib] < c
        loc = float(np.sum(d[ia[ok], ib[ok]] ** p))
        n_pairs = int(ok.sum())
        track_of_truth[rows_b[ib[ok]]] = ia[ok]
    n_missed, n_false = len(b) - n_pairs, len(a) - n_pairs
    half = c**p / 2.0
    missed, false = half * n_missed, half * n_false
    # d_p^(c,2) = (localisation + c^p/2 (missed + false))^(1/p)
    return GospaTerms(
        distance_m=float((loc + missed + false) ** (1.0 / p)),
        localisation=loc,
        missed=missed,
        false=false,
        n_missed=n_missed,
        n_false=n_false,
        track_of_truth=track_of_truth,
    )

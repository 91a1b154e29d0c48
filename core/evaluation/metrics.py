"""Tracking metrics besides the paper's loss: OSPA and the thresholds of the far-frame count.

OSPA (Schuhmacher et al. 2008) with cut-off c = 1 m and order p = 2 compares the set of
confirmed track positions with the set of persons present in a frame; it is defined for every
pair of sets, empty or not, so for frames without a track, without a person and with several
persons (rows that are NaN — an absent person, a padded track slot — are not in the set).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

__all__ = ["FAR_DISTANCE_M", "OSPA_C_M", "OSPA_P", "ospa"]

#: Distance (m) beyond which a confirmed track counts as far from the person.
FAR_DISTANCE_M = 1.0
#: OSPA cut-off c (m) and order p.
OSPA_C_M = 1.0
OSPA_P = 2


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
        rows, cols = linear_sum_assignment(d)
        cost = float(d[rows, cols].sum())
    return float(((cost + c**p * (n - m)) / n) ** (1.0 / p))

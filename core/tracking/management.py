"""Track management (SPEC §4): confirmation, deletion, merging, the track cap and the estimate.

Tracks are ordered by age (birth order = id order). Ties in ψ always favour the older track.
"""

from __future__ import annotations

import math

import numpy as np

#: Threshold on Δvᵀ (P_v,a + P_v,b)⁻¹ Δv for merging two confirmed tracks (JIPDA tracker):
#: χ²₂⁻¹(0.9) = 2 ln 10, the velocities agree within their 90 % uncertainty ellipse.
VELOCITY_MERGE_D2 = 2.0 * math.log(10.0)

__all__ = [
    "VELOCITY_MERGE_D2",
    "confirm",
    "survivors",
    "merge",
    "cap",
    "best_confirmed",
    "position_gate_distance2",
]


def confirm(
    confirmed: np.ndarray, psi: np.ndarray, updated: np.ndarray, threshold: float
) -> np.ndarray:
    """New confirmed flags: a tentative track that has been updated at least once (never in its
    birth frame) is confirmed when ψ ≥ threshold; confirmed tracks stay confirmed."""
    return confirmed | (updated & (psi >= threshold))


def survivors(psi: np.ndarray, threshold: float) -> np.ndarray:
    """Tracks kept by the deletion rule ψ ≥ threshold, (n,) bool."""
    return psi >= threshold


def position_gate_distance2(
    pos_a: np.ndarray, cov_a: np.ndarray, pos_b: np.ndarray, cov_b: np.ndarray
) -> float:
    """Squared distance of two positions (or velocities) (2,) with the combined covariance
    (2, 2)."""
    d = pos_a - pos_b
    C = cov_a + cov_b
    L = np.linalg.cholesky(C)
    w = np.linalg.solve(L, d)
    # d² = Δpᵀ (P_a + P_b)⁻¹ Δp
    return float(w @ w)


def _rank(psi: np.ndarray, ids: np.ndarray) -> np.ndarray:
    """Indices by ψ descending, ties by id ascending (older first)."""
    return np.lexsort((ids, -psi))


def merge(
    pos: np.ndarray,
    pos_cov: np.ndarray,
    psi: np.ndarray,
    ids: np.ndarray,
    gamma2: float,
    *,
    confirmed: np.ndarray | None = None,
    state: np.ndarray | None = None,
    state_cov: np.ndarray | None = None,
) -> np.ndarray:
    """Merge tracks whose positions lie within each other's 2-D gate; keep the higher ψ.

    Greedy in ψ order: each kept track removes every lower-ranked track with
    ``Δpᵀ (P_a + P_b)⁻¹ Δp ≤ γ₂`` (γ₂ = χ²₂⁻¹(P_G)). pos (n, 2), pos_cov (n, 2, 2) → keep (n,).

    With ``confirmed`` (n,) bool, ``state`` (n, d) and ``state_cov`` (n, d, d) (the JIPDA
    tracker), two *confirmed* tracks are merged only when their velocities also agree:
    ``Δvᵀ (P_v,a + P_v,b)⁻¹ Δv ≤`` :data:`VELOCITY_MERGE_D2` (velocity blocks of the
    covariances), so two people crossing at an angle keep their tracks while two tracks
    coalesced on one person (same velocity) still merge; a tentative track is merged on position
    alone.
    """
    n = len(psi)
    keep = np.ones(n, dtype=bool)
    order = _rank(psi, ids)
    for a_rank, a in enumerate(order):
        if not keep[a]:
            continue
        for b in order[a_rank + 1 :]:
            if not keep[b]:
                continue
            if position_gate_distance2(pos[a], pos_cov[a], pos[b], pos_cov[b]) > gamma2:
                continue
            if confirmed is not None and confirmed[a] and confirmed[b]:
                assert state is not None and state_cov is not None
                v_a, v_b = state[a][2:4], state[b][2:4]
                c_a, c_b = state_cov[a][2:4, 2:4], state_cov[b][2:4, 2:4]
                if position_gate_distance2(v_a, c_a, v_b, c_b) > VELOCITY_MERGE_D2:
                    continue
            keep[b] = False
    return keep


def cap(psi: np.ndarray, ids: np.ndarray, max_tracks: int) -> np.ndarray:
    """Keep at most ``max_tracks``: the lowest ψ go first (ties: the youngest). → keep (n,)."""
    keep = np.ones(len(psi), dtype=bool)
    if len(psi) > max_tracks:
        keep[_rank(psi, ids)[max_tracks:]] = False
    return keep


def best_confirmed(psi: np.ndarray, ids: np.ndarray, confirmed: np.ndarray) -> int:
    """Index of the single-person estimate: the confirmed track with the highest ψ (ties: the
    older track), or −1 when no track is confirmed."""
    best = -1
    for i in range(len(psi)):
        if confirmed[i] and (
            best < 0 or psi[i] > psi[best] or (psi[i] == psi[best] and ids[i] < ids[best])
        ):
            best = i
    return best

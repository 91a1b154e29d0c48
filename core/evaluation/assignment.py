"""Tracks assigned to people, frame by frame, and the identity switches that follow.

The rule is the one of the CLEAR MOT metrics (Bernardin & Stiefelhagen, "Evaluating multiple
object tracking performance: the CLEAR MOT metrics", EURASIP J. Image Video Process. 2008),
with a cut-off c (m) on the x–y distance between a confirmed track and a person:

1. **Keep** (hysteresis): a person present in frame f keeps the track it was paired with at its
   most recent earlier paired frame of the same trajectory, if that track is still confirmed in
   frame f and within c of the person (‖x̂ − x‖ ≤ c). Kept pairs never conflict: every track is
   paired with at most one person at a time.
2. **Assign**: the persons present and the confirmed tracks not kept in step 1 are paired by an
   optimal assignment (:func:`scipy.optimize.linear_sum_assignment`): pairs farther apart than c
   are not allowed; among the assignments with the most allowed pairs, the one with the least sum
   of distances. A person with no allowed track is unassigned in the frame.
3. **Switch**: person j has an identity switch in frame f when it is paired with a track whose id
   differs from the id of its previous pairing (its most recent earlier paired frame of the same
   trajectory). A person that loses its track and is paired again with the *same* id has no
   switch; a first pairing is no switch.

So the same person keeps its track until the track is lost (no longer confirmed) or drifts
farther than c from it; only then may the assignment change. Every trajectory starts afresh
(track ids count per trajectory).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["IDENTITY_CUTOFF_M", "IdentityAssignment", "assign_identities"]

#: Cut-off c (m) of the track-to-person assignment (the OSPA/GOSPA cut-off).
IDENTITY_CUTOFF_M = 1.0


@dataclass(frozen=True, slots=True, kw_only=True)
class IdentityAssignment:
    """Track-to-person pairing of N frames and P persons.

    Attributes
    ----------
    track_id
        (N, P) int64 id of the track paired with each person, −1 where the person is absent or
        unassigned.
    distance_m
        (N, P) distance (m) from the person to its track, NaN where unpaired.
    switch
        (N, P) bool, an identity switch of the person in the frame (see the module docstring).
    present
        (N, P) bool, the person is present (finite truth).
    """

    track_id: np.ndarray
    distance_m: np.ndarray
    switch: np.ndarray
    present: np.ndarray

    @property
    def switches_per_person(self) -> np.ndarray:
        """(P,) identity switches of each person over all frames."""
        return self.switch.sum(axis=0).astype(np.int64)

    @property
    def assigned(self) -> np.ndarray:
        """(N, P) bool, the person has a track."""
        return self.track_id >= 0


def assign_identities(
    track_ids: np.ndarray,
    track_xy: np.ndarray,
    truth_xy: np.ndarray,
    offsets: np.ndarray | None = None,
    *,
    cutoff_m: float = IDENTITY_CUTOFF_M,
) -> IdentityAssignment:
    """Pair confirmed tracks with persons frame by frame (the module's rule).

    Parameters
    ----------
    track_ids
        (N, C) int64 ids of the confirmed tracks per frame, −1 for padding.
    track_xy
        (N, C, 2) their positions (m); padding is ignored.
    truth_xy
        (N, P, 2) true positions (m), NaN where a person is absent.
    offsets
        (K + 1,) frame ranges of the trajectories (the pairing restarts in each); default: one.
    cutoff_m
        Cut-off c (m), > 0.

    Returns
    -------
    IdentityAssignment
    """
    ids = np.asarray(track_ids, dtype=np.int64)
    txy = np.asarray(track_xy, dtype=np.float64)
    truth = np.asarray(truth_xy, dtype=np.float64)
    n, p = truth.shape[0], truth.shape[1]
    if not cutoff_m > 0:
        raise ValueError(f"cutoff_m must be > 0, got {cutoff_m=}")
    if offsets is None:
        offsets = np.array([0, n], dtype=np.int64)
    present = np.all(np.isfinite(truth), axis=2)
    out_id = np.full((n, p), -1, np.int64)
    out_d = np.full((n, p), np.nan)
    switch = np.zeros((n, p), dtype=bool)
    for k in range(len(offsets) - 1):
        last = np.full(p, -1, np.int64)  # id of each person's most recent pairing
        for f in range(int(offsets[k]), int(offsets[k + 1])):
            valid = (ids[f] >= 0) & np.all(np.isfinite(txy[f]), axis=1)
            cols = np.flatnonzero(valid)
            persons = np.flatnonzero(present[f])
            if not len(cols) or not len(persons):
                continue
            # d_ij = ‖x̂_i − x_j‖ for confirmed track i and person j present
            d = np.linalg.norm(txy[f, cols][:, None, :] - truth[f, persons][None, :, :], axis=2)
            free_t = np.ones(len(cols), dtype=bool)
            free_p = np.ones(len(persons), dtype=bool)
            # 1. keep the previous pairing while it is confirmed and within c
            for b, j in enumerate(persons):
                hit = np.flatnonzero(ids[f, cols] == last[j]) if last[j] >= 0 else np.zeros(0, int)
                if len(hit) and d[hit[0], b] <= cutoff_m:
                    a = hit[0]
                    out_id[f, j], out_d[f, j] = last[j], d[a, b]
                    free_t[a] = free_p[b] = False
            # 2. optimal assignment of the rest, pairs beyond c not allowed
            ta, pb = np.flatnonzero(free_t), np.flatnonzero(free_p)
            if len(ta) and len(pb):
                sub = d[np.ix_(ta, pb)]
                cost = np.where(sub <= cutoff_m, sub, 2.0 * cutoff_m * (len(ta) + len(pb)))
                from scipy.optimize import linear_sum_assignment  # 0.5 s to import: on use

                rows, cs = linear_sum_assignment(cost)
                for a, b in zip(ta[rows], pb[cs]):
                    if d[a, b] <= cutoff_m:
                        j = persons[b]
                        out_id[f, j], out_d[f, j] = ids[f, cols[a]], d[a, b]
            # 3. switches: a pairing with another id than the person's previous one
            for j in persons:
                if out_id[f, j] >= 0:
                    switch[f, j] = last[j] >= 0 and out_id[f, j] != last[j]
                    last[j] = out_id[f, j]
    return IdentityAssignment(track_id=out_id, distance_m=out_d, switch=switch, present=present)

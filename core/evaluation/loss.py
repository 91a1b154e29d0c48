"""The paper's loss (SPEC §5, eqs. 12–14).

Per trajectory k (eqs. 12–13): N_c(k) = frames with a confirmed track (a single-person
estimate), ``MSE(k) = (1/N_c) Σ |x̂ − x_gt|²`` over those frames, ``L(k) = MSE(k)/N_c(k)``;
a trajectory with N_c = 0 scores L = 1.0 m² (the paper is silent). Total (eq. 14):
``L_t = mean_k L(k)``. Table I lists the per-class means ×10⁻³.

The tracked person is person 0 of the data set. Where the paper's scenes never go, the loss
stays defined: a frame counts in N_c only when a confirmed track exists *and* the tracked person
is present (finite truth), so a frame in which the person is absent (NaN truth) or a data set
without any person adds nothing, and a trajectory without any such frame scores 1.0 m² like one
never confirmed. Where the person is always present (every single-person data set) this is the
paper's definition, value for value.

Several persons (:func:`person_estimates`, :func:`people_trajectory_loss`): in every frame the
tracker's estimate of the P_f persons present is its P_f confirmed tracks of highest ψ (ties: the
lower id) — for P_f = 1 exactly the single-person estimate — paired with the persons by the
assignment of least Σ‖x̂ − x‖²; with fewer confirmed tracks than persons, the assignment pairs
every track and leaves the persons it does not reach without an estimate in that frame. Person j
of trajectory k then has its own N_c,j(k), MSE_j(k) and L_j(k) by eqs. (12)–(13), and

    L(k) = (1/|J_k|) Σ_{j∈J_k} L_j(k)

over the persons J_k present in at least one frame of the trajectory (L_j = 1 m² for a person
who never has an estimate); L(k) = 1 m² when nobody is present. L_t is eq. (14) over these L(k).
With one person, L(k) = L_0(k) is today's value bit for bit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from core.dataset import Dataset

__all__ = [
    "NO_CONFIRMATION_LOSS",
    "CLASSES",
    "PeopleLoss",
    "people_trajectory_loss",
    "person_estimates",
    "running_trajectory_loss",
    "tracked_person_xy",
    "trajectory_loss",
    "trajectory_losses",
]

#: L(k) of a trajectory without any confirmed frame (m²).
NO_CONFIRMATION_LOSS = 1.0
#: Trajectory classes of the paper's Table I.
CLASSES = ("a", "b", "c", "d", "e")


def tracked_person_xy(truth_xy_m: np.ndarray) -> np.ndarray:
    """Position of the tracked person (person 0) per frame.

    Parameters
    ----------
    truth_xy_m
        (F, n_persons, 2) true positions in m, NaN where a person is absent.

    Returns
    -------
    numpy.ndarray
        (F, 2) in m; NaN where person 0 is absent and everywhere when there is no person.
    """
    truth = np.asarray(truth_xy_m, dtype=np.float64)
    if truth.shape[1] == 0:
        return np.full((truth.shape[0], 2), np.nan)
    return truth[:, 0, :]


def trajectory_loss(
    estimate_xy: np.ndarray, has_estimate: np.ndarray, truth_xy: np.ndarray
) -> tuple[float, float, int]:
    """The paper's loss of one trajectory, eqs. (12)–(13).

    Parameters
    ----------
    estimate_xy
        Estimated position (N, 2) in m (ignored where ``has_estimate`` is False).
    has_estimate
        (N,) bool, a confirmed track exists in the frame.
    truth_xy
        Ground-truth position (N, 2) in m, NaN where the person is absent (such frames are
        not scored).

    Returns
    -------
    L, MSE, N_c
        ``L = MSE/N_c`` (m²), MSE (m², NaN — undefined — when N_c = 0) and N_c, the frames with
        an estimate in which the person is present; N_c = 0 gives L = 1.0.
    """
    truth = np.asarray(truth_xy)
    # scored frames: an estimate exists and the person is present
    scored = np.asarray(has_estimate, dtype=bool) & np.all(np.isfinite(truth), axis=1)
    n_c = int(scored.sum())
    if n_c == 0:
        return NO_CONFIRMATION_LOSS, math.nan, 0
    e = np.asarray(estimate_xy)[scored] - truth[scored]
    # MSE(k) = (1/N_c) Σ |x̂ − x_gt|²   (12)
    mse = float(np.sum(e * e) / n_c)
    # L(k) = MSE(k) / N_c(k)   (13)
    return mse / n_c, mse, n_c


def running_trajectory_loss(
    estimate_xy: np.ndarray, has_estimate: np.ndarray, truth_xy: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Eq. (13) and the RMSE over frames ``0..k`` for every k (the loss as a run unfolds).

    Element ``k`` is :func:`trajectory_loss` of the first ``k + 1`` frames (the same frames
    scored: an estimate exists and the person is present).

    Returns
    -------
    loss
        ``(F,)`` L_k = MSE_k / N_c,k in m² (:data:`NO_CONFIRMATION_LOSS` while N_c,k = 0).
    rmse
        ``(F,)`` sqrt(MSE_k) in m (NaN while N_c,k = 0).
    """
    has = np.asarray(has_estimate, dtype=bool) & np.isfinite(truth_xy).all(axis=1)
    e = np.where(has[:, None], np.nan_to_num(estimate_xy) - np.nan_to_num(truth_xy), 0.0)
    # MSE_k = (1/N_c,k) Σ_{j≤k} |x̂_j − x_j|²  over frames with an estimate
    n_c = np.cumsum(has)
    sse = np.cumsum(np.sum(e * e, axis=1))
    with np.errstate(invalid="ignore", divide="ignore"):
        mse = np.where(n_c > 0, sse / np.maximum(n_c, 1), np.nan)
        # L_k = MSE_k / N_c,k
        loss = np.where(n_c > 0, mse / np.maximum(n_c, 1), NO_CONFIRMATION_LOSS)
    return loss, np.sqrt(mse)


@dataclass(frozen=True, slots=True, kw_only=True)
class PeopleLoss:
    """The paper's loss of one trajectory with P persons (module docstring).

    Attributes
    ----------
    loss
        L(k) in m²: the mean of ``person_loss`` over the persons ``counted``, 1.0 if none.
    mse
        Mean MSE_j(k) over the persons with N_c,j > 0 (m²; NaN — undefined — if none).
    n_c
        Σ_j N_c,j(k), scored person-frames.
    person_loss, person_mse, person_n_c
        (P,) L_j(k) (m²; 1.0 where N_c,j = 0), MSE_j(k) (m², NaN where N_c,j = 0) and N_c,j(k).
    counted
        (P,) bool, person j is present in at least one frame of the trajectory.
    """

    loss: float
    mse: float
    n_c: int
    person_loss: np.ndarray
    person_mse: np.ndarray
    person_n_c: np.ndarray
    counted: np.ndarray


def person_estimates(ranked_xy: np.ndarray, truth_xy: np.ndarray) -> np.ndarray:
    """The tracker's estimate of each person present, per frame (module docstring).

    Parameters
    ----------
    ranked_xy
        (N, C, 2) positions (m) of the confirmed tracks ranked by ψ, highest first (NaN padded:
        :class:`core.tracking.batch.ConfirmedTracks` ``xy``).
    truth_xy
        (N, P, 2) true positions (m), NaN where a person is absent.

    Returns
    -------
    numpy.ndarray
        (N, P, 2) estimate of each person in m, NaN where the person is absent or has none.
    """
    ranked = np.asarray(ranked_xy, dtype=np.float64)
    truth = np.asarray(truth_xy, dtype=np.float64)
    n, p = truth.shape[:2]
    out = np.full((n, p, 2), np.nan)
    present = np.all(np.isfinite(truth), axis=2)
    n_present = present.sum(axis=1)
    n_tracks = np.sum(np.all(np.isfinite(ranked), axis=2), axis=1)
    k = np.minimum(n_present, n_tracks)  # pairs in each frame
    # one pair: the most probable track goes to the nearest person present
    f1 = np.flatnonzero(k == 1)
    if len(f1):
        e = ranked[f1, 0][:, None, :] - truth[f1]
        d2 = np.where(present[f1], np.sum(e * e, axis=2), np.inf)
        out[f1, np.argmin(d2, axis=1)] = ranked[f1, 0]
    # two tracks, two persons: the cheaper of the two pairings
    f2 = np.flatnonzero((k == 2) & (n_present == 2))
    if len(f2):
        ab = np.argsort(~present[f2], axis=1, kind="stable")[:, :2]  # the two persons present
        pa, pb = truth[f2, ab[:, 0]], truth[f2, ab[:, 1]]
        t0, t1 = ranked[f2, 0], ranked[f2, 1]

        def sq(u: np.ndarray, v: np.ndarray) -> np.ndarray:
            return np.sum((u - v) ** 2, axis=1)

        keep = sq(t0, pa) + sq(t1, pb) <= sq(t0, pb) + sq(t1, pa)
        out[f2, ab[:, 0]] = np.where(keep[:, None], t0, t1)
        out[f2, ab[:, 1]] = np.where(keep[:, None], t1, t0)
    for f in np.flatnonzero((k >= 2) & ~((k == 2) & (n_present == 2))):
        persons = np.flatnonzero(present[f])
        # the P_f most probable confirmed tracks (ranked first: finite rows come first)
        top = ranked[f, : k[f]]
        e = top[:, None, :] - truth[f, persons][None, :, :]
        # pairing of least Σ‖x̂ − x‖²
        from scipy.optimize import linear_sum_assignment  # 0.5 s to import: on use

        rows, cols = linear_sum_assignment(np.sum(e * e, axis=2))
        out[f, persons[cols]] = top[rows]
    return out


def people_trajectory_loss(estimate_xy: np.ndarray, truth_xy: np.ndarray) -> PeopleLoss:
    """L(k) of one trajectory with P persons: eq. (13) per person, mean over the persons.

    Parameters
    ----------
    estimate_xy
        (N, P, 2) estimate of each person (m), NaN where none (:func:`person_estimates`).
    truth_xy
        (N, P, 2) true positions (m), NaN where absent.

    Returns
    -------
    PeopleLoss
    """
    est = np.asarray(estimate_xy, dtype=np.float64)
    truth = np.asarray(truth_xy, dtype=np.float64)
    p = truth.shape[1]
    ls, ms = np.empty(p), np.empty(p)
    ns = np.zeros(p, dtype=np.int64)
    for j in range(p):
        has = np.all(np.isfinite(est[:, j]), axis=1)
        ls[j], ms[j], ns[j] = trajectory_loss(est[:, j], has, truth[:, j])
    counted = np.any(np.all(np.isfinite(truth), axis=2), axis=0)
    scored = counted & (ns > 0)
    return PeopleLoss(
        # L(k) = (1/|J_k|) Σ_{j∈J_k} L_j(k)
        loss=float(np.mean(ls[counted])) if counted.any() else NO_CONFIRMATION_LOSS,
        mse=float(np.mean(ms[scored])) if scored.any() else math.nan,
        n_c=int(ns.sum()),
        person_loss=ls,
        person_mse=ms,
        person_n_c=ns,
        counted=counted,
    )


def trajectory_losses(dataset: Dataset, estimates) -> np.ndarray:
    """L(k) of every tracked trajectory, in the order tracked, shape (K_sel,) in m².

    The cheap path for the optimiser: one person (or none) is scored from the single-person
    estimate; several persons need ``estimates.tracks`` (``track_dataset(...,
    with_tracks=True)``) and are scored by :func:`people_trajectory_loss`.
    """
    return np.array([t[0] for t in trajectory_loss_terms(dataset, estimates)], dtype=np.float64)


def trajectory_loss_terms(dataset: Dataset, estimates) -> list[tuple[float, float, int]]:
    """``(L(k), MSE(k), N_c(k))`` of every tracked trajectory, in the order tracked.

    One person (or none): eqs. (12)–(13) on the single-person estimate against person 0,
    exactly as ever. Several: :class:`PeopleLoss` ``loss``, ``mse`` and ``n_c``.
    """
    truth_all = dataset.truth_xy_m[estimates.frame_index]  # (F_sel, P, 2) m
    off = estimates.offsets
    out: list[tuple[float, float, int]] = []
    if truth_all.shape[1] <= 1:
        truth = tracked_person_xy(truth_all)  # (F_sel, 2) m
        for i in range(len(estimates.trajectories)):
            s = slice(off[i], off[i + 1])
            out.append(
                trajectory_loss(estimates.estimate_xy[s], estimates.has_estimate[s], truth[s])
            )
        return out
    if estimates.tracks is None:
        raise ValueError(
            "a data set with several persons is scored from every confirmed track: track it "
            "with track_dataset(..., with_tracks=True)"
        )
    est = person_estimates(estimates.tracks.xy, truth_all)
    for i in range(len(estimates.trajectories)):
        s = slice(off[i], off[i + 1])
        r = people_trajectory_loss(est[s], truth_all[s])
        out.append((r.loss, r.mse, r.n_c))
    return out

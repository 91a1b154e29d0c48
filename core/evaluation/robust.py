"""Robust objectives: losses that rare events cannot swamp, beside the paper's L_t.

The paper's loss of a trajectory, ``L(k) = MSE(k) / N_c(k)`` (eq. 13), is 1 m² for a trajectory
never confirmed and grows with the square of the error of a track seduced by clutter: one such
trajectory can make most of ``L_t = mean_k L(k)`` (eq. 14). Two ways to bound the influence of one
trajectory, used by the study objectives (:data:`OBJECTIVES`):

- **capped** per-frame error, as GOSPA (α = 2, p = 2) scores one person: in every frame in which
  the person is present,

  ``d_f = min(|x̂_f − x_f|, c)²``  if a confirmed estimate exists (an error beyond ``c`` counts as
  ``c²``: a track on clutter costs no more than being lost), and
  ``d_f = c² / 2``  if none (GOSPA's cost of a missed target with α = 2),

  and ``C(k) = mean_f d_f``. A frame cannot cost more than ``c²``, so a trajectory cannot cost
  more than ``c²`` either; a trajectory never confirmed costs ``c² / 2``.
- **aggregation** over trajectories other than the mean: the median of ``L(k)``, or the mean of
  ``L(k)`` without its largest ``TRIM_FRACTION`` (a one-sided trimmed mean: only the tail that
  dominates is cut).

The paper's ``L_t`` is always computed beside whichever objective a study minimises.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from core.errors import InputError

#: Cut-off of the capped loss (m): an error beyond it is as bad as a lost track.
CAPPED_CUTOFF_M = 0.5
#: A confirmed estimate farther than this from the person is not on the person (m).
FAR_DISTANCE_M = 1.0
#: Frames with the estimate beyond :data:`FAR_DISTANCE_M` that make a trajectory "on clutter".
FAR_FRAMES = 5
#: Fraction of the largest trajectory losses left out by the trimmed mean.
TRIM_FRACTION = 0.1
#: The objective a study minimises unless told otherwise: held-out on 20 test sets it gave the
#: lowest median paper loss of the four (docs/decisions/tuning-08-default-objective.md).
DEFAULT_OBJECTIVE = "trimmed"
#: Study objectives: name → (per-trajectory loss, aggregation over trajectories). The first
#: four score positions against the truth; ``count``, ``fragmentation``, ``nis`` and
#: ``reference`` need no positions (:mod:`core.evaluation.counting`: a head count, nothing for
#: ``nis``, a recording's own tracks for ``reference``) and are
#: aggregated over trajectories weighted by what each trajectory scored (frames, person-frames,
#: NIS samples), so that a short run of a recording weighs as little as it holds.
OBJECTIVES: dict[str, tuple[str, str]] = {
    "paper": ("paper", "mean"),
    "capped": ("capped", "mean"),
    "median": ("paper", "median"),
    "trimmed": ("paper", "trimmed"),
    "count": ("count", "weighted"),
    "fragmentation": ("fragmentation", "weighted"),
    "nis": ("nis", "weighted"),
    "reference": ("reference", "weighted"),
}
#: The objectives that score positions against the truth.
POSITION_OBJECTIVES = ("paper", "capped", "median", "trimmed")
#: What each objective needs of a data set: the truth's positions, a head count (``--people N``
#: or the truth), or nothing.
OBJECTIVE_NEEDS: dict[str, str] = {
    **dict.fromkeys(POSITION_OBJECTIVES, "truth"),
    "count": "head count",
    "fragmentation": "head count",
    "nis": "",
    "reference": "reference layer",
}


def check_objective(name: str) -> str:
    """``name`` if it is one of :data:`OBJECTIVES`, else one :class:`InputError` line."""
    if name not in OBJECTIVES:
        raise InputError(f"loss must be one of {', '.join(OBJECTIVES)}, got {name!r}")
    return name


def capped_loss(
    estimate_xy: np.ndarray,
    has_estimate: np.ndarray,
    truth_xy: np.ndarray,
    cutoff_m: float = CAPPED_CUTOFF_M,
) -> float:
    """``C(k)``: the mean capped squared error of one trajectory (m²).

    Parameters
    ----------
    estimate_xy
        Estimated position (N, 2) in m (ignored where ``has_estimate`` is False).
    has_estimate
        (N,) bool, a confirmed track exists in the frame.
    truth_xy
        Ground truth (N, 2) in m, NaN where the person is absent (those frames are not scored).
    cutoff_m
        ``c`` in m, > 0.

    Returns
    -------
    float
        ``mean_f d_f`` over the frames with the person present; 0 when there is none.
    """
    if not cutoff_m > 0:
        raise InputError(f"cutoff_m must be > 0, got {cutoff_m}")
    truth = np.asarray(truth_xy, dtype=np.float64)
    present = np.all(np.isfinite(truth), axis=1)
    n = int(present.sum())
    if n == 0:
        return 0.0
    has = np.asarray(has_estimate, dtype=bool)[present]
    e = np.asarray(estimate_xy, dtype=np.float64)[present] - truth[present]
    c2 = cutoff_m * cutoff_m
    # d_f = min(|x̂ − x|, c)² with an estimate, c²/2 without
    d = np.where(has, np.minimum(np.sum(e * e, axis=1), c2), 0.5 * c2)
    return float(np.sum(d) / n)


def per_trajectory(
    dataset: Any,
    estimates: Any,
    score: Callable[[np.ndarray, np.ndarray, np.ndarray], float],
    combine: Callable[[list[float]], float],
) -> list[float]:
    """``score(estimate_xy, has_estimate, truth_xy)`` of every tracked trajectory, in order.

    One person (or none): the single-person estimate against person 0. Several: each person
    present in the trajectory against the estimate the paper's multi-person loss gives them
    (:func:`core.evaluation.loss.person_estimates`), the persons' scores ``combine``d (called
    with an empty list when nobody is present).
    """
    from core.evaluation.loss import person_estimates, tracked_person_xy

    truth_all = dataset.truth_xy_m[estimates.frame_index]  # (F_sel, P, 2) m
    off = estimates.offsets
    spans = [slice(off[i], off[i + 1]) for i in range(len(estimates.trajectories))]
    if truth_all.shape[1] <= 1:
        truth = tracked_person_xy(truth_all)  # (F_sel, 2) m
        return [score(estimates.estimate_xy[s], estimates.has_estimate[s], truth[s]) for s in spans]
    est = person_estimates(estimates.tracks.xy, truth_all)  # (F_sel, P, 2) m, NaN: none
    return [
        combine([
            score(est[s, p], np.all(np.isfinite(est[s, p]), axis=1), truth_all[s, p])
            for p in range(truth_all.shape[1])
            if np.isfinite(truth_all[s, p]).all(axis=1).any()
        ])
        for s in spans
    ]  # fmt: skip


def trajectory_capped_losses(dataset: Any, estimates: Any) -> list[float]:
    """``C(k)`` of every tracked trajectory, in the order tracked (m²): :func:`capped_loss` per
    :func:`per_trajectory`, averaged over the persons present (0 when nobody is)."""
    return per_trajectory(
        dataset, estimates, capped_loss, lambda v: float(np.mean(v)) if v else 0.0
    )


def far_frames(
    estimate_xy: np.ndarray,
    has_estimate: np.ndarray,
    truth_xy: np.ndarray,
    distance_m: float = FAR_DISTANCE_M,
) -> int:
    """Frames in which a confirmed estimate lies farther than ``distance_m`` from the person.

    Parameters are those of :func:`capped_loss` ((N, 2) m, (N,) bool, (N, 2) m with NaN where
    the person is absent; those frames are not counted).
    """
    truth = np.asarray(truth_xy, dtype=np.float64)
    present = np.all(np.isfinite(truth), axis=1) & np.asarray(has_estimate, dtype=bool)
    e = np.asarray(estimate_xy, dtype=np.float64)[present] - truth[present]
    # |x̂ − x| > d  ⇔  |x̂ − x|² > d²
    return int(np.sum(np.sum(e * e, axis=1) > distance_m * distance_m))


def trajectory_far_frames(dataset: Any, estimates: Any) -> list[int]:
    """:func:`far_frames` of every tracked trajectory, in the order tracked: per
    :func:`per_trajectory`, summed over the persons."""
    return [int(v) for v in per_trajectory(dataset, estimates, far_frames, sum)]


def trimmed_mean(values: Sequence[float], fraction: float = TRIM_FRACTION) -> float:
    """Mean of ``values`` without their largest ``floor(fraction · n)`` (at least one stays)."""
    v = np.sort(np.asarray(values, dtype=np.float64))
    if v.size == 0:
        return math.nan
    keep = v.size - min(int(math.floor(fraction * v.size)), v.size - 1)
    return float(np.mean(v[:keep]))


def aggregate(values: Sequence[float], how: str, weights: Sequence[float] | None = None) -> float:
    """Trajectory losses → one objective value: ``"mean"``, ``"median"``, ``"trimmed"`` or
    ``"weighted"`` (Σ wₖ vₖ / Σ wₖ with the trajectories' ``weights``)."""
    if how == "weighted":
        if weights is None or len(weights) != len(values):
            raise ValueError("the weighted aggregation needs one weight per value")
        w = np.asarray(weights, dtype=np.float64)
        return float(np.sum(w * np.asarray(values, dtype=np.float64)) / np.sum(w))
    if how == "mean":
        return float(np.mean(values))
    if how == "median":
        return float(np.median(values))
    if how == "trimmed":
        return trimmed_mean(values)
    raise InputError(f"aggregation must be mean, median, trimmed or weighted, got {how!r}")


__all__ = [
    "CAPPED_CUTOFF_M",
    "DEFAULT_OBJECTIVE",
    "FAR_DISTANCE_M",
    "FAR_FRAMES",
    "OBJECTIVES",
    "OBJECTIVE_NEEDS",
    "POSITION_OBJECTIVES",
    "TRIM_FRACTION",
    "aggregate",
    "capped_loss",
    "check_objective",
    "far_frames",
    "trajectory_capped_losses",
    "trajectory_far_frames",
    "trimmed_mean",
]

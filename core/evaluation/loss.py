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
"""

from __future__ import annotations

import math

import numpy as np

from core.dataset import Dataset

__all__ = [
    "NO_CONFIRMATION_LOSS",
    "CLASSES",
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


def trajectory_losses(dataset: Dataset, estimates) -> np.ndarray:
    """L(k) of every tracked trajectory, in the order tracked, shape (K_sel,) in m².

    The cheap path for the optimiser (person 0 is the tracked person).
    """
    truth = tracked_person_xy(dataset.truth_xy_m[estimates.frame_index])  # (F_sel, 2) m
    off = estimates.offsets
    out = np.empty(len(estimates.trajectories))
    for i in range(len(out)):
        s = slice(off[i], off[i + 1])
        out[i] = trajectory_loss(estimates.estimate_xy[s], estimates.has_estimate[s], truth[s])[0]
    return out

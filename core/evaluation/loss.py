"""The paper's loss (SPEC §5, eqs. 12–14).

Per trajectory k (eqs. 12–13): N_c(k) = frames with a confirmed track (a single-person
estimate), ``MSE(k) = (1/N_c) Σ |x̂ − x_gt|²`` over those frames, ``L(k) = MSE(k)/N_c(k)``;
a trajectory with N_c = 0 scores L = 1.0 m² (the paper is silent). Total (eq. 14):
``L_t = mean_k L(k)``. Table I lists the per-class means ×10⁻³.
"""

from __future__ import annotations

import math

import numpy as np

from core.dataset import Dataset

__all__ = ["NO_CONFIRMATION_LOSS", "CLASSES", "trajectory_loss", "trajectory_losses"]

#: L(k) of a trajectory without any confirmed frame (m²).
NO_CONFIRMATION_LOSS = 1.0
#: Trajectory classes of the paper's Table I.
CLASSES = ("a", "b", "c", "d", "e")


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
        Ground-truth position (N, 2) in m.

    Returns
    -------
    L, MSE, N_c
        ``L = MSE/N_c`` (m²), MSE (m², NaN when N_c = 0) and N_c; N_c = 0 gives L = 1.0.
    """
    has = np.asarray(has_estimate, dtype=bool)
    n_c = int(has.sum())
    if n_c == 0:
        return NO_CONFIRMATION_LOSS, math.nan, 0
    e = np.asarray(estimate_xy)[has] - np.asarray(truth_xy)[has]
    # MSE(k) = (1/N_c) Σ |x̂ − x_gt|²   (12)
    mse = float(np.sum(e * e) / n_c)
    # L(k) = MSE(k) / N_c(k)   (13)
    return mse / n_c, mse, n_c


def trajectory_losses(dataset: Dataset, estimates) -> np.ndarray:
    """L(k) of every tracked trajectory, in the order tracked, shape (K_sel,) in m².

    The cheap path for the optimiser (person 0 is the tracked person).
    """
    truth = dataset.truth_xy_m[estimates.frame_index][:, 0, :]  # (F_sel, 2) m
    off = estimates.offsets
    out = np.empty(len(estimates.trajectories))
    for i in range(len(out)):
        s = slice(off[i], off[i + 1])
        out[i] = trajectory_loss(estimates.estimate_xy[s], estimates.has_estimate[s], truth[s])[0]
    return out

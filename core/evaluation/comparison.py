"""Comparing two tracker runs on one data set: where the paper's loss comes from, and by how much
one run beats the other (docs/report/cv-vs-ca.md).

Two tools, both pure functions of tracker output and truth:

- :func:`loss_breakdown` splits every trajectory's loss ``L(k) = MSE(k)/N_c(k) = SSE(k)/N_c(k)²``
  (eqs. 12–13, SSE = Σ |x̂ − x_gt|² over the confirmed frames) into the contributions of three
  disjoint kinds of confirmed frame — the *transient* (the first ``n_transient`` frames after the
  estimate appears or changes track), *manoeuvre* frames (the person accelerated within the last
  ``manoeuvre_window`` frames) and the *steady* rest — and reports the signed along-track error
  (negative: the estimate lags behind the person), the range / cross-range split and the time to
  first confirmation.
- :func:`paired_comparison` compares two runs trajectory by trajectory: the ratio of the totals
  ``L_t(a)/L_t(b)`` (eq. 14) with a class-stratified paired bootstrap interval, the per-trajectory
  log-ratios, wins, and the Wilcoxon signed-rank test.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from core.dataset import Dataset
from core.evaluation.loss import NO_CONFIRMATION_LOSS, tracked_person_xy

__all__ = [
    "CATEGORIES",
    "track_with_ids",
    "LossBreakdown",
    "loss_breakdown",
    "PairedComparison",
    "paired_comparison",
]

#: Frame categories of :func:`loss_breakdown`, in priority order.
CATEGORIES = ("transient", "manoeuvre", "steady")


@dataclass(frozen=True, slots=True, kw_only=True)
class LossBreakdown:
    """Per-trajectory decomposition of the paper's loss (K_sel trajectories, SI units).

    Attributes
    ----------
    trajectories, classes
        (K_sel,) trajectory index and class label.
    n_frames, n_c
        (K_sel,) frames of the trajectory and frames with an estimate (N_c).
    first_confirmed_frame
        (K_sel,) frame index (within the trajectory) of the first estimate, −1 if none.
    loss, sse
        (K_sel,) ``L(k)`` (m²; 1.0 when N_c = 0) and ``SSE(k) = N_c·MSE(k)`` (m²).
    loss_by_category, sse_by_category, frames_by_category
        (K_sel, 3) the part of ``L(k)``, of ``SSE(k)`` and of ``N_c(k)`` from the transient,
        manoeuvre and steady frames (:data:`CATEGORIES`); rows sum to ``L(k)``, ``SSE(k)`` and
        ``N_c(k)`` (0 when N_c = 0).
    along_track_mean_m
        (K_sel,) mean signed error along the true velocity direction over the non-transient
        frames in which the person moves (m; negative = lag), NaN if there are none.
    range_rms_m, cross_range_rms_m
        (K_sel,) RMS of the error along and across the line of sight, all confirmed frames.
    n_transient, manoeuvre_window, manoeuvre_accel_mps2
        The settings used.
    """

    trajectories: np.ndarray
    classes: np.ndarray
    n_frames: np.ndarray
    n_c: np.ndarray
    first_confirmed_frame: np.ndarray
    loss: np.ndarray
    sse: np.ndarray
    loss_by_category: np.ndarray
    sse_by_category: np.ndarray
    frames_by_category: np.ndarray
    along_track_mean_m: np.ndarray
    range_rms_m: np.ndarray
    cross_range_rms_m: np.ndarray
    n_transient: int
    manoeuvre_window: int
    manoeuvre_accel_mps2: float

    def class_table(self) -> list[dict]:
        """Per class and in total: mean L and its split by category (m²), mean N_c, mean SSE,
        mean first-confirmation frame, mean along-track error; JSON-ready (NaN → None)."""
        rows = []
        names = sorted(set(self.classes.tolist()))
        for name in (*names, "total"):
            sel = np.ones(len(self.classes), bool) if name == "total" else self.classes == name
            conf = sel & (self.n_c > 0)
            at = self.along_track_mean_m[sel]
            rows.append(
                {
                    "class": name.upper() if name != "total" else name,
                    "n_trajectories": int(sel.sum()),
                    "loss": _num(np.mean(self.loss[sel])),
                    **{
                        f"loss_{c}": _num(np.mean(self.loss_by_category[sel, i]))
                        for i, c in enumerate(CATEGORIES)
                    },
                    **{
                        f"frames_{c}": _num(np.mean(self.frames_by_category[sel, i]))
                        for i, c in enumerate(CATEGORIES)
                    },
                    "n_c": _num(np.mean(self.n_c[sel])),
                    "sse": _num(np.mean(self.sse[conf])) if conf.any() else None,
                    "first_confirmed_frame": (
                        _num(np.mean(self.first_confirmed_frame[conf])) if conf.any() else None
                    ),
                    "along_track_mean_m": (_num(np.nanmean(at)) if np.isfinite(at).any() else None),
                    "range_rms_m": _num(_rms_of_rms(self.range_rms_m[conf], self.n_c[conf])),
                    "cross_range_rms_m": _num(
                        _rms_of_rms(self.cross_range_rms_m[conf], self.n_c[conf])
                    ),
                }
            )
        return rows


def _num(v) -> float | None:
    v = float(v)
    return v if math.isfinite(v) else None


def _rms_of_rms(rms: np.ndarray, n: np.ndarray) -> float:
    # pooled RMS over trajectories, weighted by their frame counts
    if len(rms) == 0 or n.sum() == 0:
        return math.nan
    return float(np.sqrt(np.sum(rms**2 * n) / np.sum(n)))


def track_with_ids(dataset: Dataset, params) -> tuple:
    """Track every trajectory of a data set; also return the id of the estimate's track.

    Returns
    -------
    estimates, ids
        :class:`core.tracking.DatasetEstimates` (as :func:`core.tracking.track_dataset`) and
        (F,) int64 id of the track giving the estimate in each frame (−1: no estimate; ids
        count per trajectory from 0 in order of birth).
    """
    from core.tracking import estimate_track_ids, track_dataset

    return track_dataset(dataset, params), estimate_track_ids(dataset, params)


def _manoeuvring(truth_v: np.ndarray, period_s: float, accel: float, window: int) -> np.ndarray:
    """(N,) True where |a| > accel in this frame or one of the previous ``window − 1`` frames.

    Eq. (6): v(t) = v(t−1) + a(t−1)·Δt, so a(t−1) = (v(t) − v(t−1))/Δt acts on frame t.
    """
    n = len(truth_v)
    a = np.zeros(n)
    if n > 1:
        a[1:] = np.linalg.norm(np.diff(truth_v, axis=0), axis=1) / period_s
    hot = a > accel
    out = np.zeros(n, dtype=bool)
    for lag in range(max(1, window)):
        out[lag:] |= hot[: n - lag]
    return out


def loss_breakdown(
    dataset: Dataset,
    estimates,
    *,
    estimate_ids: np.ndarray | None = None,
    n_transient: int = 10,
    manoeuvre_window: int = 10,
    manoeuvre_accel_mps2: float = 0.05,
    period_s: float = 0.08,
) -> LossBreakdown:
    """Split every trajectory's loss by kind of frame (see the module docstring).

    Parameters
    ----------
    dataset
        The tracked data set (truth: person 0; frames in which it is absent are not scored,
        as in :func:`core.evaluation.trajectory_loss`).
    estimates
        :class:`core.tracking.DatasetEstimates` of that data set.
    estimate_ids
        Optional (F_sel,) id of the track that gives the estimate in each frame (−1: none);
        with it, a change of estimate track also starts a transient. Without it, only the
        first confirmation of a trajectory and a return after frames without an estimate do.
    n_transient
        Frames counted as transient after the estimate (re)appears.
    manoeuvre_window, manoeuvre_accel_mps2
        A frame is a manoeuvre frame when the true acceleration exceeded
        ``manoeuvre_accel_mps2`` (m/s²) in it or in the ``manoeuvre_window − 1`` frames before.
    period_s
        Frame period Δt (s), for the acceleration from the true velocities.

    Returns
    -------
    LossBreakdown
    """
    # person 0, NaN where absent; like the loss, only frames in which it is present are scored
    truth = tracked_person_xy(dataset.truth_xy_m[estimates.frame_index])  # (F_sel, 2) m
    truth_v = tracked_person_xy(dataset.truth_v_mps[estimates.frame_index])  # (F_sel, 2) m/s
    present = np.all(np.isfinite(truth), axis=1)
    off = estimates.offsets
    k_sel = len(estimates.trajectories)
    out = _breakdown_arrays(k_sel)
    for i in range(k_sel):
        s = slice(off[i], off[i + 1])
        has = np.asarray(estimates.has_estimate[s], dtype=bool) & present[s]
        n = len(has)
        out["n_frames"][i] = n
        n_c = int(has.sum())
        out["n_c"][i] = n_c
        if n_c == 0:
            out["loss"][i] = NO_CONFIRMATION_LOSS  # SPEC §5: never confirmed scores 1 m²
            continue
        out["first"][i] = int(np.argmax(has))
        e = estimates.estimate_xy[s] - truth[s]  # (N, 2) m
        e2 = np.where(has, np.sum(np.where(has[:, None], e, 0.0) ** 2, axis=1), 0.0)
        transient, manoeuvre, steady = _frame_kinds(
            has,
            None if estimate_ids is None else np.asarray(estimate_ids[s]),
            truth_v[s],
            n_transient=n_transient,
            manoeuvre_window=manoeuvre_window,
            manoeuvre_accel_mps2=manoeuvre_accel_mps2,
            period_s=period_s,
        )
        sse = float(e2.sum())
        out["sse"][i] = sse
        # L(k) = SSE(k)/N_c(k)²  (12)–(13): additive over frames
        out["loss"][i] = sse / n_c**2
        for c, mask in enumerate((transient, manoeuvre, steady)):
            out["sse_cat"][i, c] = float(e2[mask].sum())
            out["loss_cat"][i, c] = out["sse_cat"][i, c] / n_c**2
            out["frames_cat"][i, c] = int(mask.sum())
        along, range_rms, cross_rms = _error_geometry(e, has, transient, truth[s], truth_v[s])
        if along is not None:
            out["along"][i] = along
        out["range_rms"][i] = range_rms
        out["cross_rms"][i] = cross_rms
    return LossBreakdown(
        trajectories=np.asarray(estimates.trajectories),
        classes=dataset.trajectory_class[estimates.trajectories].astype(str),
        n_frames=out["n_frames"],
        n_c=out["n_c"],
        first_confirmed_frame=out["first"],
        loss=out["loss"],
        sse=out["sse"],
        loss_by_category=out["loss_cat"],
        sse_by_category=out["sse_cat"],
        frames_by_category=out["frames_cat"],
        along_track_mean_m=out["along"],
        range_rms_m=out["range_rms"],
        cross_range_rms_m=out["cross_rms"],
        n_transient=int(n_transient),
        manoeuvre_window=int(manoeuvre_window),
        manoeuvre_accel_mps2=float(manoeuvre_accel_mps2),
    )


def _breakdown_arrays(k_sel: int) -> dict[str, np.ndarray]:
    """The per-trajectory arrays :func:`loss_breakdown` fills (never-confirmed defaults)."""
    n_cat = len(CATEGORIES)
    out = {
        "n_frames": np.zeros(k_sel, np.int64),
        "n_c": np.zeros(k_sel, np.int64),
        "first": np.full(k_sel, -1, np.int64),
        "loss": np.zeros(k_sel),
        "sse": np.zeros(k_sel),
        "loss_cat": np.zeros((k_sel, n_cat)),
        "sse_cat": np.zeros((k_sel, n_cat)),
        "frames_cat": np.zeros((k_sel, n_cat), np.int64),
        "along": np.full(k_sel, math.nan),
        "range_rms": np.full(k_sel, math.nan),
        "cross_rms": np.full(k_sel, math.nan),
    }
    return out


def _frame_kinds(
    has: np.ndarray,
    ids: np.ndarray | None,
    truth_v: np.ndarray,
    *,
    n_transient: int,
    manoeuvre_window: int,
    manoeuvre_accel_mps2: float,
    period_s: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One trajectory's scored frames (``has``) split into transient, manoeuvre and steady
    frames (see :func:`loss_breakdown`); ``ids``: the estimate's track per frame, or None."""
    n = len(has)
    # frames since the estimate (re)appeared or changed track
    start = has & ~np.concatenate(([False], has[:-1]))
    if ids is not None:
        start |= has & np.concatenate(([False], ids[1:] != ids[:-1]))
    age = np.zeros(n, np.int64)
    for f in range(n):
        age[f] = 0 if start[f] or not has[f] or f == 0 else age[f - 1] + 1
    transient = has & (age < n_transient)
    manoeuvre = (
        has & ~transient & _manoeuvring(truth_v, period_s, manoeuvre_accel_mps2, manoeuvre_window)
    )
    steady = has & ~transient & ~manoeuvre
    return transient, manoeuvre, steady


def _error_geometry(
    e: np.ndarray, has: np.ndarray, transient: np.ndarray, truth: np.ndarray, truth_v: np.ndarray
) -> tuple[float | None, float, float]:
    """Mean along-track error (None when the person never moves outside transients), and the
    RMS range and cross-range errors of one trajectory's scored frames, m."""
    along = None
    # along-track error: e · v̂ (v̂ the true heading), moving, non-transient frames
    speed = np.linalg.norm(truth_v, axis=1)
    moving = has & ~transient & (speed > 0.1)
    if moving.any():
        v_hat = truth_v[moving] / speed[moving, None]
        along = float(np.mean(np.sum(e[moving] * v_hat, axis=1)))
    # range / cross-range: along and across the line of sight to the true position
    u = truth[has] / np.linalg.norm(truth[has], axis=1, keepdims=True)
    eh = e[has]
    range_rms = float(np.sqrt(np.mean(np.sum(eh * u, axis=1) ** 2)))
    cross_rms = float(np.sqrt(np.mean((eh[:, 0] * u[:, 1] - eh[:, 1] * u[:, 0]) ** 2)))
    return along, range_rms, cross_rms


@dataclass(frozen=True, slots=True, kw_only=True)
class PairedComparison:
    """Run a against run b over the same K trajectories (losses in m²).

    Attributes
    ----------
    ratio
        ``L_t(a)/L_t(b)`` (eq. 14: the ratio of the mean losses).
    ci_low, ci_high
        Percentile bootstrap interval of the ratio at ``confidence`` (trajectories resampled
        with replacement within each class, the same draw for a and b: paired, stratified).
    p_ratio_above
        Fraction of bootstrap ratios above ``threshold`` (e.g. 1.05: "a worse than b by more
        than 5 %").
    log_ratio_median
        Median over trajectories of ``ln(L_a(k)/L_b(k))``.
    wins_a, wins_b
        Trajectories with ``L_a(k) < L_b(k)`` and with ``L_b(k) < L_a(k)``.
    wilcoxon_p
        Two-sided Wilcoxon signed-rank p-value of ``ln L_a(k) − ln L_b(k)`` (NaN if all equal).
    """

    ratio: float
    ci_low: float
    ci_high: float
    confidence: float
    threshold: float
    p_ratio_above: float
    log_ratio_median: float
    wins_a: int
    wins_b: int
    n_trajectories: int
    wilcoxon_p: float
    n_boot: int

    def to_dict(self) -> dict:
        return {k: (_num(v) if isinstance(v, float) else v) for k, v in _items(self)}


def _items(obj) -> list[tuple[str, object]]:
    return [(k, getattr(obj, k)) for k in obj.__slots__]


def paired_comparison(
    loss_a: np.ndarray,
    loss_b: np.ndarray,
    classes: np.ndarray | None = None,
    *,
    n_boot: int = 10000,
    confidence: float = 0.95,
    threshold: float = 1.05,
    seed: int = 0,
) -> PairedComparison:
    """Paired comparison of two runs' per-trajectory losses (see :class:`PairedComparison`).

    Parameters
    ----------
    loss_a, loss_b
        (K,) ``L(k)`` of the two runs on the same trajectories, m², all > 0.
    classes
        (K,) class labels for the stratified bootstrap (default: one stratum).
    n_boot, confidence, threshold, seed
        Bootstrap draws, interval level, ratio threshold for ``p_ratio_above``, generator seed.
    """
    from scipy.stats import wilcoxon

    a = np.asarray(loss_a, dtype=np.float64)
    b = np.asarray(loss_b, dtype=np.float64)
    if a.shape != b.shape or a.ndim != 1 or len(a) == 0:
        raise ValueError(f"loss_a and loss_b must be equal-length 1-D, got {a.shape}, {b.shape}")
    if np.any(a <= 0) or np.any(b <= 0):
        raise ValueError("losses must be positive")
    cls = np.zeros(len(a), np.int64) if classes is None else np.asarray(classes)
    rng = np.random.default_rng(seed)
    # paired stratified bootstrap: the same resampled trajectories for a and b
    idx = np.concatenate(
        [
            rng.choice(np.flatnonzero(cls == c), size=(n_boot, int(np.sum(cls == c))))
            for c in np.unique(cls)
        ],
        axis=1,
    )
    ratios = a[idx].mean(axis=1) / b[idx].mean(axis=1)
    alpha = 1.0 - confidence
    lo, hi = np.quantile(ratios, [alpha / 2, 1.0 - alpha / 2])
    d = np.log(a) - np.log(b)
    p = float(wilcoxon(d).pvalue) if np.any(d != 0) else math.nan
    return PairedComparison(
        # L_t(a)/L_t(b), L_t = mean_k L(k)   (14)
        ratio=float(a.mean() / b.mean()),
        ci_low=float(lo),
        ci_high=float(hi),
        confidence=float(confidence),
        threshold=float(threshold),
        p_ratio_above=float(np.mean(ratios > threshold)),
        log_ratio_median=float(np.median(d)),
        wins_a=int(np.sum(a < b)),
        wins_b=int(np.sum(b < a)),
        n_trajectories=len(a),
        wilcoxon_p=p,
        n_boot=int(n_boot),
    )

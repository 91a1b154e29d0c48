"""Evaluation of tracker output (SPEC §5): the paper's loss and the usual tracking metrics.

Per trajectory k (eqs. 12–13): N_c(k) = frames with a confirmed track (a single-person
estimate), ``MSE(k) = (1/N_c) Σ |x̂ − x_gt|²`` over those frames, ``L(k) = MSE(k)/N_c(k)``;
a trajectory with N_c = 0 scores L = 1.0 m² (the paper is silent). Total (eq. 14):
``L_t = mean_k L(k)``. Table I lists the per-class means ×10⁻³.

Besides: position RMSE, fraction of frames confirmed, time to first confirmation, frames with a
confirmed track farther than 1 m from the person, OSPA (c = 1 m, p = 2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import linear_sum_assignment

from core.dataset import Dataset

__all__ = [
    "NO_CONFIRMATION_LOSS",
    "CLASSES",
    "trajectory_loss",
    "ospa",
    "trajectory_losses",
    "ClassRow",
    "Evaluation",
    "evaluate",
    "PointSpread",
    "person_point_spread",
]

#: L(k) of a trajectory without any confirmed frame (m²).
NO_CONFIRMATION_LOSS = 1.0
#: Trajectory classes of the paper's Table I.
CLASSES = ("a", "b", "c", "d", "e")
#: Distance (m) beyond which a confirmed track counts as far from the person.
FAR_DISTANCE_M = 1.0
OSPA_C_M = 1.0
OSPA_P = 2


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


def ospa(tracks_xy: np.ndarray, truth_xy: np.ndarray, c: float = OSPA_C_M, p: int = OSPA_P):
    """OSPA distance (Schuhmacher et al. 2008) between two finite sets of 2-D points (m).

    ``d = ((1/n) (min_π Σ min(d_i,π(i), c)^p + c^p (n − m)))^{1/p}``, n ≥ m the larger set
    size; 0 when both sets are empty. tracks_xy (m, 2), truth_xy (n, 2).
    """
    a = np.asarray(tracks_xy, dtype=np.float64).reshape(-1, 2)
    b = np.asarray(truth_xy, dtype=np.float64).reshape(-1, 2)
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


def _truth(dataset: Dataset, frame_index: np.ndarray) -> np.ndarray:
    return dataset.truth_xy_m[frame_index]  # (F_sel, n_persons, 2)


def trajectory_losses(dataset: Dataset, estimates) -> np.ndarray:
    """L(k) of every tracked trajectory, in the order tracked, shape (K_sel,) in m².

    The cheap path for the optimiser (person 0 is the tracked person).
    """
    truth = _truth(dataset, estimates.frame_index)[:, 0, :]
    off = estimates.offsets
    out = np.empty(len(estimates.trajectories))
    for i in range(len(out)):
        s = slice(off[i], off[i + 1])
        out[i] = trajectory_loss(estimates.estimate_xy[s], estimates.has_estimate[s], truth[s])[0]
    return out


@dataclass(frozen=True, slots=True, kw_only=True)
class ClassRow:
    """One row of the loss table (a trajectory class or the total).

    ``loss`` is the mean L(k) in m² (the table shows it ×10⁻³), ``mse`` the mean MSE(k) over
    trajectories with N_c > 0 (m²), ``n_c`` the mean N_c(k), ``n_trajectories`` the count and
    ``n_unconfirmed`` how many never confirmed (scored L = 1.0).
    """

    name: str
    loss: float
    mse: float
    n_c: float
    n_trajectories: int
    n_unconfirmed: int


@dataclass(frozen=True, slots=True, kw_only=True)
class Evaluation:
    """Metrics of one tracker run over a data set.

    Per trajectory (K_sel,): ``loss``, ``mse``, ``n_c``, ``n_frames``, ``classes``,
    ``first_confirmation_s`` (NaN when never confirmed), ``far_frames``, ``ospa_mean``.
    Totals: ``loss_total`` (L_t, eq. 14, m²), ``rmse_m`` (position RMSE over all frames with an
    estimate), ``confirmed_fraction``, ``mean_first_confirmation_s`` (over trajectories that
    confirm), ``far_frames`` (frames with a confirmed track farther than 1 m from every person)
    and ``far_fraction``, ``ospa_mean_m`` (OSPA c = 1 m, p = 2, mean over frames, all confirmed
    tracks against all persons).
    """

    trajectories: np.ndarray
    classes: np.ndarray
    loss: np.ndarray
    mse: np.ndarray
    n_c: np.ndarray
    n_frames: np.ndarray
    first_confirmation_s: np.ndarray
    far_frames: np.ndarray
    ospa_mean: np.ndarray
    loss_total: float
    rmse_m: float
    confirmed_fraction: float
    mean_first_confirmation_s: float
    far_frames_total: int
    far_fraction: float
    ospa_mean_m: float
    table: tuple[ClassRow, ...] = field(default=())

    def format_table(self) -> str:
        """The paper's Table I layout (×10⁻³) with MSE and N_c beside L, and the other metrics."""
        head = ("class", "L x1e-3", "MSE m2", "mean N_c", "traj", "no conf")
        lines = [" ".join(f"{h:>{w}}" for h, w in zip(head, (6, 10, 10, 9, 5, 8)))]
        for r in self.table:
            mse = f"{r.mse:10.5f}" if math.isfinite(r.mse) else f"{'-':>10}"
            lines.append(
                f"{r.name:>6} {r.loss * 1e3:10.4f} {mse} {r.n_c:9.1f} {r.n_trajectories:5d} "
                f"{r.n_unconfirmed:8d}"
            )
        fc = self.mean_first_confirmation_s
        lines += [
            f"position RMSE        {self.rmse_m:.4f} m",
            f"frames confirmed     {100 * self.confirmed_fraction:.1f} %",
            "first confirmation   " + (f"{fc:.3f} s (mean)" if math.isfinite(fc) else "never"),
            f"far frames (> 1 m)   {self.far_frames_total} ({100 * self.far_fraction:.2f} %)",
            f"OSPA (c=1 m, p=2)    {self.ospa_mean_m:.4f} m",
        ]
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """JSON-ready dict (NaN → None)."""

        def num(v: float) -> float | None:
            return float(v) if math.isfinite(v) else None

        return {
            "loss_total": num(self.loss_total),
            "loss_total_x1e3": num(self.loss_total * 1e3),
            "rmse_m": num(self.rmse_m),
            "confirmed_fraction": num(self.confirmed_fraction),
            "mean_first_confirmation_s": num(self.mean_first_confirmation_s),
            "far_frames": int(self.far_frames_total),
            "far_fraction": num(self.far_fraction),
            "ospa_mean_m": num(self.ospa_mean_m),
            "table": [
                {
                    "class": r.name,
                    "loss": num(r.loss),
                    "loss_x1e3": num(r.loss * 1e3),
                    "mse": num(r.mse),
                    "n_c": num(r.n_c),
                    "n_trajectories": r.n_trajectories,
                    "n_unconfirmed": r.n_unconfirmed,
                }
                for r in self.table
            ],
            "trajectories": [
                {
                    "index": int(k),
                    "class": str(c),
                    "loss": num(lo),
                    "mse": num(ms),
                    "n_c": int(nc),
                    "n_frames": int(nf),
                    "first_confirmation_s": num(fc),
                    "far_frames": int(ff),
                    "ospa_mean_m": num(om),
                }
                for k, c, lo, ms, nc, nf, fc, ff, om in zip(
                    self.trajectories,
                    self.classes,
                    self.loss,
                    self.mse,
                    self.n_c,
                    self.n_frames,
                    self.first_confirmation_s,
                    self.far_frames,
                    self.ospa_mean,
                )
            ],
        }


def _row(name: str, loss, mse, n_c) -> ClassRow:
    ok = n_c > 0
    return ClassRow(
        name=name,
        loss=float(np.mean(loss)) if len(loss) else math.nan,
        mse=float(np.mean(mse[ok])) if ok.any() else math.nan,
        n_c=float(np.mean(n_c)) if len(n_c) else math.nan,
        n_trajectories=len(loss),
        n_unconfirmed=int(np.sum(~ok)),
    )


def evaluate(dataset: Dataset, estimates) -> Evaluation:
    """Loss table and metrics of :class:`core.tracking.DatasetEstimates` against the truth.

    The single-person estimate is scored against person 0; far frames and OSPA use all
    confirmed tracks and all persons.
    """
    truth_all = _truth(dataset, estimates.frame_index)  # (F_sel, n_persons, 2)
    truth = truth_all[:, 0, :]
    t_s = dataset.truth_t_s[estimates.frame_index]
    off = estimates.offsets
    n_sel = len(estimates.trajectories)
    loss, mse = np.empty(n_sel), np.empty(n_sel)
    n_c, n_frames, far = (np.zeros(n_sel, dtype=np.int64) for _ in range(3))
    first, ospa_m = np.full(n_sel, math.nan), np.empty(n_sel)
    # per frame: distance of every confirmed track to the nearest person; OSPA
    conf = estimates.confirmed_xy  # (F_sel, C, 2), NaN padded
    valid = np.isfinite(conf[..., 0])
    dist = np.linalg.norm(conf[:, :, None, :] - truth_all[:, None, :, :], axis=3).min(axis=2)
    far_frame = np.any(valid & (dist > FAR_DISTANCE_M), axis=1)
    ospa_f = np.array(
        [ospa(conf[f][valid[f]], truth_all[f]) for f in range(len(conf))], dtype=np.float64
    )
    for i in range(n_sel):
        s = slice(off[i], off[i + 1])
        has = estimates.has_estimate[s]
        loss[i], mse[i], n_c[i] = trajectory_loss(estimates.estimate_xy[s], has, truth[s])
        n_frames[i] = off[i + 1] - off[i]
        if has.any():
            first[i] = t_s[s][np.argmax(has)] - t_s[s][0]
        far[i] = int(far_frame[s].sum())
        ospa_m[i] = float(ospa_f[s].mean()) if n_frames[i] else math.nan
    classes = dataset.trajectory_class[estimates.trajectories].astype(str)
    table = [
        _row(cl.upper(), loss[classes == cl], mse[classes == cl], n_c[classes == cl])
        for cl in (*CLASSES, *sorted(set(classes) - set(CLASSES)))
        if np.any(classes == cl)
    ]
    table.append(_row("total", loss, mse, n_c))
    has = estimates.has_estimate
    e = estimates.estimate_xy[has] - truth[has]
    total_frames = int(n_frames.sum())
    return Evaluation(
        trajectories=estimates.trajectories,
        classes=classes,
        loss=loss,
        mse=mse,
        n_c=n_c,
        n_frames=n_frames,
        first_confirmation_s=first,
        far_frames=far,
        ospa_mean=ospa_m,
        # L_t = (1/N_t) Σ L(k)   (14)
        loss_total=float(loss.mean()) if n_sel else math.nan,
        rmse_m=float(np.sqrt(np.mean(np.sum(e * e, axis=1)))) if has.any() else math.nan,
        confirmed_fraction=float(has.mean()) if total_frames else math.nan,
        mean_first_confirmation_s=(
            float(np.nanmean(first)) if np.isfinite(first).any() else math.nan
        ),
        far_frames_total=int(far.sum()),
        far_fraction=float(far.sum() / total_frames) if total_frames else math.nan,
        ospa_mean_m=float(ospa_f.mean()) if total_frames else math.nan,
        table=tuple(table),
    )


@dataclass(frozen=True, slots=True, kw_only=True)
class PointSpread:
    """Measurement spread of the person-labelled points of a data set (SI units).

    ``rms_position_m``: RMS of |p − x_gt| (x-y plane) over the points whose ``source`` is a
    person; ``median_position_m``, ``p90_position_m`` its percentiles; ``rms_range_m`` and
    ``rms_cross_range_m`` its components along and across the line of sight;
    ``rms_radial_velocity_mps``: RMS of v_r − v_gt·r̂; ``points_per_frame``: mean number of
    person points per frame with at least one.
    """

    n_points: int
    points_per_frame: float
    rms_position_m: float
    median_position_m: float
    p90_position_m: float
    rms_range_m: float
    rms_cross_range_m: float
    rms_radial_velocity_mps: float

    def to_dict(self) -> dict[str, float]:
        return {k: getattr(self, k) for k in self.__slots__}


def person_point_spread(dataset: Dataset) -> PointSpread:
    """Error of the person-labelled points against the person's true position and velocity.

    Parameters
    ----------
    dataset
        A simulated data set; a point with ``source = i >= 0`` came from person ``i``.

    Returns
    -------
    PointSpread
        Spread over all person points of all frames (m, m/s).
    """
    sel = np.flatnonzero(dataset.source >= 0)
    if sel.size == 0:
        raise ValueError("the data set has no person-labelled points")
    f = dataset.frame[sel]
    person = dataset.source[sel]
    truth = dataset.truth_xy_m[f, person]  # (P, 2) m
    v_truth = dataset.truth_v_mps[f, person]  # (P, 2) m/s
    d = np.stack([dataset.x_m[sel], dataset.y_m[sel]], axis=1) - truth  # (P, 2) m
    # r̂ = x_gt / |x_gt|: line of sight to the true position
    u = truth / np.linalg.norm(truth, axis=1, keepdims=True)
    e_range = np.sum(d * u, axis=1)
    e_cross = d[:, 0] * u[:, 1] - d[:, 1] * u[:, 0]
    # v_r,gt = v_gt · r̂
    e_vr = dataset.radial_velocity_mps[sel] - np.sum(v_truth * u, axis=1)
    e = np.hypot(d[:, 0], d[:, 1])
    _, per_frame = np.unique(f, return_counts=True)
    return PointSpread(
        n_points=int(sel.size),
        points_per_frame=float(per_frame.mean()),
        rms_position_m=float(np.sqrt(np.mean(e**2))),
        median_position_m=float(np.median(e)),
        p90_position_m=float(np.percentile(e, 90)),
        rms_range_m=float(np.sqrt(np.mean(e_range**2))),
        rms_cross_range_m=float(np.sqrt(np.mean(e_cross**2))),
        rms_radial_velocity_mps=float(np.sqrt(np.mean(e_vr**2))),
    )

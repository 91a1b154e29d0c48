"""Evaluation of one tracker run over a data set (SPEC §5): the paper's loss table (Table I) and
the usual tracking metrics.

Besides the loss (:mod:`core.evaluation.loss`): position RMSE, fraction of frames confirmed, time
to first confirmation, frames with a confirmed track farther than 1 m from the person, OSPA
(c = 1 m, p = 2; :mod:`core.evaluation.metrics`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from core.dataset import Dataset
from core.evaluation.loss import CLASSES, tracked_person_xy, trajectory_loss
from core.evaluation.metrics import FAR_DISTANCE_M, ospa

__all__ = ["ClassRow", "Evaluation", "evaluate"]


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
    Totals: ``loss_total`` (L_t, eq. 14, m²), ``rmse_m`` (position RMSE of the estimate over all
    frames with an estimate in which the tracked person is present), ``confirmed_fraction``,
    ``mean_first_confirmation_s`` (over trajectories that confirm), ``far_frames`` (frames with
    a confirmed track farther than 1 m from every person present — with nobody present, every
    confirmed track is far) and ``far_fraction``, ``ospa_mean_m`` (OSPA c = 1 m, p = 2, mean
    over frames, all confirmed tracks against the persons present in the frame).

    Undefined values are NaN here, ``None`` in :meth:`to_dict` and "–" with the reason in
    :meth:`format_table`, never printed as ``nan``: ``mse`` and ``rmse_m`` without a scored
    frame (no track confirmed, or the tracked person absent in every confirmed frame),
    ``first_confirmation_s`` when never confirmed, and the totals of an empty selection.
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
        """The paper's Table I layout (×10⁻³) with MSE and N_c beside L, and the other metrics.

        An undefined value prints as "–" (in the table) or "– (reason)" (below it).
        """
        head = ("class", "L x1e-3", "MSE m2", "mean N_c", "traj", "no conf")
        lines = [" ".join(f"{h:>{w}}" for h, w in zip(head, (6, 10, 10, 9, 5, 8)))]
        for r in self.table:
            lines.append(
                f"{r.name:>6} {_cell(r.loss * 1e3, 10, '.4f')} {_cell(r.mse, 10, '.5f')} "
                f"{_cell(r.n_c, 9, '.1f')} {r.n_trajectories:5d} {r.n_unconfirmed:8d}"
            )
        no_frames = "no frames tracked"
        if not int(np.sum(self.n_frames)):
            no_rmse = no_frames
        elif not np.isfinite(self.first_confirmation_s).any():
            no_rmse = "no track confirmed"
        else:
            no_rmse = "no person present in a confirmed frame"
        fc = self.mean_first_confirmation_s
        lines += [
            f"position RMSE        {_text(self.rmse_m, '.4f', ' m', no_rmse)}",
            f"frames confirmed     {_text(100 * self.confirmed_fraction, '.1f', ' %', no_frames)}",
            "first confirmation   " + (f"{fc:.3f} s (mean)" if math.isfinite(fc) else "never"),
            f"far frames (> 1 m)   {self.far_frames_total} "
            f"({_text(100 * self.far_fraction, '.2f', ' %', no_frames)})",
            f"OSPA (c=1 m, p=2)    {_text(self.ospa_mean_m, '.4f', ' m', no_frames)}",
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


def _cell(value: float, width: int, fmt: str) -> str:
    """A table cell: the value, or "–" when it is undefined (NaN)."""
    return f"{value:{width}{fmt}}" if math.isfinite(value) else f"{'–':>{width}}"


def _text(value: float, fmt: str, unit: str, reason: str) -> str:
    """A value with its unit, or "– (reason)" when it is undefined (NaN)."""
    return f"{value:{fmt}}{unit}" if math.isfinite(value) else f"– ({reason})"


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

    The single-person estimate is scored against person 0 in the frames in which it is present;
    far frames and OSPA use all confirmed tracks and the persons present in each frame (a
    person is absent where its truth is NaN). See :class:`Evaluation` for undefined values.
    """
    truth_all = dataset.truth_xy_m[estimates.frame_index]  # (F_sel, n_persons, 2)
    truth = tracked_person_xy(truth_all)  # (F_sel, 2), NaN where absent
    t_s = dataset.truth_t_s[estimates.frame_index]
    off = estimates.offsets
    n_sel = len(estimates.trajectories)
    loss, mse = np.empty(n_sel), np.empty(n_sel)
    n_c, n_frames, far = (np.zeros(n_sel, dtype=np.int64) for _ in range(3))
    first, ospa_m = np.full(n_sel, math.nan), np.empty(n_sel)
    # per frame: distance of every confirmed track to the nearest person present (∞: nobody)
    conf = estimates.confirmed_xy  # (F_sel, C, 2), NaN padded
    valid = np.isfinite(conf[..., 0])
    present = np.all(np.isfinite(truth_all), axis=2)  # (F_sel, n_persons)
    gap = np.linalg.norm(conf[:, :, None, :] - truth_all[:, None, :, :], axis=3)
    dist = np.where(present[:, None, :], gap, np.inf).min(axis=2, initial=np.inf)
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
    scored = has & np.all(np.isfinite(truth), axis=1)  # an estimate and the person present
    e = estimates.estimate_xy[scored] - truth[scored]
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
        rmse_m=float(np.sqrt(np.mean(np.sum(e * e, axis=1)))) if scored.any() else math.nan,
        confirmed_fraction=float(has.mean()) if total_frames else math.nan,
        mean_first_confirmation_s=(
            float(np.nanmean(first)) if np.isfinite(first).any() else math.nan
        ),
        far_frames_total=int(far.sum()),
        far_fraction=float(far.sum() / total_frames) if total_frames else math.nan,
        ospa_mean_m=float(ospa_f.mean()) if total_frames else math.nan,
        table=tuple(table),
    )

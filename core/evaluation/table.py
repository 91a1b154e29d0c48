"""Evaluation of one tracker run over a data set (SPEC §5): the paper's loss table (Table I) and
the usual tracking metrics.

Besides the loss (:mod:`core.evaluation.loss`, its several-person form with more than one
person): position RMSE, fraction of frames confirmed, time to first confirmation, frames with a
confirmed track farther than 1 m from the person, OSPA (c = 1 m, p = 2;
:mod:`core.evaluation.metrics`), GOSPA (α = 2) with its decomposition, the people-count error
and identity switches, per frame and per person (:mod:`core.evaluation.people`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from core.dataset import Dataset
from core.evaluation.loss import CLASSES, people_trajectory_loss, person_estimates
from core.evaluation.metrics import FAR_DISTANCE_M, ospa
from core.evaluation.people import FrameMetrics, PersonMetrics, frame_metrics, person_metrics

__all__ = ["ClassRow", "Evaluation", "PersonMetrics", "evaluate"]


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

    Several persons (:mod:`core.evaluation.people`): per trajectory ``gospa_mean`` (m),
    ``count_abs_error`` (mean |n_confirmed − n_present|) and ``identity_switches`` (−1: tracked
    without identities); totals ``gospa`` (means over frames: ``gospa_m``, ``localisation``,
    ``missed``, ``false`` in m², ``n_missed``, ``n_false``, ``count_error``,
    ``count_abs_error``, ``count_exact_fraction``), ``identity_switches_total`` (−1: no
    identities); ``persons`` one :class:`PersonMetrics` per person; ``frames`` the per-frame
    :class:`~core.evaluation.people.FrameMetrics` (for plots and the GUI). ``rmse_m`` is over
    every scored person-frame. With one person, every older value is unchanged.

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
    gospa_mean: np.ndarray = field(default_factory=lambda: np.zeros(0))
    count_abs_error: np.ndarray = field(default_factory=lambda: np.zeros(0))
    identity_switches: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    gospa: dict[str, float] = field(default_factory=dict)
    identity_switches_total: int = -1
    persons: tuple[PersonMetrics, ...] = ()
    frames: FrameMetrics | None = field(default=None, repr=False)

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
        g = self.gospa
        if g:
            terms = (
                f"localisation {g['localisation']:.5f}, missed {g['missed']:.5f}, false "
                f"{g['false']:.5f} m2 a frame"
                if math.isfinite(g["gospa_m"])
                else ""
            )
            no_id = "tracked without identities"
            lines += [
                f"GOSPA (c=1 m, p=2)   {_text(g['gospa_m'], '.4f', ' m', no_frames)}"
                + (f"  ({terms})" if terms else ""),
                f"people count error   {_text(g['count_error'], '+.3f', '', no_frames)} mean, "
                f"{_text(g['count_abs_error'], '.3f', '', no_frames)} mean |error|, exact in "
                f"{_text(100 * g['count_exact_fraction'], '.1f', ' %', no_frames)} of frames",
                "identity switches    "
                + (str(self.identity_switches_total) if self.identity_switches_total >= 0 else
                   f"– ({no_id})"),
            ]  # fmt: skip
        if self.persons:
            p_head = ("person", "L x1e-3", "traj", "no conf", "N_c", "RMSE m", "present", "missed",
                    "switches", "ids")  # fmt: skip
            widths = (6, 10, 5, 8, 7, 8, 8, 7, 9, 4)
            lines.append(" ".join(f"{h:>{w}}" for h, w in zip(p_head, widths)))
            for m in self.persons:
                lines.append(
                    f"{m.person:>6} {_cell(m.loss * 1e3, 10, '.4f')} {m.n_trajectories:5d} "
                    f"{m.n_unconfirmed:8d} {m.n_c:7d} {_cell(m.rmse_m, 8, '.4f')} "
                    f"{m.frames_present:8d} {m.frames_missed:7d} "
                    f"{_count(m.identity_switches, 9)} {_count(m.n_track_ids, 4)}"
                )
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
            "gospa": {k: num(v) for k, v in self.gospa.items()},
            "identity_switches": (
                int(self.identity_switches_total) if self.identity_switches_total >= 0 else None
            ),
            "persons": [m.to_dict() for m in self.persons],
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
                    "gospa_mean_m": num(gm),
                    "count_abs_error": num(ce),
                    "identity_switches": int(sw) if sw >= 0 else None,
                }
                for k, c, lo, ms, nc, nf, fc, ff, om, gm, ce, sw in zip(
                    self.trajectories,
                    self.classes,
                    self.loss,
                    self.mse,
                    self.n_c,
                    self.n_frames,
                    self.first_confirmation_s,
                    self.far_frames,
                    self.ospa_mean,
                    _pad(self.gospa_mean, len(self.loss), math.nan),
                    _pad(self.count_abs_error, len(self.loss), math.nan),
                    _pad(self.identity_switches, len(self.loss), -1),
                )
            ],
        }


def _pad(a: np.ndarray, n: int, fill: float) -> np.ndarray:
    """``a`` if it has n entries, else n × ``fill`` (an Evaluation built without these fields)."""
    return a if len(a) == n else np.full(n, fill)


def _count(value: int, width: int) -> str:
    """A count, or "–" when it is unknown (−1)."""
    return f"{value:{width}d}" if value >= 0 else f"{'–':>{width}}"


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

    One person: the single-person estimate is scored against person 0 in the frames in which it
    is present. Several: each person against its estimate (:func:`person_estimates`, which needs
    ``estimates.tracks``: ``track_dataset(..., with_tracks=True)``). Far frames, OSPA and GOSPA
    use all confirmed tracks and the persons present in each frame (a person is absent where its
    truth is NaN); identities need ``estimates.tracks`` (without them, identity switches are
    unknown, −1). See :class:`Evaluation` for undefined values.
    """
    truth_all = dataset.truth_xy_m[estimates.frame_index]  # (F_sel, n_persons, 2)
    n_persons = truth_all.shape[1]
    tracks = estimates.tracks
    if n_persons <= 1:
        # the single-person estimate (the top-ranked confirmed track) against person 0
        est_pp = np.where(
            estimates.has_estimate[:, None, None], estimates.estimate_xy[:, None, :], np.nan
        )[:, :n_persons]
    elif tracks is None:
        raise ValueError(
            "a data set with several persons is scored from every confirmed track: track it "
            "with track_dataset(..., with_tracks=True)"
        )
    else:
        est_pp = person_estimates(tracks.xy, truth_all)  # (F_sel, n_persons, 2)
    t_s = dataset.truth_t_s[estimates.frame_index]
    off = estimates.offsets
    n_sel = len(estimates.trajectories)
    loss, mse = np.empty(n_sel), np.empty(n_sel)
    n_c, n_frames, far = (np.zeros(n_sel, dtype=np.int64) for _ in range(3))
    first, ospa_m = np.full(n_sel, math.nan), np.empty(n_sel)
    p_loss = np.zeros((n_sel, n_persons))
    p_counted = np.zeros((n_sel, n_persons), dtype=bool)
    p_n_c = np.zeros((n_sel, n_persons), dtype=np.int64)
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
    if tracks is not None:
        fm = frame_metrics(truth_all, tracks.xy, tracks.ids, off)
    else:
        fm = frame_metrics(truth_all, conf, None, off)
    gospa_t, count_t = np.full(n_sel, math.nan), np.full(n_sel, math.nan)
    switches = np.full(n_sel, -1, dtype=np.int64)
    for i in range(n_sel):
        s = slice(off[i], off[i + 1])
        has = estimates.has_estimate[s]
        r = people_trajectory_loss(est_pp[s], truth_all[s])
        loss[i], mse[i], n_c[i] = r.loss, r.mse, r.n_c
        p_loss[i], p_counted[i], p_n_c[i] = r.person_loss, r.counted, r.person_n_c
        n_frames[i] = off[i + 1] - off[i]
        if has.any():
            first[i] = t_s[s][np.argmax(has)] - t_s[s][0]
        far[i] = int(far_frame[s].sum())
        ospa_m[i] = float(ospa_f[s].mean()) if n_frames[i] else math.nan
        if n_frames[i]:
            gospa_t[i] = float(fm.gospa_m[s].mean())
            count_t[i] = float(np.abs(fm.count_error[s]).mean())
        if fm.identity is not None:
            switches[i] = int(fm.identity.switch[s].sum())
    classes = dataset.trajectory_class[estimates.trajectories].astype(str)
    table = [
        _row(cl.upper(), loss[classes == cl], mse[classes == cl], n_c[classes == cl])
        for cl in (*CLASSES, *sorted(set(classes) - set(CLASSES)))
        if np.any(classes == cl)
    ]
    table.append(_row("total", loss, mse, n_c))
    has = estimates.has_estimate
    # scored person-frames: an estimate and the person present (frame-major order)
    scored = np.all(np.isfinite(est_pp), axis=2) & present  # (F_sel, n_persons)
    e = est_pp[scored] - truth_all[scored]
    e2 = np.sum(e * e, axis=1)
    sse = np.array([np.sum((est_pp[:, j] - truth_all[:, j])[scored[:, j]] ** 2)
                    for j in range(n_persons)])  # fmt: skip
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
        rmse_m=float(np.sqrt(np.mean(e2))) if scored.any() else math.nan,
        confirmed_fraction=float(has.mean()) if total_frames else math.nan,
        mean_first_confirmation_s=(
            float(np.nanmean(first)) if np.isfinite(first).any() else math.nan
        ),
        far_frames_total=int(far.sum()),
        far_fraction=float(far.sum() / total_frames) if total_frames else math.nan,
        ospa_mean_m=float(ospa_f.mean()) if total_frames else math.nan,
        table=tuple(table),
        gospa_mean=gospa_t,
        count_abs_error=count_t,
        identity_switches=switches,
        gospa=fm.mean(),
        identity_switches_total=int(switches.sum()) if fm.identity is not None else -1,
        persons=person_metrics(fm, p_loss, p_counted, p_n_c, sse, off),
        frames=fm,
    )

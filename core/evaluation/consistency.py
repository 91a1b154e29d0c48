"""Filter consistency: NEES and NIS of a tracker run against their χ² bands.

A filter is consistent when its errors are as large as its covariances say (Bar-Shalom, Li,
Kirubarajan, *Estimation with Applications to Tracking and Navigation*, Wiley 2001, §5.4):

- NEES ε_x = (x̂ − x)ᵀ P⁻¹ (x̂ − x) is χ²-distributed with n = dim x degrees of freedom; here on
  the position (n = 2, the x–y block of P) and on position and velocity (n = 4; the truth of a
  data set has both, ``truth_xy_m`` and ``truth_v_mps``; a CA track's acceleration has no truth
  and is marginalised out by taking the 4 × 4 block of P).
- NIS ε_ν = ν̃ᵀ S⁻¹ ν̃ (n = 3: range, azimuth, radial velocity), as both trackers record it per
  track and frame (:class:`core.tracking.FrameTracks` ``nis``, decision tracker-07): the
  combined PDA innovation ν̃ = Σᵢ βᵢ νᵢ and S = H P⁻ Hᵀ + R. With the association weights βᵢ < 1
  and several gated points averaged, ν̃ is smaller than a single innovation, so a consistent
  PDA filter shows a NIS *below* χ²₃ on average; a NIS above the band is the stronger finding.

Each sample is compared with the two-sided per-sample band [χ²ₙ⁻¹(α/2), χ²ₙ⁻¹(1 − α/2)] (α = 5 %:
a consistent filter has about 95 % of its samples inside); the average ε̄ of N samples with the
band of N·ε̄ ~ χ²_{N n}, divided by N — Bar-Shalom's ANEES/ANIS test. The samples of one track
over time are correlated, not the N independent Monte Carlo runs of the textbook test, so the
average band here is a narrow reference, not an exact test: the per-sample fraction is the
robust figure.

Samples are taken where a person is present and paired with a confirmed track
(:func:`core.evaluation.assignment.assign_identities`, cut-off 1 m); that track's state,
covariance and NIS in the frame are the sample. Frames without such a pairing are counted, not
scored (a track farther than the cut-off is not the person's track).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from core.dataset import Dataset
from core.errors import InputError
from core.evaluation.assignment import IDENTITY_CUTOFF_M, assign_identities
from core.evaluation.loss import CLASSES

if TYPE_CHECKING:
    from core.tracking.params import TrackerParams

__all__ = [
    "BAND_PROBABILITY",
    "STATISTICS",
    "ConsistencyStat",
    "ConsistencySamples",
    "ConsistencyReport",
    "chi2_band",
    "average_band",
    "nees",
    "consistency_stat",
    "consistency_samples",
    "consistency_report",
    "dataset_consistency",
    "plot_consistency",
    "measurement_spread",
]

#: Probability of the two-sided χ² bands (95 %).
BAND_PROBABILITY = 0.95

#: The statistics and their degrees of freedom n.
STATISTICS: dict[str, int] = {"nees_position": 2, "nees_state": 4, "nis": 3}

#: Labels of the statistics in tables and plots.
LABELS = {
    "nees_position": "NEES position (2 dof)",
    "nees_state": "NEES position+velocity (4 dof)",
    "nis": "NIS (3 dof)",
}


def _chi2_ppf(q: float | np.ndarray, dof: float) -> np.ndarray:
    # scipy.stats is imported here only: it costs about a second of start-up
    from scipy.stats import chi2

    return np.asarray(chi2.ppf(q, dof), dtype=np.float64)


def chi2_band(dof: int, probability: float = BAND_PROBABILITY) -> tuple[float, float]:
    """Two-sided per-sample band of a χ²ₙ variable.

    Parameters
    ----------
    dof
        Degrees of freedom n ≥ 1.
    probability
        Probability 1 − α inside the band, in (0, 1).

    Returns
    -------
    (low, high)
        χ²ₙ⁻¹(α/2) and χ²ₙ⁻¹(1 − α/2).
    """
    if not 0.0 < probability < 1.0:
        raise ValueError(f"probability must be in (0, 1), got {probability=}")
    a = 1.0 - probability
    lo, hi = _chi2_ppf(np.array([a / 2.0, 1.0 - a / 2.0]), dof)
    return float(lo), float(hi)


def average_band(dof: int, n: int, probability: float = BAND_PROBABILITY) -> tuple[float, float]:
    """Two-sided band of the average ε̄ of ``n`` independent χ²_dof samples (ANEES/ANIS test).

    N ε̄ ~ χ²_{N·dof}, so the band is [χ²_{N·dof}⁻¹(α/2) / N, χ²_{N·dof}⁻¹(1 − α/2) / N];
    (NaN, NaN) for N = 0.
    """
    if n <= 0:
        return math.nan, math.nan
    a = 1.0 - probability
    lo, hi = _chi2_ppf(np.array([a / 2.0, 1.0 - a / 2.0]), n * dof)
    return float(lo) / n, float(hi) / n


def nees(error: np.ndarray, covariance: np.ndarray) -> np.ndarray:
    """Normalised estimation error squared of N samples.

    Parameters
    ----------
    error
        (N, n) errors x̂ − x, in the state's SI units.
    covariance
        (N, n, n) their covariances P (symmetric positive definite).

    Returns
    -------
    numpy.ndarray
        (N,) ε = eᵀ P⁻¹ e (unitless).
    """
    e = np.asarray(error, dtype=np.float64)
    P = np.asarray(covariance, dtype=np.float64)
    if e.shape[0] == 0:
        return np.zeros(0)
    # ε = eᵀ P⁻¹ e, with P⁻¹ e from a solve (no explicit inverse)
    w = np.linalg.solve(P, e[..., None])[..., 0]
    return np.einsum("ni,ni->n", e, w)


@dataclass(frozen=True, slots=True, kw_only=True)
class ConsistencyStat:
    """One statistic (NEES or NIS) over N samples against its χ² bands.

    Attributes
    ----------
    dof
        Degrees of freedom n.
    n
        Samples N.
    mean, median
        Mean ε̄ (the time-averaged NEES/NIS) and median; NaN for N = 0. A consistent filter has
        mean n and median χ²ₙ⁻¹(0.5).
    inside, below, above
        Fractions of the samples inside, below and above the per-sample band (NaN for N = 0).
    band
        Per-sample band (low, high).
    mean_band
        Band of the average of N samples (ANEES/ANIS test), (NaN, NaN) for N = 0.
    """

    dof: int
    n: int
    mean: float
    median: float
    inside: float
    below: float
    above: float
    band: tuple[float, float]
    mean_band: tuple[float, float]

    @property
    def mean_ratio(self) -> float:
        """ε̄ / n: 1 for a consistent filter, > 1 optimistic (covariance too small)."""
        return self.mean / self.dof

    @property
    def verdict(self) -> str:
        """``"within"``, ``"above"`` (optimistic) or ``"below"`` (pessimistic) the average band,
        ``"undefined"`` without samples."""
        if self.n == 0:
            return "undefined"
        if self.mean > self.mean_band[1]:
            return "above"
        if self.mean < self.mean_band[0]:
            return "below"
        return "within"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (NaN as None)."""

        def num(v: float) -> float | None:
            return None if not math.isfinite(v) else float(v)

        return {
            "dof": self.dof,
            "n": self.n,
            "mean": num(self.mean),
            "median": num(self.median),
            "inside": num(self.inside),
            "below": num(self.below),
            "above": num(self.above),
            "band": [num(self.band[0]), num(self.band[1])],
            "mean_band": [num(self.mean_band[0]), num(self.mean_band[1])],
            "verdict": self.verdict,
        }


def consistency_stat(
    values: np.ndarray, dof: int, probability: float = BAND_PROBABILITY
) -> ConsistencyStat:
    """Mean, median and band fractions of NEES or NIS samples (NaN samples are dropped).

    Parameters
    ----------
    values
        (N,) samples ε.
    dof
        Degrees of freedom n of their χ² distribution.
    probability
        Probability of the bands.
    """
    v = np.asarray(values, dtype=np.float64).reshape(-1)
    v = v[np.isfinite(v)]
    n = int(v.size)
    lo, hi = chi2_band(dof, probability)
    if n == 0:
        nan = math.nan
        return ConsistencyStat(
            dof=dof, n=0, mean=nan, median=nan, inside=nan, below=nan, above=nan,
            band=(lo, hi), mean_band=(nan, nan),
        )  # fmt: skip
    return ConsistencyStat(
        dof=dof,
        n=n,
        mean=float(np.mean(v)),
        median=float(np.median(v)),
        inside=float(np.mean((v >= lo) & (v <= hi))),
        below=float(np.mean(v < lo)),
        above=float(np.mean(v > hi)),
        band=(lo, hi),
        mean_band=average_band(dof, n, probability),
    )


@dataclass(frozen=True, slots=True, kw_only=True)
class ConsistencySamples:
    """NEES and NIS of the confirmed track paired with each person, per frame (F frames, P persons).

    Attributes
    ----------
    trajectory
        (F,) index of the data set's trajectory of every frame.
    present
        (F, P) bool, the person is present.
    paired
        (F, P) bool, the person is paired with a confirmed track (a sample exists).
    nees_position, nees_state, nis
        (F, P) ε of that track: NEES on x–y (2 dof), on x, y, vx, vy (4 dof), and its recorded
        NIS (3 dof; NaN when no measurement was gated); NaN where not paired.
    """

    trajectory: np.ndarray
    present: np.ndarray
    paired: np.ndarray
    nees_position: np.ndarray
    nees_state: np.ndarray
    nis: np.ndarray


def consistency_samples(
    dataset: Dataset,
    params: TrackerParams,
    *,
    cutoff_m: float = IDENTITY_CUTOFF_M,
) -> ConsistencySamples:
    """Track every trajectory of a data set (compiled kernel, every track recorded) and compute
    the NEES and NIS of the confirmed track paired with each person in every frame.

    Parameters
    ----------
    dataset
        Point clouds and truth (``truth_xy_m``, ``truth_v_mps``).
    params
        :class:`core.tracking.TrackerParams`.
    cutoff_m
        Cut-off of the track-to-person pairing (m).
    """
    from core.tracking.batch import ConfirmedTracks, dataset_frame_period_s
    from core.tracking.kernel import track_frames

    period = dataset_frame_period_s(dataset)
    t_off = dataset.trajectory_offsets
    sel = np.arange(dataset.n_trajectories, dtype=np.int64)
    z = dataset.measurements()
    if not np.all(np.isfinite(z)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(z), axis=1))[0])
        raise InputError(f"measurement of point {bad} (frame {dataset.frame[bad]}) is not finite")
    rec = track_frames(z, dataset.frame_offsets, t_off, sel, params, period, record=True)[-1]
    n_f, cap = rec.ids.shape
    live = np.arange(cap)[None, :] < rec.n_tracks[:, None]  # (F, S) slots holding a track
    confirmed = rec.confirmed & live
    tracks = ConfirmedTracks.from_slots(rec.ids, rec.state[..., :2], rec.psi, confirmed)
    truth_xy = np.asarray(dataset.truth_xy_m, dtype=np.float64)
    truth_v = np.asarray(dataset.truth_v_mps, dtype=np.float64)
    pairing = assign_identities(tracks.ids, tracks.xy, truth_xy, t_off, cutoff_m=cutoff_m)
    tid = pairing.track_id  # (F, P)
    # the slot of each person's paired track: same id among the frame's confirmed slots
    match = (rec.ids[:, None, :] == tid[:, :, None]) & confirmed[:, None, :] & (tid >= 0)[..., None]
    paired = match.any(axis=2)
    slot = np.argmax(match, axis=2)
    f_idx, p_idx = np.nonzero(paired)
    s_idx = slot[f_idx, p_idx]
    x = rec.state[f_idx, s_idx]  # (M, d)
    P = rec.covariance[f_idx, s_idx]  # (M, d, d)
    e_state = np.concatenate(
        (x[:, :2] - truth_xy[f_idx, p_idx], x[:, 2:4] - truth_v[f_idx, p_idx]), axis=1
    )
    shape = paired.shape
    nees_pos = np.full(shape, np.nan)
    nees_st = np.full(shape, np.nan)
    nis = np.full(shape, np.nan)
    nees_pos[f_idx, p_idx] = nees(e_state[:, :2], P[:, :2, :2])
    nees_st[f_idx, p_idx] = nees(e_state, P[:, :4, :4])
    nis[f_idx, p_idx] = rec.nis[f_idx, s_idx]
    trajectory = np.repeat(sel, np.diff(t_off))
    return ConsistencySamples(
        trajectory=trajectory,
        present=pairing.present,
        paired=paired,
        nees_position=nees_pos,
        nees_state=nees_st,
        nis=nis,
    )


@dataclass(frozen=True, slots=True, kw_only=True)
class ConsistencyReport:
    """NEES and NIS per trajectory class and in total.

    Attributes
    ----------
    rows
        Row name (the classes present, then ``"total"``) → statistic name (:data:`STATISTICS`)
        → :class:`ConsistencyStat`.
    frames_present, frames_paired
        Row name → person-frames with the person present, and paired with a confirmed track.
    probability
        Probability of the bands.
    label
        What was tracked (free text for tables and plots).
    """

    rows: Mapping[str, Mapping[str, ConsistencyStat]]
    frames_present: Mapping[str, int]
    frames_paired: Mapping[str, int]
    probability: float = BAND_PROBABILITY
    label: str = ""
    extra: Mapping[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return {
            "label": self.label,
            "probability": self.probability,
            **dict(self.extra),
            "rows": {
                row: {
                    "frames_present": self.frames_present[row],
                    "frames_paired": self.frames_paired[row],
                    **{k: s.to_dict() for k, s in stats.items()},
                }
                for row, stats in self.rows.items()
            },
        }

    def format_table(self) -> str:
        """Per row: paired frames, and per statistic mean ε̄ [its band], inside % of the per-sample
        band, and the verdict of the average."""
        head = f"{'class':>5} {'paired':>11}"
        for name, dof in STATISTICS.items():
            lo, hi = chi2_band(dof, self.probability)
            head += f" | {name} (n={dof}) mean, in [{lo:.2f}, {hi:.2f}]"
        lines = [head]
        for row, stats in self.rows.items():
            line = f"{row:>5} {self.frames_paired[row]:5d}/{self.frames_present[row]:5d}"
            for name in STATISTICS:
                s = stats[name]
                if s.n == 0:
                    line += " | –"
                    continue
                line += (
                    f" | {s.mean:8.2f} [{s.mean_band[0]:.2f}, {s.mean_band[1]:.2f}] "
                    f"{100 * s.inside:5.1f} % in, {s.verdict}"
                )
            lines.append(line)
        return "\n".join(lines)


def consistency_report(
    samples: ConsistencySamples,
    trajectory_class: Sequence[str] | np.ndarray,
    *,
    probability: float = BAND_PROBABILITY,
    label: str = "",
    extra: Mapping[str, Any] | None = None,
) -> ConsistencyReport:
    """Per class (a–e, those present) and in total: :func:`consistency_stat` of every statistic.

    Parameters
    ----------
    samples
        From :func:`consistency_samples`.
    trajectory_class
        (K,) class of every trajectory of the data set.
    """
    cls = np.asarray(trajectory_class).astype(str)[samples.trajectory]  # (F,)
    names = [c for c in CLASSES if np.any(cls == c)]
    names += sorted(set(cls.tolist()) - set(CLASSES))
    rows: dict[str, dict[str, ConsistencyStat]] = {}
    present: dict[str, int] = {}
    paired: dict[str, int] = {}
    for row in [*names, "total"]:
        sel = np.ones(len(cls), bool) if row == "total" else cls == row
        rows[row] = {
            name: consistency_stat(getattr(samples, name)[sel], dof, probability)
            for name, dof in STATISTICS.items()
        }
        present[row] = int(samples.present[sel].sum())
        paired[row] = int(samples.paired[sel].sum())
    return ConsistencyReport(
        rows=rows,
        frames_present=present,
        frames_paired=paired,
        probability=probability,
        label=label,
        extra=dict(extra or {}),
    )


def dataset_consistency(
    dataset: Dataset,
    params: TrackerParams,
    *,
    probability: float = BAND_PROBABILITY,
    label: str = "",
    extra: Mapping[str, Any] | None = None,
) -> ConsistencyReport:
    """NEES and NIS of a tracker run on a data set, per class and in total.

    :func:`consistency_samples` then :func:`consistency_report`.
    """
    samples = consistency_samples(dataset, params)
    return consistency_report(
        samples, dataset.trajectory_class, probability=probability, label=label, extra=extra
    )


def measurement_spread(dataset: Dataset) -> np.ndarray:
    """RMS error of the person-labelled points against the person's true measurement h(x_gt).

    What a measurement covariance R = diag(σ_r², σ_az², σ_vr²) should hold if every person point
    were a noisy measurement of the person's centre (its body spread included).

    Parameters
    ----------
    dataset
        A simulated data set; a point with ``source = i >= 0`` came from person ``i``.

    Returns
    -------
    numpy.ndarray
        (3,) [σ_r (m), σ_az (rad), σ_vr (m/s)]; NaN without person points.
    """
    from core.tracking.ekf import measure, wrap_angle

    sel = np.flatnonzero(dataset.source >= 0)
    if sel.size == 0:
        return np.full(3, np.nan)
    f, person = dataset.frame[sel], dataset.source[sel]
    states = np.concatenate(
        (dataset.truth_xy_m[f, person], dataset.truth_v_mps[f, person]), axis=1
    )  # (M, 4) [x, y, vx, vy]
    z_true = np.array([measure(x) for x in states])  # (M, 3) h(x_gt)
    e = dataset.measurements()[sel] - z_true
    e[:, 1] = wrap_angle(e[:, 1])
    return np.sqrt(np.mean(e * e, axis=0))


def plot_consistency(
    reports: Sequence[ConsistencyReport], path: str | Path, *, title: str = "Filter consistency"
) -> Path:
    """One panel per statistic: the mean ε̄ per class (one marker series per report, log scale)
    against the per-sample χ² band (light grey), the band of the mean for the fewest samples of
    any row (dark grey, the widest) and the expected value n (dashed); the percentage of samples
    inside the per-sample band is written beside each marker. A report's ``extra["case"]``
    chooses its colour and ``extra["model"]`` its marker (circle CV, square CA). Written
    atomically as PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from core.files import atomic_open

    probability = reports[0].probability if reports else BAND_PROBABILITY
    rows = [r for r in (reports[0].rows if reports else {}) if r != "total"] + ["total"]
    fig, axes = plt.subplots(1, len(STATISTICS), figsize=(14, 5.6))
    # one colour per case (``extra["case"]``, else the label), a marker per motion model
    cases = list(dict.fromkeys(str(r.extra.get("case", r.label)) for r in reports))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    markers = {"cv": "o", "ca": "s"}
    width = 0.8 / max(len(reports), 1)
    for ax, (name, dof) in zip(np.atleast_1d(axes), STATISTICS.items()):
        lo, hi = chi2_band(dof, probability)
        ax.axhspan(lo, hi, color="0.9", label=f"{100 * probability:.0f} % per-sample band")
        counts = [s.n for rep in reports for st in rep.rows.values() for k, s in st.items()
                  if k == name and s.n > 0]  # fmt: skip
        if counts:
            n_min = min(counts)
            m_lo, m_hi = average_band(dof, n_min, probability)
            ax.axhspan(m_lo, m_hi, color="0.6", label=f"band of the mean, N ≥ {n_min}")
        ax.axhline(dof, color="0.3", ls="--", lw=1, label="E[ε] = n")
        for j, rep in enumerate(reports):
            xs, ys, fr = [], [], []
            for i, row in enumerate(rows):
                s = rep.rows.get(row, {}).get(name)
                if s is None or s.n == 0:
                    continue
                xs.append(i - 0.4 + width * (j + 0.5))
                ys.append(s.mean)
                fr.append(s.inside)
            colour = colours[cases.index(str(rep.extra.get("case", rep.label))) % len(colours)]
            marker = markers.get(str(rep.extra.get("model", "")), "D")
            line = ax.plot(xs, ys, marker, color=colour, ms=7, label=rep.label)[0]
            for x, y, f in zip(xs, ys, fr):
                ax.annotate(
                    f"{100 * f:.0f}", (x, y), textcoords="offset points",
                    xytext=(0, 6 if j % 2 == 0 else -12), ha="center", fontsize=6.5,
                    color=line.get_color(),
                )  # fmt: skip
        ax.set_yscale("log")
        ax.set_xticks(range(len(rows)), rows)
        for i in range(len(rows) - 1):
            ax.axvline(i + 0.5, color="0.8", lw=0.5)
        ax.set_xlabel("trajectory class")
        ax.set_title(f"{LABELS[name]}: per-sample band [{lo:.2f}, {hi:.2f}]", fontsize=10)
        ax.grid(alpha=0.3, which="major", axis="y")
    first = np.atleast_1d(axes)[0]
    first.set_ylabel("time-averaged ε̄ (log scale); numbers: % of samples in the band")
    handles, labels = first.get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=6, fontsize=8, frameon=False)
    fig.suptitle(title)
    fig.tight_layout(rect=(0, 0.09, 1, 1))
    out = Path(path)
    with atomic_open(out, "wb") as fh:
        fig.savefig(fh, format="png", dpi=100)
    plt.close(fig)
    return out

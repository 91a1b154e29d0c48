"""Scores without positions: what a recording with only a head count (or nothing) can judge.

A recording from a real room rarely has the people's positions; it often has their number (the
person who recorded it knows how many walked), and a tracker's filter consistency needs no truth
at all. Per run of the tracker (:class:`core.tracking.DatasetEstimates` with its ``record``):

- **count**, with a head count n_f per frame (``--people N`` for every frame, or the persons
  present in the truth): the fraction of frames whose number of confirmed tracks n̂_f equals
  n_f, with a 95 % interval; the count error mean |n̂_f − n_f| and its sign mean (n̂_f − n_f).
  Frames of one walk are not independent (a ghost track lives for seconds), so the interval is a
  block bootstrap: the frames cut into blocks of :data:`COUNT_BLOCK_S`, the blocks resampled
  (:func:`core.evaluation.intervals.bootstrap_interval` of Σ right / Σ frames). A run shorter than
  two blocks has no interval (NaN).
- **fragmentation**: distinct confirmed track ids per person-minute, ``N_ids / (Σ_f n_f · T / 60)``
  (T the frame period). One person walking one minute under a tracker that never loses them
  gives 1; every break of the track (a new id for the same person) and every confirmed ghost adds
  one. Tentative tracks never counted.
- **NIS**, always: the normalised innovation squared of every confirmed track's update against
  its χ²₃ band (:func:`core.evaluation.consistency.consistency_stat`; the PDA caveat there holds:
  a consistent filter sits *below* 3 on average, a NIS above the band is the finding).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from core.dataset import Dataset
from core.errors import InputError
from core.evaluation.consistency import ConsistencyStat, consistency_stat
from core.evaluation.intervals import bootstrap_interval
from core.evaluation.reference import ReferenceComparison, compare_with_reference

__all__ = [
    "COUNT_BLOCK_S",
    "CountScores",
    "RecordingScores",
    "confirmed_ids",
    "count_scores",
    "fragmentation",
    "head_counts",
    "nis_samples",
    "recording_scores",
    "reference_agreement",
    "trajectory_terms",
]

#: Block length of the count's bootstrap (s): longer than a ghost's or a lost track's life.
COUNT_BLOCK_S = 10.0
#: NIS degrees of freedom (range, azimuth, radial velocity).
NIS_DOF = 3


def head_counts(dataset: Dataset, people: int | None = None) -> np.ndarray | None:
    """(F,) int64 head count of every frame of the data set, or None when nothing gives one.

    ``people`` (``--people N``) holds for every frame; else the data set's own head count
    (``people_count``, −1 where unknown: those frames are not scored); else a data set with truth
    counts the persons present in each frame; else None.
    """
    if people is not None:
        if isinstance(people, bool) or not isinstance(people, (int, np.integer)) or people < 0:
            raise InputError(f"--people must be a whole number >= 0, got {people!r}")
        return np.full(dataset.n_frames, int(people), dtype=np.int64)
    own = np.asarray(dataset.people_count, dtype=np.int64)
    if len(own) == dataset.n_frames and dataset.n_frames and np.any(own >= 0):
        return own
    if dataset.n_persons and np.isfinite(dataset.truth_xy_m).any():
        return np.sum(np.all(np.isfinite(dataset.truth_xy_m), axis=2), axis=1).astype(np.int64)
    return None


def confirmed_ids(estimates: Any) -> np.ndarray:
    """(F_sel, cap) int64: the id of every confirmed live track (−1 elsewhere), the ids of each
    run shifted past those of the runs before it (unique over the data set)."""
    from core.formats.tracks_csv import unique_track_ids

    rec = estimates.record
    if rec is None:
        raise ValueError("scores without positions need every track: with_tracks=True")
    return np.where(rec.confirmed, unique_track_ids(rec, estimates.offsets), -1)


@dataclass(frozen=True, slots=True, kw_only=True)
class CountScores:
    """Confirmed-track count against a head count over N scored frames.

    Attributes
    ----------
    n_frames
        Frames scored.
    right
        Fraction of them with n̂_f = n_f; ``right_interval`` its 95 % block-bootstrap interval
        (NaN, NaN with fewer than two blocks).
    error, bias
        mean |n̂_f − n_f| and mean (n̂_f − n_f) (tracks per frame).
    n_ids
        Distinct confirmed track ids.
    person_minutes
        Σ_f n_f · T / 60.
    fragmentation
        ``n_ids / person_minutes`` (NaN with no person-minute).
    """

    n_frames: int
    right: float
    right_interval: tuple[float, float]
    error: float
    bias: float
    n_ids: int
    person_minutes: float
    fragmentation: float

    def to_dict(self) -> dict[str, Any]:
        return {
            "frames": self.n_frames,
            "right_count_fraction": _num(self.right),
            "right_count_interval": [_num(v) for v in self.right_interval],
            "count_error": _num(self.error),
            "count_bias": _num(self.bias),
            "confirmed_track_ids": self.n_ids,
            "person_minutes": _num(self.person_minutes),
            "fragmentation_per_person_minute": _num(self.fragmentation),
        }


def _num(v: float) -> float | None:
    return float(v) if math.isfinite(v) else None


def fragmentation(ids: np.ndarray, counts: np.ndarray, frame_period_s: float) -> float:
    """Distinct ids (≥ 0) in ``ids`` (F, cap) per person-minute of ``counts`` (F,) (NaN: none)."""
    minutes = float(np.sum(counts)) * frame_period_s / 60.0
    n_ids = int(np.unique(ids[ids >= 0]).size)
    return n_ids / minutes if minutes > 0 else math.nan


def count_scores(
    n_confirmed: np.ndarray,
    counts: np.ndarray,
    ids: np.ndarray,
    frame_period_s: float,
    *,
    seed: int = 0,
) -> CountScores:
    """:class:`CountScores` of F frames.

    Parameters
    ----------
    n_confirmed
        (F,) confirmed tracks per frame.
    counts
        (F,) head count per frame (≥ 0).
    ids
        (F, cap) confirmed track ids per frame (−1 padded), unique over the runs.
    frame_period_s
        T, s (> 0).
    seed
        Seed of the bootstrap.
    """
    if not frame_period_s > 0:
        raise ValueError(f"frame_period_s must be > 0, got {frame_period_s}")
    n_hat = np.asarray(n_confirmed, dtype=np.int64)
    n = np.asarray(counts, dtype=np.int64)
    f = len(n)
    if f == 0:
        nan = math.nan
        return CountScores(
            n_frames=0, right=nan, right_interval=(nan, nan), error=nan, bias=nan, n_ids=0,
            person_minutes=0.0, fragmentation=nan,
        )  # fmt: skip
    right = (n_hat == n).astype(np.float64)
    block = max(1, round(COUNT_BLOCK_S / frame_period_s))
    n_blocks = f // block
    interval = (math.nan, math.nan)
    if n_blocks >= 2:
        # the last partial block joins the one before it: every frame counts once
        edges = np.minimum(np.arange(n_blocks + 1) * block, f)
        edges[-1] = f
        k = np.add.reduceat(right, edges[:-1])
        m = np.diff(edges).astype(np.float64)
        _, lo, hi = bootstrap_interval(
            lambda a, b: np.sum(a, axis=-1) / np.sum(b, axis=-1), k, m, seed=seed
        )
        interval = (lo, hi)
    d = (n_hat - n).astype(np.float64)
    minutes = float(np.sum(n)) * frame_period_s / 60.0
    return CountScores(
        n_frames=f,
        right=float(right.mean()),
        right_interval=interval,
        error=float(np.mean(np.abs(d))),
        bias=float(np.mean(d)),
        n_ids=int(np.unique(ids[ids >= 0]).size),
        person_minutes=minutes,
        fragmentation=fragmentation(ids, n, frame_period_s),
    )


def nis_samples(estimates: Any) -> np.ndarray:
    """NIS of every confirmed live track's update over the run (finite values only)."""
    rec = estimates.record
    if rec is None:
        raise ValueError("scores without positions need every track: with_tracks=True")
    cap = rec.ids.shape[1]
    live = np.arange(cap)[None, :] < np.asarray(rec.n_tracks)[:, None]
    v = rec.nis[live & rec.confirmed]
    return v[np.isfinite(v)]


@dataclass(frozen=True, slots=True, kw_only=True)
class RecordingScores:
    """The scores of one tracker run that need no positions.

    ``count``: None without a head count. ``nis``: always (n = 0 without a confirmed update).
    ``people``: the head count's source, ``"--people N"``, ``"people_count"`` (the data set's
    own), ``"truth"`` or ``""``. ``reference``: the agreement of the confirmed tracks with the
    recording's reference layer (TI's own tracks; :mod:`core.evaluation.reference`) over the
    tracked frames, None without one.
    """

    count: CountScores | None
    nis: ConsistencyStat
    people: str
    reference: ReferenceComparison | None = None

    def to_dict(self) -> dict[str, Any]:
        ref = None
        if self.reference is not None:
            ref = {k: _num(v) if isinstance(v, float) else v
                   for k, v in self.reference.to_dict().items()}  # fmt: skip
        return {
            "head_count": self.people or None,
            "count": None if self.count is None else self.count.to_dict(),
            "nis": self.nis.to_dict(),
            "reference": ref,
        }

    def format_lines(self) -> list[str]:
        """Readable lines for the terminal."""
        out = []
        c = self.count
        if c is None:
            out.append("no head count (give --people N): no count or fragmentation scores")
        else:
            lo, hi = c.right_interval
            ci = (
                f" (95 % {lo:.3f}-{hi:.3f})"
                if math.isfinite(lo)
                else " (too short for an interval)"
            )
            out.append(
                f"head count from {self.people}: right number of confirmed tracks in "
                f"{c.right:.3f} of {c.n_frames} frames{ci}; count error {c.error:.3f} "
                f"(bias {c.bias:+.3f}) tracks a frame"
            )
            out.append(
                f"fragmentation: {c.n_ids} confirmed track ids over {c.person_minutes:.2f} "
                f"person-minutes = {c.fragmentation:.2f} per person-minute"
            )
        r = self.reference
        if r is not None and len(r.gospa_m):
            out.append(
                f"against the recording's own tracks (reference layer): mean GOSPA "
                f"{r.mean_gospa_m:.3f} m (c = {r.c_m:g} m) over {len(r.gospa_m)} frames; as many "
                f"confirmed tracks as reference tracks in {r.count_agreement:.3f} of them"
            )
        s = self.nis
        if s.n == 0:
            out.append("NIS: no confirmed track was updated")
        else:
            out.append(
                f"NIS ({s.dof} dof) of confirmed tracks: mean {s.mean:.2f}, median {s.median:.2f}"
                f" over {s.n} updates; {s.inside:.3f} inside the 95 % band "
                f"[{s.band[0]:.3f}, {s.band[1]:.2f}], {s.above:.3f} above; mean {s.verdict} "
                f"its band"
            )
        return out


def recording_scores(
    dataset: Dataset,
    estimates: Any,
    frame_period_s: float,
    *,
    people: int | None = None,
    nis_dof: int = NIS_DOF,
) -> RecordingScores:
    """Count, fragmentation (with a head count) and NIS of a tracker run on ``dataset``
    (``nis_dof``: the measurement's dimension, 4 for gtrack's 3-D ``[r, az, el, vr]``)."""
    counts = head_counts(dataset, people)
    count = None
    source = ""
    if counts is not None:
        if people is not None:
            source = f"--people {people}"
        elif len(dataset.people_count) == dataset.n_frames and np.any(dataset.people_count >= 0):
            source = "people_count"
        else:
            source = "truth"
        n = counts[estimates.frame_index]
        known = n >= 0  # frames of unknown head count are not scored
        count = count_scores(
            np.asarray(estimates.n_confirmed)[known],
            n[known],
            confirmed_ids(estimates)[known],
            frame_period_s,
        )
    return RecordingScores(
        count=count,
        nis=consistency_stat(nis_samples(estimates), nis_dof),
        people=source,
        reference=reference_agreement(dataset, estimates),
    )


def reference_agreement(dataset: Dataset, estimates: Any) -> ReferenceComparison | None:
    """GOSPA and count difference per tracked frame between the confirmed tracks and the
    recording's reference layer (:func:`core.evaluation.reference.compare_with_reference`,
    restricted to ``estimates.frame_index``); None without a reference layer."""
    if not dataset.has_reference:
        return None
    from dataclasses import replace

    rec = estimates.record
    if rec is None:
        raise ValueError("the reference agreement needs every track: with_tracks=True")
    cap = rec.ids.shape[1]
    live = np.arange(cap)[None, :] < np.asarray(rec.n_tracks)[:, None]
    rows, slots = np.nonzero(live & rec.confirmed)
    frames = np.asarray(estimates.frame_index, dtype=np.int64)
    cmp = compare_with_reference(dataset, frames[rows], rec.state[rows, slots, :2])
    return replace(
        cmp,
        gospa_m=cmp.gospa_m[frames],
        n_estimated=cmp.n_estimated[frames],
        n_reference=cmp.n_reference[frames],
        count_difference=cmp.count_difference[frames],
    )


def trajectory_terms(
    kind: str,
    estimates: Any,
    counts: np.ndarray | None,
    dataset: Dataset | None = None,
    *,
    nis_dof: int = NIS_DOF,
) -> list[tuple[float, float]]:
    """Per tracked trajectory, the value of a study objective without positions and its weight.

    ``kind`` (see docs/tuning.md):

    - ``"count"``: mean_f |n̂_f − n_f| over the trajectory's frames; weight: its frames.
    - ``"fragmentation"``: ``(Σ_f |n̂_f − n_f| + max(N_ids − max_f n_f, 0)) / Σ_f n_f``, the
      complement of a positionless MOTA (missed and false tracks per frame, and every confirmed
      id beyond one per person as an identity switch); weight: the person-frames Σ_f n_f (a
      run without persons weighs 1 and scores its false tracks per frame).
    - ``"nis"``: the fraction of the confirmed tracks' NIS samples outside the χ² band of
      ``nis_dof`` degrees of freedom (3, the paper tracker's [r, θ, v_r]; 4 for gtrack's 3-D
      [r, az, el, v_r]; a consistent filter: 5 %); weight: the samples. A trajectory without
      a sample scores 1 with weight 1 (a tracker that confirms nothing is not consistent, it
      is silent).
    - ``"reference"``: the mean GOSPA (m; c = 1 m, p = 2) per frame between the confirmed
      tracks and the recording's reference layer (TI's own tracks); weight: the frames.

    Frames whose head count is unknown (−1) are left out of count and fragmentation.

    Parameters
    ----------
    kind
        ``"count"``, ``"fragmentation"``, ``"nis"`` or ``"reference"``.
    estimates
        :class:`core.tracking.DatasetEstimates` (with its ``record`` unless ``kind`` is count).
    counts
        (F_sel,) head count of every output frame (None for ``"nis"`` and ``"reference"``).
    dataset
        The data set tracked (``"reference"`` only).
    """
    off = np.asarray(estimates.offsets, dtype=np.int64)
    spans = [slice(off[i], off[i + 1]) for i in range(len(off) - 1)]
    if kind == "nis":
        from core.evaluation.consistency import chi2_band

        lo, hi = chi2_band(nis_dof)
        rec = estimates.record
        if rec is None:
            raise ValueError("the nis objective needs every track: with_tracks=True")
        cap = rec.ids.shape[1]
        live = np.arange(cap)[None, :] < np.asarray(rec.n_tracks)[:, None]
        v = np.where(live & rec.confirmed, rec.nis, np.nan)
        out = []
        for s in spans:
            x = v[s][np.isfinite(v[s])]
            out.append(
                (float(np.mean((x < lo) | (x > hi))), float(x.size)) if x.size else (1.0, 1.0)
            )
        return out
    if kind == "reference":
        if dataset is None or not dataset.has_reference:
            raise InputError("the reference objective needs a recording with its own tracks")
        agreement = reference_agreement(dataset, estimates)
        assert agreement is not None
        g = agreement.gospa_m
        return [(float(np.mean(g[s])) if g[s].size else 0.0, float(g[s].size)) for s in spans]
    if counts is None:
        raise InputError(f"the {kind} objective needs a head count (--people N, or truth)")
    n_all = np.asarray(counts, np.int64)
    known = n_all >= 0  # frames of unknown head count are not scored
    d = np.where(known, np.abs(np.asarray(estimates.n_confirmed, np.int64) - n_all), 0)
    if kind == "count":
        return [
            (float(d[s].sum() / known[s].sum()) if known[s].any() else 0.0, float(known[s].sum()))
            for s in spans
        ]
    if kind == "fragmentation":
        ids = confirmed_ids(estimates)
        out = []
        for s in spans:
            n = np.where(known[s], n_all[s], 0)
            run_ids = ids[s][known[s]]
            extra = max(int(np.unique(run_ids[run_ids >= 0]).size) - int(n.max(initial=0)), 0)
            person_frames = max(float(n.sum()), 1.0)
            out.append(((float(d[s].sum()) + extra) / person_frames, person_frames))
        return out
    raise InputError(
        f"objective without positions must be count, fragmentation or nis, got {kind!r}"
    )

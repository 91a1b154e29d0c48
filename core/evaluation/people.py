"""Several-person metrics of one tracker run: GOSPA and its decomposition, the people-count error,
identities and identity switches — per frame and per person.

Every metric is defined for every frame: without a person, without a track, with a person absent
(NaN truth) — GOSPA of two empty sets is 0, of n points against none ``(c^p/2 · n)^{1/p}``; the
count error is ``n_confirmed − n_present``. Aggregates over no frames (an empty selection) are
NaN here and reported as undefined by :class:`core.evaluation.table.Evaluation`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from core.evaluation.assignment import IDENTITY_CUTOFF_M, IdentityAssignment, assign_identities
from core.evaluation.loss import PeopleLoss, people_trajectory_loss, person_estimates
from core.evaluation.metrics import GOSPA_C_M, GOSPA_P, gospa

__all__ = ["FrameMetrics", "PeopleRun", "PersonMetrics", "frame_metrics", "people_run",
           "person_metrics"]  # fmt: skip


@dataclass(frozen=True, slots=True, kw_only=True)
class FrameMetrics:
    """Per-frame several-person metrics of N frames and P persons.

    Attributes
    ----------
    present
        (N, P) bool, person present (finite truth).
    n_present
        (N,) persons present.
    n_confirmed
        (N,) confirmed tracks.
    count_error
        (N,) people-count error ``n_confirmed − n_present`` (> 0: too many tracks).
    gospa_m
        (N,) GOSPA d_p^(c,2) in m.
    localisation, missed, false
        (N,) its decomposition in m^p (``gospa_m**p`` is their sum).
    n_missed, n_false
        (N,) persons without a track and tracks without a person (GOSPA assignment).
    gospa_track
        (N, P) index (into the frame's confirmed tracks) of the track GOSPA assigns to each
        person, −1 where none.
    gospa_error2
        (N, P) ‖x̂ − x‖^p of the person's GOSPA pair, NaN where none (m^p).
    identity
        Track-to-person pairing with hysteresis and switches (:mod:`core.evaluation.assignment`),
        or None when the tracks came without ids.
    c_m, p
        GOSPA cut-off (m) and order.
    """

    present: np.ndarray
    n_present: np.ndarray
    n_confirmed: np.ndarray
    count_error: np.ndarray
    gospa_m: np.ndarray
    localisation: np.ndarray
    missed: np.ndarray
    false: np.ndarray
    n_missed: np.ndarray
    n_false: np.ndarray
    gospa_track: np.ndarray
    gospa_error2: np.ndarray
    identity: IdentityAssignment | None
    c_m: float = GOSPA_C_M
    p: float = GOSPA_P

    def mean(self, frames: slice | np.ndarray | None = None) -> dict[str, float]:
        """Means over the frames (all by default): GOSPA (m), its terms (m^p), missed and false
        counts, count error and its absolute value, the fraction of frames counted exactly; NaN
        for no frames."""
        s = slice(None) if frames is None else frames
        out = {}
        for name in ("gospa_m", "localisation", "missed", "false", "n_missed", "n_false"):
            a = getattr(self, name)[s]
            out[name] = float(np.mean(a)) if a.size else math.nan
        e = self.count_error[s]
        out["count_error"] = float(np.mean(e)) if e.size else math.nan
        out["count_abs_error"] = float(np.mean(np.abs(e))) if e.size else math.nan
        out["count_exact_fraction"] = float(np.mean(e == 0)) if e.size else math.nan
        return out


def frame_metrics(
    truth_xy: np.ndarray,
    confirmed_xy: np.ndarray,
    track_ids: np.ndarray | None = None,
    offsets: np.ndarray | None = None,
    *,
    c_m: float = GOSPA_C_M,
    p: float = GOSPA_P,
    identity_cutoff_m: float = IDENTITY_CUTOFF_M,
) -> FrameMetrics:
    """GOSPA, count error and identities of every frame.

    Parameters
    ----------
    truth_xy
        (N, P, 2) true positions (m), NaN where absent.
    confirmed_xy
        (N, C, 2) positions of the confirmed tracks (m), NaN padded.
    track_ids
        (N, C) int64 ids of those tracks (−1 padding), in the same columns; None: no identities.
    offsets
        (K + 1,) frame ranges of the trajectories (identities restart in each).
    c_m, p
        GOSPA cut-off (m) and order.
    identity_cutoff_m
        Cut-off of the identity assignment (m).
    """
    truth = np.asarray(truth_xy, dtype=np.float64)
    conf = np.asarray(confirmed_xy, dtype=np.float64)
    n, n_p = truth.shape[:2]
    present = np.all(np.isfinite(truth), axis=2)
    valid = np.all(np.isfinite(conf), axis=2)
    arrays = {k: np.zeros(n) for k in ("gospa_m", "localisation", "missed", "false")}
    n_missed = np.zeros(n, dtype=np.int64)
    n_false = np.zeros(n, dtype=np.int64)
    track = np.full((n, n_p), -1, np.int64)
    err2 = np.full((n, n_p), np.nan)
    for f in range(n):
        cols = np.flatnonzero(valid[f])
        g = gospa(conf[f, cols], truth[f], c_m, p)
        arrays["gospa_m"][f], arrays["localisation"][f] = g.distance_m, g.localisation
        arrays["missed"][f], arrays["false"][f] = g.missed, g.false
        n_missed[f], n_false[f] = g.n_missed, g.n_false
        hit = g.track_of_truth >= 0
        track[f, hit] = cols[g.track_of_truth[hit]]
        d = conf[f, track[f, hit]] - truth[f, hit]
        err2[f, hit] = np.sqrt(np.sum(d * d, axis=1)) ** p
    identity = None
    if track_ids is not None:
        ids = np.where(valid, np.asarray(track_ids, dtype=np.int64), -1)
        identity = assign_identities(ids, conf, truth, offsets, cutoff_m=identity_cutoff_m)
    n_present = present.sum(axis=1).astype(np.int64)
    n_confirmed = valid.sum(axis=1).astype(np.int64)
    return FrameMetrics(
        present=present,
        n_present=n_present,
        n_confirmed=n_confirmed,
        count_error=n_confirmed - n_present,
        n_missed=n_missed,
        n_false=n_false,
        gospa_track=track,
        gospa_error2=err2,
        identity=identity,
        c_m=float(c_m),
        p=float(p),
        **arrays,
    )


@dataclass(frozen=True, slots=True, kw_only=True)
class PersonMetrics:
    """Metrics of one person (index ``person`` of the data set) over the selected trajectories.

    Attributes
    ----------
    person
        Person index.
    loss
        Mean L_j(k) (m²) over the trajectories in which the person is present (NaN: never).
    n_trajectories, n_unconfirmed
        Trajectories in which the person is present; of those, the ones in which the person never
        has an estimate (L_j = 1 m²).
    n_c
        Σ_k N_c,j(k), frames scored by the loss.
    rmse_m
        Position RMSE (m) of the person's loss estimate over those frames (NaN: none).
    frames_present
        Frames in which the person is present.
    frames_missed
        Frames present without a GOSPA pair (no confirmed track within c).
    gospa_localisation
        Σ ‖x̂ − x‖^p of the person's GOSPA pairs (m^p) — its share of GOSPA's localisation term.
    frames_assigned
        Frames in which the identity assignment gives the person a track (−1: no identities).
    identity_switches
        Identity switches of the person (−1: no identities).
    n_track_ids
        Distinct track ids the person was paired with (−1: no identities).
    """

    person: int
    loss: float
    n_trajectories: int
    n_unconfirmed: int
    n_c: int
    rmse_m: float
    frames_present: int
    frames_missed: int
    gospa_localisation: float
    frames_assigned: int
    identity_switches: int
    n_track_ids: int

    def to_dict(self) -> dict:
        """JSON-ready dict (NaN → None; −1 identity counts → None)."""

        def num(v: float) -> float | None:
            return float(v) if math.isfinite(v) else None

        def ident(v: int) -> int | None:
            return int(v) if v >= 0 else None

        return {
            "person": self.person,
            "loss": num(self.loss),
            "loss_x1e3": num(self.loss * 1e3),
            "n_trajectories": self.n_trajectories,
            "n_unconfirmed": self.n_unconfirmed,
            "n_c": self.n_c,
            "rmse_m": num(self.rmse_m),
            "frames_present": self.frames_present,
            "frames_missed": self.frames_missed,
            "gospa_localisation_m2": num(self.gospa_localisation),
            "frames_assigned": ident(self.frames_assigned),
            "identity_switches": ident(self.identity_switches),
            "n_track_ids": ident(self.n_track_ids),
        }


def person_metrics(
    frames: FrameMetrics,
    person_loss: np.ndarray,
    counted: np.ndarray,
    person_n_c: np.ndarray,
    person_sse: np.ndarray,
    offsets: np.ndarray,
) -> tuple[PersonMetrics, ...]:
    """Per-person summary of one run.

    Parameters
    ----------
    frames
        The run's :class:`FrameMetrics` (N frames, P persons).
    person_loss, counted, person_n_c
        (K, P) L_j(k), person present in trajectory k, N_c,j(k).
    person_sse
        (P,) Σ ‖x̂ − x‖² over the frames scored by the loss (m²).
    offsets
        (K + 1,) frame ranges of the trajectories.
    """
    n_p = frames.present.shape[1]
    pres = frames.present
    ident = frames.identity
    out = []
    for j in range(n_p):
        cj = np.asarray(counted[:, j], dtype=bool)
        n_c = int(np.sum(person_n_c[:, j]))
        hit = frames.gospa_track[:, j] >= 0
        if ident is not None:
            ids = np.unique(
                np.stack([ident.track_id[:, j], _trajectory_of(offsets, len(ident.track_id))])[
                    :, ident.track_id[:, j] >= 0
                ],
                axis=1,
            )
        out.append(
            PersonMetrics(
                person=j,
                loss=float(np.mean(person_loss[cj, j])) if cj.any() else math.nan,
                n_trajectories=int(cj.sum()),
                n_unconfirmed=int(np.sum(cj & (person_n_c[:, j] == 0))),
                n_c=n_c,
                rmse_m=math.sqrt(person_sse[j] / n_c) if n_c else math.nan,
                frames_present=int(pres[:, j].sum()),
                frames_missed=int(np.sum(pres[:, j] & ~hit)),
                gospa_localisation=float(np.sum(frames.gospa_error2[hit, j])),
                frames_assigned=int(ident.assigned[:, j].sum()) if ident is not None else -1,
                identity_switches=int(ident.switch[:, j].sum()) if ident is not None else -1,
                n_track_ids=int(ids.shape[1]) if ident is not None else -1,
            )
        )
    return tuple(out)


def _trajectory_of(offsets: np.ndarray, n: int) -> np.ndarray:
    """(n,) index of the trajectory of every frame."""
    return np.searchsorted(np.asarray(offsets)[1:], np.arange(n), side="right")


@dataclass(frozen=True, slots=True, kw_only=True)
class PeopleRun:
    """Every several-person metric of one tracker run over one trajectory (what the GUI shows).

    Attributes
    ----------
    loss
        The paper's loss in its several-person form (:class:`core.evaluation.loss.PeopleLoss`).
    frames
        Per-frame GOSPA, decomposition, count error and identities (:class:`FrameMetrics`).
    persons
        One :class:`PersonMetrics` per person.
    estimate_xy
        (N, P, 2) estimate of each person scored by the loss (m), NaN where none.
    """

    loss: PeopleLoss
    frames: FrameMetrics
    persons: tuple[PersonMetrics, ...]
    estimate_xy: np.ndarray


def people_run(truth_xy: np.ndarray, tracks) -> PeopleRun:
    """Several-person metrics of one run (one trajectory).

    Parameters
    ----------
    truth_xy
        (N, P, 2) true positions (m), NaN where absent.
    tracks
        :class:`core.tracking.batch.ConfirmedTracks` of the N frames (for a readable-tracker run:
        ``ConfirmedTracks.from_frames(result.frames)``).
    """
    truth = np.asarray(truth_xy, dtype=np.float64)
    n = len(truth)
    est = person_estimates(tracks.xy, truth)
    loss = people_trajectory_loss(est, truth)
    offsets = np.array([0, n], dtype=np.int64)
    fm = frame_metrics(truth, tracks.xy, tracks.ids, offsets)
    scored = np.all(np.isfinite(est), axis=2) & fm.present
    sse = np.array([np.sum((est[:, j] - truth[:, j])[scored[:, j]] ** 2)
                    for j in range(truth.shape[1])])  # fmt: skip
    persons = person_metrics(
        fm, loss.person_loss[None], loss.counted[None], loss.person_n_c[None], sse, offsets
    )
    return PeopleRun(loss=loss, frames=fm, persons=persons, estimate_xy=est)

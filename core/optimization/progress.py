"""Reading studies without touching them: trials as :class:`TrialSummary`, progress, model, names.

Everything here is what the GUI, the CLI and the report read from a study while workers run it
(:mod:`core.optimization.study`); no Optuna type leaves this module. :func:`enqueue_params`
only queues a trial for the workers to run.
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from core.errors import InputError
from core.optimization.storage import load_existing_study, open_storage, redact
from core.tracking.space import flat_params, tracker_params_dict


@dataclass(frozen=True, slots=True, kw_only=True)
class TrialSummary:
    """One trial as the GUI and the report see it (no Optuna types).

    ``params`` are the flat Optuna parameters (``q_coeff``, ``p0_00``, …); ``value`` is L_t in m²
    (the running mean at the pruning point for a PRUNED trial); ``duration_s`` is None while
    RUNNING. ``state`` is Optuna's state name, except ``"SURPLUS"`` for a trial a worker opened
    after the total was reached and closed at once (stored as FAIL with ``surplus=True``, since
    Optuna cannot delete a trial): it neither counts nor failed.
    """

    number: int
    state: str
    value: float | None
    params: dict[str, float]
    duration_s: float | None
    datetime_start: dt.datetime | None
    datetime_complete: dt.datetime | None
    worker: str = ""
    #: why a FAIL trial failed (``"TypeName: message"``, recorded by the worker); "" otherwise
    error: str = ""

    def tracker_params(self, model: str, mode: str = "paper") -> dict[str, Any]:
        """The trial's parameters as TrackerParams JSON (``mode``: the study's tracker mode)."""
        return tracker_params_dict(self.params, model, mode)


def _summary(t: Any) -> TrialSummary:
    dur = None
    if t.datetime_start is not None and t.datetime_complete is not None:
        dur = (t.datetime_complete - t.datetime_start).total_seconds()
    value = t.value if t.state.name == "COMPLETE" else None
    if t.state.name == "PRUNED":
        iv = t.intermediate_values
        value = iv[max(iv)] if iv else None
    return TrialSummary(
        number=t.number,
        state="SURPLUS" if t.state.name == "FAIL" and t.user_attrs.get("surplus") else t.state.name,
        value=None if value is None else float(value),
        params={k: float(v) for k, v in t.params.items()},
        duration_s=dur,
        datetime_start=t.datetime_start,
        datetime_complete=t.datetime_complete,
        worker=str(t.user_attrs.get("worker", "")),
        error=str(t.user_attrs.get("error", "")),
    )


def study_progress(storage: str, name: str) -> tuple[list[TrialSummary], TrialSummary | None]:
    """All trials of a study and the best COMPLETE one (None before the first completes)."""
    store = open_storage(storage, create=False)
    study = load_existing_study(store, name)
    if study is None:
        raise InputError(f"no study {name!r} in {redact(storage)}")
    trials = study.get_trials(deepcopy=False)
    summaries = [_summary(t) for t in trials]
    done = [s for s in summaries if s.state == "COMPLETE" and s.value is not None]
    best = min(done, key=lambda s: (s.value, s.number)) if done else None
    return summaries, best


def study_model(storage: str, name: str) -> str:
    """The motion model recorded in a study."""
    store = open_storage(storage, create=False)
    study = load_existing_study(store, name)
    if study is None:
        raise InputError(f"no study {name!r} in {redact(storage)}")
    return str(study.user_attrs.get("model", ""))


def list_studies(storage: str) -> list[str]:
    """Names of the studies in a storage."""
    import optuna

    return [s.study_name for s in optuna.get_all_study_summaries(open_storage(storage))]


def enqueue_params(storage: str, name: str, params: dict[str, Any]) -> None:
    """Queue TrackerParams JSON as the next trial of a study (``study.enqueue_trial``).

    The parameters must match the study's model and lie inside the paper's bounds.
    """
    import optuna

    store = open_storage(storage, create=False)
    study = load_existing_study(store, name)
    if study is None:
        raise InputError(f"no study {name!r} in {redact(storage)}")
    from core.tracking.space import GTRACK, search_space

    model = study.user_attrs.get("model")
    # gtrack's parameters (GtrackParams JSON) carry no "model": they are known by their names
    gtrack_names = {p.name for p in search_space(GTRACK)}
    is_gtrack = "model" not in params and gtrack_names <= set(params)
    given = GTRACK if is_gtrack else params.get("model", "cv")
    if given != model:
        raise InputError(f"parameters are for model {given!r}, study is {model!r}")
    optuna.load_study(study_name=name, storage=store).enqueue_trial(flat_params(params))


def counted(summaries: Sequence[TrialSummary]) -> int:
    """Trials that count toward the total: COMPLETE and PRUNED."""
    return sum(1 for s in summaries if s.state in ("COMPLETE", "PRUNED"))


#: an idle gap between trials is left out of the busy time when it is longer than this many
#: median trial durations (and than :data:`IDLE_GAP_MIN_S`): a study resumed an hour later
IDLE_GAP_TRIALS = 5.0
IDLE_GAP_MIN_S = 10.0


def busy_time_s(summaries: Iterable[TrialSummary], at: Iterable[dt.datetime]) -> np.ndarray:
    """The study's busy time (s) at each datetime of ``at``: the time since its first trial
    started with the idle gaps between runs left out.

    Each finished trial spans [start, complete]; spans that overlap (parallel workers) or follow
    one another within an idle threshold (a worker's sampling between trials) are one busy
    stretch. A gap longer than ``IDLE_GAP_TRIALS`` median trial durations and longer than
    ``IDLE_GAP_MIN_S`` (the study stopped and resumed, or a second run on its storage) counts
    zero, so a second run continues the first one's time axis instead of drawing the pause.
    The app's study panel and the report's loss-against-time plots both use it.
    """
    spans = sorted(
        (s.datetime_start, s.datetime_complete)
        for s in summaries
        if s.datetime_start is not None and s.datetime_complete is not None
    )
    at = list(at)
    if not spans or not at:
        return np.zeros(len(at))
    t0 = spans[0][0]
    a = np.array([(s0 - t0).total_seconds() for s0, _ in spans])
    b = np.maximum(a, [(s1 - t0).total_seconds() for _, s1 in spans])
    max_gap = max(IDLE_GAP_TRIALS * float(np.median(b - a)), IDLE_GAP_MIN_S)
    # merge into busy stretches [lo, hi]
    lo, hi = [a[0]], [b[0]]
    for ai, bi in zip(a[1:], b[1:], strict=True):
        if ai - hi[-1] <= max_gap:
            hi[-1] = max(hi[-1], bi)
        else:
            lo.append(ai)
            hi.append(bi)
    lo_a, hi_a = np.array(lo), np.array(hi)
    before = np.concatenate([[0.0], np.cumsum(hi_a - lo_a)])  # busy time before each stretch
    t = np.array([(x - t0).total_seconds() for x in at])
    k = np.clip(np.searchsorted(lo_a, t, side="right") - 1, 0, len(lo_a) - 1)
    return before[k] + np.clip(t - lo_a[k], 0.0, hi_a[k] - lo_a[k])

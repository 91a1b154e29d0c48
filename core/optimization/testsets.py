"""Chosen parameters judged on many held-out test data sets: distributions, not one number.

The chosen parameters of a study (:mod:`core.optimization.validation`) are tracked on each of
``N`` test data sets (default: the paper data sets of :data:`TEST_SEEDS`, with the training
set's person model, trajectory count and persons per trajectory). Per set and per class
:func:`score_test_sets` records the paper's ``L`` (mean of eq. (13) over the class's
trajectories; eq. (14) in total), the capped loss (:mod:`core.evaluation.robust`) and the
fraction of trajectories never confirmed (``N_c = 0``). The test sets are the independent units
over which :func:`summarise` gives the mean and the median with 95 % bootstrap intervals, and
:func:`compare_models` the CV / CA ratio of medians and of means with a paired bootstrap (the
same resampled sets for both models): :func:`core.evaluation.intervals.bootstrap_interval`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from core.errors import InputError
from core.evaluation.intervals import bootstrap_interval
from core.optimization.validation import TEST_SEEDS, check_same_radar

#: Score names of :class:`SetScore` that :func:`summarise` accepts.
METRICS = ("loss", "capped", "unconfirmed")


@dataclass(frozen=True, slots=True, kw_only=True)
class SetScore:
    """Scores of one parameter set on one test data set.

    ``loss``, ``capped`` (m²) and ``unconfirmed`` (fraction of trajectories with ``N_c = 0``)
    map the class label (``"A"`` …) and ``"total"`` to the value over those trajectories.
    """

    dataset: str
    seed: int
    loss: dict[str, float]
    capped: dict[str, float]
    unconfirmed: dict[str, float]

    def to_dict(self) -> dict[str, Any]:
        return {
            "dataset": self.dataset,
            "seed": self.seed,
            "loss": self.loss,
            "capped": self.capped,
            "unconfirmed": self.unconfirmed,
        }


@dataclass(frozen=True, slots=True, kw_only=True)
class Spread:
    """Mean and median of one score over the test sets, each with its 95 % bootstrap interval."""

    n_sets: int
    mean: float
    mean_lo: float
    mean_hi: float
    median: float
    median_lo: float
    median_hi: float

    def to_dict(self) -> dict[str, float | int]:
        return {
            "n_sets": self.n_sets,
            "mean": self.mean,
            "mean_lo": self.mean_lo,
            "mean_hi": self.mean_hi,
            "median": self.median,
            "median_lo": self.median_lo,
            "median_hi": self.median_hi,
        }


def _mean(x: np.ndarray) -> np.ndarray:
    return np.mean(x, axis=-1)


def _median(x: np.ndarray) -> np.ndarray:
    return np.median(x, axis=-1)


def check_test_sets(n_sets: int) -> int:
    """``n_sets`` if it is a valid number of paper test sets (0: none), else one
    :class:`InputError` line."""
    if not 0 <= n_sets <= len(TEST_SEEDS):
        raise InputError(f"--test-sets must be in [0, {len(TEST_SEEDS)}], got {n_sets}")
    return n_sets


def default_test_paths(training_path: str, n_sets: int) -> list[str]:
    """Paths of the first ``n_sets`` paper test data sets (:data:`TEST_SEEDS`), made like the
    training set (its person model, trajectory count and persons per trajectory); simulated
    and cached on first use (minutes each)."""
    from core.dataset import Dataset
    from core.optimization.data import person_model_of
    from core.pipeline import paper_dataset_file

    check_test_sets(n_sets)
    train = Dataset.load(training_path)
    model = person_model_of(training_path)
    return [
        str(
            paper_dataset_file(
                seed,
                train.n_trajectories,
                person_model=model,
                n_persons=max(int(train.n_persons), 1),
            )
        )
        for seed in TEST_SEEDS[:n_sets]
    ]


def score_test_sets(
    params: dict[str, Any],
    paths: Sequence[str],
    *,
    training_path: str | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> list[SetScore]:
    """Track every test data set with TrackerParams JSON ``params``; scores per set and class.

    Parameters
    ----------
    params
        TrackerParams JSON (CV or CA).
    paths
        Test data-set files.
    training_path
        When given, a test set made with another radar configuration is refused
        (:func:`core.optimization.validation.check_same_radar`).
    progress
        Called with (sets done, sets) after each set.

    Returns
    -------
    list[SetScore]
        In the order of ``paths``; ``loss["total"]`` is the set's ``L_t`` (eq. 14), as
        :func:`core.evaluation.evaluate` gives it.
    """
    from core.dataset import Dataset
    from core.optimization.objective import TrackerLosses, evaluate

    if not paths:
        raise InputError("no test data sets given")
    if training_path is not None:
        for p in paths:
            check_same_radar(training_path, p, "test")
    out = []
    for i, p in enumerate(paths):
        ds = Dataset.load(p)
        r = evaluate(TrackerLosses(ds), params)
        classes = np.array([str(ds.trajectory_class[k]).upper() for k in r.order])
        loss, capped = np.array(r.losses), np.array(r.capped)
        never = np.array(r.n_c) == 0
        groups = {c: classes == c for c in sorted(set(classes.tolist()))}
        groups["total"] = np.ones(len(classes), dtype=bool)
        out.append(
            SetScore(
                dataset=str(p),
                seed=int(ds.seed),
                loss={c: float(loss[m].mean()) for c, m in groups.items()},
                capped={c: float(capped[m].mean()) for c, m in groups.items()},
                unconfirmed={c: float(never[m].mean()) for c, m in groups.items()},
            )
        )
        if progress is not None:
            progress(i + 1, len(paths))
    return out


def summarise(scores: Sequence[SetScore], metric: str = "loss") -> dict[str, Spread]:
    """Per class and in total: mean and median of ``metric`` over the sets, with 95 % bootstrap
    intervals over the sets (a class missing from a set is left out for that set)."""
    if metric not in METRICS:
        raise InputError(f"metric must be one of {', '.join(METRICS)}, got {metric!r}")
    keys = sorted({c for s in scores for c in getattr(s, metric)} - {"total"}) + ["total"]
    out = {}
    for c in keys:
        x = np.array([getattr(s, metric)[c] for s in scores if c in getattr(s, metric)])
        if not len(x):
            continue
        mean, mean_lo, mean_hi = bootstrap_interval(_mean, x)
        median, median_lo, median_hi = bootstrap_interval(_median, x)
        out[c] = Spread(n_sets=len(x), mean=mean, mean_lo=mean_lo, mean_hi=mean_hi,
                        median=median, median_lo=median_lo, median_hi=median_hi)  # fmt: skip
    return out


def compare_models(cv: Sequence[SetScore], ca: Sequence[SetScore]) -> dict[str, float]:
    """CV / CA ratio of the median and of the mean per-set ``L_t``, with paired bootstrap 95 %
    intervals over the test sets (both models must have been scored on the same sets)."""
    if [s.dataset for s in cv] != [s.dataset for s in ca]:
        raise InputError("CV and CA were scored on different test data sets; cannot pair them")
    a = np.array([s.loss["total"] for s in cv])
    b = np.array([s.loss["total"] for s in ca])
    med, med_lo, med_hi = bootstrap_interval(lambda x, y: _median(x) / _median(y), a, b)
    mean, mean_lo, mean_hi = bootstrap_interval(lambda x, y: _mean(x) / _mean(y), a, b)
    return {
        "n_sets": len(a),
        "median_ratio": med,
        "median_ratio_lo": med_lo,
        "median_ratio_hi": med_hi,
        "mean_ratio": mean,
        "mean_ratio_lo": mean_lo,
        "mean_ratio_hi": mean_hi,
        "cv_better_sets": int(np.sum(a < b)),
    }


def chosen_params(
    storage: str, studies: Sequence[str], model: str
) -> tuple[dict[str, Any], str, int, str]:
    """The chosen parameters among ``studies`` (all of one motion model ``model``).

    The trial with the lowest validation objective when any study recorded a ``validation``
    user attribute (:func:`core.optimization.validation.validate_study`; with
    ``tune --repeats`` the choice is among all studies' validated trials), else the best trial
    by training objective. Returns (TrackerParams JSON, study, trial number, ``"validation"`` or
    ``"training"``).
    """
    from core.optimization.storage import load_existing_study, open_storage, redact
    from core.tracking.space import tracker_params_dict

    store = open_storage(storage, create=False)
    validated: list[tuple[float, str, int, Any]] = []
    trained: list[tuple[float, str, int, Any]] = []
    for name in studies:
        s = load_existing_study(store, name)
        if s is None:
            raise InputError(f"no study {name!r} in {redact(storage)}")
        done = {
            t.number: t
            for t in s.get_trials(deepcopy=False)
            if t.state.name == "COMPLETE" and t.value is not None
        }
        record = (s.user_attrs.get("validation") or {}).get("trials") or {}
        validated += [(float(v[0]), name, int(k), done[int(k)]) for k, v in record.items()
                      if int(k) in done]  # fmt: skip
        trained += [(float(t.value), name, n, t) for n, t in done.items()]
    pool, how = (validated, "validation") if validated else (trained, "training")
    if not pool:
        raise InputError(f"no completed trial in the {model.upper()} studies {list(studies)}")
    _, name, number, trial = min(pool, key=lambda v: (v[0], v[1], v[2]))
    flat = {k: float(v) for k, v in trial.params.items()}
    return tracker_params_dict(flat, model), name, number, how


__all__ = [
    "METRICS",
    "SetScore",
    "Spread",
    "check_test_sets",
    "chosen_params",
    "compare_models",
    "default_test_paths",
    "score_test_sets",
    "summarise",
]

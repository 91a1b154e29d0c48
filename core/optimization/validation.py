"""Held-out data: training, validation and test sets from separate seeds; choosing by validation.

A study minimises its objective on a *training* data set. Its best trial there is the one that
fitted that data set best, rare events included, so it is not what a study reports: the
:data:`TOP_K` best trials by training objective are tracked again on a *validation* data set of
another seed, and the trial with the lowest validation objective is the study's choice
(:func:`validate_study`). ``radartune tune --repeats K`` runs K studies (sampler seeds
``seed … seed + K − 1``, training sets of seeds ``s … s + K − 1``) and chooses among all their
validated trials. The chosen parameters are judged on *test* sets (:data:`TEST_SEEDS`) that
neither the studies nor the choice saw.

Paper data sets (``paper:SEED``) of the three roles never share a seed: training seeds lie below
:data:`VALIDATION_SEED`, test seeds above it.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import Any

from core.errors import InputError
from core.optimization.objective import (
    evaluate,
    make_losses,
    tracker_losses,
    uses_capped,
    without_positions,
)
from core.optimization.storage import load_existing_study, open_storage, redact

#: Seed of the paper validation data set (training seeds must lie below it).
VALIDATION_SEED = 1000
#: Seeds of the paper test data sets.
TEST_SEEDS = tuple(range(2000, 2020))
#: Trials of a study re-tracked on the validation set (the best by training objective).
TOP_K = 10


@dataclass(frozen=True, slots=True, kw_only=True)
class ValidatedTrial:
    """One trial tracked again on the validation set.

    ``train_value``: the study's objective on its training set; ``validation_value``: the same
    objective on the validation set; ``validation_paper_loss``: the paper's L_t there (m²).
    ``params`` are TrackerParams JSON.
    """

    study: str
    number: int
    params: dict[str, Any]
    train_value: float
    validation_value: float
    validation_paper_loss: float

    def to_dict(self) -> dict[str, Any]:
        return {
            "study": self.study,
            "trial": self.number,
            "train_value": self.train_value,
            "validation_value": self.validation_value,
            # None on a validation set without truth (JSON has no NaN)
            "validation_paper_loss": (
                self.validation_paper_loss if math.isfinite(self.validation_paper_loss) else None
            ),
            "params": self.params,
        }


def check_training_seed(seed: int, n_repeats: int = 1) -> None:
    """Training seeds ``seed … seed + n_repeats − 1`` must lie below :data:`VALIDATION_SEED`."""
    if n_repeats < 1:
        raise InputError(f"--repeats must be >= 1, got {n_repeats}")
    if seed < 0 or seed + n_repeats - 1 >= VALIDATION_SEED:
        raise InputError(
            f"training data sets paper:{seed}…paper:{seed + n_repeats - 1} must use seeds in "
            f"[0, {VALIDATION_SEED}); {VALIDATION_SEED} and above are the validation and test sets"
        )


def radar_of(path: str) -> dict[str, Any]:
    """The radar configuration a data set was made with (its ``radar_json``), parsed."""
    from core.dataset import Dataset

    text = Dataset.load(path).radar_json
    return json.loads(text) if text else {}


def check_same_radar(training: str, other: str, role: str) -> None:
    """One :class:`InputError` line when ``other`` was made with another radar than ``training``.

    Parameters
    ----------
    training, other
        Data-set paths.
    role
        ``"validation"`` or ``"test"``: named in the message.
    """
    a, b = radar_of(training), radar_of(other)
    keys = sorted(k for k in a.keys() | b.keys() if not _same_setting(a.get(k), b.get(k)))
    if keys:
        raise InputError(
            f"{role} data set {other!r} was made with another radar configuration than the "
            f"training set {training!r} (differs in {', '.join(keys[:4])})"
        )


#: Relative difference up to which two numeric radar settings are the same: a recording's frame
#: period is measured from its time stamps (0.0993-0.1000 s over three files of one sensor).
RADAR_TOLERANCE = 0.02


def _same_setting(a: Any, b: Any) -> bool:
    """Equal, or two numbers within :data:`RADAR_TOLERANCE` of each other."""
    numbers = (int, float)
    if isinstance(a, numbers) and isinstance(b, numbers) and not isinstance(a, bool):
        return math.isclose(float(a), float(b), rel_tol=RADAR_TOLERANCE)
    return bool(a == b)


def validate_study(
    storage: str, name: str, validation_path: str, *, top_k: int = TOP_K
) -> list[ValidatedTrial]:
    """Track the ``top_k`` best trials of a study on the validation set; best first.

    The study records them in its user attribute ``validation``
    (``{"dataset": path, "loss": objective, "trials": {number: [value, paper L_t]}}``; Optuna
    cannot change a finished trial); trials validated before on the same data set with the same
    objective are not tracked again.

    Returns
    -------
    list[ValidatedTrial]
        Sorted by validation objective (then trial number); empty when no trial completed.
    """
    from core.dataset import Dataset
    from core.tracking.space import GTRACK, tracker_params_dict

    if top_k < 1:
        raise InputError(f"top_k must be >= 1, got {top_k}")
    store = open_storage(storage, create=False)
    study = load_existing_study(store, name)
    if study is None:
        raise InputError(f"no study {name!r} in {redact(storage)}")
    attrs = dict(study.user_attrs)
    model = str(attrs.get("model", ""))
    loss = str(attrs.get("loss", "paper"))
    if attrs.get("objective", "tracker") != "tracker":
        raise InputError(f"study {name!r} does not track a data set; nothing to validate")
    training = [str(attrs["dataset"])] if attrs.get("dataset") else []
    training += [str(p) for p, _ in attrs.get("mix") or []]
    if training:
        # a mixed study's validation set is made with the radar of one of its training sets
        errors = []
        for path in training:
            try:
                check_same_radar(path, validation_path, "validation")
                break
            except InputError as exc:
                errors.append(exc)
        else:
            raise errors[0]
    record = attrs.get("validation") or {}
    if record.get("dataset") != validation_path or record.get("loss") != loss:
        record = {"dataset": validation_path, "loss": loss, "trials": {}}
    known = dict(record.get("trials") or {})
    done = [
        t
        for t in study.get_trials(deepcopy=False)
        if t.state.name == "COMPLETE" and t.value is not None and math.isfinite(t.value)
    ]
    best = sorted(done, key=lambda t: (t.value, t.number))[:top_k]
    from core.optimization.mix import objective_for, recording_objective

    people = attrs.get("people")
    val_set = Dataset.load(validation_path)
    # the study's objective where the validation set has what it needs, else the recording one
    loss = objective_for(
        val_set, loss, str(attrs.get("recording_loss") or recording_objective(people)), people
    )
    if model == GTRACK:  # gtrack's own loss source, with the study's fixed gtrack lines
        losses = make_losses(
            "tracker", model, val_set, capped=uses_capped(loss),
            without_positions=without_positions(loss), people=people,
            **dict(attrs.get("objective_options") or {}),
        )  # fmt: skip
    else:
        losses = tracker_losses(val_set, loss, people=people)
    out = []
    for t in best:
        params = tracker_params_dict(
            {k: float(v) for k, v in t.params.items()}, model, str(attrs.get("mode", "paper"))
        )
        if str(t.number) in known:
            value, paper = (float(x) for x in known[str(t.number)])
        else:
            r = evaluate(losses, params, loss=loss)
            value, paper = r.value, r.paper_value
            known[str(t.number)] = [value, paper]
        out.append(
            ValidatedTrial(
                study=name,
                number=t.number,
                params=params,
                train_value=float(t.value),
                validation_value=value,
                validation_paper_loss=paper,
            )
        )
    study.set_user_attr("validation", {**record, "trials": known})
    return sorted(out, key=lambda v: (v.validation_value, v.number))


__all__ = [
    "TEST_SEEDS",
    "TOP_K",
    "VALIDATION_SEED",
    "ValidatedTrial",
    "check_same_radar",
    "check_training_seed",
    "radar_of",
    "validate_study",
]

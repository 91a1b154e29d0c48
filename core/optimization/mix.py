"""Mixed studies: one parameter set judged on several data sets at once (simulated and recorded).

A study's training set (``--dataset``) may be joined by others (``--mix DATASET=WEIGHT``), e.g.
the paper's open field with a recording of a real room. Each data set is scored with the
objective that fits it (:func:`objective_for`): the study's ``--loss`` where the data set has what
it needs (:data:`core.evaluation.robust.OBJECTIVE_NEEDS`), else the study's recording objective
(``fragmentation`` with a head count, else ``nis``). The objectives differ in units and scale
(m² for the paper's loss, tracks a frame for a count), so each is divided by the value the
model's default parameters get on the same data set:

``J(θ) = Σ_i w_i · J_i(θ) / J_i(θ₀) / Σ_i w_i``

— every term is "times the default tracker's", and the weights say how much each data set
matters. A default value of 0 (nothing to improve) divides by 1 instead. A mixed trial is
scored whole: no pruning (the parts have different trajectories and objectives).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from core.errors import InputError

__all__ = ["MixPart", "MixedObjective", "objective_for", "parse_mix", "recording_objective"]


@dataclass(frozen=True, slots=True, kw_only=True)
class MixPart:
    """One data set of a mixed study: ``dataset`` (a path or ``paper:SEED[:MODEL]``) and its
    ``weight`` (> 0)."""

    dataset: str
    weight: float = 1.0

    def __post_init__(self) -> None:
        if not self.dataset:
            raise InputError("--mix: the data set is empty")
        if not (math.isfinite(self.weight) and self.weight > 0):
            raise InputError(f"--mix {self.dataset}: weight must be > 0, got {self.weight}")

    def to_dict(self) -> dict[str, Any]:
        return {"dataset": self.dataset, "weight": self.weight}


def parse_mix(text: str) -> MixPart:
    """``DATASET`` or ``DATASET=WEIGHT`` → :class:`MixPart` (one InputError line if bad)."""
    name, sep, w = str(text).rpartition("=")
    if not sep:
        return MixPart(dataset=str(text))
    try:
        weight = float(w)
    except ValueError:
        raise InputError(f"--mix {text!r}: the weight {w!r} is not a number") from None
    return MixPart(dataset=name, weight=weight)


def recording_objective(people: int | None) -> str:
    """The objective of a data set without truth: fragmentation with a head count, else nis."""
    return "fragmentation" if people is not None else "nis"


def objective_for(dataset: Any, loss: str, recording_loss: str, people: int | None) -> str:
    """``loss`` if ``dataset`` has what it needs, else ``recording_loss``."""
    from core.evaluation.robust import OBJECTIVE_NEEDS
    from core.formats.recording import has_truth

    need = OBJECTIVE_NEEDS[loss]
    if need == "truth" and not has_truth(dataset):
        return recording_loss
    if need == "reference layer" and not dataset.has_reference:
        return recording_loss
    return loss


class MixedObjective:
    """``J(θ)`` of the module over the data sets ``parts`` (loaded :class:`Dataset`, weight).

    Parameters
    ----------
    parts
        ``(dataset, weight)`` pairs; the first is the study's own ``--dataset``.
    model
        ``"cv"`` or ``"ca"``: the default parameters θ₀ of the normalisation.
    loss, recording_loss, people
        The study's objective, the objective of data sets without what it needs, the head count.
    """

    def __init__(
        self,
        parts: list[tuple[Any, float]],
        model: str,
        *,
        loss: str,
        recording_loss: str,
        people: int | None,
    ) -> None:
        from core.optimization.objective import evaluate, tracker_losses
        from core.tracking import TrackerParams

        if not parts:
            raise InputError("a mixed study needs at least one data set")
        self.losses = []
        self.objectives = []
        self.weights = [float(w) for _, w in parts]
        self.baselines = []
        default = TrackerParams.default(model).to_dict()
        for ds, _ in parts:
            obj = objective_for(ds, loss, recording_loss, people)
            src = tracker_losses(ds, obj, people=people)
            self.losses.append(src)
            self.objectives.append(obj)
            v0 = evaluate(src, default, loss=obj).value
            self.baselines.append(v0 if v0 > 0 else 1.0)

    def evaluate(self, params: dict[str, Any]) -> Any:
        """The trial's :class:`~core.optimization.objective.TrialResult`: ``value`` J(θ), the
        first data set's per-trajectory scores and paper loss."""
        from dataclasses import replace

        from core.optimization.objective import evaluate

        parts = [
            evaluate(src, params, loss=obj)
            for src, obj in zip(self.losses, self.objectives, strict=True)
        ]
        total = sum(
            w * r.value / b for w, r, b in zip(self.weights, parts, self.baselines, strict=True)
        )
        return replace(parts[0], value=total / sum(self.weights))

    def part_values(self, params: dict[str, Any]) -> list[float]:
        """Each data set's own objective value (not normalised), in order."""
        from core.optimization.objective import evaluate

        return [
            evaluate(src, params, loss=obj).value
            for src, obj in zip(self.losses, self.objectives, strict=True)
        ]

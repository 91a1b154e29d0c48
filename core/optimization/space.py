"""The search space of eq. (15) as Optuna sees it: the one place that calls ``suggest_*``.

The table itself (names, symbols, units, bounds, scales, models, defaults) and the flat ⇄
TrackerParams JSON mapping are :mod:`core.tracking.space`'s; this module only maps the table to
Optuna. Optuna parameter names are the :class:`core.tracking.TrackerParams` JSON keys, with the
initial state standard deviations ``p0`` spelled ``p0_00`` … ``p0_55`` (the diagonal of P(0|0)).
The CV model never samples ``p0_44`` and ``p0_55``; the CA model samples all six. Parameters are
suggested in table order (changing it changes every seeded study).
"""

from __future__ import annotations

from typing import Protocol

from core.tracking.space import (
    GTRACK,
    MODELS,
    P0_NAMES,
    SEARCH_SPACE,
    Parameter,
    check_model,
    check_tuned,
    search_space,
)

__all__ = [
    "GTRACK",
    "MODELS",
    "P0_NAMES",
    "SEARCH_SPACE",
    "Parameter",
    "check_model",
    "check_tuned",
    "search_space",
    "suggest_params",
]


class SuggestsFloats(Protocol):
    """What :func:`suggest_params` needs from an Optuna trial."""

    def suggest_float(self, name: str, low: float, high: float, *, log: bool = False) -> float: ...

    def suggest_int(self, name: str, low: int, high: int, *, log: bool = False) -> int: ...


def suggest_params(trial: SuggestsFloats, model: str, mode: str = "paper") -> dict[str, float]:
    """Sample one point of the space with the trial's sampler; flat dict by Optuna name
    (whole numbers for integer rows: gtrack's counters and point threshold). The room mode
    suggests the paper's rows, then the room tracker's (the paper mode never samples those)."""
    return {
        b.name: trial.suggest_int(b.name, int(b.low), int(b.high), log=b.log)
        if b.integer
        else trial.suggest_float(b.name, b.low, b.high, log=b.log)
        for b in search_space(model, mode)
    }

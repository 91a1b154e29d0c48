"""The search space of eq. (15) as Optuna sees it: the one place that calls ``suggest_*``.

The table itself (names, symbols, units, bounds, scales, models, defaults) is
:data:`core.tracking.space.SEARCH_SPACE`; this module only maps it to Optuna. Optuna parameter
names are the :class:`core.tracking.TrackerParams` JSON keys, with the initial state standard
deviations ``p0`` spelled ``p0_00`` … ``p0_55`` (the diagonal of P(0|0)). The CV model never
samples ``p0_44`` and ``p0_55``; the CA model samples all six. Parameters are suggested in table
order (changing it changes every seeded study).
"""

from __future__ import annotations

from typing import Any, Protocol

from core.errors import InputError
from core.tracking.space import (
    GTRACK,
    MODELS,
    P0_NAMES,
    SEARCH_SPACE,
    STATE_DIM,
    Parameter,
    check_model,
    check_tuned,
    p0_names,
    search_space,
)

__all__ = [
    "MODELS",
    "P0_NAMES",
    "SEARCH_SPACE",
    "Parameter",
    "check_model",
    "check_tuned",
    "flat_params",
    "search_space",
    "suggest_params",
    "tracker_params_dict",
]


class SuggestsFloats(Protocol):
    """What :func:`suggest_params` needs from an Optuna trial."""

    def suggest_float(self, name: str, low: float, high: float, *, log: bool = False) -> float: ...

    def suggest_int(self, name: str, low: int, high: int, *, log: bool = False) -> int: ...


def suggest_params(trial: SuggestsFloats, model: str) -> dict[str, float]:
    """Sample one point of the space with the trial's sampler; flat dict by Optuna name
    (whole numbers for integer rows: gtrack's counters and point threshold)."""
    return {
        b.name: trial.suggest_int(b.name, int(b.low), int(b.high), log=b.log)
        if b.integer
        else trial.suggest_float(b.name, b.low, b.high, log=b.log)
        for b in search_space(model)
    }


def tracker_params_dict(flat: dict[str, Any], model: str) -> dict[str, Any]:
    """Flat Optuna parameters → TrackerParams JSON (SPEC §6): ``p0_ii`` become the ``p0`` list.

    Keys not in the search space (``p_g``, thresholds, clutter density) are left out so that
    they take the TrackerParams defaults.
    """
    names = [b.name for b in search_space(model)]
    missing = [n for n in names if n not in flat]
    if missing:
        raise InputError(f"parameters missing for model {model}: {', '.join(missing)}")
    if model == GTRACK:  # GtrackParams JSON: the rows by name, counters as integers
        return {
            b.name: int(round(float(flat[b.name]))) if b.integer else float(flat[b.name])
            for b in search_space(model)
        }
    out: dict[str, Any] = {"model": model}
    for n in names:
        if n not in P0_NAMES:
            out[n] = float(flat[n])
    out["p0"] = [float(flat[p]) for p in p0_names(model)]
    return out


def flat_params(params: dict[str, Any]) -> dict[str, float]:
    """TrackerParams JSON → flat Optuna parameters (inverse of :func:`tracker_params_dict`).

    Used to enqueue known parameters (``study.enqueue_trial``); values outside the bounds are an
    error naming the field.
    """
    if "model" not in params and any(b.name in params for b in search_space(GTRACK)):
        flat: dict[str, float] = {}
        for b in search_space(GTRACK):
            if b.name not in params:
                raise InputError(f"parameter {b.name} missing")
            value = float(params[b.name])
            if not b.low <= value <= b.high:
                raise InputError(f"{b.name} must be in [{b.low}, {b.high}], got {value}")
            flat[b.name] = value
        return flat
    model = check_model(str(params.get("model", "cv")))
    p0 = list(params.get("p0", []))
    n_p0 = STATE_DIM[model]
    if len(p0) != n_p0:
        raise InputError(f"p0 must have {n_p0} entries for model {model}, got {len(p0)}")
    flat = {}
    for b in search_space(model):
        if b.name in P0_NAMES:
            value = float(p0[P0_NAMES.index(b.name)])
        elif b.name in params:
            value = float(params[b.name])
        else:
            raise InputError(f"parameter {b.name} missing")
        if not b.low <= value <= b.high:
            raise InputError(f"{b.name} must be in [{b.low}, {b.high}], got {value}")
        flat[b.name] = value
    return flat

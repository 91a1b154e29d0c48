"""The search space of the paper's eq. (15): the one place that maps parameters to ``suggest_*``.

Optuna parameter names are the :class:`core.tracking.TrackerParams` JSON keys, with the initial
state standard deviations ``p0`` spelled ``p0_00`` … ``p0_55`` (the diagonal of P(0|0)).
The CV model never samples ``p0_44`` and ``p0_55``; the CA model samples all six.
Ranges spanning a decade or more are sampled on a log scale (SPEC §5).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol

from core.errors import InputError

MODELS = ("cv", "ca")


@dataclass(frozen=True, slots=True, kw_only=True)
class Bound:
    """One optimised parameter: its Optuna name, closed interval and scale."""

    name: str
    low: float
    high: float
    log: bool
    #: which motion models sample it
    models: tuple[str, ...] = MODELS
    #: label for plots and the GUI
    label: str = ""

    def __post_init__(self) -> None:
        if not self.low < self.high:
            raise InputError(f"bound {self.name}: low must be < high, got {self.low}, {self.high}")
        if self.log and self.low <= 0:
            raise InputError(f"bound {self.name}: a log scale needs low > 0, got {self.low}")


#: eq. (15) of the paper, in the order the paper lists them.
SEARCH_SPACE: tuple[Bound, ...] = (
    Bound(name="q_coeff", low=0.1, high=30.0, log=True, label="q_coeff"),
    Bound(name="r11", low=0.01, high=0.5, log=True, label="r11 (range σ, m)"),
    Bound(name="r22", low=0.01, high=0.2, log=True, label="r22 (azimuth σ, rad)"),
    Bound(name="r33", low=0.1, high=3.0, log=True, label="r33 (radial velocity σ, m/s)"),
    Bound(name="p0_00", low=0.1, high=10.0, log=True, label="p0,00 (x σ, m)"),
    Bound(name="p0_11", low=0.1, high=10.0, log=True, label="p0,11 (y σ, m)"),
    Bound(name="p0_22", low=0.01, high=10.0, log=True, label="p0,22 (vx σ, m/s)"),
    Bound(name="p0_33", low=0.01, high=10.0, log=True, label="p0,33 (vy σ, m/s)"),
    Bound(name="p0_44", low=0.001, high=10.0, log=True, models=("ca",), label="p0,44 (ax σ)"),
    Bound(name="p0_55", low=0.001, high=10.0, log=True, models=("ca",), label="p0,55 (ay σ)"),
    Bound(name="p_d", low=0.8, high=0.99, log=False, label="P_D"),
    Bound(name="p_te", low=0.2, high=1.0, log=False, label="P_te"),
    Bound(name="p11", low=0.7, high=1.0, log=False, label="p11"),
    Bound(name="p21", low=0.0, high=0.4, log=False, label="p21"),
)

P0_NAMES = ("p0_00", "p0_11", "p0_22", "p0_33", "p0_44", "p0_55")


def check_model(model: str) -> str:
    """Return ``model`` if it is a known motion model, else raise :class:`InputError`."""
    if model not in MODELS:
        raise InputError(f"model must be one of {', '.join(MODELS)}, got {model!r}")
    return model


def search_space(model: str) -> tuple[Bound, ...]:
    """The bounds sampled for ``model`` (``"cv"``: 12 parameters, ``"ca"``: 14)."""
    check_model(model)
    return tuple(b for b in SEARCH_SPACE if model in b.models)


class SuggestsFloats(Protocol):
    """What :func:`suggest_params` needs from an Optuna trial."""

    def suggest_float(self, name: str, low: float, high: float, *, log: bool = False) -> float: ...


def suggest_params(trial: SuggestsFloats, model: str) -> dict[str, float]:
    """Sample one point of the space with the trial's sampler; flat dict by Optuna name."""
    return {
        b.name: trial.suggest_float(b.name, b.low, b.high, log=b.log) for b in search_space(model)
    }


def tracker_params_dict(flat: dict[str, Any], model: str) -> dict[str, Any]:
    """Flat Optuna parameters → TrackerParams JSON (SPEC §6): ``p0_ii`` become the ``p0`` list.

    Keys not in the search space (``p_g``, thresholds, clutter density) are left out so that
    they take the TrackerParams defaults.
    """
    check_model(model)
    names = [b.name for b in search_space(model)]
    missing = [n for n in names if n not in flat]
    if missing:
        raise InputError(f"parameters missing for model {model}: {', '.join(missing)}")
    n_p0 = 6 if model == "ca" else 4
    out: dict[str, Any] = {"model": model}
    for n in names:
        if not n.startswith("p0_"):
            out[n] = float(flat[n])
    out["p0"] = [float(flat[p]) for p in P0_NAMES[:n_p0]]
    return out


def flat_params(params: dict[str, Any]) -> dict[str, float]:
    """TrackerParams JSON → flat Optuna parameters (inverse of :func:`tracker_params_dict`).

    Used to enqueue known parameters (``study.enqueue_trial``); values outside the bounds are an
    error naming the field.
    """
    model = check_model(str(params.get("model", "cv")))
    p0 = list(params.get("p0", []))
    n_p0 = 6 if model == "ca" else 4
    if len(p0) != n_p0:
        raise InputError(f"p0 must have {n_p0} entries for model {model}, got {len(p0)}")
    flat: dict[str, float] = {}
    for b in search_space(model):
        if b.name.startswith("p0_"):
            value = float(p0[P0_NAMES.index(b.name)])
        elif b.name in params:
            value = float(params[b.name])
        else:
            raise InputError(f"parameter {b.name} missing")
        if not b.low <= value <= b.high:
            raise InputError(f"{b.name} must be in [{b.low}, {b.high}], got {value}")
        flat[b.name] = value
    return flat

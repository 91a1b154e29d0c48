"""Which parameters matter: importance from a study's trials, one-at-a-time sweeps at the optimum.

- :func:`parameter_importance` — Optuna's PED-ANOVA importance evaluator
  (:class:`optuna.importance.PedAnovaImportanceEvaluator`; Watanabe et al., "PED-ANOVA:
  Efficiently quantifying hyperparameter importance in arbitrary subspaces", IJCAI 2023) on the
  completed trials of one study: how much each parameter of eq. (15) separates the best trials
  (the top ``γ'`` quantile of the objective) from all trials, as the Pearson divergence of their
  Parzen densities; the importances sum to 1. PED-ANOVA is the one of Optuna's three evaluators
  that needs no other package: fANOVA and mean decrease impurity fit a scikit-learn random
  forest, which RadarTune does not depend on. Only COMPLETE trials enter (a pruned trial's value
  is the loss of a prefix of the trajectories, not comparable).
- :func:`oat_sweep` — one-at-a-time sensitivity: every parameter of the model's search space
  (:data:`core.tracking.space.SEARCH_SPACE`) swept across its bounds on a grid even in the
  sampling scale (logarithmic where the space is), the others held at the optimum, scored with
  the objective's own :func:`core.optimization.objective.evaluate` on one or more loss sources
  (training, held-out). The optimum's own value is always one of the grid points, so the sweep
  passes through the optimum's loss exactly.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from core.errors import InputError
from core.optimization.objective import TrajectoryLosses, evaluate
from core.optimization.progress import TrialSummary
from core.optimization.space import search_space
from core.tracking.space import flat_params, tracker_params_dict

#: The importance evaluator used (see the module docstring for why this one).
IMPORTANCE_EVALUATOR = "PED-ANOVA"
#: Fewest COMPLETE trials an importance is computed from.
MIN_IMPORTANCE_TRIALS = 10
#: PED-ANOVA's top quantile γ' is raised from Optuna's 0.1 until it holds this many trials
#: (Optuna's advice for a stable estimate), to at most 0.5.
MIN_TOP_TRIALS = 5
#: Grid points of a one-at-a-time sweep (the optimum's value is added to them).
OAT_POINTS = 15


@dataclass(frozen=True, slots=True, kw_only=True)
class Importance:
    """PED-ANOVA importances of one study.

    ``values`` maps every parameter of the model's search space, in table order, to its
    importance (≥ 0, summing to 1); ``n_trials`` COMPLETE trials were used, ``target_quantile``
    is PED-ANOVA's γ'.
    """

    model: str
    n_trials: int
    target_quantile: float
    values: dict[str, float]

    def ranked(self) -> list[tuple[str, float]]:
        """(parameter, importance), most important first (ties in table order)."""
        return sorted(self.values.items(), key=lambda kv: -kv[1])

    def to_dict(self) -> dict[str, Any]:
        return {
            "evaluator": IMPORTANCE_EVALUATOR,
            "model": self.model,
            "n_trials": self.n_trials,
            "target_quantile": self.target_quantile,
            "values": dict(self.values),
        }


def parameter_importance(trials: Sequence[TrialSummary], model: str) -> Importance:
    """PED-ANOVA importance of every parameter of ``model``'s space from a study's trials.

    Parameters
    ----------
    trials
        The study's trials (:func:`core.optimization.progress.study_progress`); only COMPLETE
        ones with a finite value and every parameter of the space are used.
    model
        ``"cv"`` or ``"ca"``.

    Returns
    -------
    Importance
        Raises :class:`InputError` with fewer than :data:`MIN_IMPORTANCE_TRIALS` usable trials.
    """
    import optuna
    from optuna.distributions import FloatDistribution
    from optuna.importance import PedAnovaImportanceEvaluator, get_param_importances

    space = search_space(model)
    dists = {b.name: FloatDistribution(b.low, b.high, log=b.log) for b in space}
    done = [
        t
        for t in trials
        if t.state == "COMPLETE"
        and t.value is not None
        and math.isfinite(t.value)
        and all(b.name in t.params and b.low <= t.params[b.name] <= b.high for b in space)
    ]
    if len(done) < MIN_IMPORTANCE_TRIALS:
        raise InputError(
            f"parameter importance needs at least {MIN_IMPORTANCE_TRIALS} completed trials, "
            f"got {len(done)}"
        )
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    study = optuna.create_study(direction="minimize")  # in memory, from the summaries
    study.add_trials(
        [
            optuna.trial.create_trial(
                params={n: float(t.params[n]) for n in dists},
                distributions=dists,
                value=float(t.value),
            )
            for t in done
        ]
    )
    q = min(0.5, max(0.1, MIN_TOP_TRIALS / len(done)))
    imp = get_param_importances(
        study,
        evaluator=PedAnovaImportanceEvaluator(target_quantile=q),
        params=list(dists),
        normalize=True,
    )
    values = {n: float(imp.get(n, 0.0)) for n in dists}
    return Importance(model=model, n_trials=len(done), target_quantile=q, values=values)


@dataclass(frozen=True, slots=True, kw_only=True)
class Sweep:
    """One parameter swept on one loss source, the others at the optimum.

    ``values`` (SI units of the parameter, ascending) include the optimum's value at
    ``optimum_index``; ``loss`` is the paper's ``L_t`` (eq. 14, m²) and ``capped`` the mean
    capped loss (m², :mod:`core.evaluation.robust`) at each value.
    """

    parameter: str
    values: tuple[float, ...]
    loss: tuple[float, ...]
    capped: tuple[float, ...]
    optimum_index: int

    def to_dict(self) -> dict[str, Any]:
        return {
            "parameter": self.parameter,
            "values": list(self.values),
            "loss": list(self.loss),
            "capped": [None if not math.isfinite(c) else c for c in self.capped],
            "optimum_index": self.optimum_index,
        }


def sweep_values(name: str, optimum: float, n_points: int = OAT_POINTS) -> np.ndarray:
    """``n_points`` values across the bounds of parameter ``name``, evenly spaced in its
    sampling scale (log where the space is log), plus ``optimum`` (which replaces a grid point
    equal to it up to rounding); ascending, unique."""
    from core.tracking.space import parameter

    if n_points < 2:
        raise InputError(f"a sweep needs at least 2 points, got {n_points}")
    b = parameter(name)
    if b.log:
        grid = np.geomspace(b.low, b.high, n_points)
    else:
        grid = np.linspace(b.low, b.high, n_points)
    grid[0], grid[-1] = b.low, b.high  # the bounds exactly (geomspace may round)
    # a grid point that is the optimum up to rounding gives way to the optimum itself
    scale = np.log if b.log else (lambda v: v)
    width = scale(b.high) - scale(b.low)
    near = np.abs(scale(grid) - scale(float(optimum))) <= 1e-9 * width
    return np.unique(np.append(grid[~near], float(optimum)))


def oat_sweep(
    sources: Mapping[str, TrajectoryLosses],
    params: dict[str, Any],
    *,
    n_points: int = OAT_POINTS,
    progress: Callable[[str], None] | None = None,
) -> dict[str, dict[str, Sweep]]:
    """One-at-a-time sensitivity of ``params`` (TrackerParams JSON) on every loss source.

    Parameters
    ----------
    sources
        Label → loss source (:class:`core.optimization.objective.TrackerLosses` with the capped
        loss on, for a data set); e.g. ``{"training": …, "held-out": …}``.
    params
        The optimum, TrackerParams JSON; keys outside the search space (``clutter_density``,
        thresholds) are kept in every evaluation.
    n_points
        Grid points per parameter (:func:`sweep_values`).
    progress
        Called with a line after each parameter.

    Returns
    -------
    dict
        ``{label: {parameter: Sweep}}``, parameters in table order. The sweep's loss at
        ``optimum_index`` is ``evaluate(source, params).paper_value`` itself.
    """
    model = str(params.get("model", "cv"))
    flat = flat_params(params)
    extra = {k: v for k, v in params.items() if k not in flat and k not in ("p0", "model")}
    out: dict[str, dict[str, Sweep]] = {label: {} for label in sources}
    for b in search_space(model):
        xs = sweep_values(b.name, flat[b.name], n_points)
        at = int(np.flatnonzero(xs == flat[b.name])[0])
        for label, src in sources.items():
            loss, capped = [], []
            for x in xs:
                p = {**extra, **tracker_params_dict({**flat, b.name: float(x)}, model)}
                r = evaluate(src, p, loss="paper")
                loss.append(r.paper_value)
                capped.append(float(np.mean(r.capped)))
            out[label][b.name] = Sweep(parameter=b.name, values=tuple(float(x) for x in xs),
                                       loss=tuple(loss), capped=tuple(capped),
                                       optimum_index=at)  # fmt: skip
        if progress is not None:
            progress(f"{model.upper()}: {b.name} swept")
    return out


__all__ = [
    "IMPORTANCE_EVALUATOR",
    "MIN_IMPORTANCE_TRIALS",
    "MIN_TOP_TRIALS",
    "OAT_POINTS",
    "Importance",
    "Sweep",
    "oat_sweep",
    "parameter_importance",
    "sweep_values",
]

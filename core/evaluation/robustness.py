"""Clutter robustness: fixed tracker parameters re-tracked under other clutter than tuned for.

Two kinds of mismatch between the tracker and the data:

- the tracker's **clutter density** ρ (:attr:`core.tracking.TrackerParams.clutter_density`, per
  m · rad · m/s; 0.0073 by default, not optimised) scaled by a factor while the data stay the
  same: the parameters are re-tracked with ``ρ' = f_ρ · ρ``;
- the **scene clutter rate** λ of the data (Poisson clutter reflectors per m² of the area of
  interest per frame, :attr:`core.scene.Scene.clutter_density_per_m2`; the paper's 0.02 m⁻²)
  different from the one tuned on: the caller passes data sets simulated with another λ (for
  paper data sets, :func:`core.optimization.data.paper_dataset_variant`) and the tracker's ρ
  stays as given.

:func:`clutter_robustness` tracks every data set with every ρ factor and returns one
:class:`ClutterRow` per pair: the paper's ``L_t`` (eq. 14), the median trajectory loss, the
capped loss (:mod:`core.evaluation.robust`), the fraction of frames with a confirmed track and
the trajectories never confirmed (``N_c = 0``, scored 1 m² by eq. 13). With factor 1 a row is
the plain evaluation (:func:`core.evaluation.evaluate` of :func:`core.tracking.track_dataset`)
bit for bit. It knows nothing of studies or reports: the report and the CV / CA campaign both
call it.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from core.dataset import Dataset
from core.errors import InputError
from core.evaluation.robust import trajectory_capped_losses, trajectory_far_frames
from core.evaluation.table import evaluate
from core.tracking import TrackerParams, track_dataset

#: The ρ factors of the issue: ×0.2 … ×5 (ρ = 0.0073 × 5 ≈ 0.037).
RHO_FACTORS: tuple[float, ...] = (0.2, 0.5, 1.0, 2.0, 5.0)
#: The λ factors of the data sets the report makes (×1 is the data set itself).
LAMBDA_FACTORS: tuple[float, ...] = (0.5, 1.0, 2.0)


@dataclass(frozen=True, slots=True, kw_only=True)
class ClutterRow:
    """One data set tracked with one ρ factor.

    Attributes
    ----------
    dataset
        The caller's label of the data set.
    clutter_per_m2
        The data set's scene clutter rate λ (m⁻², read from its scenes; NaN if it records none,
        or its scenes disagree).
    rho_factor, clutter_density
        ``f_ρ`` and the tracker's ``ρ' = f_ρ · ρ`` (per m · rad · m/s).
    loss_total
        ``L_t`` (eq. 14, m²), as :func:`core.evaluation.evaluate` gives it.
    median_loss
        Median of the trajectory losses ``L(k)`` (m²).
    capped_total
        Mean capped loss ``C(k)`` over the trajectories (m², :mod:`core.evaluation.robust`).
    confirmed_fraction
        Fraction of the frames with a confirmed track (:attr:`Evaluation.confirmed_fraction`).
    n_never_confirmed, n_trajectories
        Trajectories with ``N_c = 0``, and all trajectories.
    losses, capped, n_c, far_frames
        Per trajectory (K,), in the data set's order: ``L(k)`` (eq. 13) and ``C(k)`` (m²), the
        confirmed frames ``N_c(k)`` and the frames whose estimate is more than 1 m off
        (:func:`core.evaluation.robust.trajectory_far_frames`), for statistics of the caller's
        own (tails, catastrophic runs, bootstrap intervals).
    """

    dataset: str
    clutter_per_m2: float
    rho_factor: float
    clutter_density: float
    loss_total: float
    median_loss: float
    capped_total: float
    confirmed_fraction: float
    n_never_confirmed: int
    n_trajectories: int
    losses: tuple[float, ...]
    capped: tuple[float, ...]
    n_c: tuple[int, ...]
    far_frames: tuple[int, ...]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (NaN as None)."""
        d = dataclasses.asdict(self)
        for key in ("losses", "capped", "n_c", "far_frames"):
            d[key] = list(d[key])
        return {k: None if isinstance(v, float) and not math.isfinite(v) else v
                for k, v in d.items()}  # fmt: skip


@dataclass(frozen=True, slots=True, kw_only=True)
class ClutterRobustness:
    """Every (data set, ρ factor) pair of one parameter set, data set-major, factors in order."""

    params: dict[str, Any]
    rho_factors: tuple[float, ...]
    rows: tuple[ClutterRow, ...]

    def row(self, dataset: str, rho_factor: float) -> ClutterRow:
        """The row of ``dataset`` tracked with ``rho_factor``; KeyError if there is none."""
        for r in self.rows:
            if r.dataset == dataset and r.rho_factor == rho_factor:
                return r
        raise KeyError((dataset, rho_factor))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: the parameters, the factors and the rows."""
        return {
            "params": self.params,
            "rho_factors": list(self.rho_factors),
            "rows": [r.to_dict() for r in self.rows],
        }


def scene_clutter_rate(dataset: Dataset) -> float:
    """λ (m⁻²) of the scenes a data set was simulated from; NaN when none is recorded or the
    scenes disagree (read from the stored scene JSON, key ``clutter_density_per_m2``)."""
    try:
        scenes = dataset.scene()
    except ValueError:
        return math.nan
    items = scenes if isinstance(scenes, list) else [scenes]
    rates = {
        float(s["clutter_density_per_m2"])
        for s in items
        if isinstance(s, dict) and isinstance(s.get("clutter_density_per_m2"), int | float)
    }
    return rates.pop() if len(rates) == 1 else math.nan


def clutter_robustness(
    params: TrackerParams,
    datasets: Mapping[str, Dataset],
    rho_factors: Sequence[float] = RHO_FACTORS,
) -> ClutterRobustness:
    """Track every data set with the tracker's clutter density ρ scaled by every factor.

    Parameters
    ----------
    params
        The parameters under test (a parametric ``clutter_density`` ρ: the nonparametric
        estimate has nothing to scale).
    datasets
        Label → data set, e.g. ``{"training": ds, "training, λ ×2": ds_2}``; data sets with
        another scene clutter rate λ are simulated by the caller (:func:`scene_clutter_rate`
        reads λ back for the rows).
    rho_factors
        Factors ``f_ρ`` > 0; the tracker runs with ``ρ' = f_ρ · ρ`` (``f_ρ = 1``: ρ itself,
        exactly).

    Returns
    -------
    ClutterRobustness
        ``len(datasets) · len(rho_factors)`` rows, data set-major.
    """
    if params.nonparametric:
        raise InputError("clutter_robustness needs a numeric clutter_density to scale, got "
                         f"clutter_density={params.clutter_density!r}")  # fmt: skip
    factors = tuple(float(f) for f in rho_factors)
    bad = [f for f in factors if not (math.isfinite(f) and f > 0)]
    if not factors or bad:
        raise InputError(f"rho_factors must be positive numbers, got {list(rho_factors)}")
    if not datasets:
        raise InputError("clutter_robustness needs at least one data set")
    rho = float(params.clutter_density)
    rows = []
    for label, ds in datasets.items():
        lam = scene_clutter_rate(ds)
        for f in factors:
            # ρ' = f_ρ · ρ
            p = dataclasses.replace(params, clutter_density=rho * f)
            est = track_dataset(ds, p, with_tracks=True)
            ev = evaluate(ds, est)
            capped = trajectory_capped_losses(ds, est)
            rows.append(
                ClutterRow(
                    dataset=str(label),
                    clutter_per_m2=lam,
                    rho_factor=f,
                    clutter_density=rho * f,
                    loss_total=float(ev.loss_total),
                    median_loss=float(np.median(ev.loss)) if len(ev.loss) else math.nan,
                    capped_total=float(np.mean(capped)) if capped else math.nan,
                    confirmed_fraction=float(ev.confirmed_fraction),
                    n_never_confirmed=int(np.sum(ev.n_c == 0)),
                    n_trajectories=len(ev.loss),
                    losses=tuple(float(v) for v in ev.loss),
                    capped=tuple(float(v) for v in capped),
                    n_c=tuple(int(v) for v in ev.n_c),
                    far_frames=tuple(int(v) for v in trajectory_far_frames(ds, est)),
                )
            )
    return ClutterRobustness(params=params.to_dict(), rho_factors=factors, rows=tuple(rows))


__all__ = [
    "LAMBDA_FACTORS",
    "RHO_FACTORS",
    "ClutterRobustness",
    "ClutterRow",
    "clutter_robustness",
    "scene_clutter_rate",
]

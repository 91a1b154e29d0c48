"""CV against CA: parameter pairs tracked on the paper data sets, compared trajectory by trajectory.

``radartune bench cvca [--quick]`` writes ``bench/results/cvca.json``. For every data set
(paper:0 and paper:1 with the point person, paper:0 with the extended person; cached by
:func:`core.pipeline.paper_dataset`) and every committed pair of CV and CA tracker parameters
(:data:`PAIRS`, those whose files exist):

- ``L_t`` of both models (eq. 14) and the paired comparison over the trajectories
  (:func:`core.evaluation.paired_comparison`: ratio of the totals with a class-stratified
  bootstrap interval, wins, Wilcoxon);
- the motion model isolated: CA's parameters with the CV model (the acceleration entries of
  p0 dropped) and q_coeff re-scanned (:data:`Q_GRID` and CA's own q), the best against CA's
  own, paired (decision evaluation-04, item 4);
- per class, each model's loss split into transient, manoeuvre and steady frames
  (:func:`core.evaluation.loss_breakdown`), with N_c, the first confirmed frame and the
  mean along-track error;

and per data set the spread of its person-labelled points against the truth
(:func:`core.evaluation.person_point_spread`). Tracking only: nothing is tuned, nothing is
simulated once the data sets are cached.

This replaces the one-off scripts ``bench/report_recheck.py`` (docs/report/current-chain/
recheck.json), the loss breakdown of ``bench/cvca2_diagnose.py`` (docs/report/cv-vs-ca.md §2)
and ``bench/cvca_cross_eval.py`` (docs/report/extended-person/cross_evaluation.json).

``--quick``: the first five trajectories (one per class) of paper:0, simulated without the
cache, the default CV and CA parameters, 5 values of q; seconds once numba's cache is warm.
"""

from __future__ import annotations

import dataclasses
import json
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from core.dataset import Dataset
from core.evaluation import (
    evaluate,
    loss_breakdown,
    paired_comparison,
    person_point_spread,
    track_with_ids,
    trajectory_losses,
)
from core.pipeline import paper_dataset
from core.tracking import TrackerParams, track_dataset

#: Committed CV/CA parameter pairs: name -> (CV file, CA file); ``polish:<model>`` is the
#: ``params`` entry of docs/report/cv-vs-ca/polish.json.
PAIRS: dict[str, tuple[str, str]] = {
    "report (docs/report/best_*.json)": (
        "docs/report/best_cv.json",
        "docs/report/best_ca.json",
    ),
    "current chain (docs/report/current-chain/best_*.json)": (
        "docs/report/current-chain/best_cv.json",
        "docs/report/current-chain/best_ca.json",
    ),
    "extended person (docs/report/extended-person/best_*.json)": (
        "docs/report/extended-person/best_cv.json",
        "docs/report/extended-person/best_ca.json",
    ),
    "best of 8 seeds x 1000 trials, polished (docs/report/cv-vs-ca/polish.json)": (
        "polish:cv",
        "polish:ca",
    ),
}
POLISH_FILE = "docs/report/cv-vs-ca/polish.json"
#: (label, seed, person model) of the data sets of the full run
DATASETS = (("paper:0", 0, "point"), ("paper:1", 1, "point"), ("paper:0:extended", 0, "extended"))
QUICK_TRAJECTORIES = 5
#: q_coeff values of the matched comparison: log-spaced over eq. (15)'s range [0.1, 30]
Q_GRID = tuple(np.geomspace(0.1, 30.0, 25).tolist())
QUICK_Q_GRID = tuple(np.geomspace(0.1, 30.0, 5).tolist())


@dataclass(frozen=True, slots=True, kw_only=True)
class ModelRun:
    """One parameter set tracked on one data set: per-trajectory losses and their breakdown."""

    loss: np.ndarray  # (K,) L(k) in m², eq. (12)
    loss_total: float  # L_t in m², eq. (14)
    breakdown: list[dict[str, Any]]  # LossBreakdown.class_table()


def params_from_ref(ref: str, root: Path = Path(".")) -> TrackerParams:
    """A :data:`PAIRS` entry: a TrackerParams JSON file, or ``polish:<model>``."""
    if ref.startswith("polish:"):
        models = json.loads((root / POLISH_FILE).read_text())["models"]
        return TrackerParams.from_dict(models[ref.split(":", 1)[1]]["params"])
    return TrackerParams.load(root / ref)


def available_pairs(root: Path = Path(".")) -> dict[str, tuple[TrackerParams, TrackerParams]]:
    """The :data:`PAIRS` whose files exist under ``root``, loaded."""
    out = {}
    for name, refs in PAIRS.items():
        files = [root / (POLISH_FILE if r.startswith("polish:") else r) for r in refs]
        if all(f.is_file() for f in files):
            out[name] = (params_from_ref(refs[0], root), params_from_ref(refs[1], root))
    return out


def track_model(dataset: Dataset, params: TrackerParams) -> ModelRun:
    """Track ``dataset`` with ``params``; losses from :func:`core.evaluation.evaluate` and
    their split by frame kind from :func:`core.evaluation.loss_breakdown`."""
    estimates, ids = track_with_ids(dataset, params)
    ev = evaluate(dataset, estimates)
    period = float(json.loads(dataset.radar_json)["frame_period_s"])
    bd = loss_breakdown(dataset, estimates, estimate_ids=ids, period_s=period)
    return ModelRun(
        loss=np.asarray(ev.loss, dtype=float),
        loss_total=float(ev.loss_total),
        breakdown=bd.class_table(),
    )


def matched(
    dataset: Dataset, params_ca: TrackerParams, loss_ca: np.ndarray, q_grid: tuple[float, ...]
) -> dict:
    """CA's parameters with the CV motion model, q_coeff re-scanned, against CA's own losses.

    The grid is ``q_grid`` plus CA's own q_coeff; everything but the motion model, the
    acceleration entries of p0 and q_coeff is CA's. Losses in m².
    """
    cv = dataclasses.replace(params_ca, model="cv", p0=tuple(params_ca.p0 or ())[:4])
    grid = sorted({*q_grid, params_ca.q_coeff})
    per_q = [
        trajectory_losses(dataset, track_dataset(dataset, dataclasses.replace(cv, q_coeff=q)))
        for q in grid
    ]
    totals = [float(v.mean()) for v in per_q]
    i = int(np.argmin(totals))
    classes = np.asarray(dataset.trajectory_class).astype(str)
    return {
        "q_grid": grid,
        "loss_total": totals,
        "best_q": grid[i],
        "best_x1e3": 1e3 * totals[i],
        "paired_with_ca": paired_comparison(per_q[i], loss_ca, classes).to_dict(),
    }


def compare(
    dataset: Dataset,
    params_cv: TrackerParams,
    params_ca: TrackerParams,
    q_grid: tuple[float, ...] = Q_GRID,
) -> dict:
    """Both parameter sets on one data set, their paired comparison and the matched one."""
    runs = {"cv": track_model(dataset, params_cv), "ca": track_model(dataset, params_ca)}
    classes = np.asarray(dataset.trajectory_class).astype(str)
    pc = paired_comparison(runs["cv"].loss, runs["ca"].loss, classes)
    return {
        "cv_x1e3": 1e3 * runs["cv"].loss_total,
        "ca_x1e3": 1e3 * runs["ca"].loss_total,
        "paired": pc.to_dict(),
        "matched_cv_with_ca_params": matched(dataset, params_ca, runs["ca"].loss, q_grid),
        "trajectory_loss": {m: r.loss.tolist() for m, r in runs.items()},
        "breakdown": {m: r.breakdown for m, r in runs.items()},
    }


def datasets(quick: bool = False) -> dict[str, Dataset]:
    """The data sets of the run (see the module docstring), by label."""
    if quick:
        return {"paper:0 (first 5)": paper_dataset(0, QUICK_TRAJECTORIES, use_cache=False)}
    return {
        label: paper_dataset(seed, 35, person_model=person, jobs=2)
        for label, seed, person in DATASETS
    }


def pairs(quick: bool = False) -> dict[str, tuple[TrackerParams, TrackerParams]]:
    """The parameter pairs of the run: the committed ones, or the defaults when quick."""
    if quick:
        return {"defaults": (TrackerParams(model="cv"), TrackerParams(model="ca"))}
    return available_pairs()


def table(
    sets: dict[str, Dataset],
    params: dict[str, tuple[TrackerParams, TrackerParams]],
    q_grid: tuple[float, ...] = Q_GRID,
) -> dict:
    """Every pair on every data set (:func:`compare`), and each data set's point spread."""
    rows = []
    for label, ds in sets.items():
        for name, (p_cv, p_ca) in params.items():
            rows.append({"dataset": label, "parameters": name, **compare(ds, p_cv, p_ca, q_grid)})
    return {
        "datasets": {
            label: {
                "trajectories": int(ds.n_trajectories),
                "frames": int(ds.n_frames),
                "points": len(ds.frame),
                "spread": person_point_spread(ds).to_dict(),
            }
            for label, ds in sets.items()
        },
        "parameters": {
            name: {"cv": p_cv.to_dict(), "ca": p_ca.to_dict()}
            for name, (p_cv, p_ca) in params.items()
        },
        "rows": rows,
    }


def run(quick: bool = False) -> dict:
    t0 = time.perf_counter()
    sets = datasets(quick)
    t1 = time.perf_counter()
    out = table(sets, pairs(quick), QUICK_Q_GRID if quick else Q_GRID)
    return {**out, "datasets_s": t1 - t0, "tracking_s": time.perf_counter() - t1}


def summary(result: dict) -> str:
    lines = ["CV against CA, L_t x1e-3 (eq. 14), paired over the trajectories:"]
    for r in result["rows"]:
        p, m = r["paired"], r["matched_cv_with_ca_params"]
        lines.append(
            f"  {r['dataset']:<18} {r['parameters'][:40]:<40} CV {r['cv_x1e3']:8.4f}  "
            f"CA {r['ca_x1e3']:8.4f}  CV/CA {p['ratio']:.2f} [{p['ci_low']:.2f}, "
            f"{p['ci_high']:.2f}]  wins {p['wins_a']}/{p['wins_b']}  CV with CA's parameters "
            f"{m['best_x1e3']:8.4f} (q {m['best_q']:.3g})"
        )
    return "\n".join(lines)

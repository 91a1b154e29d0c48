"""CV against CA over sampler seeds: does the comparison survive the optimiser's own noise?

``radartune bench cvca_seeds [--quick]`` writes ``bench/results/cvca_seeds.json``. Long: 16
studies of 1000 trials (about 1–4 min each on the 2-core machine) and the polish.

1. Per model (CV, CA) and sampler seed 0–7, a TPE + ASHA study of 1000 trials with 2 workers
   on the training set paper:0, as ``radartune tune --jobs 2 --sampler tpe --pruner asha``
   runs it (one study at a time, in a journal file in a temporary folder).
2. Each study's best parameters re-tracked on paper:0 and on the independent set paper:1
   (nothing is selected there); per model the median, min and max over seeds, and the best
   value within the first 300 trials (a 300-trial study of the same seed, up to the workers'
   interleaving).
3. CV against CA trajectory by trajectory (:func:`core.evaluation.paired_comparison`) for
   every seed and for the best of all seeds, on both sets.
4. Each model's best of all seeds polished by coordinate search inside eq. (15)
   (:func:`polish`) on paper:0, then compared again on both sets.

This replaces ``bench/cvca2_settle.py``, ``bench/cvca2_polish.py`` and ``bench/cvca2_summary.py``
(docs/report/cv-vs-ca.md §3, run at commit 1aec029).

``--quick``: seeds 0 and 1, 6 trials per study, run in this process, on the first five
trajectories of paper:0 and paper:1 (simulated, not cached); polish with 3 points, 1 sweep.
"""

from __future__ import annotations

import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from core.dataset import Dataset
from core.evaluation import paired_comparison, trajectory_losses
from core.optimization.space import search_space
from core.pipeline import paper_dataset
from core.tracking import TrackerParams, track_dataset
from core.tracking.space import flat_params, tracker_params_dict

MODELS = ("cv", "ca")
EARLY_BUDGET = 300


@dataclass(frozen=True, slots=True, kw_only=True)
class Settings:
    """One run of the benchmark."""

    seeds: tuple[int, ...] = tuple(range(8))
    n_trials: int = 1000
    n_jobs: int = 2
    n_trajectories: int = 35
    polish_points: int = 13
    polish_sweeps: int = 3
    in_process: bool = False  # run the studies' trials in this process (one worker)


QUICK = Settings(
    seeds=(0, 1), n_trials=6, n_jobs=1, n_trajectories=5, polish_points=3, polish_sweeps=1,
    in_process=True,
)  # fmt: skip


def losses(dataset: Dataset, params: dict[str, Any]) -> np.ndarray:
    """L(k) of every trajectory (m², eq. 12) with TrackerParams JSON ``params``."""
    return trajectory_losses(dataset, track_dataset(dataset, TrackerParams.from_dict(params)))


def polish(
    dataset: Dataset, params: dict[str, Any], points: int, sweeps: int
) -> tuple[dict[str, Any], list[float], int]:
    """Coordinate search from ``params`` (TrackerParams JSON) inside the search space.

    Every optimised parameter in turn is set to each of ``points`` values spread over its range
    (log-spaced where the space is log-scaled) with the others held; a value is kept when it
    lowers L_t. Sweeps repeat until one changes nothing or ``sweeps`` is reached.

    Returns
    -------
    params, history, evaluations
        The polished TrackerParams JSON, L_t (m²) at the start and after each sweep
        (non-increasing), and the number of tracker runs over the data set.
    """
    model = params["model"]
    flat = flat_params(params)
    best = float(losses(dataset, tracker_params_dict(flat, model)).mean())
    history, n_eval = [best], 1
    for _ in range(sweeps):
        changed = False
        for b in search_space(model):
            grid = (
                np.geomspace(b.low, b.high, points) if b.log else np.linspace(b.low, b.high, points)
            )
            for v in grid:
                trial = dict(flat, **{b.name: float(v)})
                val = float(losses(dataset, tracker_params_dict(trial, model)).mean())
                n_eval += 1
                if val < best:
                    best, flat, changed = val, trial, True
        history.append(best)
        if not changed:
            break
    return tracker_params_dict(flat, model), history, n_eval


def _best(trials: list[Any], limit: int | None = None) -> Any:
    """The best COMPLETE trial (lowest value, then number) among the first ``limit`` finished."""
    done = sorted((t for t in trials if t.state in ("COMPLETE", "PRUNED")), key=lambda t: t.number)
    done = done[:limit] if limit is not None else done
    complete = [t for t in done if t.state == "COMPLETE" and t.value is not None]
    return min(complete, key=lambda t: (t.value, t.number)) if complete else None


def run_study(
    model: str, seed: int, s: Settings, storage: str, dataset_path: str
) -> tuple[str, list[Any]]:
    """One TPE + ASHA study; returns its name and its trials (TrialSummary)."""
    from core.optimization.progress import study_progress
    from core.optimization.study import StudySettings, prepare_study, run_worker, start_study

    settings = StudySettings(
        model=model,
        n_trials=s.n_trials,
        n_jobs=s.n_jobs,
        storage=storage,
        study_name=f"{model}-tpe-asha-{s.n_trials}-s{seed}",
        seed=seed,
        sampler="tpe",
        pruner="asha",
        loss="paper",  # the paper objective, as its documented run (before the trimmed default)
        dataset=dataset_path,
    )
    if s.in_process:
        prepare_study(settings, dataset_path=dataset_path)
        run_worker(storage, settings.name, seed=seed, dataset_path=dataset_path)
    else:
        start_study(settings, dataset_path=dataset_path).wait()
    trials, _ = study_progress(storage, settings.name)
    return settings.name, trials


def _stats(values: list[float]) -> dict[str, Any]:
    a = np.asarray(values, dtype=float)
    return {"median": float(np.median(a)), "min": float(a.min()), "max": float(a.max()),
            "values": a.tolist()}  # fmt: skip


def _paired(a: np.ndarray, b: np.ndarray, classes: np.ndarray) -> dict[str, Any]:
    return paired_comparison(a, b, classes).to_dict()


def measure(s: Settings, sets: dict[str, Dataset], workdir: Path) -> dict[str, Any]:
    """Steps 1–4 of the module docstring; ``sets``: ``"paper:0"`` (training), ``"paper:1"``."""
    train_path = str(sets["paper:0"].save(workdir / "paper0.npz"))
    storage = f"journal:///{(workdir / 'studies.log').resolve()}"
    classes = {k: np.asarray(d.trajectory_class).astype(str) for k, d in sets.items()}
    studies: dict[str, dict[str, Any]] = {}
    loss: dict[str, dict[str, np.ndarray]] = {}
    for seed in s.seeds:
        for model in MODELS:
            t0 = time.perf_counter()
            name, trials = run_study(model, seed, s, storage, train_path)
            wall = time.perf_counter() - t0
            best, early = _best(trials), _best(trials, EARLY_BUDGET)
            if best is None:
                continue
            params = best.tracker_params(model)
            loss[name] = {k: losses(d, params) for k, d in sets.items()}
            studies[name] = {
                "model": model,
                "seed": seed,
                "trials": sum(1 for t in trials if t.state in ("COMPLETE", "PRUNED")),
                "pruned": sum(1 for t in trials if t.state == "PRUNED"),
                "wall_s": wall,
                "best_trial": best.number,
                "best_value": best.value,
                f"best_value_first_{EARLY_BUDGET}": early.value if early else None,
                "params": params,
                **{k: float(v.mean()) for k, v in loss[name].items()},
            }
    by_model = {m: [n for n, r in studies.items() if r["model"] == m] for m in MODELS}
    per_model: dict[str, dict[str, Any]] = {
        m: {
            "studies": names,
            "best_value": _stats([studies[n]["best_value"] for n in names]),
            **{k: _stats([studies[n][k] for n in names]) for k in sets},
        }
        for m, names in by_model.items()
        if names
    }
    out: dict[str, Any] = {"settings": _settings_dict(s), "studies": studies}
    out["per_model"] = per_model
    if not (by_model["cv"] and by_model["ca"]):
        return out
    out["median_ratio_cv_over_ca"] = {
        k: per_model["cv"][k]["median"] / per_model["ca"][k]["median"]
        for k in ("best_value", *sets)
    }
    pairs = {
        f"seed {seed}": (f"cv-tpe-asha-{s.n_trials}-s{seed}", f"ca-tpe-asha-{s.n_trials}-s{seed}")
        for seed in s.seeds
    }
    best_of = {m: min(by_model[m], key=lambda n: studies[n]["best_value"]) for m in MODELS}
    pairs["best of all seeds"] = (best_of["cv"], best_of["ca"])
    out["paired"] = {
        label: {"cv": a, "ca": b} | {k: _paired(loss[a][k], loss[b][k], classes[k]) for k in sets}
        for label, (a, b) in pairs.items()
        if a in loss and b in loss
    }
    polished: dict[str, Any] = {}
    for m in MODELS:
        start = studies[best_of[m]]["params"]
        params, history, n_eval = polish(sets["paper:0"], start, s.polish_points, s.polish_sweeps)
        polished[m] = {
            "start_study": best_of[m],
            "history": history,
            "evaluations": n_eval,
            "params": params,
            "loss": {k: losses(d, params) for k, d in sets.items()},
        }
    out["polished"] = {
        m: {k: v for k, v in p.items() if k != "loss"}
        | {k: float(v.mean()) for k, v in p["loss"].items()}
        for m, p in polished.items()
    }
    out["polished_paired"] = {
        k: _paired(polished["cv"]["loss"][k], polished["ca"]["loss"][k], classes[k]) for k in sets
    }
    return out


def _settings_dict(s: Settings) -> dict[str, Any]:
    return {f: getattr(s, f) for f in Settings.__slots__}


def datasets(s: Settings) -> dict[str, Dataset]:
    """paper:0 (training) and paper:1 (independent) with ``s.n_trajectories`` trajectories."""
    cached = s.n_trajectories == 35
    return {
        f"paper:{seed}": paper_dataset(seed, s.n_trajectories, use_cache=cached, jobs=2)
        for seed in (0, 1)
    }


def run(quick: bool = False) -> dict:
    s = QUICK if quick else Settings()
    t0 = time.perf_counter()
    sets = datasets(s)
    with tempfile.TemporaryDirectory(prefix="radartune-cvca-seeds-") as tmp:
        out = measure(s, sets, Path(tmp))
    return {**out, "wall_s": time.perf_counter() - t0}


def summary(result: dict) -> str:
    lines = ["CV against CA over sampler seeds, L_t x1e-3:"]
    for name, r in result["studies"].items():
        lines.append(
            f"  {name:<24} best {r['best_value'] * 1e3:9.4f}  paper:0 {r['paper:0'] * 1e3:9.4f}"
            f"  paper:1 {r['paper:1'] * 1e3:9.4f}"
        )
    for k, v in result.get("median_ratio_cv_over_ca", {}).items():
        lines.append(f"  median CV / median CA, {k}: {v:.2f}")
    for k, p in result.get("polished_paired", {}).items():
        lines.append(
            f"  polished best of all seeds, {k}: CV/CA {p['ratio']:.2f} "
            f"[{p['ci_low']:.2f}, {p['ci_high']:.2f}]  wins {p['wins_a']}/{p['wins_b']}"
        )
    return "\n".join(lines)

"""The objective comparison and CV against CA, run as pre-registered (decision evaluation-07).

``radartune bench campaign [--quick]`` writes ``bench/results/campaign.json`` and renders the
tables and plots (``--render-only`` re-renders them from the JSON). Long: about 48 studies.

A. **Objective comparison.** Every position objective
   (:data:`core.evaluation.robust.POSITION_OBJECTIVES`) × CV, CA × study indices ``0 … n−1``:
   a TPE + ASHA study (sampler seed *i*, training set
   ``paper:i:walking``, one worker, journal storage), its choice by validation on
   ``paper:1000:walking`` among its 10 best trials (:func:`validate_study`), that choice scored
   on the 20 test sets ``paper:2000 … 2019:walking`` (:func:`score_choice`) — also with the
   tracker's clutter density ρ scaled by :data:`RHO_FACTORS`, and on the first
   :attr:`Settings.n_lambda` test sets simulated with the scene clutter rate λ scaled by
   :data:`LAMBDA_FACTORS` (:func:`score_lambda`). The winner by the pre-registered rule
   (:func:`choose_objective`; the λ scores are reported beside it, not part of it).
B. **Final design.** The winner × CV, CA × study indices 0–7, 1000 trials, scored the same way;
   per class and total the median and mean of L over the (study, test set) cells with two-level
   bootstrap intervals (:func:`core.evaluation.intervals.two_level_bootstrap`), the CV / CA ratios
   and the verdict (:func:`verdict`).

Each finished study's record is kept in a work folder (``$RADARTUNE_CAMPAIGN_DIR``, default
``<tmp>/radartune-campaign``) with its journal, so an interrupted campaign resumes where it
stopped; a finished record without λ scores (made before they existed) gets them from its
stored parameters on the next run, and :func:`add_lambda` adds them to a stored result
(``radartune bench campaign --lambda-only``) without running any study. Both clutter checks go
through :func:`core.evaluation.robustness.clutter_robustness`.

``--quick``: 5 trajectories per data set, two objectives, one study per model in phase A and
two in phase B, 6 trials, 3 test sets (the λ check on the first), in this process.
"""

from __future__ import annotations

import json
import os
import tempfile
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from core.evaluation.intervals import two_level_bootstrap
from core.evaluation.robust import FAR_FRAMES, POSITION_OBJECTIVES
from core.files import save_figure

MODELS = ("cv", "ca")
CLASSES = ("A", "B", "C", "D", "E")
#: clutter-density factors of the robustness check (×1 is the test score itself)
RHO_FACTORS = (0.2, 0.5, 2.0, 5.0)
#: scene clutter-rate factors of the λ check (×1 is the test score itself)
LAMBDA_FACTORS = (0.5, 2.0)
#: objectives within this fraction of the lowest relative median are tied (evaluation-07)
TIE = 0.05
#: the verdict's margin: CV not worse than CA by more than 5 %
MARGIN = 1.05
#: the paper's Table I (×10⁻³ m²), per class and total
PAPER_TABLE = {
    "cv": {"A": 1.279, "B": 1.639, "C": 1.142, "D": 0.729, "E": 0.476, "total": 1.021},
    "ca": {"A": 1.283, "B": 1.791, "C": 1.180, "D": 0.709, "E": 0.488, "total": 1.046},
}
PERSON = "walking"


@dataclass(frozen=True, slots=True, kw_only=True)
class Settings:
    """One campaign (decision evaluation-07)."""

    objectives: tuple[str, ...] = POSITION_OBJECTIVES
    compare_seeds: tuple[int, ...] = (0, 1, 2, 3)
    compare_trials: int = 300
    final_seeds: tuple[int, ...] = tuple(range(8))
    final_trials: int = 1000  # evaluation-07 (a 500-trial run: bench/results/campaign-500trials)
    n_test: int = 20
    n_lambda: int = 5  # test sets simulated again with λ × each of LAMBDA_FACTORS
    n_trajectories: int = 35
    parallel: int = 2  # studies at a time
    in_process: bool = False


QUICK = Settings(
    objectives=("paper", "capped"), compare_seeds=(0,), compare_trials=6, final_seeds=(0, 1),
    final_trials=6, n_test=3, n_lambda=1, n_trajectories=5, parallel=1, in_process=True,
)  # fmt: skip


def work_dir(quick: bool) -> Path:
    """Folder of the journals and finished-study records (kept between runs: resumable)."""
    base = os.environ.get("RADARTUNE_CAMPAIGN_DIR") or str(
        Path(tempfile.gettempdir()) / "radartune-campaign"
    )
    out = Path(base) / ("quick" if quick else "full")
    out.mkdir(parents=True, exist_ok=True)
    return out


def lambda_paths(test: list[str], n_lambda: int) -> dict[str, list[str]]:
    """Factor → paths of the first ``n_lambda`` test sets simulated with the scene clutter rate
    λ × that factor (:func:`core.optimization.data.paper_dataset_variant`: simulated on first
    use, cached; everything but the clutter as in the test set)."""
    from core.optimization.data import paper_dataset_variant

    return {
        str(f): [paper_dataset_variant(p, clutter_factor=f) for p in test[:n_lambda]]
        for f in LAMBDA_FACTORS
    }


def data_paths(s: Settings) -> dict[str, Any]:
    """Training (per seed), validation, test and λ-variant data-set paths (walking paper sets,
    cached)."""
    from core.optimization.validation import TEST_SEEDS, VALIDATION_SEED
    from core.pipeline import paper_dataset_file

    def path(seed: int) -> str:
        return str(paper_dataset_file(seed, s.n_trajectories, person_model=PERSON))

    seeds = sorted(set(s.compare_seeds) | set(s.final_seeds))
    test = [path(t) for t in TEST_SEEDS[: s.n_test]]
    return {
        "train": {i: path(i) for i in seeds},
        "validation": path(VALIDATION_SEED),
        "test": test,
        "lambda": lambda_paths(test, s.n_lambda),
    }


def catastrophic_runs(n_c: Any, far_frames: Any) -> int:
    """Trajectories never confirmed (``N_c = 0``) or confirmed but more than 1 m off in
    ≥ :data:`FAR_FRAMES` frames, from per-trajectory ``N_c`` and far-frame counts."""
    n_c, far = np.asarray(n_c), np.asarray(far_frames)
    return int(np.sum(n_c == 0) + np.sum((n_c > 0) & (far >= FAR_FRAMES)))


def score_lambda(params: dict[str, Any], sets: dict[str, list[Any]]) -> dict[str, Any]:
    """Scores of TrackerParams JSON ``params`` on data sets of another scene clutter rate λ.

    Parameters
    ----------
    params
        The choice under test; the tracker's ρ stays as given.
    sets
        λ factor (str) → data sets simulated with λ × that factor (:func:`lambda_paths`).

    Returns
    -------
    dict
        factor → ``{"total": [...], "catastrophic": [...]}`` over the sets: L_t (eq. 14, m²)
        and the catastrophic runs (:func:`catastrophic_runs`), as for the ρ factors of
        :func:`score_choice`.
    """
    from core.evaluation.robustness import clutter_robustness
    from core.tracking import TrackerParams

    base = TrackerParams.from_dict(params)
    out: dict[str, Any] = {}
    for f, datasets in sets.items():
        rows = clutter_robustness(base, {str(i): ds for i, ds in enumerate(datasets)}, (1.0,))
        out[str(f)] = {
            "total": [float(np.mean(row.losses)) for row in rows.rows],
            "catastrophic": [catastrophic_runs(row.n_c, row.far_frames) for row in rows.rows],
        }
    return out


def score_choice(params: dict[str, Any], test_sets: list[Any]) -> dict[str, Any]:
    """Scores of TrackerParams JSON ``params`` on every test set, at ρ and at ρ × each factor.

    Returns
    -------
    dict
        ``loss``: class → list over sets of the mean paper L of that class's trajectories
        (``"total"``: L_t, eq. 14, m²); ``capped``: list over sets of the mean capped loss;
        ``never``, ``clutter``: lists over sets of the trajectories never confirmed and of those
        confirmed but more than 1 m off in ≥ :data:`FAR_FRAMES` frames; ``rho``: factor →
        ``{"total": [...], "catastrophic": [...]}`` over the sets.
    """
    from core.evaluation import trajectory_loss_terms
    from core.evaluation.robust import trajectory_capped_losses, trajectory_far_frames
    from core.evaluation.robustness import clutter_robustness
    from core.tracking import TrackerParams, track_dataset

    base = TrackerParams.from_dict(params)
    out: dict[str, Any] = {
        "loss": {c: [] for c in (*CLASSES, "total")},
        "capped": [],
        "never": [],
        "clutter": [],
        "rho": {str(f): {"total": [], "catastrophic": []} for f in RHO_FACTORS},
    }
    for ds in test_sets:
        classes = np.array([str(c).upper() for c in ds.trajectory_class])
        est = track_dataset(ds, base)
        terms = trajectory_loss_terms(ds, est)
        loss = np.array([t[0] for t in terms])
        n_c = np.array([t[2] for t in terms])
        far = np.array(trajectory_far_frames(ds, est))
        cls = classes[np.asarray(est.trajectories)]
        for c in CLASSES:
            if np.any(cls == c):
                out["loss"][c].append(float(loss[cls == c].mean()))
        out["loss"]["total"].append(float(loss.mean()))
        out["capped"].append(float(np.mean(trajectory_capped_losses(ds, est))))
        out["never"].append(int(np.sum(n_c == 0)))
        out["clutter"].append(int(np.sum((n_c > 0) & (far >= FAR_FRAMES))))
        for row in clutter_robustness(base, {"test": ds}, RHO_FACTORS).rows:
            catastrophic = catastrophic_runs(row.n_c, row.far_frames)
            out["rho"][str(row.rho_factor)]["total"].append(float(np.mean(row.losses)))
            out["rho"][str(row.rho_factor)]["catastrophic"].append(catastrophic)
    return out


def _study(objective: str, model: str, seed: int, trials: int) -> str:
    return f"{objective}-{model}-s{seed}-t{trials}"


def run_studies(
    jobs: list[tuple[str, str, int, int]], paths: dict[str, Any], s: Settings, folder: Path
) -> dict[str, dict[str, Any]]:
    """Run, validate and score every (objective, model, seed, trials) study; records by name.

    Studies whose record exists in ``folder`` are not run again. Up to ``s.parallel`` studies
    run at a time (one worker process each); validation and scoring run here meanwhile.
    """
    from core.dataset import Dataset
    from core.files import write_json_atomic
    from core.optimization.study import StudySettings, prepare_study, run_worker, start_study
    from core.optimization.validation import validate_study

    tests = [Dataset.load(p) for p in paths["test"]]
    lam = {f: [Dataset.load(p) for p in ps] for f, ps in paths["lambda"].items()}
    records: dict[str, dict[str, Any]] = {}
    todo = []
    for job in jobs:
        name = _study(*job)
        rec = folder / f"{name}.json"
        if rec.exists():
            records[name] = json.loads(rec.read_text())
            if "lambda" not in records[name]:  # a record made before the λ check: add it
                records[name]["lambda"] = score_lambda(records[name]["params"], lam)
                write_json_atomic(rec, records[name])
        else:
            todo.append(job)

    def settings(job: tuple[str, str, int, int]) -> StudySettings:
        objective, model, seed, trials = job
        return StudySettings(
            model=model, n_trials=trials, n_jobs=1, storage=f"journal:///{folder}/{_study(*job)}.log",
            study_name=_study(*job), seed=seed, sampler="tpe", pruner="asha",
            dataset=paths["train"][seed], loss=objective,
        )  # fmt: skip

    def finish(job: tuple[str, str, int, int], seconds: float) -> None:
        st = settings(job)
        validated = validate_study(st.storage, st.name, paths["validation"])
        top = validated[0]
        rec = {
            "objective": job[0], "model": job[1], "seed": job[2], "trials": job[3],
            "study_seconds": seconds, "trial": top.number, "train_value": top.train_value,
            "validation_value": top.validation_value,
            "validation_paper_loss": top.validation_paper_loss, "params": top.params,
            **score_choice(top.params, tests), "lambda": score_lambda(top.params, lam),
        }  # fmt: skip
        write_json_atomic(folder / f"{st.name}.json", rec)
        records[st.name] = rec
        print(f"  {st.name}: {seconds:.0f} s, test median L_t "
              f"{np.median(rec['loss']['total']) * 1e3:.4f}e-3", flush=True)  # fmt: skip

    running: list[tuple[tuple[str, str, int, int], Any, float]] = []
    queue = list(todo)
    while queue or running:
        done = [item for item in running if not item[1].is_running()]
        running = [item for item in running if item not in done]
        # the next studies start before the finished ones are validated and scored
        while queue and len(running) < s.parallel:
            job = queue.pop(0)
            st = settings(job)
            t0 = time.monotonic()
            if s.in_process:
                prepare_study(st, dataset_path=st.dataset)
                run_worker(st.storage, st.name, seed=st.seed, dataset_path=st.dataset)
                finish(job, time.monotonic() - t0)
            else:
                running.append((job, start_study(st, dataset_path=st.dataset), t0))
        for job, _, t0 in done:
            finish(job, time.monotonic() - t0)
        if running:
            time.sleep(0.5)
    return records


def _cells(records: list[dict[str, Any]], key: str = "total") -> np.ndarray:
    """(S, T) per-set losses of ``key`` (a class or total), studies in seed order."""
    rs = sorted(records, key=lambda r: r["seed"])
    return np.array([r["loss"][key] for r in rs], dtype=float)


def _median(x: np.ndarray) -> np.ndarray:
    return np.median(x, axis=(-2, -1))


def _mean(x: np.ndarray) -> np.ndarray:
    return np.mean(x, axis=(-2, -1))


def spread(cells: np.ndarray) -> dict[str, float]:
    """Median and mean over the (S, T) cells with two-level bootstrap 95 % intervals."""
    med = two_level_bootstrap(_median, cells)
    mean = two_level_bootstrap(_mean, cells)
    return {"median": med[0], "median_lo": med[1], "median_hi": med[2],
            "mean": mean[0], "mean_lo": mean[1], "mean_hi": mean[2]}  # fmt: skip


def ratios(cv: np.ndarray, ca: np.ndarray) -> dict[str, float]:
    """CV / CA ratio of medians and of means, paired two-level bootstrap 95 % intervals."""
    med = two_level_bootstrap(lambda x, y: _median(x) / _median(y), cv, ca)
    mean = two_level_bootstrap(lambda x, y: _mean(x) / _mean(y), cv, ca)
    return {"median_ratio": med[0], "median_ratio_lo": med[1], "median_ratio_hi": med[2],
            "mean_ratio": mean[0], "mean_ratio_lo": mean[1], "mean_ratio_hi": mean[2],
            "cv_better_cells": int(np.sum(cv < ca)), "cells": int(cv.size)}  # fmt: skip


def verdict(lo: float, hi: float, margin: float = MARGIN) -> str:
    """The pre-registered verdict on the primary ratio's interval [lo, hi] (evaluation-07)."""
    if hi <= margin:
        return "CV not worse than CA by more than 5 %"
    if lo > margin:
        return "CV worse than CA by more than 5 %"
    return "not settled by this design"


def summarise(records: list[dict[str, Any]]) -> dict[str, Any]:
    """One model's (or one objective's) studies: medians, catastrophic runs, seed spread, ρ."""
    cells = _cells(records)
    per_study = np.median(cells, axis=1)
    q1, q3 = np.percentile(per_study, [25, 75])
    never = int(sum(sum(r["never"]) for r in records))
    clutter = int(sum(sum(r["clutter"]) for r in records))
    rho = {}
    for f in RHO_FACTORS:
        x = np.array([r["rho"][str(f)]["total"] for r in sorted(records, key=lambda r: r["seed"])])
        cat = int(sum(sum(r["rho"][str(f)]["catastrophic"]) for r in records))
        rho[str(f)] = {"median": float(np.median(x)), "mean": float(np.mean(x)),
                       "catastrophic": cat}  # fmt: skip
    rho["1.0"] = {"median": float(np.median(cells)), "mean": float(np.mean(cells)),
                  "catastrophic": never + clutter}  # fmt: skip
    extra = {"lambda": summarise_lambda(records)} if all("lambda" in r for r in records) else {}
    return {
        **spread(cells),
        "n_studies": len(records),
        "n_sets": int(cells.shape[1]),
        "never": never,
        "clutter": clutter,
        "catastrophic": never + clutter,
        "per_study_median": per_study.tolist(),
        "seed_iqr_rel": float((q3 - q1) / np.median(cells)),
        "capped_median": float(np.median([r["capped"] for r in records])),
        "rho": rho,
        **extra,
    }


def _ratio_interval(x: np.ndarray, base: np.ndarray) -> tuple[float, float]:
    """95 % interval of ``median(x) / median(base)``, paired (study, set) matrices."""
    _, lo, hi = two_level_bootstrap(lambda a, b: _median(a) / _median(b), x, base)
    return float(lo), float(hi)


def summarise_lambda(records: list[dict[str, Any]]) -> dict[str, Any]:
    """The λ check of one model's (or objective's) studies: per factor (×1: the same first test
    sets as scored plainly) the median and mean of L_t over the (study, set) cells, the ratio of
    the median to the one at ×1 with its paired two-level bootstrap 95 % interval (studies and
    sets resampled together, :func:`~core.evaluation.intervals.two_level_bootstrap`), and the
    catastrophic runs of all cells."""
    rs = sorted(records, key=lambda r: r["seed"])
    n = len(rs[0]["lambda"][str(LAMBDA_FACTORS[0])]["total"])
    base = _cells(rs)[:, :n]
    # the catastrophic runs at λ × 1 are the plain scores' on those sets
    cat1 = int(sum(sum(r["never"][:n]) + sum(r["clutter"][:n]) for r in rs))
    out: dict[str, dict[str, Any]] = {
        "1.0": {"median": float(np.median(base)), "mean": float(np.mean(base)), "ratio": 1.0,
                "catastrophic": cat1}
    }  # fmt: skip
    for f in LAMBDA_FACTORS:
        x = np.array([r["lambda"][str(f)]["total"] for r in rs], dtype=float)
        out[str(f)] = {
            "median": float(np.median(x)),
            "mean": float(np.mean(x)),
            # median L_t at λ × f over median L_t at λ × 1, on the same sets and studies
            "ratio": float(np.median(x) / np.median(base)),
            "ratio_ci95": list(_ratio_interval(x, base)),
            "catastrophic": int(sum(sum(r["lambda"][str(f)]["catastrophic"]) for r in rs)),
        }
    return {"n_sets": n, "n_runs": int(base.size), "factors": out}


def add_lambda(result: dict[str, Any], quick: bool = False) -> dict[str, Any]:
    """A stored campaign result with the λ check added: every record (phase A and B) scored on
    the λ variants from its stored parameters, and the λ summaries beside the others; nothing
    else changes and no study runs. Records that already have λ scores keep them."""
    s = result["settings"]
    n_lambda = int(s.get("n_lambda", (QUICK if quick else Settings()).n_lambda))
    from core.dataset import Dataset

    out = json.loads(json.dumps(result))
    out["settings"]["n_lambda"] = n_lambda
    missing = [
        rec for rec in (*out["objectives"]["records"], *out["final"]["records"])
        if "lambda" not in rec
    ]  # fmt: skip
    if missing:  # the λ variants are simulated (or read from the cache) only when needed
        paths = lambda_paths(result["data"]["test"], n_lambda)
        lam = {f: [Dataset.load(p) for p in ps] for f, ps in paths.items()}
        out["data"]["lambda"] = paths
        for rec in missing:
            rec["lambda"] = score_lambda(rec["params"], lam)
    a = out["objectives"]["records"]
    for o, per in out["objectives"]["table"].items():
        for m in per:
            per[m]["lambda"] = summarise_lambda([r for r in a if r["objective"] == o
                                                 and r["model"] == m])  # fmt: skip
    for m, per in out["final"]["models"].items():
        per["lambda"] = summarise_lambda([r for r in out["final"]["records"] if r["model"] == m])
    return out


def choose_objective(table: dict[str, dict[str, dict[str, Any]]]) -> dict[str, Any]:
    """The pre-registered rule (evaluation-07) on ``table[objective][model]`` summaries."""
    rel = {
        o: 0.5 * sum(table[o][m]["median"] / table["paper"][m]["median"] for m in MODELS)
        for o in table
    }
    low = min(rel.values())
    tied = [o for o in table if rel[o] <= low * (1 + TIE)]
    cat = {o: sum(table[o][m]["catastrophic"] for m in MODELS) for o in table}
    spread_ = {o: sum(table[o][m]["seed_iqr_rel"] for m in MODELS) for o in table}
    order = sorted(tied, key=lambda o: (cat[o], spread_[o], o != "paper"))
    return {"winner": order[0], "relative_median": rel, "tied": tied, "catastrophic": cat,
            "seed_spread": spread_}  # fmt: skip


def analyse_final(records: list[dict[str, Any]]) -> dict[str, Any]:
    """Table I per class and total, the ratios and the verdict, from the final studies."""
    by = {m: [r for r in records if r["model"] == m] for m in MODELS}
    table = {m: {c: spread(_cells(by[m], c)) for c in (*CLASSES, "total")} for m in MODELS}
    ratio = {c: ratios(_cells(by["cv"], c), _cells(by["ca"], c)) for c in (*CLASSES, "total")}
    total = ratio["total"]
    chosen = {}
    for m in MODELS:
        best = min(by[m], key=lambda r: (r["validation_value"], r["seed"]))
        chosen[m] = {"seed": best["seed"], "trial": best["trial"], "params": best["params"],
                     "validation_value": best["validation_value"],
                     "test_median": float(np.median(best["loss"]["total"]))}  # fmt: skip
    return {
        "table": table,
        "ratios": ratio,
        "primary": "median_ratio",
        "verdict": verdict(total["median_ratio_lo"], total["median_ratio_hi"]),
        "secondary_verdict": verdict(total["mean_ratio_lo"], total["mean_ratio_hi"]),
        "models": {m: summarise(by[m]) for m in MODELS},
        "chosen": chosen,
    }


def run(quick: bool = False, settings: Settings | None = None) -> dict[str, Any]:
    """Phase A, the rule, phase B; every record and the analysis, JSON-ready."""
    s = settings or (QUICK if quick else Settings())
    folder = work_dir(quick)
    t0 = time.monotonic()
    paths = data_paths(s)
    print(f"campaign: work folder {folder}", flush=True)
    jobs_a = [(o, m, i, s.compare_trials) for o in s.objectives for m in MODELS
              for i in s.compare_seeds]  # fmt: skip
    rec_a = run_studies(jobs_a, paths, s, folder)
    table = {
        o: {m: summarise([rec_a[_study(o, m, i, s.compare_trials)] for i in s.compare_seeds])
            for m in MODELS}
        for o in s.objectives
    }  # fmt: skip
    choice = choose_objective(table)
    print(f"campaign: objective {choice['winner']} by the rule", flush=True)
    jobs_b = [(choice["winner"], m, i, s.final_trials) for m in MODELS for i in s.final_seeds]
    rec_b = run_studies(jobs_b, paths, s, folder)
    final = [rec_b[_study(*j)] for j in jobs_b]
    result = {
        "settings": asdict(s),
        "design": "docs/decisions/evaluation-07-cv-ca-design.md",
        "data": {
            "train": {str(k): v for k, v in paths["train"].items()},
            "validation": paths["validation"],
            "test": paths["test"],
            "lambda": paths["lambda"],
        },  # fmt: skip
        "objectives": {
            "table": table,
            "choice": choice,
            "records": [rec_a[_study(*j)] for j in jobs_a],
        },  # fmt: skip
        "final": {**analyse_final(final), "records": final},
        "seconds": time.monotonic() - t0,
    }
    for p in render(result, quick=quick):
        print(f"written: {p}", flush=True)
    return result


def report_dirs(quick: bool = False) -> tuple[Path, Path]:
    """(tables and plots, parameters): docs/campaign and docs/report/walking-campaign; quick:
    under bench/results/campaign-quick."""
    if quick:
        q = Path("bench/results/campaign-quick")
        return q, q / "params"
    return Path("docs/campaign"), Path("docs/report/walking-campaign")


def _ratio_cell(x: dict[str, Any]) -> str:
    """``0.98 [0.85, 1.10]``: a λ ratio and its interval (results made before it: the ratio)."""
    ci = x.get("ratio_ci95")
    return f"{x['ratio']:.2f}" + ("" if ci is None else f" [{ci[0]:.2f}, {ci[1]:.2f}]")


def _fmt(x: float) -> str:
    return f"{x * 1e3:.4f}"


def objective_table(result: dict[str, Any]) -> str:
    """Markdown: per objective and model the held-out median and mean of L_t (×10⁻³) with
    intervals, catastrophic runs, seed spread and the medians at ρ × each factor."""
    t = result["objectives"]["table"]
    ch = result["objectives"]["choice"]
    n_runs = {o: {m: t[o][m]["n_studies"] * t[o][m]["n_sets"] for m in MODELS} for o in t}
    fs = [str(f) for f in sorted((*RHO_FACTORS, 1.0))]
    rows = [
        "| objective | model | median L_t [95 %] | mean L_t [95 %] | catastrophic (never / "
        "clutter) of runs | seed IQR / median | R | "
        + " | ".join(f"median at ρ×{f}" for f in fs) + " |",
        "|---|---|---|---|---|---|---|" + "---|" * len(fs),
    ]  # fmt: skip
    for o in t:
        for m in MODELS:
            x = t[o][m]
            n = n_runs[o][m] * result["settings"]["n_trajectories"]
            rows.append(
                f"| {o}{' (winner)' if o == ch['winner'] else ''} | {m.upper()} | "
                f"{_fmt(x['median'])} [{_fmt(x['median_lo'])}, {_fmt(x['median_hi'])}] | "
                f"{_fmt(x['mean'])} [{_fmt(x['mean_lo'])}, {_fmt(x['mean_hi'])}] | "
                f"{x['catastrophic']} ({x['never']} / {x['clutter']}) of {n} | "
                f"{x['seed_iqr_rel']:.2f} | {ch['relative_median'][o]:.3f} | "
                + " | ".join(_fmt(x["rho"][f]["median"]) for f in fs) + " |"
            )  # fmt: skip
    return "\n".join(rows)


def lambda_table(result: dict[str, Any]) -> str:
    """Markdown: per objective and model (then per model of the final design) the median L_t
    (×10⁻³) on the first test sets simulated at λ × 0.5, × 1 and × 2, the ratios to × 1 and the
    catastrophic runs; empty when the result has no λ check."""
    t = result["objectives"]["table"]
    finals = result["final"]["models"]
    if not all("lambda" in t[o][m] for o in t for m in MODELS) or not all(
        "lambda" in finals[m] for m in MODELS
    ):
        return ""
    ch = result["objectives"]["choice"]
    fs = [str(f) for f in sorted((*LAMBDA_FACTORS, 1.0))]
    others = [str(f) for f in sorted(LAMBDA_FACTORS)]
    rows = [
        "| objective | model | " + " | ".join(f"median L_t at λ×{float(f):g}" for f in fs)
        + " | " + " | ".join(f"ratio λ×{float(f):g} / ×1" for f in others)
        + " | catastrophic at " + " / ".join(f"×{float(f):g}" for f in fs) + " of runs |",
        "|---|---|" + "---|" * (len(fs) + len(others) + 1),
    ]  # fmt: skip
    n_traj = result["settings"]["n_trajectories"]

    def row(label: str, m: str, lam: dict[str, Any]) -> str:
        x = lam["factors"]
        return (
            f"| {label} | {m.upper()} | " + " | ".join(_fmt(x[f]["median"]) for f in fs) + " | "
            + " | ".join(_ratio_cell(x[f]) for f in others) + " | "
            + " / ".join(str(x[f]["catastrophic"]) for f in fs)
            + f" of {lam['n_runs'] * n_traj} |"
        )  # fmt: skip

    for o in t:
        for m in MODELS:
            rows.append(row(f"{o}{' (winner)' if o == ch['winner'] else ''}", m, t[o][m]["lambda"]))
    for m in MODELS:
        rows.append(row(f"final design ({ch['winner']})", m, finals[m]["lambda"]))
    return "\n".join(rows)


def table_one(result: dict[str, Any]) -> str:
    """Markdown Table I: per class and total, CV and CA, median and mean (×10⁻³) with
    two-level intervals, beside the paper's values; then the CV / CA ratios."""
    f = result["final"]
    cols = (*CLASSES, "total")
    rows = [
        "| model | statistic | " + " | ".join(cols) + " |",
        "|---|---|" + "---|" * len(cols),
    ]
    for m in MODELS:
        t = f["table"][m]
        for stat in ("median", "mean"):
            rows.append(
                f"| {m.upper()} | {stat} [95 %] | " + " | ".join(
                    f"{_fmt(t[c][stat])} [{_fmt(t[c][stat + '_lo'])}, {_fmt(t[c][stat + '_hi'])}]"
                    for c in cols
                ) + " |"
            )  # fmt: skip
        rows.append(
            f"| {m.upper()} | paper | "
            + " | ".join(f"{PAPER_TABLE[m][c]:.3f}" for c in cols) + " |"
        )  # fmt: skip
    for stat in ("median", "mean"):
        rows.append(
            f"| CV/CA | ratio of {stat}s [95 %] | " + " | ".join(
                f"{f['ratios'][c][stat + '_ratio']:.3f} [{f['ratios'][c][stat + '_ratio_lo']:.3f}, "
                f"{f['ratios'][c][stat + '_ratio_hi']:.3f}]" for c in cols
            ) + " |"
        )  # fmt: skip
    rows.append("| CV/CA | paper | – | – | – | – | – | 0.976 |")
    return "\n".join(rows)


def render(result: dict[str, Any], quick: bool = False) -> list[Path]:
    """Write the tables (``campaign.md``), the plots and each model's chosen parameters."""
    from core.files import write_json_atomic, write_text_atomic

    out, params = report_dirs(quick)
    out.mkdir(parents=True, exist_ok=True)
    params.mkdir(parents=True, exist_ok=True)
    f = result["final"]
    md = out / "campaign.md"
    r = f["ratios"]["total"]
    text = (
        "<!-- written by `radartune bench campaign` (core/benchmarks/campaign.py); "
        "do not edit -->\n"
        "Design: [evaluation-07](../decisions/evaluation-07-cv-ca-design.md). L in m² ×10⁻³. "
        f"Objectives: {len(result['settings']['compare_seeds'])} studies of "
        f"{result['settings']['compare_trials']} trials per objective and model; Table I: "
        f"{len(result['settings']['final_seeds'])} studies of "
        f"{result['settings']['final_trials']} trials per model.\n\n"
        "## Objectives on the test sets\n\n" + objective_table(result) + "\n\n"
        f"Winner by the rule: **{result['objectives']['choice']['winner']}**.\n\n"
        + _lambda_section(result)
        + "## Table I\n\n"
        + table_one(result)
        + "\n\n"
        f"Primary (ratio of medians) {r['median_ratio']:.3f} [{r['median_ratio_lo']:.3f}, "
        f"{r['median_ratio_hi']:.3f}]: **{f['verdict']}**. Secondary (ratio of means) "
        f"{r['mean_ratio']:.3f} [{r['mean_ratio_lo']:.3f}, {r['mean_ratio_hi']:.3f}]: "
        f"{f['secondary_verdict']}. CV lower in {r['cv_better_cells']} of {r['cells']} "
        "(study, test set) cells.\n"
    )
    write_text_atomic(md, text)
    written = [md]
    for m in MODELS:
        path = params / f"best_{m}.json"
        write_json_atomic(path, f["chosen"][m]["params"])
        written.append(path)
    return [*written, *_plots(result, out)]


def _lambda_section(result: dict[str, Any]) -> str:
    table = lambda_table(result)
    if not table:
        return ""
    n = result["settings"].get("n_lambda")
    return (
        "## Objectives when the scene clutter λ changes\n\n"
        f"Each study's choice (tracker ρ as tuned) on the first {n} test sets simulated again "
        "with the scene clutter rate λ (0.02 m⁻² in the paper) × 0.5 and × 2, everything else "
        "the same; × 1 is the plain score on those sets. Median over (study, set) cells; ratio: "
        "that median over the one at × 1; catastrophic: never confirmed, or more than 1 m off "
        f"in ≥ {FAR_FRAMES} frames. Not part of the pre-registered rule.\n\n" + table + "\n\n"
    )


_COLOURS = {"cv": "tab:blue", "ca": "tab:orange"}


def _plots(result: dict[str, Any], out: Path) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    return [_plot_test_sets(result, out), _plot_table1(result, out), _plot_objectives(result, out)]


def _plot_test_sets(result: dict[str, Any], out: Path) -> Path:
    """Per test set, every study's L_t; the median over cells with its interval."""
    import matplotlib.pyplot as plt

    f = result["final"]
    recs = f["records"]
    colours = _COLOURS
    # 1. per test set, every study's L_t; the median over cells with its interval
    fig, ax = plt.subplots(figsize=(9, 4.2), layout="constrained")
    tests = result["data"]["test"]
    x = np.arange(len(tests))
    for j, m in enumerate(MODELS):
        cells = _cells([r for r in recs if r["model"] == m]) * 1e3
        dx = -0.15 if j == 0 else 0.15
        for row in cells:
            ax.scatter(x + dx, row, s=9, color=colours[m], alpha=0.45, lw=0)
        ax.scatter(x + dx, np.median(cells, axis=0), marker="_", s=120, color=colours[m])
        t = f["table"][m]["total"]
        ax.axhline(t["median"] * 1e3, color=colours[m], lw=1.2,
                   label=f"{m.upper()} median {t['median'] * 1e3:.4f}")  # fmt: skip
        ax.axhspan(t["median_lo"] * 1e3, t["median_hi"] * 1e3, color=colours[m], alpha=0.15)
    ax.set_yscale("log")
    ax.set_xticks(x, [str(2000 + i) for i in x], rotation=60, fontsize=7)
    ax.set_xlabel("test data set (paper seed, walking body)")
    ax.set_ylabel("L_t (m² ×10⁻³)")
    r = f["ratios"]["total"]
    ax.set_title(
        f"Each study's choice on each test set ({len(result['settings']['final_seeds'])} studies "
        f"of {result['settings']['final_trials']} trials per model; dots; bar: median over "
        f"studies)\nband: two-level 95 % interval of the median; CV/CA ratio of medians "
        f"{r['median_ratio']:.3f} "
        f"[{r['median_ratio_lo']:.3f}, {r['median_ratio_hi']:.3f}]: {f['verdict']}",
        fontsize=9,
    )
    ax.legend(fontsize=8)
    p = out / "test_sets.png"
    written = save_figure(fig, p, dpi=110)
    plt.close(fig)
    return written


def _plot_table1(result: dict[str, Any], out: Path) -> Path:
    """Table I per class: medians with intervals."""
    import matplotlib.pyplot as plt

    f = result["final"]
    colours = _COLOURS
    # 2. Table I per class: medians with intervals
    fig, ax = plt.subplots(figsize=(7, 3.8), layout="constrained")
    cols = (*CLASSES, "total")
    xc = np.arange(len(cols))
    for j, m in enumerate(MODELS):
        t = f["table"][m]
        med = np.array([t[c]["median"] for c in cols]) * 1e3
        lo = np.array([t[c]["median_lo"] for c in cols]) * 1e3
        hi = np.array([t[c]["median_hi"] for c in cols]) * 1e3
        ax.bar(xc + (j - 0.5) * 0.38, med, 0.38, color=colours[m], label=f"{m.upper()} median")
        ax.errorbar(xc + (j - 0.5) * 0.38, med, yerr=[med - lo, hi - med], fmt="none",
                    ecolor="k", capsize=3, lw=1)  # fmt: skip
    ax.set_xticks(xc, [c if c == "total" else f"class {c}" for c in cols])
    ax.set_ylabel("median L (m² ×10⁻³)")
    ax.set_title(
        "Table I on the walking-body test sets: median over (study, test set) cells, two-level "
        f"95 % interval\n({len(result['settings']['final_seeds'])} studies of "
        f"{result['settings']['final_trials']} trials per model)",
        fontsize=9,
    )
    ax.legend(fontsize=8)
    p = out / "table1.png"
    written = save_figure(fig, p, dpi=110)
    plt.close(fig)
    return written


def _plot_objectives(result: dict[str, Any], out: Path) -> Path:
    """Held-out median per objective, and against the clutter densities ρ and λ."""
    import matplotlib.pyplot as plt

    colours = _COLOURS
    # 3. objectives: held-out median per objective, and against the clutter density
    t = result["objectives"]["table"]
    objs = list(t)
    has_lambda = bool(lambda_table(result))
    if has_lambda:
        fig, (a1, a2, a3) = plt.subplots(1, 3, figsize=(14, 3.9), layout="constrained")
    else:
        fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 3.8), layout="constrained")
    xo = np.arange(len(objs))
    for j, m in enumerate(MODELS):
        dx = (j - 0.5) * 0.3
        med = np.array([t[o][m]["median"] for o in objs]) * 1e3
        lo = np.array([t[o][m]["median_lo"] for o in objs]) * 1e3
        hi = np.array([t[o][m]["median_hi"] for o in objs]) * 1e3
        a1.errorbar(xo + dx, med, yerr=[med - lo, hi - med], fmt="o", color=colours[m],
                    capsize=3, label=f"{m.upper()} median, 95 %")  # fmt: skip
        for k, o in enumerate(objs):
            ps = np.array(t[o][m]["per_study_median"]) * 1e3
            a1.scatter(np.full(len(ps), k + dx + 0.08), ps, s=8, color=colours[m], alpha=0.5)
        fs = sorted((*RHO_FACTORS, 1.0))
        for k, o in enumerate(objs):
            a2.plot(fs, [t[o][m]["rho"][str(v)]["median"] * 1e3 for v in fs],
                    "-" if m == "cv" else "--", color=f"C{k + 2}", marker=".",
                    label=f"{m.upper()} {o}")  # fmt: skip
            if has_lambda:
                lam = t[o][m]["lambda"]["factors"]
                fl = sorted((*LAMBDA_FACTORS, 1.0))
                a3.plot(fl, [lam[str(v)]["median"] * 1e3 for v in fl],
                        "-" if m == "cv" else "--", color=f"C{k + 2}", marker=".",
                        label=f"{m.upper()} {o}")  # fmt: skip
    a1.set_xticks(xo, objs)
    a1.set_yscale("log")
    a1.set_ylabel("held-out median L_t (m² ×10⁻³)")
    a1.set_title("Objective a study minimises → paper loss on test sets\n(dots: per study)",
                 fontsize=9)  # fmt: skip
    a1.legend(fontsize=7)
    a2.set_xscale("log")
    a2.set_yscale("log")
    a2.set_xticks(sorted((*RHO_FACTORS, 1.0)), [f"×{v:g}" for v in sorted((*RHO_FACTORS, 1.0))])
    a2.minorticks_off()
    a2.set_xlabel("tracker clutter density ρ / tuned ρ")
    a2.set_ylabel("median L_t (m² ×10⁻³)")
    a2.set_title("Robustness to ρ (test sets, each study's choice)", fontsize=9)
    a2.legend(fontsize=6, ncol=2)
    if has_lambda:
        fl = sorted((*LAMBDA_FACTORS, 1.0))
        a3.set_xscale("log")
        a3.set_yscale("log")
        a3.set_xticks(fl, [f"×{v:g}" for v in fl])
        a3.minorticks_off()
        a3.set_xlabel("scene clutter rate λ / paper's λ (data simulated again)")
        a3.set_ylabel("median L_t (m² ×10⁻³)")
        a3.set_title(
            f"Robustness to λ (first {result['settings'].get('n_lambda')} test sets, each "
            "study's choice)", fontsize=9,
        )  # fmt: skip
        a3.legend(fontsize=6, ncol=2)
    p = out / "objectives.png"
    written = save_figure(fig, p, dpi=110)
    plt.close(fig)
    return written


def summary(result: dict[str, Any]) -> str:
    """Terminal lines: the objective table, the choice, Table I and the verdict."""
    lines = ["objective comparison (held-out median L_t ×10⁻³, catastrophic runs, seed IQR):"]
    for o, per in result["objectives"]["table"].items():
        lines.append(
            f"  {o:8s} "
            + "  ".join(
                f"{m.upper()} {per[m]['median'] * 1e3:.4f} [{per[m]['median_lo'] * 1e3:.4f}, "
                f"{per[m]['median_hi'] * 1e3:.4f}] cat {per[m]['catastrophic']} "
                f"iqr {per[m]['seed_iqr_rel']:.2f}"
                for m in MODELS
            )
        )
    ch = result["objectives"]["choice"]
    lines.append(f"winner: {ch['winner']} (tied: {', '.join(ch['tied'])})")
    if lambda_table(result):
        lines.append("at scene clutter λ × 0.5 / 1 / 2 (median L_t ×10⁻³, catastrophic runs):")
        for o, per in result["objectives"]["table"].items():
            lines.append(f"  {o:8s} " + "  ".join(
                f"{m.upper()} " + " / ".join(
                    f"{x['median'] * 1e3:.4f} ({x['catastrophic']})"
                    for x in (per[m]["lambda"]["factors"][str(v)]
                              for v in sorted((*LAMBDA_FACTORS, 1.0)))
                ) for m in MODELS))  # fmt: skip
    f = result["final"]
    lines.append("Table I, final design (median [95 %] / mean [95 %], ×10⁻³):")
    for m in MODELS:
        t = f["table"][m]["total"]
        lines.append(
            f"  {m.upper()} total {t['median'] * 1e3:.4f} [{t['median_lo'] * 1e3:.4f}, "
            f"{t['median_hi'] * 1e3:.4f}] / {t['mean'] * 1e3:.4f} [{t['mean_lo'] * 1e3:.4f}, "
            f"{t['mean_hi'] * 1e3:.4f}]"
        )
    r = f["ratios"]["total"]
    lines.append(
        f"CV/CA median ratio {r['median_ratio']:.3f} [{r['median_ratio_lo']:.3f}, "
        f"{r['median_ratio_hi']:.3f}], mean ratio {r['mean_ratio']:.3f} "
        f"[{r['mean_ratio_lo']:.3f}, {r['mean_ratio_hi']:.3f}]: {f['verdict']}"
    )
    return "\n".join(lines)


__all__ = [
    "LAMBDA_FACTORS",
    "MARGIN",
    "PAPER_TABLE",
    "QUICK",
    "RHO_FACTORS",
    "Settings",
    "add_lambda",
    "analyse_final",
    "catastrophic_runs",
    "lambda_paths",
    "lambda_table",
    "render",
    "choose_objective",
    "ratios",
    "run",
    "score_choice",
    "score_lambda",
    "spread",
    "summarise",
    "summarise_lambda",
    "summary",
    "verdict",
]

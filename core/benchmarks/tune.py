"""``radartune bench tune``: completed trials per second of a CV study on the cached data set.

Measured with 1 and 2 worker processes, on the SQLite file (default storage) and the journal
file, TPE + ASHA as ``radartune tune`` runs it. Two rates per run: end to end (wall clock from
the ``tune`` call to the last worker's exit, process start-up included) and steady state
(trials finished between the first trial's start and the last trial's end). The reference, in
the same run, is the bare objective in this process — the IPDA tracker on the 35 trajectories
with random parameters, no Optuna, no storage — so the ratio shows what Optuna and the storage
cost. Goal: at least 10 trials/s with 2 jobs on the 2-core machine.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np


def _reference(dataset_path: str, n: int) -> dict[str, float]:
    from core.dataset import Dataset
    from core.optimization.objective import TrackerLosses, evaluate
    from core.optimization.space import search_space, tracker_params_dict

    ds = Dataset.load(dataset_path)
    losses = TrackerLosses(ds, capped=False)  # the work of a default (paper-loss) trial
    rng = np.random.default_rng(0)

    def draw() -> dict[str, Any]:
        flat = {}
        for b in search_space("cv"):
            if b.log:
                flat[b.name] = float(np.exp(rng.uniform(np.log(b.low), np.log(b.high))))
            else:
                flat[b.name] = float(rng.uniform(b.low, b.high))
        return tracker_params_dict(flat, "cv")

    evaluate(losses, draw())  # compile / warm caches
    t0 = time.perf_counter()
    for _ in range(n):
        evaluate(losses, draw())
    dt = time.perf_counter() - t0
    return {"trials": n, "seconds": dt, "trials_per_s": n / dt}


def _study(dataset_path: str, storage: str, n_jobs: int, n_trials: int) -> dict[str, Any]:
    from core.optimization.progress import counted, study_progress
    from core.optimization.study import StudySettings, start_study

    s = StudySettings(
        model="cv", n_trials=n_trials, n_jobs=n_jobs, storage=storage, dataset=dataset_path
    )
    t0 = time.perf_counter()
    handle = start_study(s, dataset_path=dataset_path)
    handle.wait()
    wall = time.perf_counter() - t0
    summaries, best = study_progress(storage, s.name)
    done = [t for t in summaries if t.state in ("COMPLETE", "PRUNED")]
    first = min(t.datetime_start for t in done)
    last = max(t.datetime_complete for t in done)
    steady = (last - first).total_seconds()
    return {
        "storage": storage.split(":", 1)[0],
        "jobs": n_jobs,
        "trials": counted(summaries),
        "pruned": sum(1 for t in done if t.state == "PRUNED"),
        "wall_s": wall,
        "trials_per_s_end_to_end": counted(summaries) / wall,
        "steady_s": steady,
        "trials_per_s_steady": (len(done) - 1) / steady if steady > 0 else float("nan"),
        "best_loss": None if best is None else best.value,
        "returncodes": handle.returncodes(),
    }


def run(quick: bool = False) -> dict:
    from core.optimization.data import resolve_dataset

    dataset_path = resolve_dataset(None)
    n_trials = 20 if quick else 200
    ref = _reference(dataset_path, 5 if quick else 30)
    runs = []
    with tempfile.TemporaryDirectory(prefix="radartune-bench-") as tmp:
        for kind, url in (("sqlite", "sqlite:///{}/b{}.db"), ("journal", "journal:///{}/b{}.log")):
            for jobs in (1, 2):
                r = _study(dataset_path, url.format(tmp, jobs), jobs, n_trials)
                r["storage"] = kind
                r["ratio_to_reference"] = r["trials_per_s_steady"] / ref["trials_per_s"]
                runs.append(r)
    return {
        "dataset": Path(dataset_path).name,
        "n_trials": n_trials,
        "goal_trials_per_s_2_jobs": 10.0,
        "reference_objective_in_process": ref,
        "studies": runs,
    }


def summary(result: dict) -> str:
    ref = result["reference_objective_in_process"]
    lines = [
        f"bench tune: CV study, TPE + ASHA, {result['n_trials']} trials on {result['dataset']}",
        f"  reference (bare objective, no Optuna, full 35 trajectories): "
        f"{ref['trials_per_s']:.2f} trials/s",
    ]
    for r in result["studies"]:
        lines.append(
            f"  {r['storage']:<8} jobs={r['jobs']}: {r['trials_per_s_steady']:.2f} trials/s steady,"
            f" {r['trials_per_s_end_to_end']:.2f} end to end ({r['trials']} trials,"
            f" {r['pruned']} pruned, {r['wall_s']:.1f} s), x{r['ratio_to_reference']:.2f} of ref"
        )
    return "\n".join(lines)

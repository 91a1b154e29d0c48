"""Cross-evaluate best tracker parameters on the point and extended paper data sets.

Run from the repository root::

    python bench/cvca_cross_eval.py --point P.npz --extended E.npz \
        --params cv-point=docs/report/best_cv.json ... --out FILE.json

Writes, per parameter set and data set, L_t and the per-class table (L, MSE, N_c), RMSE and
far frames, plus the measurement spread of the person-labelled points of each data set
(:func:`core.evaluation.person_point_spread`). No tuning happens here.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from core.dataset import Dataset  # noqa: E402
from core.evaluation import person_point_spread  # noqa: E402
from core.optimization.report import evaluate_params  # noqa: E402


def _studies(storage: str) -> dict:
    """Per study: trials by state, and the best L_t within the first N trials (by number)."""
    import optuna
    from optuna.trial import TrialState

    from core.optimization.storage import open_storage

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    store = open_storage(storage, create=False)
    res = {}
    names = [s.study_name for s in optuna.get_all_study_summaries(store)]
    n_min = None
    trials = {}
    for name in names:
        ts = optuna.load_study(study_name=name, storage=store).get_trials(deepcopy=False)
        done = [t for t in ts if t.state in (TrialState.COMPLETE, TrialState.PRUNED)]
        trials[name] = ts
        n_min = len(done) if n_min is None else min(n_min, len(done))
    for name, ts in trials.items():
        done = sorted(
            (t for t in ts if t.state in (TrialState.COMPLETE, TrialState.PRUNED)),
            key=lambda t: t.number,
        )
        complete = [t for t in done if t.state == TrialState.COMPLETE]

        def best(ts_: list) -> float | None:
            vals = [t.value for t in ts_ if t.state == TrialState.COMPLETE]
            return min(vals) if vals else None

        b = min(complete, key=lambda t: t.value) if complete else None
        res[name] = {
            "finished": len(done),
            "complete": len(complete),
            "pruned": len(done) - len(complete),
            "best_loss": b.value if b else None,
            "best_trial": b.number if b else None,
            "equal_budget_trials": n_min,
            "best_loss_at_equal_budget": best(done[:n_min]),
        }
        print(f"{name}: {res[name]}", flush=True)
    return res


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--point", required=True, help="point-model data set .npz")
    ap.add_argument("--extended", required=True, help="extended-model data set .npz")
    ap.add_argument("--params", action="append", default=[], metavar="NAME=FILE.json")
    ap.add_argument("--storage", default=None, help="studies: best L_t at equal trial counts")
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    sets = {"point": Dataset.load(args.point), "extended": Dataset.load(args.extended)}
    out: dict = {
        "datasets": {
            k: {"file": Path(v).name, "frames": d.n_frames, "points": len(d.frame)}
            for (k, d), v in zip(sets.items(), (args.point, args.extended), strict=True)
        },
        "spread": {k: person_point_spread(d).to_dict() for k, d in sets.items()},
        "results": {},
    }
    if args.storage:
        out["studies"] = _studies(args.storage)
    for item in args.params:
        name, _, path = item.partition("=")
        params = json.loads(Path(path).read_text())
        out["results"][name] = {"params_file": path, "model": params["model"]}
        for k, d in sets.items():
            _, ev = evaluate_params(d, params)
            r = ev.to_dict() if hasattr(ev, "to_dict") else ev
            out["results"][name][k] = r
            print(f"{name:>14} on {k:>8}: L_t = {ev.loss_total * 1e3:.4f} x1e-3", flush=True)
    fd, tmp = tempfile.mkstemp(dir=Path(args.out).parent, suffix=".tmp")
    with os.fdopen(fd, "w") as f:
        json.dump(out, f, indent=1)
    os.replace(tmp, args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

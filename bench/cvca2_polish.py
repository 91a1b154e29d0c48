"""Local polish of each model's best parameters by coordinate search inside eq. (15).

Run from the repository root after ``bench/cvca2_settle.py``::

    python bench/cvca2_polish.py --settle docs/report/cv-vs-ca/settle.json \
        --out docs/report/cv-vs-ca/polish.json

Is a study's best trial near a local optimum, or is the CV-vs-CA gap partly the optimiser's
noise? Starting from each model's best parameters over all sampler seeds, every optimised
parameter in turn is set to each of ``--points`` values spread over its range (log-spaced where
the search space is log-scaled) with the others held, and the best value is kept; sweeps repeat
until one changes nothing or ``--sweeps`` is reached. The same procedure and grid for both
models; the evaluation budget (tracker runs over the 35 trajectories) is recorded. The polished
parameters are then re-tracked on the independent set paper:1 (nothing is selected there) and
compared trajectory by trajectory (:func:`core.evaluation.paired_comparison`).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from core.dataset import Dataset  # noqa: E402
from core.evaluation import paired_comparison, trajectory_losses  # noqa: E402
from core.optimization.space import flat_params, search_space, tracker_params_dict  # noqa: E402
from core.pipeline import paper_dataset_file  # noqa: E402
from core.tracking import TrackerParams, track_dataset  # noqa: E402


def _losses(ds: Dataset, flat: dict, model: str) -> np.ndarray:
    p = TrackerParams.from_dict(tracker_params_dict(flat, model))
    return trajectory_losses(ds, track_dataset(ds, p))


def polish(ds: Dataset, params: dict, points: int, sweeps: int) -> tuple[dict, list, int]:
    """Coordinate search; returns the polished flat parameters, the history and the budget."""
    model = params["model"]
    flat = flat_params(params)
    best = float(_losses(ds, flat, model).mean())
    history = [{"sweep": 0, "loss_total": best}]
    n_eval = 1
    for sweep in range(1, sweeps + 1):
        changed = False
        for b in search_space(model):
            grid = (
                np.geomspace(b.low, b.high, points) if b.log else np.linspace(b.low, b.high, points)
            )
            for v in grid:
                trial = dict(flat, **{b.name: float(v)})
                val = float(_losses(ds, trial, model).mean())
                n_eval += 1
                if val < best:
                    best, flat, changed = val, trial, True
        history.append({"sweep": sweep, "loss_total": best})
        print(f"{model} sweep {sweep}: L_t = {best * 1e3:.5f} x1e-3", flush=True)
        if not changed:
            break
    return flat, history, n_eval


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--settle", required=True, help="settle.json of bench/cvca2_settle.py")
    ap.add_argument("--points", type=int, default=13)
    ap.add_argument("--sweeps", type=int, default=3)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    settle = json.loads(Path(args.settle).read_text())
    sets = {
        "paper:0": Dataset.load(paper_dataset_file(0, 35)),
        "paper:1": Dataset.load(paper_dataset_file(1, 35)),
    }
    out: dict = {"settle": args.settle, "points": args.points, "sweeps": args.sweeps, "models": {}}
    losses = {}
    for m in ("cv", "ca"):
        names = settle["per_model"][m]["studies"]
        start = min(names, key=lambda n: settle["studies"][n]["best_value"])
        params = settle["studies"][start]["params"]
        flat, history, n_eval = polish(sets["paper:0"], params, args.points, args.sweeps)
        polished = tracker_params_dict(flat, m)
        losses[m] = {k: _losses(d, flat, m) for k, d in sets.items()}
        out["models"][m] = {
            "start_study": start,
            "start_loss_total": settle["studies"][start]["best_value"],
            "history": history,
            "evaluations": n_eval,
            "params": polished,
            **{k: float(v.mean()) for k, v in losses[m].items()},
        }
        print(
            f"{m}: {start} {history[0]['loss_total'] * 1e3:.5f} -> "
            f"{history[-1]['loss_total'] * 1e3:.5f}; "
            f"paper:1 {losses[m]['paper:1'].mean() * 1e3:.5f}",
            flush=True,
        )
    out["paired"] = {
        k: paired_comparison(
            losses["cv"][k], losses["ca"][k], d.trajectory_class.astype(str)
        ).to_dict()
        for k, d in sets.items()
    }
    for k, c in out["paired"].items():
        print(f"polished {k}: CV/CA = {c['ratio']:.3f} [{c['ci_low']:.3f}, {c['ci_high']:.3f}]")
    path = Path(args.out)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    with os.fdopen(fd, "w") as f:
        json.dump(out, f, indent=1)
    os.replace(tmp, path)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Evaluate committed tracker parameters on the paper data sets of the current chain.

Usage (from the repository root)::

    python bench/report_recheck.py --out docs/report/current-chain/recheck.json

For each parameter pair (CV, CA) and each data set (paper:0, paper:1, simulated by the current
code and cached): L_t of both models (eq. 14) and the paired comparison over the 35 trajectories
(:func:`core.evaluation.paired_comparison`: ratio of the totals with a class-stratified
bootstrap interval, wins, Wilcoxon). Tracking only; nothing is tuned.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from core.evaluation import paired_comparison, trajectory_losses
from core.pipeline import paper_dataset
from core.tracking import TrackerParams
from core.tracking.batch import track_dataset

PAIRS = {
    "report at 1aec029 (docs/report/best_*.json)": (
        "docs/report/best_cv.json",
        "docs/report/best_ca.json",
    ),
    "current chain (docs/report/current-chain/best_*.json)": (
        "docs/report/current-chain/best_cv.json",
        "docs/report/current-chain/best_ca.json",
    ),
    "best of 8 seeds x 1000 trials, polished, at 1aec029 (cv-vs-ca/polish.json)": (
        "polish:cv",
        "polish:ca",
    ),
}


def _params(ref: str) -> TrackerParams:
    if ref.startswith("polish:"):
        models = json.loads(Path("docs/report/cv-vs-ca/polish.json").read_text())["models"]
        return TrackerParams.from_dict(models[ref.split(":")[1]]["params"])
    return TrackerParams.load(ref)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    rows = []
    for seed in (0, 1):
        ds = paper_dataset(seed, 35, jobs=2)
        classes = np.asarray(ds.trajectory_class)
        for name, (cv_ref, ca_ref) in PAIRS.items():
            loss_cv = trajectory_losses(ds, track_dataset(ds, _params(cv_ref)))
            loss_ca = trajectory_losses(ds, track_dataset(ds, _params(ca_ref)))
            pc = paired_comparison(loss_cv, loss_ca, classes)
            row = {
                "dataset": f"paper:{seed}",
                "parameters": name,
                "cv_x1e3": 1e3 * float(loss_cv.mean()),
                "ca_x1e3": 1e3 * float(loss_ca.mean()),
                "ratio": pc.ratio,
                "ci95": [pc.ci_low, pc.ci_high],
                "wins_cv": pc.wins_a,
                "wins_ca": pc.wins_b,
                "wilcoxon_p": pc.wilcoxon_p,
                "median_log_ratio": pc.log_ratio_median,
            }
            rows.append(row)
            print(
                f"paper:{seed}  {name}: CV {row['cv_x1e3']:.4f}  CA {row['ca_x1e3']:.4f} x1e-3"
                f"  CV/CA {pc.ratio:.2f} [{pc.ci_low:.2f}, {pc.ci_high:.2f}]"
                f"  wins {pc.wins_a}/{pc.wins_b}  Wilcoxon p {pc.wilcoxon_p:.3f}",
                flush=True,
            )
    Path(args.out).write_text(json.dumps({"rows": rows}, indent=1) + "\n")


if __name__ == "__main__":
    main()

"""Why does CA beat CV on the paper data set? Loss breakdown of the report's best parameters.

Run from the repository root::

    python bench/cvca2_diagnose.py --out docs/report/cv-vs-ca/diagnosis.json

On the cached paper data set (seed 0) with ``docs/report/best_cv.json`` / ``best_ca.json``:

1. per class, the loss split into transient / manoeuvre / steady frames
   (:func:`core.evaluation.loss_breakdown`), N_c, SSE, first confirmation, lag;
2. the 2.2 % radial-velocity bias of the chain (decision sim-01): both parameter sets tracked on
   a copy of the data set whose v_r is divided by the bias factor (a diagnostic of the tracker's
   sensitivity; the simulation is unchanged);
3. a matched-parameter comparison: each model's best parameters with only the motion model
   swapped (CA → CV drops the acceleration entries of P0; CV → CA adds the CA best's), q_coeff
   re-scanned on a log grid over the search range, everything else equal;
4. a paired statistic of the two best parameter sets over the 35 trajectories.

No tuning and no simulation happens here (the data set is read from the cache).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from core.dataset import Dataset  # noqa: E402
from core.evaluation import (  # noqa: E402
    evaluate,
    loss_breakdown,
    paired_comparison,
    track_with_ids,
)
from core.pipeline import paper_dataset_file  # noqa: E402
from core.tracking import TrackerParams, track_dataset  # noqa: E402

#: Reported radial velocities are this factor too high (docs/radar-chain.md, decision sim-01):
#: Doppler follows the mid-sampling frequency Fc + S·(Nadc − 1)/(2·Fs), the chain uses λ = c/Fc.
VR_BIAS = 1.0 + 61.366e12 * 255 / (2 * 5.9e6) / 60e9


def _loss(ds: Dataset, params: TrackerParams) -> tuple[float, np.ndarray]:
    ev = evaluate(ds, track_dataset(ds, params))
    return float(ev.loss_total), ev.loss


def _breakdown(ds: Dataset, params: TrackerParams) -> dict:
    est, ids = track_with_ids(ds, params)
    bd = loss_breakdown(ds, est, estimate_ids=ids)
    ev = evaluate(ds, est)
    return {
        "loss_total": float(ev.loss_total),
        "classes": bd.class_table(),
        "trajectories": [
            {
                "index": int(k),
                "class": str(c),
                "loss": float(lo),
                "n_c": int(nc),
                "sse": float(sse),
                "first_confirmed_frame": int(fc),
                "loss_transient": float(lc[0]),
                "loss_manoeuvre": float(lc[1]),
                "loss_steady": float(lc[2]),
                "along_track_mean_m": (float(at) if np.isfinite(at) else None),
                "far_frames": int(ff),
            }
            for k, c, lo, nc, sse, fc, lc, at, ff in zip(
                bd.trajectories,
                bd.classes,
                bd.loss,
                bd.n_c,
                bd.sse,
                bd.first_confirmed_frame,
                bd.loss_by_category,
                bd.along_track_mean_m,
                ev.far_frames,
                strict=True,
            )
        ],
    }, bd


def _swap(params: TrackerParams, model: str, extra_p0: tuple[float, ...]) -> TrackerParams:
    p0 = params.p0[:4] + (extra_p0 if model == "ca" else ())
    return dataclasses.replace(params, model=model, p0=p0)


def _q_scan(ds: Dataset, params: TrackerParams, grid: np.ndarray) -> dict:
    vals = [_loss(ds, dataclasses.replace(params, q_coeff=float(q)))[0] for q in grid]
    i = int(np.argmin(vals))
    return {"q_grid": grid.tolist(), "loss": vals, "best_q": float(grid[i]), "best": vals[i]}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cv", default="docs/report/best_cv.json")
    ap.add_argument("--ca", default="docs/report/best_ca.json")
    ap.add_argument("--seed", type=int, default=0, help="paper data set seed")
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    ds = Dataset.load(paper_dataset_file(args.seed, 35))
    best = {m: TrackerParams.load(p) for m, p in (("cv", args.cv), ("ca", args.ca))}
    out: dict = {"dataset": f"paper:{args.seed}", "params_files": {"cv": args.cv, "ca": args.ca}}

    # 1. where the loss comes from
    out["breakdown"] = {}
    bds = {}
    for m, p in best.items():
        out["breakdown"][m], bds[m] = _breakdown(ds, p)
        print(f"{m}: L_t = {out['breakdown'][m]['loss_total'] * 1e3:.4f} x1e-3", flush=True)
        for row in out["breakdown"][m]["classes"]:
            print(
                f"  {row['class']:>5} L={row['loss'] * 1e6:6.3f}e-6 "
                f"trans={row['loss_transient'] * 1e6:6.3f} man={row['loss_manoeuvre'] * 1e6:6.3f} "
                f"steady={row['loss_steady'] * 1e6:6.3f} N_c={row['n_c']:6.1f} "
                f"first={row['first_confirmed_frame']:5.1f} along={row['along_track_mean_m']}",
                flush=True,
            )
    # log(L_cv/L_ca) per trajectory = log(SSE ratio) − 2 log(N_c ratio)
    both = (bds["cv"].n_c > 0) & (bds["ca"].n_c > 0)
    sse_r = np.log(bds["cv"].sse[both] / bds["ca"].sse[both])
    nc_r = np.log(bds["cv"].n_c[both] / bds["ca"].n_c[both])
    out["log_ratio_split"] = {
        "mean_log_loss_ratio": float(np.mean(sse_r - 2 * nc_r)),
        "mean_log_sse_ratio": float(np.mean(sse_r)),
        "mean_minus_2_log_nc_ratio": float(np.mean(-2 * nc_r)),
    }
    # the same loss with the transient frames removed from both (L over the rest only)
    out["without_transient"] = {}
    for m, bd in bds.items():
        keep = bd.frames_by_category[:, 1:].sum(axis=1)
        sse = bd.sse_by_category[:, 1:].sum(axis=1)
        lk = np.where(keep > 0, sse / np.maximum(keep, 1) ** 2, 1.0)
        out["without_transient"][m] = {
            "loss_total": float(lk.mean()),
            "by_class": {
                c.upper(): float(lk[bd.classes == c].mean()) for c in sorted(set(bd.classes))
            },
        }
    print("without transient:", json.dumps(out["without_transient"]), flush=True)

    # 2. radial-velocity bias
    ds_unbiased = dataclasses.replace(ds, radial_velocity_mps=ds.radial_velocity_mps / VR_BIAS)
    out["vr_bias"] = {"factor": VR_BIAS}
    for m, p in best.items():
        a, la = _loss(ds, p)
        b, lb = _loss(ds_unbiased, p)
        k = int(np.argmax(np.abs(lb - la)))
        out["vr_bias"][m] = {
            "loss_total_as_simulated": a,
            "loss_total_vr_divided_by_factor": b,
            "largest_change": {
                "trajectory": k,
                "class": str(ds.trajectory_class[k]),
                "loss_as_simulated": float(la[k]),
                "loss_vr_divided_by_factor": float(lb[k]),
            },
        }
    print("vr bias:", json.dumps(out["vr_bias"]), flush=True)

    # 3. matched parameters: swap only the motion model, re-scan q
    grid = np.geomspace(0.1, 30.0, 25)
    ca_acc = best["ca"].p0[4:]
    out["matched"] = {
        "q_grid_note": "25 log-spaced q_coeff values over the search range [0.1, 30]",
        "ca_params_cv_model": _q_scan(ds, _swap(best["ca"], "cv", ()), grid),
        "ca_params_ca_model": _q_scan(ds, best["ca"], grid),
        "cv_params_cv_model": _q_scan(ds, best["cv"], grid),
        "cv_params_ca_model": _q_scan(ds, _swap(best["cv"], "ca", ca_acc), grid),
    }
    # diagnostic only, outside eq. (15): does CV want more process noise than q <= 30 allows?
    beyond = np.geomspace(30.0, 1000.0, 9)
    out["matched"]["beyond_search_range_note"] = (
        "diagnostic only: q_coeff in [30, 1000], outside the paper's search range (eq. 15)"
    )
    out["matched"]["cv_params_cv_model_beyond"] = _q_scan(ds, best["cv"], beyond)
    out["matched"]["ca_params_cv_model_beyond"] = _q_scan(ds, _swap(best["ca"], "cv", ()), beyond)
    for k, v in out["matched"].items():
        if isinstance(v, dict):
            print(f"matched {k}: best q = {v['best_q']:.3g}, L_t = {v['best'] * 1e3:.5f}e-3")
    # paired: CV with CA's other parameters (q re-scanned within the range) against CA's best
    q_cv = out["matched"]["ca_params_cv_model"]["best_q"]
    cv_m = dataclasses.replace(_swap(best["ca"], "cv", ()), q_coeff=q_cv)
    out["matched"]["paired_cv_with_ca_params_vs_ca"] = paired_comparison(
        _loss(ds, cv_m)[1], bds["ca"].loss, bds["ca"].classes
    ).to_dict()
    out["matched"]["breakdown_cv_with_ca_params"] = _breakdown(ds, cv_m)[0]["classes"]
    print("matched paired:", out["matched"]["paired_cv_with_ca_params_vs_ca"], flush=True)
    # the same matched pair on the independent seed-1 set (no parameter was chosen on it)
    ds1 = Dataset.load(paper_dataset_file(1, 35))
    out["matched"]["paired_cv_with_ca_params_vs_ca_on_paper1"] = paired_comparison(
        _loss(ds1, cv_m)[1], _loss(ds1, best["ca"])[1], ds1.trajectory_class.astype(str)
    ).to_dict()
    out["matched"]["cv_with_ca_params_q"] = q_cv
    print("matched paired paper:1:", out["matched"]["paired_cv_with_ca_params_vs_ca_on_paper1"])

    # 4. paired statistic of the two best parameter sets
    cls = bds["cv"].classes
    out["paired_best"] = paired_comparison(bds["cv"].loss, bds["ca"].loss, cls).to_dict()
    print("paired:", json.dumps(out["paired_best"]), flush=True)

    path = Path(args.out)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    with os.fdopen(fd, "w") as f:
        json.dump(out, f, indent=1)
    os.replace(tmp, path)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

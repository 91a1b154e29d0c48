"""Settle CV vs CA over several sampler seeds: every study's best parameters, re-tracked on the
training set (paper:0) and on an independent set (paper:1), compared trajectory by trajectory.

Run from the repository root after the studies (docs/report/cv-vs-ca.md has the commands)::

    python bench/cvca2_settle.py --storage journal:////tmp/cvca2/studies.log \
        --out docs/report/cv-vs-ca/settle.json

Per study (named ``<model>-...-s<seed>``): trials, best L_t, best L_t within the first 300
trials (the sampler does not know the budget, so this is a 300-trial study of the same seed,
up to the two workers' interleaving), and the best parameters' L_t on both data sets. Per model:
median, min and max over seeds. Comparisons (:func:`core.evaluation.paired_comparison`,
class-stratified paired bootstrap over the 35 trajectories): CV vs CA for every seed pair, for
the best of all seeds, on both data sets; and the ratio of the per-model medians.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import re
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from core.dataset import Dataset  # noqa: E402
from core.evaluation import evaluate, paired_comparison  # noqa: E402
from core.optimization.report import load_studies  # noqa: E402
from core.pipeline import paper_dataset_file  # noqa: E402
from core.tracking import TrackerParams, track_dataset  # noqa: E402

EARLY_BUDGET = 300
#: The chain's radial-velocity scale error (bench/cvca2_diagnose.py, decision sim-01).
VR_BIAS = 1.0 + 61.366e12 * 255 / (2 * 5.9e6) / 60e9


def _best(trials, limit: int | None = None):
    done = [t for t in trials if t.state in ("COMPLETE", "PRUNED")]
    done.sort(key=lambda t: t.number)
    if limit is not None:
        done = done[:limit]
    complete = [t for t in done if t.state == "COMPLETE" and t.value is not None]
    return min(complete, key=lambda t: (t.value, t.number)) if complete else None


def _stats(v: list[float]) -> dict:
    a = np.asarray(v)
    return {
        "median": float(np.median(a)),
        "min": float(a.min()),
        "max": float(a.max()),
        "values": a.tolist(),
    }


def _figure(out: dict, path: Path) -> None:
    """Left: best L_t per sampler seed and model on both sets. Middle, right: L(k) of CV against
    CA per trajectory (best of all seeds), by class, on the training and the independent set."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2))
    ax = axes[0]
    for j, name in enumerate(("best_value", "paper:1")):
        for i, m in enumerate(("cv", "ca")):
            v = np.asarray(out["per_model"][m][name]["values"]) * 1e3
            x = np.full(len(v), 2 * j + i) + np.linspace(-0.15, 0.15, len(v))
            ax.scatter(x, v, color=f"C{i}", label=m.upper() if j == 0 else None)
            ax.hlines(np.median(v), 2 * j + i - 0.3, 2 * j + i + 0.3, color=f"C{i}")
    ax.set_xticks([0.5, 2.5], ["paper:0 (training)", "paper:1 (independent)"])
    ax.set_yscale("log")
    ax.set_ylabel("L_t of each seed's best trial (×10⁻³)")
    ax.set_title("one point per sampler seed; bar: median")
    ax.legend()
    for ax, name in zip(axes[1:], ("paper:0", "paper:1"), strict=True):
        d = out["best_of_all_per_trajectory"][name]
        cls = np.asarray(d["classes"])
        a, b = np.asarray(d["cv"]) * 1e3, np.asarray(d["ca"]) * 1e3
        for i, c in enumerate(sorted(set(cls))):
            ax.scatter(b[cls == c], a[cls == c], s=14, color=f"C{i}", label=c.upper())
        lo, hi = min(a.min(), b.min()), max(a.max(), b.max())
        ax.plot([lo, hi], [lo, hi], "k-", lw=0.8)
        ax.plot([lo, hi], [1.05 * lo, 1.05 * hi], "k:", lw=0.8)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("L(k) CA (×10⁻³)")
        ax.set_ylabel("L(k) CV (×10⁻³)")
        ax.set_title(f"{name}: best CV vs best CA per trajectory")
        ax.legend(fontsize=8)
    fig.tight_layout()
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".png")
    os.close(fd)
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    os.replace(tmp, path)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--storage", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--figure", default=None, help="PNG: per-seed bests and per-trajectory L")
    ap.add_argument("--prefix", default="", help="only studies whose name starts with this")
    args = ap.parse_args()
    ds0 = Dataset.load(paper_dataset_file(0, 35))
    sets = {
        "paper:0": ds0,
        "paper:1": Dataset.load(paper_dataset_file(1, 35)),
        # diagnostic: the training set with the chain's 2.2 % v_r bias divided out
        "paper:0 vr/bias": dataclasses.replace(
            ds0, radial_velocity_mps=ds0.radial_velocity_mps / VR_BIAS
        ),
    }
    classes = {k: d.trajectory_class.astype(str) for k, d in sets.items()}
    studies = [s for s in load_studies(args.storage) if s.name.startswith(args.prefix)]
    rows: dict[str, dict] = {}
    losses: dict[str, dict[str, np.ndarray]] = {}
    for s in sorted(studies, key=lambda s: s.name):
        m = re.search(r"-s(\d+)$", s.name)
        best = _best(s.trials)
        early = _best(s.trials, EARLY_BUDGET)
        if best is None or m is None:
            continue
        params = best.tracker_params(s.model)
        row = {
            "model": s.model,
            "seed": int(m.group(1)),
            "trials": s.counted(),
            "pruned": sum(1 for t in s.trials if t.state == "PRUNED"),
            "wall_s": s.wall_s(),
            "best_trial": best.number,
            "best_value": best.value,
            f"best_value_first_{EARLY_BUDGET}": early.value if early else None,
            "params": params,
        }
        losses[s.name] = {}
        for name, ds in sets.items():
            ev = evaluate(ds, track_dataset(ds, TrackerParams.from_dict(params)))
            losses[s.name][name] = ev.loss
            row[name] = {
                "loss_total": float(ev.loss_total),
                "rmse_m": float(ev.rmse_m),
                "far_frames": int(ev.far_frames_total),
                "mean_first_confirmation_s": float(ev.mean_first_confirmation_s),
                "by_class": {r.name: float(r.loss) for r in ev.table},
            }
        rows[s.name] = row
        print(
            f"{s.name}: best {best.value * 1e3:.5f} (first {EARLY_BUDGET}: "
            f"{early.value * 1e3 if early else float('nan'):.5f}) paper:0 "
            f"{row['paper:0']['loss_total'] * 1e3:.5f} paper:1 "
            f"{row['paper:1']['loss_total'] * 1e3:.5f} vr/bias "
            f"{row['paper:0 vr/bias']['loss_total'] * 1e3:.5f} x1e-3",
            flush=True,
        )
    out: dict = {"storage": args.storage, "early_budget": EARLY_BUDGET, "studies": rows}
    by_model = {m: sorted(n for n, r in rows.items() if r["model"] == m) for m in ("cv", "ca")}
    out["per_model"] = {}
    for m, names in by_model.items():
        if not names:
            continue
        out["per_model"][m] = {
            "studies": names,
            "best_value": _stats([rows[n]["best_value"] for n in names]),
            f"best_value_first_{EARLY_BUDGET}": _stats(
                [rows[n][f"best_value_first_{EARLY_BUDGET}"] for n in names]
            ),
            "paper:1": _stats([rows[n]["paper:1"]["loss_total"] for n in names]),
            "paper:0 vr/bias": _stats([rows[n]["paper:0 vr/bias"]["loss_total"] for n in names]),
        }
    if by_model["cv"] and by_model["ca"]:
        pm = out["per_model"]
        out["median_ratio_cv_over_ca"] = {
            "training (best value)": pm["cv"]["best_value"]["median"]
            / pm["ca"]["best_value"]["median"],
            f"training, first {EARLY_BUDGET} trials": pm["cv"][f"best_value_first_{EARLY_BUDGET}"][
                "median"
            ]
            / pm["ca"][f"best_value_first_{EARLY_BUDGET}"]["median"],
            "paper:1": pm["cv"]["paper:1"]["median"] / pm["ca"]["paper:1"]["median"],
            "paper:0 vr/bias": pm["cv"]["paper:0 vr/bias"]["median"]
            / pm["ca"]["paper:0 vr/bias"]["median"],
        }
        # every CV study against every CA study: how often is CV within 5 %?
        out["all_pairs"] = {}
        for name in sets:
            r = np.array(
                [
                    [
                        rows[a][name]["loss_total"] / rows[b][name]["loss_total"]
                        for b in by_model["ca"]
                    ]
                    for a in by_model["cv"]
                ]
            )
            out["all_pairs"][name] = {
                "ratios_cv_rows_ca_columns": r.tolist(),
                "fraction_within_5_percent": float(np.mean(r <= 1.05)),
            }
        # paired per seed, and best of all seeds
        out["paired"] = {}
        seeds_cv = {rows[n]["seed"]: n for n in by_model["cv"]}
        seeds_ca = {rows[n]["seed"]: n for n in by_model["ca"]}
        pairs = {f"seed {s}": (seeds_cv[s], seeds_ca[s]) for s in sorted(seeds_cv) if s in seeds_ca}
        best_cv = min(by_model["cv"], key=lambda n: rows[n]["best_value"])
        best_ca = min(by_model["ca"], key=lambda n: rows[n]["best_value"])
        pairs["best of all seeds"] = (best_cv, best_ca)
        for label, (a, b) in pairs.items():
            out["paired"][label] = {"cv": a, "ca": b}
            for name in sets:
                c = paired_comparison(losses[a][name], losses[b][name], classes[name])
                out["paired"][label][name] = c.to_dict()
                print(
                    f"{label:>18} {name}: CV/CA = {c.ratio:.3f} "
                    f"[{c.ci_low:.3f}, {c.ci_high:.3f}] P(>1.05) = {c.p_ratio_above:.2f} "
                    f"wins CV {c.wins_a} CA {c.wins_b} Wilcoxon p = {c.wilcoxon_p:.3g}",
                    flush=True,
                )
        # the per-trajectory losses of the best-of-all pair (for the report's figure/table)
        out["best_of_all_per_trajectory"] = {
            name: {
                "classes": classes[name].tolist(),
                "cv": losses[best_cv][name].tolist(),
                "ca": losses[best_ca][name].tolist(),
            }
            for name in sets
        }
    path = Path(args.out)
    path.parent.mkdir(parents=True, exist_ok=True)
    if args.figure and by_model["cv"] and by_model["ca"]:
        _figure(out, Path(args.figure))
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    with os.fdopen(fd, "w") as f:
        json.dump(out, f, indent=1)
    os.replace(tmp, path)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

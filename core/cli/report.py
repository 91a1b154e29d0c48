"""``radartune report --storage URL --out DIR``: Table I, best parameters, loss against time."""

from __future__ import annotations

import argparse
import shlex
import sys


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("report", help="write the tuning report (Table I, plots, best parameters)")
    p.add_argument("--storage", required=True, help="storage URL holding the studies")
    p.add_argument("--out", required=True, help="folder to write report.md, PNGs and JSON into")
    p.add_argument("--dataset", default=None, help="training data set (default: the studies')")
    p.add_argument(
        "--generalisation",
        default="paper:1",
        help="second data set from another seed (default: %(default)s; 'none' skips it)",
    )
    p.add_argument(
        "--person-model",
        default=None,
        help="person model of a paper:SEED generalisation set (default: the training set's): "
        "walking, point (the paper's) or blob (former name extended)",
    )
    p.add_argument(
        "--test-sets",
        type=int,
        default=20,
        metavar="N",
        help="score the chosen parameters on N paper test data sets (seeds 2000…; made like the "
        "training set; simulated on first use, minutes each, cached) (default: %(default)s; 0: "
        "off)",
    )
    p.add_argument(
        "--test-set",
        action="append",
        default=None,
        metavar="PATH",
        help="a test data-set file instead of the paper ones (repeatable)",
    )
    p.add_argument(
        "--no-sensitivity",
        action="store_true",
        help="leave out the sensitivity sections (parameter importance, one-at-a-time sweeps, "
        "clutter robustness)",
    )
    p.add_argument(
        "--sensitivity-points",
        type=int,
        default=15,
        metavar="N",
        help="grid points per parameter of the one-at-a-time sweeps, 2-200 (default: "
        "%(default)s; 0: no sweeps)",
    )
    p.add_argument(
        "--no-clutter-variants",
        action="store_true",
        help="score the clutter robustness on the data sets as they are only, without their "
        "variants with the scene clutter rate ×0.5 and ×2 (simulated on first use, cached)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from core.errors import InputError
    from core.optimization.report import write_report

    if args.sensitivity_points != 0 and not 2 <= args.sensitivity_points <= 200:
        raise InputError(
            f"--sensitivity-points must be 0 or in [2, 200], got {args.sensitivity_points}"
        )
    gen = None if args.generalisation in ("none", "") else args.generalisation
    if args.person_model is not None:
        if gen is None or not gen.startswith("paper:"):
            raise InputError("--person-model needs a paper:SEED --generalisation set")
        if gen.count(":") == 1:
            gen = f"{gen}:{args.person_model}"
    command = "radartune " + " ".join(shlex.quote(a) for a in sys.argv[1:])
    r = write_report(
        args.storage,
        args.out,
        dataset=args.dataset,
        generalisation_dataset=gen,
        command=command,
        test_sets=args.test_sets,
        test_paths=args.test_set,
        progress=lambda line: print(line, file=sys.stderr, flush=True),
        sensitivity=not args.no_sensitivity,
        sensitivity_points=args.sensitivity_points,
        clutter_variants=not args.no_clutter_variants,
    )
    for model, m in r["models"].items():
        line = f"{model.upper()}: L_t = {m['training']['loss_total_x1e3']:.4f} x1e-3"
        if "generalisation" in m:
            line += f" (other seed: {m['generalisation']['loss_total_x1e3']:.4f} x1e-3)"
        print(line)
    for model, m in r.get("test_sets", {}).get("models", {}).items():
        t = m["loss"]["total"]
        print(
            f"{model.upper()} on {t['n_sets']} test sets: median L_t = {t['median'] * 1e3:.4f} "
            f"[{t['median_lo'] * 1e3:.4f}, {t['median_hi'] * 1e3:.4f}] x1e-3, mean "
            f"{t['mean'] * 1e3:.4f} [{t['mean_lo'] * 1e3:.4f}, {t['mean_hi'] * 1e3:.4f}] x1e-3"
        )
    if "conclusion" in r:
        print(f"CV/CA = {r['conclusion']['cv_over_ca']:.3f}")
    print(f"written: {args.out}/report.md")
    return 0

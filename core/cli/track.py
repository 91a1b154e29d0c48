"""``radartune track``: run the (J)IPDA tracker on a data set and print the paper's loss table."""

from __future__ import annotations

import argparse


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("track", help="track a data set and print the loss table (Table I)")
    p.add_argument("--data", required=True, help="data set (.npz)")
    p.add_argument(
        "--params", help="tracker parameters (JSON, SPEC §6); default: the model's defaults"
    )
    p.add_argument(
        "--model", choices=("cv", "ca"), help="motion model when --params is not given (cv)"
    )
    p.add_argument("--out", help="write parameters, table and metrics to this JSON file")
    p.add_argument(
        "--trajectories", help="comma-separated trajectory indices to track (default: all)"
    )
    p.add_argument(
        "--engine", choices=("numba", "numpy"), default="numba", help="default: %(default)s"
    )
    p.add_argument(
        "--association",
        choices=("ipda", "jipda"),
        help="data association: joint IPDA over tracks sharing measurements, or independent "
        "IPDA per track (default: the parameters' 'association', jipda)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import time
    from dataclasses import replace
    from pathlib import Path

    from core.dataset import Dataset
    from core.errors import InputError
    from core.evaluation import evaluate
    from core.files import check_output_path, write_json_atomic
    from core.tracking import TrackerParams, track_dataset

    if args.params and args.model:
        raise InputError("give either --params or --model, not both")
    if args.out:
        check_output_path(args.out)
    params = (
        TrackerParams.load(args.params)
        if args.params
        else TrackerParams.default(args.model or "cv")
    )
    if args.association:
        params = replace(params, association=args.association)
    ds = Dataset.load(args.data)
    traj = None
    if args.trajectories:
        try:
            traj = [int(t) for t in args.trajectories.split(",") if t.strip()]
        except ValueError:
            raise InputError(
                f"--trajectories must be comma-separated integers, got {args.trajectories!r}"
            ) from None
        bad = [t for t in traj if not 0 <= t < ds.n_trajectories]
        if bad:
            raise InputError(
                f"--trajectories must be indices in [0, {ds.n_trajectories}), got {bad}"
            )
    t0 = time.perf_counter()
    est = track_dataset(ds, params, trajectories=traj, engine=args.engine)
    elapsed = time.perf_counter() - t0
    ev = evaluate(ds, est)
    print(
        f"{args.data}: {len(est.trajectories)} trajectories, {len(est.frame_index)} frames, "
        f"model {params.model}, association {params.association}, "
        f"tracked in {elapsed * 1e3:.1f} ms"
    )
    print(ev.format_table())
    if args.out:
        out = Path(args.out)
        doc = {
            "data": str(args.data),
            "params": params.to_dict(),
            "engine": args.engine,
            "elapsed_s": elapsed,
            **ev.to_dict(),
        }
        write_json_atomic(out, doc)
        print(f"written: {out}")
    return 0

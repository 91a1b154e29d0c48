"""``radartune simulate``: one scene file → a data set ``.npz`` (SPEC §6)."""

from __future__ import annotations

import argparse
import sys
import time


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "simulate",
        help="simulate a scene through the radar chain into a data set .npz",
        description="Simulate a scene JSON file (SPEC §6) frame by frame through the radar "
        "chain and write its point clouds and ground truth as a data set .npz.",
    )
    p.add_argument("--scene", required=True, metavar="FILE", help="scene JSON file")
    p.add_argument("--out", metavar="FILE", help="output data set .npz (written atomically)")
    p.add_argument("--seed", type=int, default=None, help="seed (default: the scene's seed)")
    p.add_argument("--fidelity", default="exact", help="simulator level (default: exact)")
    p.add_argument(
        "--explain", action="store_true", help="print the plan: every stage, run or skipped, why"
    )
    p.add_argument(
        "--keep-rd-maps", action="store_true", help="plan with range-Doppler maps kept (as the GUI)"
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from core.cli.progress import ProgressBar
    from core.errors import InputError
    from core.files import check_output_path
    from core.pipeline import plan, simulate_scene
    from core.scene import Scene

    t0 = time.perf_counter()
    if args.seed is not None and args.seed < 0:
        raise InputError(f"--seed must be >= 0, got {args.seed}")
    scene = Scene.from_json(args.scene)
    the_plan = plan(scene, keep_rd_maps=args.keep_rd_maps, fidelity=args.fidelity)
    if args.explain:
        print(the_plan.explain())
    if args.out is None:
        if args.explain:
            return 0
        raise InputError("--out FILE is required (or use --explain alone)")
    check_output_path(args.out, what="data set")
    run_ = simulate_scene(
        scene, seed=args.seed, the_plan=the_plan, progress=ProgressBar("simulate")
    )
    run_.to_dataset().save(args.out)
    n_points = sum(len(c) for c in run_.clouds)
    print(
        f"wrote {args.out}: {scene.n_frames} frames, {n_points} points, "
        f"{scene.n_persons} person(s); elapsed {time.perf_counter() - t0:.1f} s",
        file=sys.stdout,
    )
    return 0

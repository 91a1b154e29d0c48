"""``radartune export``: simulate a scene and write its point clouds in a format other tools read
(TI UART log, Industrial Visualizer replay), with the TI ``.cfg`` that matches."""

from __future__ import annotations

import argparse


def add_parser(sub: argparse._SubParsersAction) -> None:
    from core.recordings import FORMATS

    writable = tuple(
        n for n, row in FORMATS.items() if row.write is not None or row.write_scene is not None
    )
    p = sub.add_parser(
        "export",
        help="simulate a scene and write it as a TI UART log or visualizer replay (+ .cfg)",
        description="Simulate a scene through the radar chain (as `radartune simulate`) and "
        "write its point clouds in a sensor format, with the matching TI .cfg next to it.",
    )
    p.add_argument("--scene", required=True, metavar="FILE", help="scene JSON file")
    p.add_argument("--format", required=True, choices=writable, help="output format")
    p.add_argument("--out", required=True, metavar="FILE", help="file to write")
    p.add_argument(
        "--variant",
        help="uart: point format sdk3 (float, default), sdk2 (Q9, xWR16xx header), "
        "sdk1-xwr14 (Q9, 36-byte header), sdk5 (xWRL6432 TLV 301), tracking (TLV 1020)",
    )
    p.add_argument("--seed", type=int, default=None, help="seed (default: the scene's seed)")
    p.add_argument("--fidelity", default="exact", help="simulator level (default: exact)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import time
    from pathlib import Path

    from core.cli.progress import ProgressBar
    from core.errors import InputError
    from core.files import check_output_path
    from core.pipeline import plan, simulate_scene
    from core.recordings import FORMATS
    from core.scene import Scene

    t0 = time.perf_counter()
    row = FORMATS[args.format]
    if args.variant is not None and args.variant not in row.variants:
        raise InputError(
            f"--variant must be one of {list(row.variants)} for {args.format}, got {args.variant!r}"
        )
    if args.seed is not None and args.seed < 0:
        raise InputError(f"--seed must be >= 0, got {args.seed}")
    out = check_output_path(args.out)
    scene = Scene.from_json(args.scene)
    if row.write_scene is not None:  # e.g. ADC captures: the format simulates what it needs
        written = row.write_scene(
            Path(out), scene, seed=args.seed, fidelity=args.fidelity, variant=args.variant
        )
        what = f"{scene.n_frames} frames"
    else:
        the_plan = plan(scene, fidelity=args.fidelity)
        run_ = simulate_scene(
            scene, seed=args.seed, the_plan=the_plan, progress=ProgressBar("export")
        )
        assert row.write is not None
        written = row.write(Path(out), list(run_.clouds), scene.radar, args.variant)
        what = f"{len(run_.clouds)} frames, {sum(len(c) for c in run_.clouds)} points"
    print(
        f"wrote {', '.join(str(p) for p in written)}: {args.format}"
        f"{' ' + args.variant if args.variant else ''}, {what}; "
        f"elapsed {time.perf_counter() - t0:.1f} s"
    )
    return 0

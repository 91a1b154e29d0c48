"""``radartune simulate``: one scene file → a data set ``.npz`` (SPEC §6)."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from core.config import ChainConfig


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
    p.add_argument(
        "--cfg",
        metavar="TI.cfg",
        help="a TI .cfg: the radar and the detection chain it selects (paper, oob or "
        "people-counting; docs/radar-chain.md); replaces the scene's radar",
    )
    p.add_argument(
        "--chain",
        metavar="NAME",
        help="detection chain with TI's default settings: paper, oob or people-counting "
        "(without --cfg)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from core.cli.progress import ProgressBar
    from core.errors import InputError
    from core.files import check_output_path, parse_json, read_text
    from core.pipeline import plan, simulate_scene
    from core.scene import Scene

    t0 = time.perf_counter()
    if args.seed is not None and args.seed < 0:
        raise InputError(f"--seed must be >= 0, got {args.seed}")
    chain = _chain(args)
    if args.cfg is not None:
        # the scene with the cfg's radar (its frame period samples the trajectories)
        cfg = str(Path(args.cfg).resolve())
        data = parse_json(read_text(args.scene, what="scene"), args.scene)
        if isinstance(data, dict):
            data = {**data, "radar": cfg}
        scene = Scene.from_dict(data, source=args.scene, base_dir=Path(args.scene).parent)
        ignored = ", ".join(chain.ignored) if chain.ignored else "none"
        print(f"chain {chain.name} from {args.cfg}; commands ignored: {ignored}", file=sys.stderr)
    else:
        scene = Scene.from_json(args.scene)
    the_plan = plan(scene, keep_rd_maps=args.keep_rd_maps, fidelity=args.fidelity, chain=chain)
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


def _chain(args: argparse.Namespace) -> ChainConfig:
    """The chain of ``--cfg`` or ``--chain`` (paper when neither); one line naming a bad one."""
    from core.config import default_chain
    from core.errors import InputError
    from core.formats.ti_cfg import read_ti_chain

    if args.cfg is not None and args.chain is not None:
        raise InputError("--cfg selects the chain itself: give --cfg or --chain, not both")
    if args.cfg is not None:
        return read_ti_chain(args.cfg)
    try:
        return default_chain("paper" if args.chain is None else args.chain)
    except InputError as exc:
        raise InputError(f"--{exc.message}") from None

"""``radartune track``: run the (J)IPDA tracker on a data set and print the paper's loss table,
GOSPA, the people-count error, identity switches and the metrics of every person; for every data
set (with or without truth) the scores that need no positions (head count, fragmentation, NIS)
and, with ``--tracks``, every track of every frame as a CSV."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from core.dataset import Dataset
    from core.evaluation.counting import RecordingScores
    from core.tracking import DatasetEstimates, TrackerParams
    from core.tracking.zones import Zones


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
        "--tracks",
        help="write every track of every frame to this CSV (frame,time_s,track_id,status,x_m,"
        "y_m,z_m,vx_mps,vy_mps,existence,n_points)",
    )
    p.add_argument(
        "--people",
        type=int,
        help="people in the room in every frame: scores the confirmed-track count and the "
        "fragmentation without positions (default: the count in the truth, if any)",
    )
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
    p.add_argument(
        "--tracker",
        choices=("paper", "gtrack"),
        default="paper",
        help="the paper's (J)IPDA, or TI's people tracker rebuilt (gtrack); default: paper",
    )
    p.add_argument("--cfg", help="gtrack: take the tracker lines of this TI .cfg")
    p.add_argument(
        "--mode",
        choices=("paper", "room"),
        help="tracker: the paper's one-point IPDA, or the tracker for real rooms (groups of "
        "points, static points, ghosts; default: the parameters' 'mode', paper)",
    )
    p.add_argument(
        "--zones",
        metavar="TI_CFG",
        help="room mode: boundary, static and presence boxes from a TI .cfg's boundaryBox, "
        "staticBoundaryBox and presenceBoundaryBox lines (default: none)",
    )
    p.add_argument(
        "--room",
        metavar="ROOM_JSON",
        help="room mode: the room's walls (a room file: walls/furniture/sensor, docs/rooms.md); "
        "tentative tracks at a confirmed track's predicted wall ghosts are not confirmed",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import time

    from core.cli.track_scores import scores_without_positions
    from core.dataset import Dataset
    from core.formats.recording import has_truth
    from core.tracking import track_dataset
    from core.tracking.warm import load_compiled

    if args.tracker == "gtrack":
        return _run_gtrack(args)
    _check_args(args)
    params = _params_from(args)
    zones = _zones_from(args, params)
    ds = Dataset.load(args.data)
    traj = _trajectories_from(args, ds)
    # loading the compiled kernels is start-up, not tracking: paid first, reported apart
    startup = load_compiled(params) if args.engine == "numba" else 0.0
    t0 = time.perf_counter()
    est = track_dataset(
        ds, params, trajectories=traj, engine=args.engine, with_tracks=True, zones=zones
    )
    elapsed = time.perf_counter() - t0
    scores = scores_without_positions(ds, est, args.people)
    if not has_truth(ds):
        _report_without_truth(args, ds, est, params, elapsed, scores)
    else:
        _report_with_truth(args, ds, est, params, elapsed, startup, scores)
    return 0


def _run_gtrack(args: argparse.Namespace) -> int:
    """``--tracker gtrack``: TI's tracker rebuilt (:mod:`core.cli.gtrack`); refuses the options
    that set RadarTune's tracker."""
    from core.cli.gtrack import run_track
    from core.errors import InputError

    if args.mode or args.zones or args.room:
        raise InputError(
            "--mode, --zones and --room set RadarTune's tracker; gtrack takes its boxes from --cfg"
        )
    return run_track(args)


def _check_args(args: argparse.Namespace) -> None:
    """One-line refusals of option combinations and outputs before anything is read."""
    from core.errors import InputError
    from core.files import check_output_path

    if args.cfg:
        raise InputError("--cfg sets gtrack's tracker lines: use it with --tracker gtrack")
    if args.params and args.model:
        raise InputError("give either --params or --model, not both")
    for out_path, what in ((args.out, "--out"), (args.tracks, "--tracks")):
        if out_path:
            check_output_path(out_path, what=f"{what} file")
    if args.people is not None and args.people < 0:
        raise InputError(f"--people must be >= 0, got {args.people}")


def _params_from(args: argparse.Namespace) -> TrackerParams:
    """The tracker parameters: the file or the model's defaults, with the association and mode
    options applied."""
    from dataclasses import replace

    from core.tracking import TrackerParams

    params = (
        TrackerParams.load(args.params)
        if args.params
        else TrackerParams.default(args.model or "cv")
    )
    if args.association:
        params = replace(params, association=args.association)
    if args.mode:
        params = replace(params, mode=args.mode)
    return params


def _zones_from(args: argparse.Namespace, params: TrackerParams) -> Zones | None:
    """The room mode's zones from ``--zones`` (a TI .cfg) and walls from ``--room``; None."""
    from dataclasses import replace

    from core.errors import InputError

    zones: Zones | None = None
    if args.zones:
        from core.tracking.zones import zones_from_cfg

        if params.mode != "room":
            raise InputError("--zones needs the room mode (--mode room)")
        zones = zones_from_cfg(args.zones)
    if args.room:
        from core.scene.room import Room
        from core.tracking.zones import Zones

        if params.mode != "room":
            raise InputError("--room needs the room mode (--mode room)")
        zones = replace(zones or Zones(), walls=Room.from_json(args.room).wall_segments())
    return zones


def _trajectories_from(args: argparse.Namespace, ds: Dataset) -> list[int] | None:
    """``--trajectories`` as indices checked against the data set; None: all."""
    from core.errors import InputError

    if not args.trajectories:
        return None
    try:
        traj = [int(t) for t in args.trajectories.split(",") if t.strip()]
    except ValueError:
        raise InputError(
            f"--trajectories must be comma-separated integers, got {args.trajectories!r}"
        ) from None
    bad = [t for t in traj if not 0 <= t < ds.n_trajectories]
    if bad:
        raise InputError(f"--trajectories must be indices in [0, {ds.n_trajectories}), got {bad}")
    return traj


def _report_without_truth(
    args: argparse.Namespace,
    ds: Dataset,
    est: DatasetEstimates,
    params: TrackerParams,
    elapsed: float,
    scores: RecordingScores,
) -> None:
    """A recording without truth: the confirmed frames and the scores without positions."""
    from pathlib import Path

    import numpy as np

    from core.cli.track_scores import per_frame
    from core.files import write_json_atomic

    n_conf = int(np.sum(np.isfinite(est.confirmed_xy[..., 0]).any(axis=1)))
    print(
        f"{args.data}: {len(est.trajectories)} trajectories, {len(est.frame_index)} frames, "
        f"model {params.model}, tracked in {elapsed * 1e3:.1f} ms; {n_conf} frames with a "
        "confirmed track; no ground truth, so no loss table (import with --truth to score)"
    )
    print("\n".join(scores.format_lines()))
    _write_tracks(args.tracks, ds, est)
    if args.out:
        doc = {
            "data": str(args.data),
            "params": params.to_dict(),
            "engine": args.engine,
            "elapsed_s": elapsed,
            "frames_with_confirmed_track": n_conf,
            "truth": False,
            **per_frame(est),
            "without_positions": scores.to_dict(),
        }
        write_json_atomic(Path(args.out), doc)
        print(f"written: {args.out}")


def _report_with_truth(
    args: argparse.Namespace,
    ds: Dataset,
    est: DatasetEstimates,
    params: TrackerParams,
    elapsed: float,
    startup: float,
    scores: RecordingScores,
) -> None:
    """A data set with truth: the loss table (eq. 14), its metrics and the scores."""
    from pathlib import Path

    from core.cli.track_scores import per_frame
    from core.evaluation import evaluate
    from core.files import write_json_atomic

    ev = evaluate(ds, est)
    print(
        f"{args.data}: {len(est.trajectories)} trajectories, {len(est.frame_index)} frames, "
        f"model {params.model}, association {params.association}, "
        f"tracked in {elapsed * 1e3:.1f} ms "
        f"({elapsed / max(len(est.frame_index), 1) * 1e6:.1f} µs a frame; loading the compiled "
        f"tracker took {startup * 1e3:.0f} ms before)"
    )
    print(ev.format_table())
    print("\n".join(scores.format_lines()))
    _write_tracks(args.tracks, ds, est)
    if args.out:
        out = Path(args.out)
        doc = {
            "data": str(args.data),
            "params": params.to_dict(),
            "engine": args.engine,
            "elapsed_s": elapsed,
            "startup_s": startup,
            **ev.to_dict(),
            **per_frame(est),
            "without_positions": scores.to_dict(),
        }
        write_json_atomic(out, doc)
        print(f"written: {out}")


def _write_tracks(path: str | None, ds: Dataset, est: DatasetEstimates) -> None:
    """The tracks CSV (:mod:`core.formats.tracks_csv`), when asked for."""
    if not path:
        return
    from core.formats.tracks_csv import track_rows, write_tracks_csv

    rows = track_rows(ds, est)
    write_tracks_csv(path, rows)
    print(f"written: {path} ({len(rows)} rows)")

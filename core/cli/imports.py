"""``radartune import``: a recording from a real sensor (TI UART log, Industrial Visualizer
replay, …) → a data set ``.npz`` that ``track``, ``report`` and (with truth) ``tune`` use."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from core.formats.recording import TruthAlignment


def add_parser(sub: argparse._SubParsersAction) -> None:
    from core.recordings import FORMATS

    p = sub.add_parser(
        "import",
        help="turn a real recording (TI UART log, visualizer replay, DCA1000 capture) into a "
        "data set .npz",
        description="Read a recording (format detected from its content, or --format), "
        "optionally with the TI .cfg it was recorded with and a ground-truth CSV "
        "(time_s,person,x_m,y_m), and write it as a RadarTune data set. Dropped frames and "
        "skipped TLVs are counted and printed.",
    )
    p.add_argument("file", metavar="FILE", help="the recording (a file, or a folder of replays)")
    p.add_argument("--cfg", metavar="CFG", help="TI .cfg the recording was made with")
    p.add_argument("--truth", metavar="CSV", help="ground truth: time_s,person,x_m,y_m per line")
    p.add_argument(
        "--truth-offset",
        type=float,
        default=0.0,
        metavar="S",
        help="seconds added to the truth's (and head count's) times to put them on the "
        "recording's clock (its first frame at 0)",
    )
    p.add_argument(
        "--truth-drift",
        type=float,
        default=0.0,
        metavar="PPM",
        help="the truth clock's rate error: recording time = offset + t·(1 + PPM·1e-6)",
    )
    p.add_argument(
        "--sensor-pose",
        metavar="X,Y,HEIGHT,YAW,TILT",
        help="the radar in the truth's coordinates: position (m), height above the truth's "
        "z = 0 (m), boresight bearing from +y towards +x (deg), tilt down (deg)",
    )
    p.add_argument("--people", type=int, metavar="N", help="head count: N people in every frame")
    p.add_argument(
        "--people-csv",
        metavar="CSV",
        help="head count over time intervals: t_start_s,t_end_s,people per line",
    )
    p.add_argument("--format", choices=tuple(FORMATS), help="skip detection: read as this format")
    p.add_argument(
        "--columns",
        metavar="MAP",
        help="a plain CSV's column map: frame=COL,x=COL,y=COL[,z=,doppler=,snr=,time=] "
        "(header names; implies --format csv)",
    )
    p.add_argument("--out", required=True, metavar="DATASET.npz", help="data set to write")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import time

    from core.files import check_output_path
    from core.formats.recording import (
        read_count_csv,
        read_truth_csv,
        to_dataset,
    )
    from core.recordings import read_recording

    t0 = time.perf_counter()
    check_output_path(args.out, what="data set")
    alignment = _alignment(args)
    truth = read_truth_csv(args.truth) if args.truth else None
    counts = read_count_csv(args.people_csv) if args.people_csv else None
    rec = read_recording(args.file, fmt=args.format, cfg=args.cfg, columns=args.columns)
    ds = to_dataset(
        rec,
        truth=truth,
        source_name=str(args.file),
        alignment=alignment,
        counts=counts,
        people=args.people,
        truth_name=str(args.truth),
    )
    ds.save(args.out)
    for line in rec.notes:
        print(line)
    truth_note = f"{ds.n_persons} person(s) of truth" if truth is not None else "no truth"
    if len(ds.people_count):
        known = ds.people_count >= 0
        truth_note += f", a head count on {int(known.sum())} frames"
    if ds.has_reference:
        truth_note += f", {len(ds.ref_frame)} rows of the sensor's own tracks"
    print(
        f"wrote {args.out}: {rec.format}, {ds.n_frames} frames in {ds.n_trajectories} run(s), "
        f"{len(ds.frame)} points, {truth_note}; elapsed {time.perf_counter() - t0:.1f} s"
    )
    return 0


def _alignment(args: argparse.Namespace) -> TruthAlignment:
    import math

    from core.errors import InputError
    from core.formats.recording import TruthAlignment

    pose = [0.0] * 5
    if args.sensor_pose:
        parts = args.sensor_pose.split(",")
        try:
            pose = [float(v) for v in parts]
        except ValueError:
            pose = []
        if len(pose) != 5 or not all(math.isfinite(v) for v in pose):
            raise InputError(
                f"--sensor-pose must be five numbers X,Y,HEIGHT,YAW,TILT, got {args.sensor_pose!r}"
            )
    for name in ("truth_offset", "truth_drift"):
        if not math.isfinite(getattr(args, name)):
            raise InputError(f"--{name.replace('_', '-')} must be finite")
    x, y, h, yaw, tilt = pose
    return TruthAlignment(
        offset_s=args.truth_offset,
        drift_ppm=args.truth_drift,
        sensor_x_m=x,
        sensor_y_m=y,
        sensor_height_m=h,
        yaw_deg=yaw,
        tilt_deg=tilt,
    )

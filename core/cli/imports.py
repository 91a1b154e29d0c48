"""``radartune import``: a recording from a real sensor (TI UART log, Industrial Visualizer
replay, …) → a data set ``.npz`` that ``track``, ``report`` and (with truth) ``tune`` use."""

from __future__ import annotations

import argparse


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
    from core.formats.recording import read_truth_csv, to_dataset
    from core.recordings import read_recording

    t0 = time.perf_counter()
    check_output_path(args.out, what="data set")
    truth = read_truth_csv(args.truth) if args.truth else None
    rec = read_recording(args.file, fmt=args.format, cfg=args.cfg, columns=args.columns)
    ds = to_dataset(rec, truth=truth, source_name=str(args.file))
    ds.save(args.out)
    for line in rec.notes:
        print(line)
    truth_note = f"{ds.n_persons} person(s) of truth" if truth is not None else "no truth"
    print(
        f"wrote {args.out}: {rec.format}, {ds.n_frames} frames in {ds.n_trajectories} run(s), "
        f"{len(ds.frame)} points, {truth_note}; elapsed {time.perf_counter() - t0:.1f} s"
    )
    return 0

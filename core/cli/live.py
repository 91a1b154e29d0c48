"""``radartune live``: a TI mmWave sensor on its two serial ports, configured from a ``.cfg``,
tracked frame by frame, its data port recorded unchanged."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from core.live import LiveFrame


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "live",
        help="configure a TI mmWave sensor over its serial ports, track and record it live",
        description="Send the .cfg line by line on the CLI port (each answer checked; the first "
        "line the sensor rejects ends the run, named), then read the data port through the UART "
        "log reader, track every frame with RadarTune's tracker and print one status line a "
        "frame. sensorStop is sent on the way out (Ctrl-C, --frames reached, a port lost). "
        "Exit 0 when stopped by --frames or the end of the stream, 2 on a rejected line or a "
        "port that vanished (one line), 130 on Ctrl-C.",
    )
    p.add_argument("--cli-port", required=True, metavar="PORT", help="CLI (user) UART port")
    p.add_argument("--data-port", required=True, metavar="PORT", help="data (auxiliary) UART port")
    p.add_argument("--cfg", required=True, metavar="CFG", help="TI .cfg to send")
    p.add_argument(
        "--record",
        metavar="FILE",
        help="write the data port's bytes unchanged to FILE (a UART log: radartune import and "
        "TI's tools read it)",
    )
    p.add_argument(
        "--tracks", metavar="FILE.csv", help="write every track of every frame to this CSV"
    )
    p.add_argument("--frames", type=int, metavar="N", help="stop after N frames")
    p.add_argument(
        "--params", help="tracker parameters (JSON, SPEC §6); default: the model's defaults"
    )
    p.add_argument("--model", choices=("cv", "ca"), help="motion model without --params (cv)")
    p.add_argument(
        "--cli-baud", type=int, default=115_200, metavar="BAUD", help="default: %(default)s"
    )
    p.add_argument(
        "--data-baud",
        type=int,
        metavar="BAUD",
        help="default: the cfg's baudRate line, else 921600",
    )
    p.add_argument(
        "--quiet", action="store_true", help="no status line per frame (only the summary)"
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:

    from core.errors import InputError
    from core.files import check_output_path
    from core.live import LinkError, LinkSettings, LiveLink
    from core.live.tracks import LiveTracksWriter
    from core.tracking import TrackerParams

    if args.frames is not None and args.frames < 1:
        raise InputError(f"--frames must be >= 1, got {args.frames}")
    if args.params and args.model:
        raise InputError("give either --params or --model, not both")
    for out in (args.record, args.tracks):
        if out:
            check_output_path(out)
    if args.record and args.tracks and args.record == args.tracks:
        raise InputError("--record and --tracks must be two files")
    params = (
        TrackerParams.load(args.params)
        if args.params
        else TrackerParams.default(args.model or "cv")
    )
    settings = LinkSettings(
        cli_port=args.cli_port,
        data_port=args.data_port,
        cfg=args.cfg,
        cli_baud=args.cli_baud,
        data_baud=args.data_baud,
    )
    link = LiveLink(settings, params, record=args.record)
    tracks = LiveTracksWriter(args.tracks) if args.tracks else None
    failure: LinkError | None = None
    n = 0
    try:
        link.start()
        print(
            f"{args.cfg}: {len(link.commands)} lines accepted; reading {args.data_port} at "
            f"{link.data_baud} baud, frame period {link.radar.frame_period_s * 1e3:g} ms",
            flush=True,
        )
        for frame in link.frames():
            n += 1
            if tracks is not None:
                tracks.add(frame)
            if not args.quiet:
                print(status_line(frame), flush=True)
            if args.frames is not None and n >= args.frames:
                break
    except LinkError as exc:
        failure = exc
    finally:
        # however it ended (Ctrl-C included): sensorStop, ports closed, files put in place
        recorded = link.recorded_bytes
        path = link.close()
        # a link that failed before its first frame leaves no tracks file (as no recording)
        written = [tracks.close()] if tracks is not None and (n > 0 or failure is None) else []
    kept = f"; {path} keeps the {recorded} bytes that arrived" if path is not None else ""
    kept += "".join(f"; {w} holds the tracks of the {n} frames" for w in written)
    if failure is not None:
        raise LinkError(failure.message + kept, failure.source)
    for note in link.notes:
        print(note)
    r = link.report
    print(
        f"{n} frames tracked, {r.n_dropped} dropped (frame-number gaps), {r.n_damaged} damaged "
        f"packets skipped, {r.bytes_skipped} bytes outside packets"
        + (f"; recorded {recorded} bytes to {path}" if path is not None else "")
        + "".join(f"; tracks written to {w}" for w in written)
    )
    return 0


def status_line(frame: LiveFrame) -> str:
    """One line for a :class:`core.live.LiveFrame`: frame, points, tracks, the confirmed ones."""
    t = frame.tracks
    conf = [
        f"#{int(i)} ({x:+.2f}, {y:+.2f}) m"
        for i, (x, y), c in zip(t.ids, t.state[:, :2], t.confirmed)
        if c
    ]
    return (
        f"frame {frame.index} (no. {frame.frame_number}) t={frame.t_s:.2f} s: "
        f"{len(frame.cloud)} points, {len(t)} tracks, {len(conf)} confirmed"
        + (": " + ", ".join(conf) if conf else "")
        + f"; dropped {frame.n_dropped}, damaged {frame.n_damaged}"
    )

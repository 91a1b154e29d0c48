"""``radartune export-cfg``: write tracker parameters as TI ``.cfg`` lines into a base ``.cfg``.

Every line of the base other than the tracker lines is kept as it was; without ``--params`` the
base's own tracker values are written back (a round trip).
"""

from __future__ import annotations

import argparse


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "export-cfg", help="write tracker parameters as TI .cfg tracker lines into a base .cfg"
    )
    p.add_argument("--tracker", choices=("gtrack",), default="gtrack", help="default: gtrack")
    p.add_argument("--cfg", required=True, help="the base TI .cfg")
    p.add_argument("--params", help="gtrack parameters (JSON); default: the base's own values")
    p.add_argument("--out", required=True, help="the .cfg to write (replaced whole)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from core.cli.gtrack import load_params
    from core.files import check_output_path, read_text, write_text_atomic
    from core.formats.ti_cfg import replace_tracker_lines
    from core.tracking.gtrack.params import cfg_lines

    check_output_path(args.out)
    params = load_params(args.cfg, args.params)
    base = read_text(Path(args.cfg), what="TI configuration")
    lines = cfg_lines(params)
    write_text_atomic(args.out, replace_tracker_lines(base, lines))
    print(f"written: {args.out}; the tracker lines:")
    for line in lines.values():
        print(f"  {line}")
    return 0

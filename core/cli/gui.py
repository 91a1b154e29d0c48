"""``radartune gui``: start the desktop app (Qt is imported lazily, inside the function)."""

from __future__ import annotations

import argparse


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser("gui", help="start the desktop app with the paper scene playing")
    add_arguments(p)
    p.set_defaults(func=run)


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The app's options, shared by ``radartune gui`` and ``python -m app``."""
    p.add_argument("--scene", metavar="FILE", help="scene JSON to open (default: the paper scene)")
    p.add_argument(
        "--quit-after",
        metavar="SECONDS",
        type=float,
        default=None,
        help="close the window after this many seconds (smoke tests)",
    )
    p.add_argument("--paused", action="store_true", help="open without playing")
    p.add_argument(
        "--settings",
        metavar="FILE",
        default=None,
        help="settings file (INI); default: the user's RadarTune settings",
    )


def run(args: argparse.Namespace) -> int:
    from app.main import run as run_app  # imports Qt; never at module import

    return run_app(args.scene, args.quit_after, args.paused, args.settings)

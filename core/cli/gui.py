"""``radartune gui``: start the desktop app, which owns its own options.

The app (:mod:`app.main`) defines the GUI's arguments and parses them; this sub-command only
passes everything after ``gui`` through to it, so building the ``radartune`` parser never imports
the app. The app is found by name when the command runs (:func:`importlib.import_module`): this is
the one place ``core`` reaches ``app``, at run time, never at import or parser build
(``tests/test_architecture.py`` checks both). ``radartune gui --help`` prints the app's options.
"""

from __future__ import annotations

import argparse
import importlib

from core.errors import InputError

#: The module that starts the desktop app: ``main(argv: list[str]) -> int``.
APP_MODULE = "app.main"


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "gui",
        help="start the desktop app with the paper scene playing (radartune gui --help: options)",
        description="Start the RadarTune window; every argument is the app's (see --help).",
        add_help=False,  # --help goes through to the app's own parser
        prefix_chars="\0",  # so that no argument after ``gui`` is taken for one of ours
    )
    p.add_argument("app_args", nargs=argparse.REMAINDER, help=argparse.SUPPRESS)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Import the app (which imports Qt) and hand it the arguments."""
    try:
        app_main = importlib.import_module(APP_MODULE)
    except ModuleNotFoundError as exc:
        if exc.name not in ("app", APP_MODULE):
            raise
        raise InputError(
            "the desktop app is not installed here (it needs the 'app' package next to 'core')",
            "gui",
        ) from None
    return app_main.main(list(args.app_args))

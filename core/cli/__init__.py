"""``radartune`` command line: one module per subcommand, imported lazily.

Each module ``core.cli.<name>`` defines ``add_parser(subparsers)``, which adds its sub-parser
and sets ``func=<callable(args) -> int>`` as a default. Heavy imports stay inside the functions
so that ``radartune --help`` is fast. Bad input raises :class:`core.errors.InputError`; ``main``
prints it as one line and exits with code 2.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from core.errors import InputError

#: subcommand -> module; the module owns the subcommand's arguments and behaviour.
COMMANDS = {
    "radar": "core.cli.radar",
    "simulate": "core.cli.simulate",
    "dataset": "core.cli.dataset",
    "track": "core.cli.track",
    "stability": "core.cli.stability",
    "tune": "core.cli.tune",
    "worker": "core.cli.worker",
    "dashboard": "core.cli.dashboard",
    "report": "core.cli.report",
    "bench": "core.cli.bench",
    "gui": "core.cli.gui",
}

EXIT_INPUT_ERROR = 2


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="radartune",
        description="FMCW radar simulation, IPDA people tracking and Optuna parameter tuning.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for module_name in COMMANDS.values():
        try:
            module = importlib.import_module(module_name)
        except ModuleNotFoundError as exc:
            if exc.name != module_name:
                raise
            continue  # subcommand not built yet
        module.add_parser(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        code = args.func(args)
    except InputError as exc:
        print(f"radartune {args.command}: error: {exc}", file=sys.stderr)
        return EXIT_INPUT_ERROR
    except KeyboardInterrupt:
        print(f"radartune {args.command}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader went away (`radartune radar --json | head`): not an error of ours
        sys.stdout = None
        return 0
    return int(code or 0)


if __name__ == "__main__":
    sys.exit(main())

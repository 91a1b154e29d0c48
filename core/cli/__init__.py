"""``radartune`` command line: one module per subcommand, imported lazily.

Each module ``core.cli.<name>`` defines ``add_parser(subparsers)``, which adds its sub-parser
and sets ``func=<callable(args) -> int>`` as a default. Heavy imports stay inside the functions
so that ``radartune --help`` is fast. Bad input raises :class:`core.errors.InputError`; ``main``
prints it as one line and exits with code 2. Any other exception is also one line (its type,
message and the input files named on the command line) with exit code 2 — a traceback is never
the user's answer; ``radartune --debug COMMAND`` shows it.
"""

from __future__ import annotations

import argparse
import importlib
import sys
import traceback
from typing import NoReturn

from core.cli.exit_codes import EXIT_INPUT_ERROR, EXIT_INTERRUPTED, EXIT_OK
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
    "import": "core.cli.imports",
    "export": "core.cli.export",
    "live": "core.cli.live",
    "export-cfg": "core.cli.export_cfg",
    "bench": "core.cli.bench",
    "gui": "core.cli.gui",
}


class OneLineParser(argparse.ArgumentParser):
    """An argument parser whose usage errors are one line on stderr (exit 2), like every other
    bad input; ``--help`` still prints the full usage."""

    def error(self, message: str) -> NoReturn:
        line = " ".join(f"{self.prog}: error: {message} (see {self.prog} --help)".split())
        self.exit(EXIT_INPUT_ERROR, line + "\n")


def build_parser() -> argparse.ArgumentParser:
    parser = OneLineParser(
        prog="radartune",
        description="FMCW radar simulation, IPDA people tracking and Optuna parameter tuning.",
    )
    parser.add_argument(
        "--debug", action="store_true", help="show the traceback of an unexpected error"
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
        _error_line(args, str(exc))
        return EXIT_INPUT_ERROR
    except KeyboardInterrupt:
        print(f"radartune {args.command}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        # the reader went away (`radartune radar --json | head`): not an error of ours
        sys.stdout = None
        return EXIT_OK
    except (SystemExit, GeneratorExit):
        raise
    except BaseException as exc:  # noqa: BLE001 - the one place that turns any error into a line
        if args.debug:
            traceback.print_exc()
        files = _input_files(args)
        where = f" (reading {', '.join(files)})" if files else ""
        what = str(exc).splitlines()[0] if str(exc) else ""
        _error_line(
            args,
            f"unexpected {type(exc).__name__}{where}: {what or 'no message'}"
            + ("" if args.debug else " (radartune --debug shows the traceback)"),
        )
        return EXIT_INPUT_ERROR
    return int(code or 0)


#: Arguments that name input files, in the order they are worth naming.
INPUT_ARGUMENTS = ("scene", "data", "dataset", "params", "cfg", "settings", "file", "truth")


def _input_files(args: argparse.Namespace) -> list[str]:
    return [str(v) for k in INPUT_ARGUMENTS if isinstance(v := getattr(args, k, None), str)]


def _error_line(args: argparse.Namespace, message: str) -> None:
    """Print ``message`` as exactly one line on stderr, safe for any terminal encoding."""
    from core.files import printable

    line = printable(f"radartune {args.command}: error: {message}")
    try:
        print(line, file=sys.stderr)
    except UnicodeEncodeError:
        enc = getattr(sys.stderr, "encoding", None) or "ascii"
        print(line.encode(enc, "backslashreplace").decode(enc), file=sys.stderr)


if __name__ == "__main__":
    sys.exit(main())

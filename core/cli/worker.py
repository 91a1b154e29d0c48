"""``radartune worker``: join a running study (also from another machine) and run trials.

The study must exist (``radartune tune`` creates it); the worker reads the model, sampler,
pruner, data set, seed and total from the study's attributes. SIGTERM or a first Ctrl-C stops after
the current trial; a second Ctrl-C aborts it (the trial is marked FAIL). Exit codes:
:mod:`core.cli.exit_codes` (also in ``radartune worker --help``).
"""

from __future__ import annotations

import argparse
import os
import signal
import sys

from core.cli.exit_codes import EXIT_INTERRUPTED, EXIT_OK, epilog


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "worker",
        help="join a running study and run trials until its total",
        epilog=epilog("worker"),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--storage", required=True, help="storage URL of the study")
    p.add_argument("--study", required=True, help="study name")
    p.add_argument(
        "--seed",
        type=int,
        default=None,
        help="base sampler seed (default: the study's --seed); trial n samples with a seed "
        "derived from it and n, so workers never repeat one another",
    )
    p.add_argument("--dataset", default=None, help="data-set .npz on this machine")
    p.set_defaults(func=run)


class StopFlag:
    """Set by SIGTERM or a first SIGINT; a second SIGINT raises KeyboardInterrupt."""

    def __init__(self) -> None:
        self.stopped = False
        #: the signal that first asked to stop (SIGTERM or SIGINT), None while running
        self.by: int | None = None

    def install(self) -> None:
        signal.signal(signal.SIGTERM, self._term)
        signal.signal(signal.SIGINT, self._int)

    def _term(self, signum: int, frame: object) -> None:
        self.by = self.by or signum
        self.stopped = True

    def _int(self, signum: int, frame: object) -> None:
        if self.stopped:
            raise KeyboardInterrupt
        self.by = signum
        self.stopped = True

    def __call__(self) -> bool:
        return self.stopped


def run(args: argparse.Namespace) -> int:
    from core.optimization.study import run_worker

    flag = StopFlag()
    flag.install()
    n = run_worker(
        args.storage,
        args.study,
        seed=args.seed,
        dataset_path=args.dataset,
        stop=flag,
        log=lambda s: print(f"radartune worker: {s}", file=sys.stderr),
    )
    print(f"worker {os.getpid()}: {n} trials finished", file=sys.stderr)
    # Ctrl-C (SIGINT) is an interrupt; SIGTERM is how tune and the GUI stop workers politely
    return EXIT_INTERRUPTED if flag.by == signal.SIGINT else EXIT_OK

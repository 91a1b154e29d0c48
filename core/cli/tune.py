"""``radartune tune``: create or resume a study and run K worker processes on it.

Example: ``radartune tune --model cv --trials 300 --jobs 2 --storage sqlite:///studies.db``.
Progress bar with the best loss so far; Ctrl-C stops after the running trials (twice: abort).
Exit codes: :mod:`core.cli.exit_codes` (also in ``radartune tune --help``).
"""

from __future__ import annotations

import argparse
import json
import signal
import sys
import time

from core.cli.exit_codes import (
    EXIT_INPUT_ERROR,
    EXIT_INTERRUPTED,
    EXIT_OK,
    EXIT_WORKER_LOST,
    epilog,
)
from core.errors import InputError


def add_parser(sub: argparse._SubParsersAction) -> None:
    from core.optimization.storage import DEFAULT_STORAGE

    p = sub.add_parser(
        "tune",
        help="find optimal tracker parameters with Optuna",
        epilog=epilog("tune"),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--model", required=True, help="motion model: cv or ca")
    p.add_argument("--trials", type=int, default=300, help="total trials (all workers)")
    p.add_argument("--jobs", type=int, default=1, help="worker processes (default: %(default)s)")
    p.add_argument("--storage", default=DEFAULT_STORAGE, help="storage URL (default: %(default)s)")
    p.add_argument("--study", default=None, help="study name (default: radartune-<model>)")
    p.add_argument("--seed", type=int, default=0, help="base seed (default: %(default)s)")
    p.add_argument("--sampler", default="tpe", help="tpe or random (default: %(default)s)")
    p.add_argument("--pruner", default="asha", help="asha, wilcoxon or none (default: %(default)s)")
    p.add_argument(
        "--dataset",
        default=None,
        help="data-set .npz, or paper:SEED (default: the paper's data set, seed 0, cached)",
    )
    p.add_argument(
        "--person-model",
        default=None,
        help="person model of the paper data set: point (default), blob (former name "
        "extended) or walking; same "
        "trajectories and seeds (docs/report/extended-person.md)",
    )
    p.add_argument(
        "--objective", default="tracker", help="tracker, or quadratic (machinery tests only)"
    )
    p.add_argument(
        "--objective-option",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="quadratic objective options: n_trajectories, delay_s",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=run)


def _options(items: list[str]) -> dict[str, float]:
    out = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or key not in ("n_trajectories", "delay_s"):
            raise InputError(f"--objective-option {item!r}: expected n_trajectories=N or delay_s=S")
        try:
            out[key] = float(value)
        except ValueError:
            raise InputError(f"--objective-option {item!r}: {value!r} is not a number") from None
    return out


def run(args: argparse.Namespace) -> int:
    from core.optimization.data import resolve_dataset
    from core.optimization.progress import counted, study_progress
    from core.optimization.study import StudySettings, start_study, worker_alive

    settings = StudySettings(
        model=args.model,
        n_trials=args.trials,
        n_jobs=args.jobs,
        storage=args.storage,
        study_name=args.study,
        seed=args.seed,
        sampler=args.sampler,
        pruner=args.pruner,
        dataset=args.dataset,
        objective=args.objective,
        objective_options=_options(args.objective_option),
    )
    path = None
    if settings.objective == "tracker":
        if args.dataset in (None, "", "paper") or str(args.dataset).startswith("paper:"):
            print(
                "data set: the paper's (simulated once and cached; minutes the first time)",
                file=sys.stderr,
            )
        path = resolve_dataset(args.dataset, person_model=args.person_model)
    handle = start_study(settings, dataset_path=path)
    bar = None
    if not args.no_progress:
        from tqdm import tqdm

        bar = tqdm(total=settings.n_trials, desc=settings.name, unit="trial", file=sys.stderr)
    interrupted = False
    best = None
    quiet_polls = 0
    while True:
        try:
            running = handle.is_running()
            summaries, best = study_progress(settings.storage, settings.name)
            if bar is not None:
                bar.n = min(counted(summaries), settings.n_trials)
                if best is not None:
                    bar.set_postfix_str(f"best L_t={best.value:.4g} (#{best.number})")
                bar.refresh()
            if not running:
                # another run's (or a joined worker's) live trial may hold the last slots: the
                # study is not lost, it finishes when that trial does. Two polls without one
                # (0.5 s apart) end the wait: a worker between two trials shows none briefly
                others = [
                    t for t in summaries if t.state == "RUNNING" and worker_alive(t.worker) is True
                ]
                quiet_polls = 0 if others else quiet_polls + 1
                if interrupted or counted(summaries) >= settings.n_trials or quiet_polls >= 2:
                    break
            time.sleep(0.5)
        except KeyboardInterrupt:
            if interrupted:
                continue  # the workers abort their trials on the second Ctrl-C
            interrupted = True
            print("\nstopping after the running trials (Ctrl-C again aborts them)", file=sys.stderr)
            for p in handle.procs:
                if p.poll() is None:
                    p.terminate()  # SIGTERM: the worker finishes its trial, then exits
    if bar is not None:
        bar.close()
    codes = handle.returncodes()
    n = counted(summaries)
    print(f"study {settings.name}: {n} of {settings.n_trials} trials counted", file=sys.stderr)
    if best is not None:
        print(
            json.dumps(
                {
                    "best_trial": best.number,
                    "best_loss": best.value,
                    "params": best.tracker_params(settings.model),
                }
            )
        )
    pids = [p.pid for p in handle.procs]
    return exit_code(codes, pids, n, settings.n_trials, settings.name, interrupted=interrupted)


def _ending(code: int) -> str:
    """How a worker process ended, from its ``Popen.returncode``."""
    if code < 0:
        try:
            return f"was killed by {signal.Signals(-code).name}"
        except ValueError:
            return f"was killed by signal {-code}"
    return f"exited with code {code}"


def exit_code(
    codes: list[int | None],
    pids: list[int],
    n_counted: int,
    total: int,
    name: str,
    *,
    interrupted: bool,
) -> int:
    """``tune``'s exit code from its workers' return codes (see :mod:`core.cli.exit_codes`).

    ``codes`` are the workers' ``Popen.returncode`` (negative: killed by that signal), ``pids``
    their process ids; ``n_counted`` of ``total`` trials are COMPLETE or PRUNED. Prints one
    line on stderr for every worker that ended abnormally.
    """
    if EXIT_INPUT_ERROR in codes:
        return EXIT_INPUT_ERROR  # the worker printed its one line
    done = n_counted >= total
    lost = [(pid, c) for pid, c in zip(pids, codes, strict=True) if c not in (EXIT_OK, None)]
    if interrupted:
        return EXIT_OK if done else EXIT_INTERRUPTED
    for pid, code in lost:
        if done:
            print(
                f"radartune tune: worker {pid} {_ending(code)}; the other workers reached "
                f"the total",
                file=sys.stderr,
            )
        else:
            print(
                f"radartune tune: worker {pid} {_ending(code)}; study {name!r} is resumable "
                f"({n_counted} of {total} trials counted): run the same command again",
                file=sys.stderr,
            )
    if done:
        return EXIT_OK
    if not lost:
        print(
            f"radartune tune: the workers stopped before the total ({n_counted} of {total} "
            f"trials counted); study {name!r} is resumable: run the same command again",
            file=sys.stderr,
        )
    return EXIT_WORKER_LOST

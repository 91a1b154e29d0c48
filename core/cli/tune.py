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
from typing import TYPE_CHECKING

from core.cli.exit_codes import (
    EXIT_INPUT_ERROR,
    EXIT_INTERRUPTED,
    EXIT_OK,
    EXIT_WORKER_LOST,
    epilog,
)
from core.errors import InputError

if TYPE_CHECKING:
    from core.optimization.progress import TrialSummary
    from core.optimization.study import StudySettings


def add_parser(sub: argparse._SubParsersAction) -> None:
    from core.optimization.storage import DEFAULT_STORAGE
    from core.tracking.space import MODES

    p = sub.add_parser(
        "tune",
        help="find optimal tracker parameters with Optuna",
        epilog=epilog("tune"),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--model", help="motion model: cv or ca (the paper's tracker)")
    p.add_argument(
        "--tracker",
        choices=("paper", "gtrack"),
        default="paper",
        help="paper: the (J)IPDA with --model; gtrack: TI's people tracker rebuilt, its own "
        "parameter table (default: paper)",
    )
    p.add_argument(
        "--mode",
        choices=MODES,
        default="paper",
        help="the (J)IPDA's mode: paper (one point a person) or room (groups of points, static "
        "points, ghosts; also tunes the room tracker's 11 parameters). Default: paper",
    )
    p.add_argument("--trials", type=int, default=300, help="total trials (all workers)")
    p.add_argument("--jobs", type=int, default=1, help="worker processes (default: %(default)s)")
    p.add_argument("--storage", default=DEFAULT_STORAGE, help="storage URL (default: %(default)s)")
    p.add_argument("--study", default=None, help="study name (default: radartune-<model>)")
    p.add_argument("--seed", type=int, default=0, help="base seed (default: %(default)s)")
    p.add_argument(
        "--sampler",
        default="tpe",
        help="tpe, random, cmaes (needs the cmaes package) or gp (needs torch) "
        "(default: %(default)s)",
    )
    p.add_argument("--pruner", default="asha", help="asha, wilcoxon or none (default: %(default)s)")
    p.add_argument(
        "--dataset",
        default=None,
        help="data-set .npz, or paper:SEED (default: the paper's data set, seed 0, cached)",
    )
    p.add_argument(
        "--person-model",
        default=None,
        help="person model of the paper data sets: walking (default), point (the paper's), "
        "blob (former name extended); same trajectories and seeds",
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
    p.add_argument(
        "--loss",
        default=None,
        help="what trials minimise: trimmed (default for a new study: L_t without the largest "
        "10 %% of the trajectory losses), paper (L_t, eq. 14), capped or median; without "
        "positions (recordings): count, fragmentation (default with a head count), nis "
        "(default without) or reference (agreement with the recording's own tracks) "
        "(docs/tuning.md; the paper's L_t is recorded where there is truth; a "
        "resumed study keeps its own)",
    )
    p.add_argument(
        "--people",
        type=int,
        default=None,
        help="people in every frame of the data sets (a recording without truth): the head "
        "count of the count and fragmentation objectives",
    )
    p.add_argument(
        "--mix",
        action="append",
        default=[],
        metavar="DATASET[=WEIGHT]",
        help="another training data set (a .npz or paper:SEED[:MODEL]), weight 1 unless given; "
        "repeatable. Each set is scored with --loss where it has what --loss needs, else with "
        "--recording-loss, divided by the default parameters' score on it (docs/tuning.md)",
    )
    p.add_argument(
        "--recording-loss",
        default=None,
        help="objective of a mixed or validation data set without truth: fragmentation "
        "(default with --people), nis (default without), count or reference",
    )
    p.add_argument(
        "--validation",
        default=None,
        help="validation data set: the best trials by training loss are tracked on it and the "
        "best there is chosen (default for paper data sets: paper:1000; for a file: none)",
    )
    p.add_argument(
        "--repeats",
        type=int,
        default=1,
        help="K studies <study>-r0 … with sampler seeds seed … seed+K-1 and, on paper data "
        "sets, training sets of seeds SEED … SEED+K-1; chosen by validation",
    )
    p.add_argument(
        "--top-k",
        type=int,
        default=None,
        help="trials of each study tracked on the validation set (default: 10)",
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


def _paper_seed(dataset: str | None) -> int | None:
    """The seed of a ``paper`` / ``paper:SEED[:MODEL]`` data-set argument; None for a file."""
    if dataset in (None, "", "paper"):
        return 0
    parts = str(dataset).split(":")
    if parts[0] != "paper":
        return None
    try:
        return int(parts[1])
    except (IndexError, ValueError):
        raise InputError(f"data set {dataset!r}: expected paper:SEED or paper:SEED:MODEL") from None


def _training_sets(args: argparse.Namespace) -> list[str | None]:
    """The training data-set argument of each repeat."""
    from core.optimization.validation import check_training_seed

    seed = _paper_seed(args.dataset)
    if seed is None:
        return [args.dataset] * args.repeats  # a file: repeats differ by sampler seed only
    check_training_seed(seed, args.repeats)
    model = _paper_model(args)
    return [f"paper:{seed + i}:{model}" for i in range(args.repeats)]


def _paper_model(args: argparse.Namespace) -> str:
    """The person model of the run's paper data sets, spelled out so the studies record it."""
    from core.scene.scene import DEFAULT_PERSON_MODEL

    named = str(args.dataset).split(":")[2:] if args.dataset else []
    return named[0] if named else (args.person_model or DEFAULT_PERSON_MODEL)


def run(args: argparse.Namespace) -> int:
    from dataclasses import replace

    from core.evaluation.robust import check_objective
    from core.optimization.data import like_training, resolve_dataset
    from core.optimization.study import StudySettings
    from core.optimization.validation import TOP_K, VALIDATION_SEED, check_same_radar

    if args.tracker == "gtrack":
        if args.model not in (None, "gtrack"):
            raise InputError(
                "--model is the paper tracker's motion model: not with --tracker gtrack"
            )
        args.model = "gtrack"
    elif args.model is None:
        raise InputError("--model is required (cv or ca), or give --tracker gtrack")
    if args.repeats < 1:
        raise InputError(f"--repeats must be >= 1, got {args.repeats}")
    if args.recording_loss is not None:
        check_objective(args.recording_loss)
    top_k = TOP_K if args.top_k is None else args.top_k
    if top_k < 1:
        raise InputError(f"--top-k must be >= 1, got {top_k}")
    if args.people is not None and args.people < 0:
        raise InputError(f"--people must be >= 0, got {args.people}")
    if args.loss is None:
        args.loss = _default_loss(args)
    check_objective(args.loss)
    base = StudySettings(
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
        loss=args.loss,
        people=args.people,
        recording_loss=args.recording_loss or "",
        mode=args.mode,
    )
    # every data set is resolved and checked before any study is touched
    plans: list[tuple[StudySettings, str | None]] = []
    validation: str | None = None
    if base.objective == "tracker":
        if any(_paper_seed(d) is not None for d in [args.dataset, args.validation] if d):
            print(
                "data sets: the paper's (simulated once and cached; minutes the first time)",
                file=sys.stderr,
            )
        sets = _training_sets(args)
        paths = [resolve_dataset(d, person_model=args.person_model) for d in sets]
        mix = _mix(args)
        if mix:
            base = replace(base, mix=tuple(mix))
        for train_path in dict.fromkeys([*paths, *(p for p, _ in mix)]):
            require_truth(train_path, _loss_for(train_path, args) if mix else args.loss,
                          args.people)  # fmt: skip
        val_arg = args.validation
        if val_arg is None and _paper_seed(args.dataset) is not None:
            val_arg = f"paper:{VALIDATION_SEED}:{_paper_model(args)}"
        if val_arg is not None:
            val_seed = _paper_seed(val_arg)
            if val_seed is not None and val_seed < VALIDATION_SEED:
                raise InputError(
                    f"--validation {val_arg!r}: paper seeds below {VALIDATION_SEED} are "
                    "training sets; use paper:SEED with SEED >= 1000"
                )
            if args.person_model is None:
                val_arg = like_training(val_arg, paths[0])
            validation = resolve_dataset(val_arg, person_model=args.person_model)
            require_truth(validation, _loss_for(validation, args), args.people)
            if validation in paths or validation in (p for p, _ in mix):
                raise InputError(f"--validation {val_arg!r} is a training set of this run")
            _check_validation_radar([paths[0], *(p for p, _ in mix)], validation)
        for i, train_path in enumerate(paths):
            check_same_radar(paths[0], train_path, "training")
            plans.append((_repeat(base, i, args.repeats, dataset=sets[i]), train_path))
    else:
        plans = [(_repeat(base, i, args.repeats, dataset=None), None) for i in range(args.repeats)]
    chosen: list[dict] = []
    for settings, path in plans:
        code, best = run_study(settings, path, progress=not args.no_progress)
        record: dict = {"study": settings.name}
        if best is not None:
            record.update(best_trial=best.number, best_loss=best.value)
            record["params"] = best.tracker_params(settings.model, settings.mode)
        if code != EXIT_OK:
            # interrupted or a worker lost: the best so far, not validated, and the study's code
            print(json.dumps({"loss": args.loss, "studies": [*chosen, record]}))
            return code
        if validation is not None and best is not None:
            from core.optimization.validation import validate_study

            validated = validate_study(settings.storage, settings.name, validation, top_k=top_k)
            top = validated[0]
            record.update(top.to_dict())
            print(
                f"study {settings.name}: chosen trial {top.number} by validation: "
                f"{_loss_for(validation, args)} {top.validation_value:.4g} on the validation set "
                f"(training {top.train_value:.4g})",
                file=sys.stderr,
            )
        chosen.append(record)
    out: dict = {"loss": args.loss, "validation": validation, "studies": chosen}
    if chosen and all("params" in r for r in chosen):
        key = "validation_value" if validation is not None else "best_loss"
        win = min(chosen, key=lambda r: (r[key], r["study"]))
        out.update(
            chosen_study=win["study"],
            best_trial=win.get("trial", win["best_trial"]),
            best_loss=win.get("train_value", win["best_loss"]),
            params=win["params"],
        )
        if validation is not None:
            out["validation_value"] = win["validation_value"]
    print(json.dumps(out))
    return EXIT_OK


def _mix(args: argparse.Namespace) -> list[tuple[str, float]]:
    """The ``--mix`` data sets, resolved to paths, with their weights."""
    from core.optimization.data import resolve_dataset
    from core.optimization.mix import parse_mix

    out = []
    for item in args.mix:
        part = parse_mix(item)
        out.append((resolve_dataset(part.dataset, person_model=args.person_model), part.weight))
    return out


def _loss_for(path: str, args: argparse.Namespace) -> str:
    """The objective a data set is scored with: ``--loss`` where it has what that needs, else
    the recording objective (:func:`core.optimization.mix.objective_for`)."""
    from core.dataset import Dataset
    from core.optimization.mix import objective_for, recording_objective

    rec = args.recording_loss or recording_objective(args.people)
    return objective_for(Dataset.load(path), args.loss, rec, args.people)


def _check_validation_radar(training: list[str], validation: str) -> None:
    """The validation set must share the radar of one of the training sets."""
    from core.optimization.validation import check_same_radar

    first: InputError | None = None
    for path in training:
        try:
            check_same_radar(path, validation, "validation")
            return
        except InputError as exc:
            first = first or exc
    if first is not None:
        raise first


def _default_loss(args: argparse.Namespace) -> str:
    """The objective when ``--loss`` is not given (:func:`core.optimization.loss_of_study`); for
    a new study on a data-set file without truth: ``fragmentation`` with ``--people``, else
    ``nis`` (said on stderr)."""
    from core.evaluation.robust import DEFAULT_OBJECTIVE
    from core.optimization.study import loss_of_study

    name = args.study or f"radartune-{args.model}"
    loss = loss_of_study(args.storage, f"{name}-r0" if args.repeats > 1 else name)
    if loss != DEFAULT_OBJECTIVE or _paper_seed(args.dataset) is not None:
        return loss
    if args.objective == "tracker" and not args.mix and not _file_has_truth(args.dataset):
        loss = "fragmentation" if args.people is not None else "nis"
        print(f"the data set has no truth: the study minimises --loss {loss}", file=sys.stderr)
    return loss


def _file_has_truth(path: str) -> bool:
    from core.dataset import Dataset
    from core.formats.recording import has_truth

    return has_truth(Dataset.load(path))


def _repeat(base: StudySettings, i: int, n: int, *, dataset: str | None) -> StudySettings:
    """The settings of repeat ``i`` of ``n`` (the base settings themselves when n = 1)."""
    from dataclasses import replace

    if n == 1:
        return base
    return replace(base, study_name=f"{base.name}-r{i}", seed=base.seed + i, dataset=dataset)


def run_study(
    settings: StudySettings, path: str | None, *, progress: bool = True
) -> tuple[int, TrialSummary | None]:
    """Create or resume one study, run its workers to the total; (exit code, best trial)."""
    from core.optimization.progress import counted, study_progress
    from core.optimization.study import start_study, worker_alive

    handle = start_study(settings, dataset_path=path)
    bar = None
    if progress:
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
                    bar.set_postfix_str(f"best={best.value:.4g} (#{best.number})")
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
    pids = [p.pid for p in handle.procs]
    code = exit_code(codes, pids, n, settings.n_trials, settings.name, interrupted=interrupted)
    return code, best


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


def require_truth(path: str, loss: str = "paper", people: int | None = None) -> None:
    """What the objective ``loss`` needs of a data set (:data:`core.evaluation.robust.
    OBJECTIVE_NEEDS`): refuse, with one line, a data set without truth for an objective on
    positions, or without a head count (``--people`` or the truth) for count and fragmentation."""
    from core.dataset import Dataset
    from core.errors import InputError
    from core.evaluation.robust import OBJECTIVE_NEEDS
    from core.formats.recording import has_truth

    need = OBJECTIVE_NEEDS[loss]
    if not need or (need == "head count" and people is not None):
        return
    ds = Dataset.load(path)
    if need == "reference layer":
        if not ds.has_reference:
            raise InputError(
                "the data set has no reference layer (no tracks of the sensor's own): --loss "
                "reference needs one",
                str(path),
            )
        return
    if need == "head count" and len(ds.people_count) and bool((ds.people_count >= 0).any()):
        return
    if not has_truth(ds):
        raise InputError(
            f"the data set has no ground truth (imported without --truth?): --loss {loss} needs "
            f"{'positions' if need == 'truth' else 'a head count'}; import it again with --truth "
            "CSV, or tune without positions: --loss count|fragmentation with --people N, or "
            "--loss nis",
            str(path),
        )

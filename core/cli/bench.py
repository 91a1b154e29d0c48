"""``radartune bench NAME``: run a benchmark, print its figures and write them to a JSON file.

Each benchmark lives in ``core.benchmarks.<name>`` and defines
``run(quick: bool = False) -> dict`` returning JSON-ready figures, including a plain reference
implementation measured in the same run and the ratio (this machine is shared and noisy), and
``summary(result: dict) -> str`` for the terminal.
"""

from __future__ import annotations

import argparse
import datetime as dt
import importlib
import math
import platform
from pathlib import Path

from core.files import write_json_atomic

BENCHMARKS = (
    "sim",
    "track",
    "tune",
    "fidelity",
    "dataset",
    "false_alarms",
    "cvca",
    "import",
    "gtrack_ti",
    "chain_calibration",
    "room",
)
#: benchmark name -> module in core.benchmarks, where the name is a Python keyword
MODULES = {"import": "import_"}
#: not part of ``all``: hours of studies (16 x 1000 trials); person clouds (a calibration, not
#: a speed figure); the desktop app (needs Qt); held-out loss against run time per sampler
#: (60 studies); the objective comparison and the CV-against-CA design (hours of studies)
#: transfer: tuned parameters judged on held-out public recordings (needs them: $RADARTUNE_REAL);
#: trackers: four trackers, tuned and not, on held-out simulated rooms and recordings
#: room_levels: the three fidelity levels in the shipped rooms (an error table, not a speed)
LONG = (
    "cvca_seeds", "clouds", "gui", "samplers", "campaign", "transfer", "trackers", "room_levels",
)  # fmt: skip
#: benchmarks whose tables and plots ``--render-only`` re-writes from their stored JSON
RENDERABLE = ("fidelity", "clouds", "samplers", "campaign")


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "bench",
        help="measure speed (and error against run time); cvca, cvca_seeds: CV against CA; "
        "samplers: held-out loss against trials and seconds per sampler and pruner; "
        "import: reading real recordings; gui: the desktop app (offscreen and under Xvfb)",
    )
    p.add_argument("name", choices=(*BENCHMARKS, *LONG, "all"))
    p.add_argument(
        "--out-dir", default="bench/results", help="folder for <name>.json (default: %(default)s)"
    )
    p.add_argument("--quick", action="store_true", help="short run (smoke test)")
    p.add_argument(
        "--render-only",
        action="store_true",
        help="fidelity, clouds, samplers, campaign: re-write the tables and plots from "
        "<out-dir>/<name>.json, no run",
    )
    p.add_argument(
        "--lambda-only",
        action="store_true",
        help="campaign: add the scene-clutter (λ × 0.5, × 2) scores of every stored choice to "
        "<out-dir>/campaign.json and re-render; no study runs, nothing else changes",
    )
    for model in ("cv", "ca"):
        p.add_argument(
            f"--params-{model}",
            metavar="FILE",
            help=f"fidelity: {model.upper()} tracker parameters (default: "
            f"docs/report/best_{model}.json when present, else the defaults)",
        )
    p.add_argument(
        "--person-model",
        default="point",
        help="fidelity: the paper scenes' person, point (the paper's, default), blob or walking "
        "(writes fidelity-walking.json and docs/fidelity/results-walking.md)",
    )
    p.add_argument(
        "--recording",
        metavar="NPZ",
        help="tune: measure a study on this recording's first 2 000 frames instead (written to "
        "tune-recording.json)",
    )
    p.add_argument(
        "--people", type=int, help="tune --recording: people in every frame (the head count)"
    )
    p.add_argument(
        "--soak",
        type=float,
        metavar="SECONDS",
        help="gui: the live link alone at 20 frames/s for this long (written to gui-soak.json)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if args.person_model != "point" and args.name != "fidelity":
        from core.errors import InputError

        raise InputError(f"--person-model is for fidelity only, not {args.name!r}")
    if (getattr(args, "recording", None) or args.people is not None) and args.name != "tune":
        from core.errors import InputError

        raise InputError(f"--recording and --people are for tune only, not {args.name!r}")
    if getattr(args, "soak", None) is not None and args.name != "gui":
        from core.errors import InputError

        raise InputError(f"--soak is for gui only, not {args.name!r}")
    if getattr(args, "soak", None) is not None and not (0 < args.soak < math.inf):
        from core.errors import InputError

        raise InputError(f"--soak must be a positive number of seconds, got {args.soak!r}")
    if args.render_only:
        return _render_only(args)
    if getattr(args, "lambda_only", False):
        return _lambda_only(args)
    names = BENCHMARKS if args.name == "all" else (args.name,)
    out_dir = Path(args.out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    for name in names:
        module = importlib.import_module(f"core.benchmarks.{MODULES.get(name, name)}")
        extra, flags, stem = {}, "", _result_stem(name, args)
        if name == "tune" and getattr(args, "recording", None):
            extra = {"recording": args.recording, "people": args.people}
            flags = f" --recording {args.recording}" + (
                f" --people {args.people}" if args.people is not None else ""
            )
        if name == "fidelity":
            model = args.person_model  # checked by _result_stem
            extra = {"params_cv": args.params_cv, "params_ca": args.params_ca}
            extra["person_model"] = model
            flags = "".join(
                f" --params-{m} {v}"
                for m, v in (("cv", args.params_cv), ("ca", args.params_ca))
                if v
            ) + ("" if model == "point" else f" --person-model {model}")
        if name == "gui" and getattr(args, "soak", None) is not None:
            extra = {"soak_s": args.soak}
            flags = f" --soak {args.soak:g}"
        result = module.run(quick=args.quick, **extra)
        result = {
            "benchmark": name,
            "command": f"radartune bench {name}" + (" --quick" if args.quick else "") + flags,
            "date": dt.datetime.now(dt.UTC).isoformat(timespec="seconds"),
            "machine": {"python": platform.python_version(), "cpu": platform.processor()},
            **result,
        }
        # a quick run never overwrites the full run's figures
        path = out_dir / f"{stem}.json"
        write_json_atomic(path, result)
        print(module.summary(result))
        print(f"written: {path}")
    return 0


def _result_stem(name: str, args: argparse.Namespace) -> str:
    """A benchmark result's file stem in ``--out-dir``: ``<name>[-quick]``; for fidelity
    :func:`~core.benchmarks.fidelity_report.result_name` of ``--person-model``, checked against
    the scene's person models (one-line InputError)."""
    if name == "gui" and getattr(args, "soak", None) is not None:
        return f"gui-soak{'-quick' if args.quick else ''}"
    if name == "tune" and getattr(args, "recording", None):
        return f"tune-recording{'-quick' if args.quick else ''}"
    if name != "fidelity":
        return f"{name}{'-quick' if args.quick else ''}"
    from core.benchmarks.fidelity_report import result_name
    from core.errors import InputError
    from core.scene.scene import PERSON_MODELS

    model = args.person_model
    if model not in PERSON_MODELS:
        raise InputError(f"--person-model must be one of {list(PERSON_MODELS)}, got {model!r}")
    return result_name(model, args.quick)


def _lambda_only(args: argparse.Namespace) -> int:
    """``campaign --lambda-only``: the λ check added to the stored campaign result."""
    from core.benchmarks.campaign import add_lambda, render, summary
    from core.errors import InputError

    if args.name != "campaign":
        raise InputError(f"--lambda-only is for campaign only, not {args.name!r}")
    path = Path(args.out_dir) / f"{_result_stem('campaign', args)}.json"
    result = _load_result(path, args.name)
    try:
        result = add_lambda(result, quick=args.quick)
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise InputError(f"not a campaign result: {exc!r}", str(path)) from None
    write_json_atomic(path, result)
    print(summary(result))
    for out in (path, *render(result, quick=args.quick)):
        print(f"written: {out}")
    return 0


def _load_result(path: Path, name: str) -> dict:
    """A stored benchmark result; one-line InputError when it is missing or not JSON."""
    import json

    from core.errors import InputError

    if not path.exists():
        raise InputError(f"no such file (run `radartune bench {name}` first)", str(path))
    try:
        result = json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"not JSON: {exc}", str(path)) from None
    if not isinstance(result, dict):
        raise InputError(f"not a {name} result", str(path))
    return result


def _render_only(args: argparse.Namespace) -> int:
    """``--render-only``: a benchmark's tables and plots re-rendered from its stored result."""
    from core.errors import InputError

    if args.name not in RENDERABLE:
        raise InputError(f"--render-only is for {', '.join(RENDERABLE)} only, not {args.name!r}")
    if args.name == "fidelity":
        from core.benchmarks.fidelity_report import render, summary
    elif args.name == "campaign":
        from core.benchmarks.campaign import render, summary  # type: ignore[assignment]
    elif args.name == "clouds":
        from core.benchmarks.clouds import render, summary  # type: ignore[assignment]
    else:
        from core.benchmarks.samplers import render, summary  # type: ignore[assignment]

    path = Path(args.out_dir) / f"{_result_stem(args.name, args)}.json"
    result = _load_result(path, args.name)
    try:
        written = render(result, quick=args.quick)
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise InputError(f"not a {args.name} result: {exc!r}", str(path)) from None
    print(summary(result))
    for out in written:
        print(f"written: {out}")
    return 0

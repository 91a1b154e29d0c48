"""``radartune stability``: the tracker's numerical-stability sweep over the search-space corners,
and the filter consistency of the tuned trackers on the chain's own data.

Sweep: all 2¹² CV corners and a seeded sample of CA corners (2048 by default) each track the
synthetic paper-like scene and three multi-person scenes with crossings for 300 frames, and a
seeded sample of the room mode's corners (512 by default) the two room scenes; any NaN/Inf or
non-SPD covariance makes the command exit 1.

Consistency: NEES and NIS (:mod:`core.evaluation.consistency`) per trajectory class of the tuned
parameters (``docs/report/best_*.json`` on the point person, ``docs/report/walking-campaign/
best_*.json`` on the walking body), and on the walking body of the defaults and of the defaults
with R set to the measured spread of the person's points, on the paper data set of each person
model. An inconsistent filter is a finding, not a failure: it does not change the
exit code.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

#: The repository root (the tuned parameter files are in its docs/report/).
ROOT = Path(__file__).resolve().parents[2]

#: Consistency cases: (label, person model, parameters): a folder relative to ROOT holding
#: best_cv.json and best_ca.json, ``"defaults"``, or ``"spread"`` (the defaults with R set to the
#: person points' measured spread, :func:`core.evaluation.consistency.measurement_spread`).
CONSISTENCY_CASES: tuple[tuple[str, str, str], ...] = (
    ("point, tuned", "point", "docs/report"),
    ("walking, tuned", "walking", "docs/report/walking-campaign"),
    ("walking, defaults", "walking", "defaults"),
    ("walking, R = spread", "walking", "spread"),
)


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "stability",
        help="numerical-stability sweep of the tracker over all corners of the search space, "
        "and NEES/NIS consistency of the tuned trackers on the paper data set",
    )
    p.add_argument("--quick", action="store_true", help="256 CV and 128 CA corners (smoke test)")
    p.add_argument(
        "--ca-corners", type=int, default=2048, help="CA corners sampled (default: %(default)s)"
    )
    p.add_argument(
        "--room-corners",
        type=int,
        default=512,
        help="room-mode CV corners sampled, on the room scenes (default: %(default)s)",
    )
    p.add_argument("--frames", type=int, default=300, help="frames per run (default: %(default)s)")
    p.add_argument("--seed", type=int, default=0, help="scene and sample seed")
    p.add_argument(
        "--no-sweep", action="store_true", help="skip the corner sweep (consistency only)"
    )
    p.add_argument(
        "--no-consistency", action="store_true", help="skip the NEES/NIS consistency section"
    )
    p.add_argument(
        "--paper-seed",
        type=int,
        default=0,
        help="seed of the paper data sets of the consistency section (default: %(default)s)",
    )
    p.add_argument("--json", metavar="PATH", help="write the results as JSON")
    p.add_argument("--plot", metavar="PNG", help="plot NEES/NIS per class against the χ² bands")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from core.errors import InputError
    from core.files import check_output_path, write_json_atomic
    from core.limits import MAX_FRAMES

    if not 2 <= args.frames <= MAX_FRAMES or args.ca_corners < 1 or args.room_corners < 1:
        raise InputError(
            f"--frames must be in [2, {MAX_FRAMES}], --ca-corners and --room-corners >= 1"
        )
    if args.paper_seed < 0:
        raise InputError(f"--paper-seed must be >= 0, got {args.paper_seed}")
    for path in (args.json, args.plot):
        if path:
            check_output_path(path)
    doc: dict[str, Any] = {}
    ok = True
    if not args.no_sweep:
        ok, doc["sweep"] = _sweep(args)
    if not args.no_consistency:
        reports = consistency_reports(args.paper_seed)
        doc["consistency"] = [r.to_dict() for r in reports]
        if args.plot:
            from core.evaluation.consistency import plot_consistency

            title = (
                f"NEES / NIS per class, paper data set seed {args.paper_seed} "
                "(mean ε, log scale; grey: 95 % per-sample χ² band)"
            )
            print(f"plot: {plot_consistency(reports, args.plot, title=title)}")
    if args.json:
        doc["ok"] = ok
        print(f"results: {write_json_atomic(args.json, doc)}")
    if not args.no_sweep:
        print("stability: OK" if ok else "stability: FAILED")
    return 0 if ok else 1


def _sweep(args: argparse.Namespace) -> tuple[bool, list[dict[str, Any]]]:
    from core.tracking.stability import (
        all_corners,
        multi_person_scenes,
        room_scenes,
        stability_scene,
        sweep,
    )

    scenes = {"1 person circling": stability_scene(args.frames, args.seed)}
    scenes.update(multi_person_scenes(args.frames, args.seed))
    plans = [
        ("cv", "paper", all_corners("cv", 256 if args.quick else None, args.seed)),
        ("ca", "paper", all_corners("ca", 128 if args.quick else args.ca_corners, args.seed)),
    ]
    room = all_corners("cv", 32 if args.quick else args.room_corners, args.seed, "room")
    runs = [(scene, ds, plan) for scene, ds in scenes.items() for plan in plans]
    runs += [(scene, ds, ("cv", "room", room)) for scene, ds in room_scenes(args.frames).items()]
    ok = True
    rows = []
    for scene, ds, (model, mode, corners) in runs:
        t0 = time.perf_counter()
        rep = sweep(model, corners, ds, mode)
        dt = time.perf_counter() - t0
        print(
            f"{scene}, {model}{' room' if mode == 'room' else ''}: {rep.n_corners} corners x "
            f"{rep.n_frames} frames in "
            f"{dt:.1f} s: {rep.bad_corners} bad corners, {rep.bad_track_frames} unhealthy "
            f"track-frames (NaN/Inf, psi outside [0,1] or P not SPD), "
            f"{rep.nonfinite_outputs} non-finite outputs; at most {rep.max_tracks_seen} "
            "live tracks"
        )
        for bits in rep.failures:
            print(f"  failing corner ({model}): {''.join(map(str, bits))}")
        ok &= rep.ok
        rows.append(
            {
                "scene": scene,
                "model": model,
                "mode": mode,
                "corners": rep.n_corners,
                "frames": rep.n_frames,
                "bad_corners": rep.bad_corners,
                "unhealthy_track_frames": rep.bad_track_frames,
                "nonfinite_outputs": rep.nonfinite_outputs,
                "max_tracks": rep.max_tracks_seen,
                "seconds": round(dt, 2),
            }
        )
    return ok, rows


def consistency_reports(paper_seed: int = 0) -> list:
    """NEES/NIS of every case of :data:`CONSISTENCY_CASES` and both models, printed as tables.

    Returns
    -------
    list of :class:`core.evaluation.consistency.ConsistencyReport`
    """
    from core.evaluation.consistency import dataset_consistency, measurement_spread
    from core.pipeline import paper_dataset
    from core.tracking import TrackerParams

    reports = []
    datasets: dict[str, Any] = {}
    spreads: dict[str, list[float]] = {}
    print(
        f"consistency: NEES/NIS of the track paired with the person, paper data set seed "
        f"{paper_seed}; mean eps [its 95 % band for N samples], % of samples inside the 95 % "
        "per-sample chi2 band, verdict of the mean (above: covariance too small)"
    )
    for label, person, source in CONSISTENCY_CASES:
        if person not in datasets:
            ds = datasets[person] = paper_dataset(paper_seed, person_model=person)
            spreads[person] = [float(v) for v in measurement_spread(ds)]
            sr, saz, svr = spreads[person]
            print(
                f"{person} person: its points around the truth h(x_gt), RMS: range {sr:.3g} m, "
                f"azimuth {saz:.3g} rad, radial velocity {svr:.3g} m/s"
            )
        ds = datasets[person]
        for model in ("cv", "ca"):
            if source == "defaults":
                params = TrackerParams(model=model)
            elif source == "spread":
                sr, saz, svr = spreads[person]
                params = TrackerParams(model=model, r11=sr, r22=saz, r33=svr)
            else:
                params = TrackerParams.load(ROOT / source / f"best_{model}.json")
            where = source if source in ("defaults", "spread") else f"{source}/best_{model}.json"
            t0 = time.perf_counter()
            rep = dataset_consistency(
                ds,
                params,
                label=f"{model.upper()}, {label}",
                extra={
                    "case": label,
                    "person_model": person,
                    "model": model,
                    "params": where,
                    "paper_seed": paper_seed,
                    "r_std": [params.r11, params.r22, params.r33],
                    "q_coeff": params.q_coeff,
                    "measurement_spread": spreads[person],
                },
            )
            dt = time.perf_counter() - t0
            print(
                f"\n{model.upper()}, {person} person, {where} (q={params.q_coeff:.3g}, "
                f"r=[{params.r11:.3g} m, {params.r22:.3g} rad, {params.r33:.3g} m/s]), "
                f"{dt:.1f} s:"
            )
            print(rep.format_table())
            reports.append(rep)
    return reports

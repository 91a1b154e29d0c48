"""``radartune dataset``: the paper's data set (35 trajectories, 7 per class) → ``.npz``."""

from __future__ import annotations

import argparse
import time


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "dataset",
        help="simulate the paper's data set of trajectories (cached) into a .npz",
        description="Generate the paper's data set (classes a-e round-robin, 7 per class for "
        "35 trajectories) from one seed, simulate it on all cores and write it as a .npz. "
        "Results are cached by hash in $RADARTUNE_CACHE (default ~/.cache/radartune).",
    )
    p.add_argument("--out", required=True, metavar="FILE", help="output data set .npz")
    p.add_argument("--seed", type=int, default=0, help="seed of the whole set (default 0)")
    p.add_argument("--trajectories", type=int, default=35, help="number of trajectories")
    p.add_argument("--jobs", type=int, default=None, help="worker processes (default: all cores)")
    p.add_argument("--fidelity", default="exact", help="simulator level (default: exact)")
    p.add_argument("--no-cache", action="store_true", help="neither read nor write the cache")
    p.add_argument(
        "--person-model",
        default=None,
        help="person scattering model: walking (default: 17 segments driven by Boulic's gait "
        "model), point (the paper's: the paper-faithful set) or blob (5 scatterers: torso, "
        "arms, legs; 'extended' is its former name); the trajectories and seeds are the same "
        "for every model (docs/person-models.md)",
    )
    p.add_argument(
        "--persons",
        type=int,
        default=1,
        help="persons per trajectory, 1-8 (default 1: the paper's set); person j of trajectory "
        "k walks class abcde[(k+j) %% 5], person 0 is the one-person set's",
    )
    p.add_argument(
        "--room",
        metavar="FILE",
        default=None,
        help="put every trajectory in this room: a JSON file of walls, furniture and a sensor "
        "pose (docs/rooms.md); the trajectories and seeds stay the paper's",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from core.cli.progress import ProgressBar
    from core.errors import InputError
    from core.files import check_output_path
    from core.limits import MAX_DATASET_TRAJECTORIES, MAX_JOBS, MAX_PERSONS
    from core.pipeline import paper_dataset

    t0 = time.perf_counter()
    if args.seed < 0:
        raise InputError(f"--seed must be >= 0, got {args.seed}")
    if not 1 <= args.trajectories <= MAX_DATASET_TRAJECTORIES:
        raise InputError(
            f"--trajectories must be in [1, {MAX_DATASET_TRAJECTORIES}], got {args.trajectories}"
        )
    if not 1 <= args.persons <= MAX_PERSONS:
        raise InputError(f"--persons must be in [1, {MAX_PERSONS}], got {args.persons}")
    if args.jobs is not None and not 1 <= args.jobs <= MAX_JOBS:
        raise InputError(f"--jobs must be in [1, {MAX_JOBS}], got {args.jobs}")
    check_output_path(args.out, what="data set")
    from core.scene.scene import DEFAULT_PERSON_MODEL, PERSON_MODELS, person_model_kind

    if args.person_model is None:
        args.person_model = DEFAULT_PERSON_MODEL

    try:
        person_model_kind(args.person_model)
    except InputError:
        raise InputError(
            f"--person-model must be one of {list(PERSON_MODELS)}, got {args.person_model!r}"
        ) from None
    room = None
    if args.room is not None:
        from core.scene.room import Room

        room = Room.from_json(args.room)
    ds = paper_dataset(
        args.seed,
        args.trajectories,
        fidelity=args.fidelity,
        jobs=args.jobs,
        progress=ProgressBar("dataset"),
        use_cache=not args.no_cache,
        person_model=args.person_model,
        n_persons=args.persons,
        room=room,
    )
    ds.save(args.out)
    per_class = {c: int(np.sum(ds.trajectory_class == c)) for c in "abcde"}
    print(
        f"wrote {args.out}: {ds.n_trajectories} trajectories {per_class}, "
        f"{ds.n_persons} person(s), {ds.n_frames} frames, "
        f"{len(ds.frame)} points; elapsed {time.perf_counter() - t0:.1f} s"
    )
    if room is not None:
        from core.scene.room import inside_walls

        xy = ds.truth_xy_m.reshape(-1, 2)
        xy = xy[~np.isnan(xy[:, 0])]
        out = 1.0 - float(np.mean(inside_walls(room.walls, xy))) if len(xy) else 0.0
        ghosts = float(np.mean(ds.path_order > 0)) if ds.path_order is not None else 0.0
        print(
            f"room {args.room}: {100 * ghosts:.1f} % of the points from wall bounces; "
            f"{100 * out:.1f} % of the persons' positions lie outside its walls"
        )
    return 0

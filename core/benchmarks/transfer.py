"""``radartune bench transfer``: which tuned parameters transfer to a real room?

CV studies (TPE + ASHA, one worker, SQLite) tuned three ways, judged on recordings that no study
and no choice ever saw:

- **open field**: on the paper's walking-body data set ``paper:0:walking`` (``--loss trimmed``),
  chosen by validation on ``paper:1000:walking``;
- **simulated rooms**: on the same trajectories walked in a room (:data:`HALL`, as
  ``radartune dataset --room`` simulates them: walls that make ghosts, a sensor 2 m up and tilted),
  chosen by validation on ``paper:1000:walking`` in the same room; no recording seen;
- **recording**: on the mmgait walker ``002`` with ``--people 1`` (``--loss fragmentation``),
  chosen by validation on the walker ``022``;
- **mixed**: on ``paper:0:walking`` with the walker ``002`` mixed in at weight 1
  (:mod:`core.optimization.mix`), chosen on the walker ``022``;
- and the model's **defaults**, untuned, as the reference.

Held out of every study and every choice: the mmgait walker ``076`` (one person throughout:
right-count fraction, count error, fragmentation, NIS) and the people-counting recording
``pc3_2023-06-21-12-27-01`` (TI's own tracks as the reference layer: mean GOSPA against them,
NIS; it has no head count). Each way is run with study seeds ``0 … S−1``; a figure is the mean
over the seeds with a 95 % bootstrap interval over them (three seeds make a crude interval: it
says how much the study's own randomness moves the figure, and the per-seed figures are kept
with the block-bootstrap interval of each recording's right-count fraction).

The recordings are read from ``$RADARTUNE_REAL`` (default: ``../shared/real`` from the working
folder). The mmgait recordings carry no licence: the result file keeps scores only, never
parameters tuned on them or any of their points.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from core.errors import InputError

MODEL = "cv"
TRAIN_RECORDING = "mmgait_walkers/room2_1p_fixed_60GHz_002.csv"
VALIDATION_RECORDING = "mmgait_walkers/room2_1p_fixed_60GHz_022.csv"
TEST_WALKER = "mmgait_walkers/room2_1p_fixed_60GHz_076.csv"
TEST_REFERENCE = "pc3_iwr6843/pc3_2023-06-21-12-27-01.csv"
OPEN_FIELD = "paper:0:walking"
OPEN_FIELD_VALIDATION = "paper:1000:walking"
WAYS = ("defaults", "open field", "simulated rooms", "recording", "mixed")
#: The room of the "simulated rooms" way: 18 x 10.5 m, so every trajectory of the paper's set
#: (10 m at +-60 degrees) stays inside it (docs/rooms.md), walls of -6 dB, the sensor on the near
#: wall 2 m up and tilted 10 degrees down, as TI's people-counting mounting (its cfg: 2 m, 15 deg).
HALL: dict[str, Any] = {
    "walls": [
        {"from_m": [-9.0, 0.0], "to_m": [9.0, 0.0], "reflection_db": -6.0},
        {"from_m": [9.0, 0.0], "to_m": [9.0, 10.5], "reflection_db": -6.0},
        {"from_m": [9.0, 10.5], "to_m": [-9.0, 10.5], "reflection_db": -6.0},
        {"from_m": [-9.0, 10.5], "to_m": [-9.0, 0.0], "reflection_db": -6.0},
    ],
    "sensor": {"height_m": 2.0, "tilt_deg": 10.0},
}


def room_dataset(seed: int, n_trajectories: int = 35) -> str:
    """The paper's walking-body data set of ``seed`` walked in :data:`HALL` (cached)."""
    from core.pipeline import paper_dataset_file
    from core.scene.room import parse_room

    path = paper_dataset_file(seed, n_trajectories, person_model="walking", room=parse_room(HALL))
    return str(path)


def real_folder() -> Path:
    """The folder of the public recordings (:func:`core.benchmarks.clouds.real_data_dir`:
    ``$RADARTUNE_REAL``, else ``../shared/real`` beside the checkout)."""
    from core.benchmarks.clouds import real_data_dir

    root = real_data_dir()
    if (root / TEST_WALKER).is_file():
        return root
    raise InputError(
        "the public recordings were not found: set RADARTUNE_REAL to the folder holding "
        f"{TEST_WALKER} and {TEST_REFERENCE}"
    )


def import_recording(src: Path, out: Path) -> str:
    """A recording as a data set in the temporary folder (never in the repository)."""
    from core.formats.recording import to_dataset
    from core.recordings import read_recording

    rec = read_recording(src, fmt=None, cfg=None)
    to_dataset(rec, source_name=str(src)).save(out)
    return str(out)


def run_study(
    tmp: str,
    name: str,
    dataset: str,
    validation: str,
    seed: int,
    n_trials: int,
    *,
    model: str = MODEL,
    **kw: Any,
) -> dict[str, Any]:
    """One in-process study and its choice by validation: the chosen parameters' JSON
    (TrackerParams, or GtrackParams with ``model="gtrack"``). Raises :class:`InputError` when no
    trial completed."""
    from core.optimization.study import StudySettings, prepare_study, run_worker
    from core.optimization.validation import validate_study

    s = StudySettings(
        model=model,
        n_trials=n_trials,
        n_jobs=1,
        storage=f"sqlite:///{tmp}/studies.db",
        study_name=f"{name}-s{seed}",
        seed=seed,
        dataset=dataset,
        **kw,
    )
    t0 = time.perf_counter()
    prepare_study(s, dataset_path=dataset)
    run_worker(s.storage, s.name, seed=seed, dataset_path=dataset)
    ranked = validate_study(s.storage, s.name, validation, top_k=10)
    if not ranked:
        raise InputError(f"study {s.name}: no trial completed on {Path(dataset).name}")
    top = ranked[0]
    return {"params": top.params, "seconds": time.perf_counter() - t0, "trial": top.number}


def _scores(params: dict, walker: Any, reference: Any) -> dict[str, Any]:
    """The held-out figures of one parameter set."""
    from core.evaluation.counting import recording_scores
    from core.tracking import TrackerParams, track_dataset
    from core.tracking.batch import dataset_frame_period_s

    tp = TrackerParams.from_dict(params)
    w_est = track_dataset(walker, tp, with_tracks=True)
    w = recording_scores(walker, w_est, dataset_frame_period_s(walker), people=1)
    r_est = track_dataset(reference, tp, with_tracks=True)
    r = recording_scores(reference, r_est, dataset_frame_period_s(reference))
    assert w.count is not None and r.reference is not None
    return {
        "walker_right_count": w.count.right,
        "walker_right_count_interval": list(w.count.right_interval),
        "walker_count_error": w.count.error,
        "walker_ids_per_person_minute": w.count.fragmentation,
        "walker_nis_inside": w.nis.inside,
        "walker_nis_mean": w.nis.mean,
        "reference_mean_gospa_m": r.reference.mean_gospa_m,
        "reference_same_count": r.reference.count_agreement,
        "reference_nis_inside": r.nis.inside,
    }


FIGURES = (
    "walker_right_count",
    "walker_count_error",
    "walker_ids_per_person_minute",
    "walker_nis_inside",
    "reference_mean_gospa_m",
    "reference_same_count",
    "reference_nis_inside",
)


def run(quick: bool = False) -> dict:
    from core.dataset import Dataset
    from core.evaluation.intervals import bootstrap_interval
    from core.optimization.data import resolve_dataset
    from core.tracking import TrackerParams

    n_trials = 8 if quick else 80
    seeds = (0,) if quick else (0, 1, 2)
    real = real_folder()
    open_field = resolve_dataset(OPEN_FIELD)
    open_val = resolve_dataset(OPEN_FIELD_VALIDATION)
    n_room = 5 if quick else 35
    room_train, room_val = room_dataset(0, n_room), room_dataset(1000, n_room)
    per_seed: dict[str, list[dict[str, Any]]] = {w: [] for w in WAYS}
    with tempfile.TemporaryDirectory(prefix="radartune-transfer-") as tmp:
        train = import_recording(real / TRAIN_RECORDING, Path(tmp) / "train.npz")
        val = import_recording(real / VALIDATION_RECORDING, Path(tmp) / "val.npz")
        walker = Dataset.load(import_recording(real / TEST_WALKER, Path(tmp) / "walker.npz"))
        reference = Dataset.load(
            import_recording(real / TEST_REFERENCE, Path(tmp) / "reference.npz")
        )
        default = TrackerParams.default(MODEL).to_dict()
        per_seed["defaults"].append({"seed": None, **_scores(default, walker, reference)})
        for seed in seeds:
            runs = {
                "open field": run_study(tmp, "open", open_field, open_val, seed, n_trials,
                                     loss="trimmed"),
                "simulated rooms": run_study(tmp, "room", room_train, room_val, seed, n_trials,
                                          loss="trimmed"),
                "recording": run_study(tmp, "rec", train, val, seed, n_trials,
                                    loss="fragmentation", people=1),
                "mixed": run_study(tmp, "mixed", open_field, val, seed, n_trials, loss="trimmed",
                                people=1, mix=((train, 1.0),)),
            }  # fmt: skip
            for way, r in runs.items():
                entry = {"seed": seed, "trial": r["trial"], "study_s": r["seconds"]}
                if way in ("open field", "simulated rooms"):
                    entry["params"] = r["params"]  # tuned on simulations only
                per_seed[way].append({**entry, **_scores(r["params"], walker, reference)})
    summary: dict[str, dict[str, list[float]]] = {}
    for way, rows in per_seed.items():
        summary[way] = {}
        for fig in FIGURES:
            v = np.array([row[fig] for row in rows], dtype=float)
            if len(v) > 1:
                value, lo, hi = bootstrap_interval(lambda x: np.mean(x, axis=-1), v)
            else:
                value, lo, hi = float(v[0]), float("nan"), float("nan")
            summary[way][fig] = [value, lo, hi]
    return {
        "model": MODEL,
        "n_trials": n_trials,
        "seeds": list(seeds),
        "training": {"open field": OPEN_FIELD,
                     "simulated rooms": f"{OPEN_FIELD} in the room HALL of core/benchmarks/"
                     "transfer.py (18 x 10.5 m, walls -6 dB, sensor 2 m up, tilted 10 deg)"
                     + ("" if n_room == 35 else f" ({n_room} trajectories)"),
                     "recording": Path(TRAIN_RECORDING).name,
                     "mixed": f"{OPEN_FIELD} + {Path(TRAIN_RECORDING).name} (weight 1)"},
        "validation": {"open field": OPEN_FIELD_VALIDATION,
                       "simulated rooms": f"{OPEN_FIELD_VALIDATION} in the same room",
                       "recording": Path(VALIDATION_RECORDING).name,
                       "mixed": Path(VALIDATION_RECORDING).name},
        "held_out": [Path(TEST_WALKER).name, Path(TEST_REFERENCE).name],
        "per_seed": per_seed,
        "summary": summary,
    }  # fmt: skip


def _fmt(v: list[float], digits: int = 3) -> str:
    value, lo, hi = v
    if not np.isfinite(lo):
        return f"{value:.{digits}f}"
    return f"{value:.{digits}f} ({lo:.{digits}f}-{hi:.{digits}f})"


def summary(result: dict) -> str:
    lines = [
        f"bench transfer: {result['model'].upper()} studies of {result['n_trials']} trials, "
        f"seeds {result['seeds']}; held out: {', '.join(result['held_out'])}",
        f"{'tuned on':<16} {'right count':>22} {'count err':>20} {'ids/person-min':>22} "
        f"{'GOSPA vs TI m':>22} {'NIS inside':>20}",
    ]
    for way, s in result["summary"].items():
        lines.append(
            f"{way:<16} {_fmt(s['walker_right_count']):>22} {_fmt(s['walker_count_error']):>20} "
            f"{_fmt(s['walker_ids_per_person_minute'], 2):>22} "
            f"{_fmt(s['reference_mean_gospa_m']):>22} {_fmt(s['walker_nis_inside']):>20}"
        )
    return "\n".join(lines)

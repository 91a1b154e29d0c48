"""``radartune bench trackers``: four people trackers compared on simulated rooms and recordings.

The trackers (CV for RadarTune's own):

- **IPDA**: the paper's tracker (``mode`` paper), its defaults and tuned;
- **room mode**: RadarTune's tracker for real rooms (``--mode room``), its defaults and tuned;
- **gtrack, TI**: RadarTune's gtrack with TI's published people-counting tracker lines
  (``resources/gtrack/ti_people_counting_isk.cfg``);
- **gtrack tuned**: gtrack after a study (``--tracker gtrack``).

Every study is TPE + ASHA, one worker, SQLite, and chooses by validation on a data set it did
not train on. Two sources of tuning, each judged on data no study and no choice saw:

(a) **Simulated rooms** with truth. Training: ``room_office`` (three people, one sitting still,
    walls and furniture) simulated with seed :data:`TRAIN_SEED` (``--loss trimmed``); validation:
    the same scene with seed :data:`VALIDATION_SEED`. Held out: all four room scenes
    (:data:`SCENES`: walker, chair, office, corridor) with the seeds :data:`TEST_SEEDS`. Scores:
    GOSPA (c = 2 m, p = 2) and its parts (localisation, missed, false: mean per frame in m²), the
    fraction of frames with as many confirmed tracks as people present, identity switches
    (:mod:`core.evaluation.assignment`) and ghost tracks (:func:`ghost_tracks`).
(b) **Recordings**. Training: the mmgait walker ``002`` (``--people 1``, ``--loss
    fragmentation``); validation: walker ``022``. Held out: walker ``076`` (``--people 1``: the
    fraction of frames with one confirmed track, confirmed ids per person-minute) and the
    people-counting file ``pc3_2023-06-21-12-27-01`` (mean GOSPA to TI's own tracks, the
    recording's reference layer, and the share of frames with as many tracks as TI's). The
    parameters tuned on simulated rooms are scored there too (simulation to a real room). A
    tracker whose study cannot run on a recording without truth gets no recording-tuned row
    (the result says why).

Figures are means with 95 % intervals: over the held-out data sets and the study seeds (a
two-level bootstrap, :func:`core.evaluation.intervals.two_level_bootstrap`) on the simulated
rooms, over the study seeds on the recordings (one recording each).

gtrack runs with the data set's frame period (TI's ``trackingCfg`` carries the radar's frame
period; its 55 ms is the people-counting chirp's). The mmgait recordings carry no licence: the
result keeps scores only, never parameters tuned on them.
"""

from __future__ import annotations

import dataclasses
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from core.errors import InputError
from core.files import save_figure

SCENES = ("room_walker", "room_chair", "room_office", "room_corridor")
TRAIN_SCENE = "room_office"
TRAIN_SEED = 100
VALIDATION_SEED = 200
TEST_SEEDS = (300, 301)
#: A false track is a ghost when its nearest point of the frame, within this distance (m,
#: x-y), came over a wall (``path_order`` >= 1).
GHOST_RADIUS_M = 0.5
#: (name, tracker kind, parameter source); ``kind``: paper, room or gtrack.
TRACKERS = (
    ("IPDA defaults", "paper", "defaults"),
    ("IPDA tuned", "paper", "tuned"),
    ("room mode defaults", "room", "defaults"),
    ("room mode tuned", "room", "tuned"),
    ("gtrack TI", "gtrack", "ti"),
    ("gtrack tuned", "gtrack", "tuned"),
)
SIM_FIGURES = (
    "gospa_m", "localisation_m2", "missed_m2", "false_m2", "right_count", "identity_switches",
    "ghost_tracks_per_frame", "false_tracks_per_frame",
)  # fmt: skip
REC_FIGURES = ("walker_right_count", "walker_ids_per_person_minute", "pc3_gospa_m",
               "pc3_same_count")  # fmt: skip


def _scene_dataset(name: str, seed: int, fidelity: str):
    from core.pipeline import plan, simulate_scene
    from core.scene import Scene

    path = Path(__file__).resolve().parents[2] / "resources" / "scenes" / f"{name}.json"
    scene = dataclasses.replace(Scene.from_json(path), seed=seed)
    return simulate_scene(scene, the_plan=plan(scene, fidelity=fidelity)).to_dataset()


def ti_gtrack_params() -> dict[str, Any]:
    """gtrack's parameters from TI's people-counting cfg (``resources/gtrack``, as ``bench
    gtrack_ti`` reads it)."""
    from core.files import read_text
    from core.formats.ti_cfg import parse_ti_cfg
    from core.tracking.gtrack.params import params_from_cfg

    path = Path(__file__).resolve().parents[2] / "resources/gtrack/ti_people_counting_isk.cfg"
    return params_from_cfg(parse_ti_cfg(read_text(path), str(path)), str(path)).to_dict()


def default_params(kind: str) -> dict[str, Any]:
    """The untuned parameters of a tracker kind (gtrack: TI's cfg)."""
    from core.tracking import TrackerParams

    if kind == "gtrack":
        return ti_gtrack_params()
    return TrackerParams.default("cv", mode=kind).to_dict()


def run_tracker(kind: str, params: dict[str, Any], ds: Any) -> Any:
    """:class:`core.tracking.DatasetEstimates` (with every confirmed track) of one tracker."""
    if kind == "gtrack":
        from core.tracking.batch import dataset_frame_period_s
        from core.tracking.gtrack import GtrackParams
        from core.tracking.gtrack.batch import gtrack_dataset

        gp = GtrackParams.from_dict({**params, "frame_period_s": dataset_frame_period_s(ds)})
        return gtrack_dataset(ds, gp)[0]
    from core.tracking import TrackerParams, track_dataset

    return track_dataset(ds, TrackerParams.from_dict(params), with_tracks=True)


def ghost_tracks(ds: Any, est: Any, fm: Any, radius_m: float = GHOST_RADIUS_M) -> np.ndarray:
    """(N,) ghost tracks per frame: confirmed tracks that GOSPA pairs with no person and whose
    nearest point of the frame (x-y, within ``radius_m``) has ``path_order`` >= 1 (a wall
    bounce). Zero everywhere for a data set without ``path_order``."""
    n = len(est.frame_index)
    out = np.zeros(n, dtype=np.int64)
    if ds.path_order is None:
        return out
    xy = est.tracks.xy
    f_off = ds.frame_offsets
    pxy = np.column_stack((ds.x_m, ds.y_m))
    for f in range(n):
        cols = np.flatnonzero(np.all(np.isfinite(xy[f]), axis=1))
        false = np.setdiff1d(cols, fm.gospa_track[f][fm.gospa_track[f] >= 0])
        if not len(false):
            continue
        a, b = f_off[est.frame_index[f]], f_off[est.frame_index[f] + 1]
        if a == b:
            continue
        d = np.linalg.norm(pxy[a:b][None, :, :] - xy[f, false][:, None, :], axis=2)
        near = np.argmin(d, axis=1)
        hit = d[np.arange(len(false)), near] <= radius_m
        out[f] = int(np.sum(hit & (ds.path_order[a:b][near] >= 1)))
    return out


def sim_scores(ds: Any, est: Any) -> dict[str, float]:
    """The figures of one tracker run on one simulated room (see the module docstring)."""
    from core.evaluation.people import frame_metrics

    truth = ds.truth_xy_m[est.frame_index]
    fm = frame_metrics(truth, est.tracks.xy, est.tracks.ids, est.offsets)
    assert fm.identity is not None
    return {
        "gospa_m": float(np.mean(fm.gospa_m)),
        "localisation_m2": float(np.mean(fm.localisation)),
        "missed_m2": float(np.mean(fm.missed)),
        "false_m2": float(np.mean(fm.false)),
        "right_count": float(np.mean(fm.count_error == 0)),
        "identity_switches": float(np.sum(fm.identity.switch)),
        "ghost_tracks_per_frame": float(np.mean(ghost_tracks(ds, est, fm))),
        "false_tracks_per_frame": float(np.mean(fm.n_false)),
    }


def rec_scores(walker: Any, reference: Any, kind: str, params: dict[str, Any]) -> dict[str, float]:
    """Walker 076 with one person, pc3 against TI's tracks (see the module docstring)."""
    from core.evaluation.counting import count_scores
    from core.evaluation.reference import compare_with_reference
    from core.tracking.batch import dataset_frame_period_s

    w = run_tracker(kind, params, walker)
    ids = np.where(np.all(np.isfinite(w.tracks.xy), axis=2), w.tracks.ids, -1)
    c = count_scores(
        np.asarray(w.n_confirmed), np.ones(len(w.n_confirmed), dtype=np.int64), ids,
        dataset_frame_period_s(walker),
    )  # fmt: skip
    r = run_tracker(kind, params, reference)
    rows, cols = np.nonzero(np.all(np.isfinite(r.tracks.xy), axis=2))
    cmp = compare_with_reference(
        reference, np.asarray(r.frame_index)[rows], r.tracks.xy[rows, cols]
    )
    return {
        "walker_right_count": c.right,
        "walker_ids_per_person_minute": c.fragmentation,
        "pc3_gospa_m": cmp.mean_gospa_m,
        "pc3_same_count": cmp.count_agreement,
    }


def _study_of(kind: str, tmp: str, name: str, train: str, val: str, seed: int, n: int, **kw):
    from core.benchmarks.transfer import run_study

    if kind == "gtrack":
        return _gtrack_study(tmp, f"{kind}-{name}", train, val, seed, n, **kw)
    return run_study(tmp, f"{kind}-{name}", train, val, seed, n, model="cv", mode=kind, **kw)


def _gtrack_study(
    tmp: str, name: str, train: str, val: str, seed: int, n: int, *, loss: str, **kw: Any
) -> dict[str, Any]:
    """A gtrack study chosen as :func:`core.optimization.validation.validate_study` chooses
    (the ten best training trials, the best on the validation set), with gtrack's own loss
    source on the validation set."""
    import math

    from core.dataset import Dataset
    from core.optimization.objective import (
        evaluate,
        make_losses,
        uses_capped,
        without_positions,
    )
    from core.optimization.storage import load_existing_study, open_storage
    from core.optimization.study import StudySettings, prepare_study, run_worker
    from core.tracking.space import tracker_params_dict

    s = StudySettings(
        model="gtrack", n_trials=n, n_jobs=1, storage=f"sqlite:///{tmp}/g.db",
        study_name=f"{name}-s{seed}", seed=seed, dataset=train, loss=loss, **kw,
    )  # fmt: skip
    t0 = time.perf_counter()
    prepare_study(s, dataset_path=train)
    run_worker(s.storage, s.name, seed=seed, dataset_path=train)
    study = load_existing_study(open_storage(s.storage, create=False), s.name)
    assert study is not None
    done = [
        t
        for t in study.get_trials(deepcopy=False)
        if t.state.name == "COMPLETE" and t.value is not None and math.isfinite(t.value)
    ]
    if not done:
        raise InputError(f"study {s.name}: no trial completed on {Path(train).name}")
    losses = make_losses(
        "tracker", "gtrack", dataset=Dataset.load(val), capped=uses_capped(loss),
        without_positions=without_positions(loss), people=kw.get("people"),
    )  # fmt: skip
    ranked = []
    for t in sorted(done, key=lambda t: (t.value, t.number))[:10]:
        params = tracker_params_dict({k: float(v) for k, v in t.params.items()}, "gtrack")
        ranked.append((evaluate(losses, params, loss=loss).value, t.number, params))
    value, number, params = min(ranked, key=lambda r: (r[0], r[1]))
    return {"params": params, "seconds": time.perf_counter() - t0, "trial": number}


def _summarise(rows: list[list[dict[str, float]]], figures: tuple[str, ...]) -> dict:
    """rows[s][t]: study s, data set t → mean and 95 % interval of each figure."""
    from core.evaluation.intervals import two_level_bootstrap

    out = {}
    for fig in figures:
        m = np.array([[r[fig] for r in row] for row in rows], dtype=float)
        if m.size == 1:
            out[fig] = [float(m[0, 0]), float("nan"), float("nan")]
        else:
            out[fig] = list(two_level_bootstrap(lambda x: np.nanmean(x, axis=(-2, -1)), m))
    return out


def run(quick: bool = False) -> dict:
    from core.benchmarks.transfer import (
        TEST_REFERENCE,
        TEST_WALKER,
        TRAIN_RECORDING,
        VALIDATION_RECORDING,
        import_recording,
    )
    from core.benchmarks.transfer import real_folder as _real
    from core.dataset import Dataset

    n_trials = 4 if quick else 50
    seeds = (0,) if quick else (0, 1, 2)
    fidelity = "measurement" if quick else "exact"
    scenes = ("room_corridor",) if quick else SCENES
    test_seeds = TEST_SEEDS[:1] if quick else TEST_SEEDS
    train_scene = "room_corridor" if quick else TRAIN_SCENE
    try:
        real: Path | None = _real()
    except InputError:
        real = None
    t0 = time.perf_counter()
    notes: list[str] = []
    with tempfile.TemporaryDirectory(prefix="radartune-trackers-") as tmp:
        train_ds = _scene_dataset(train_scene, TRAIN_SEED, fidelity)
        train_ds.save(f"{tmp}/train.npz")
        _scene_dataset(train_scene, VALIDATION_SEED, fidelity).save(f"{tmp}/val.npz")
        tests = [(s, k, _scene_dataset(s, k, fidelity)) for s in scenes for k in test_seeds]
        recs = None
        if real is not None:
            rec_train = import_recording(real / TRAIN_RECORDING, Path(tmp) / "rtrain.npz")
            rec_val = import_recording(real / VALIDATION_RECORDING, Path(tmp) / "rval.npz")
            recs = (
                Dataset.load(import_recording(real / TEST_WALKER, Path(tmp) / "walker.npz")),
                Dataset.load(import_recording(real / TEST_REFERENCE, Path(tmp) / "pc3.npz")),
            )
        else:
            notes.append("the public recordings were not found ($RADARTUNE_REAL): no part (b)")
        sim_t = time.perf_counter() - t0
        print(f"bench trackers: data sets ready after {sim_t:.0f} s", flush=True)
        sim: dict[str, Any] = {}
        rec: dict[str, Any] = {}
        for name, kind, source in TRACKERS:
            if source != "tuned":
                sets = [default_params(kind)]
                studies_s: list[float] = []
            else:
                sets, studies_s = [], []
                for seed in seeds:
                    r = _study_of(kind, tmp, "sim", f"{tmp}/train.npz", f"{tmp}/val.npz", seed,
                                  n_trials, loss="trimmed")  # fmt: skip
                    sets.append(r["params"])
                    studies_s.append(r["seconds"])
            rows = [[sim_scores(ds, run_tracker(kind, p, ds)) for _, _, ds in tests] for p in sets]
            print(f"bench trackers: {name} after {time.perf_counter() - t0:.0f} s", flush=True)
            sim[name] = {"per_study": rows, "study_s": studies_s,
                         "summary": _summarise(rows, SIM_FIGURES)}  # fmt: skip
            if recs is None:
                continue
            rec_rows = {"as simulated" if source == "tuned" else source: sets}
            if source == "tuned":
                rec_sets: list[dict[str, Any]] = []
                try:
                    for seed in seeds:
                        rec_sets.append(
                            _study_of(kind, tmp, "rec", rec_train, rec_val, seed, n_trials,
                                      loss="fragmentation", people=1)["params"]
                        )  # fmt: skip
                    rec_rows["on recordings"] = rec_sets
                except InputError as exc:
                    notes.append(f"{name}: not tuned on a recording ({exc.message})")
            for src, psets in rec_rows.items():
                per = [rec_scores(recs[0], recs[1], kind, p) for p in psets]
                rec[f"{name} ({src})" if source == "tuned" else name] = {
                    "per_study": per,
                    "summary": _summarise([[r] for r in per], REC_FIGURES),
                }
    result = {
        "quick": quick,
        "model": "cv (IPDA, room mode); gtrack 3-D",
        "n_trials": n_trials,
        "study_seeds": list(seeds),
        "fidelity": fidelity,
        "training": {"simulated rooms": f"{train_scene} seed {TRAIN_SEED}, --loss trimmed",
                     "recordings": f"{Path(TRAIN_RECORDING).name}, --people 1, --loss "
                                   "fragmentation"},
        "validation": {"simulated rooms": f"{train_scene} seed {VALIDATION_SEED}",
                       "recordings": Path(VALIDATION_RECORDING).name},
        "held_out": {"simulated rooms": [f"{s} seed {k}" for s, k, _ in tests],
                     "recordings": [Path(TEST_WALKER).name, Path(TEST_REFERENCE).name]},
        "ghost_radius_m": GHOST_RADIUS_M,
        "simulation_s": sim_t,
        "total_s": time.perf_counter() - t0,
        "notes": notes,
        "simulated_rooms": sim,
        "recordings": rec,
    }  # fmt: skip
    result["plot"] = str(_plot(result, quick))
    return result


def _plot(result: dict, quick: bool) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path = Path("bench/results/trackers-quick.png" if quick else "docs/tracking/trackers.png")
    path.parent.mkdir(parents=True, exist_ok=True)
    panels = [
        ("simulated_rooms", "gospa_m", "held-out simulated rooms:\nmean GOSPA (m)"),
        ("simulated_rooms", "right_count", "held-out simulated rooms:\nright count (share)"),
        ("recordings", "walker_right_count", "walker 076 (one person):\nright count (share)"),
        ("recordings", "pc3_gospa_m", "pc3 2023: mean GOSPA\nto TI's tracks (m)"),
    ]
    fig, axes = plt.subplots(1, 4, figsize=(13, 4.2), sharey=False)
    for ax, (part, fig_name, title) in zip(axes, panels):
        names = list(result[part])
        if not names:  # no recordings found
            ax.set_axis_off()
            ax.set_title(f"{title}\n(not measured)", fontsize=9)
            continue
        vals = np.array([result[part][n]["summary"][fig_name] for n in names], dtype=float)
        y = np.arange(len(names))
        err = np.abs(np.nan_to_num(vals[:, 1:].T - vals[:, 0], nan=0.0))
        colours = ["tab:red" if n.startswith("IPDA") else "tab:blue" if n.startswith("room")
                   else "tab:green" for n in names]  # fmt: skip
        ax.barh(y, vals[:, 0], xerr=err, color=colours, alpha=0.8, capsize=3)
        ax.set_yticks(y)
        ax.set_yticklabels(names if ax is axes[0] or part != panels[0][0] else [], fontsize=7)
        ax.invert_yaxis()
        ax.set_title(title, fontsize=9)
        ax.grid(axis="x", alpha=0.3)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    plt.close(fig)
    return path


def _fmt(v: list[float], digits: int = 3) -> str:
    value, lo, hi = v
    if not np.isfinite(value):
        return "–"
    if not np.isfinite(lo):
        return f"{value:.{digits}f}"
    return f"{value:.{digits}f} ({lo:.{digits}f}–{hi:.{digits}f})"


def summary(result: dict) -> str:
    lines = [
        f"bench trackers: {result['n_trials']} trials a study, study seeds "
        f"{result['study_seeds']}; simulated rooms held out: "
        f"{', '.join(result['held_out']['simulated rooms'])}",
        f"{'tracker':<22} {'GOSPA m':>22} {'right count':>22} {'id switches':>22} "
        f"{'ghosts/frame':>22}",
    ]
    for name, r in result["simulated_rooms"].items():
        s = r["summary"]
        lines.append(
            f"{name:<22} {_fmt(s['gospa_m']):>22} {_fmt(s['right_count']):>22} "
            f"{_fmt(s['identity_switches'], 1):>22} {_fmt(s['ghost_tracks_per_frame']):>22}"
        )
    if result["recordings"]:
        lines.append(f"{'recordings':<34} {'076 right count':>22} {'076 ids/person-min':>22} "
                     f"{'pc3 GOSPA to TI m':>22}")  # fmt: skip
        for name, r in result["recordings"].items():
            s = r["summary"]
            lines.append(
                f"{name:<34} {_fmt(s['walker_right_count']):>22} "
                f"{_fmt(s['walker_ids_per_person_minute'], 1):>22} {_fmt(s['pc3_gospa_m']):>22}"
            )
    lines += [f"note: {n}" for n in result["notes"]]
    lines.append(f"plot: {result['plot']}")
    return "\n".join(lines)

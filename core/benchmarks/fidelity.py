"""``radartune bench fidelity``: error against run time of the simulation's fidelity levels.

The same scenes (a subset of the paper's data set: ``n`` trajectories per class) and the same
per-frame reflectors and noise seeds go through every level of
:data:`core.simulation.FIDELITY_LEVELS`. Only the simulator call is timed (process CPU time,
so that the other processes on a shared machine count less), frame by frame, and the levels run
interleaved trajectory by trajectory so that a load change hits all of them alike. A second
``exact`` run with other noise seeds (``exact*``) shows how far two statistically identical
simulations differ: the yardstick for every distance below.

Figures per level: frames per second and speed-up over ``exact``; detection probability of the
person; range, azimuth and radial-velocity errors of the person's points (mean, spread) and
their Kolmogorov-Smirnov distance to ``exact``; the same for the reported SNR; clutter and
false detections per frame; the tracking loss (eq. 14) of the same tracker parameters (the
tuned ones of ``docs/report/best_<model>.json`` by default) on each level's data set for the CV
and CA models, with the run time of one trial. The loss is compared twice: as a whole, and split
into its two parts — the trajectory runs without any confirmed track (``N_c = 0``: ``L = 1 m^2``
each by SPEC §5, a rare event that dominates the mean when it happens) with their rate, and the
"regular" loss of the runs with a confirmed track; that in turn into its tail events (runs above
``TAIL_FACTOR`` times the exact level's median loss of the trajectory) with their rate, and the
bulk, whose mean loss carries the 10 % verdict.

Writes ``docs/fidelity/results.md`` and ``docs/fidelity/error_vs_runtime.png`` (``--quick``:
``bench/results/fidelity-quick.*``) through :mod:`core.benchmarks.fidelity_report`, which can
also re-render them from the JSON (``radartune bench fidelity --render-only``). The statistics
of the loss comparison are in :mod:`core.evaluation.intervals`.
"""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Any

import numpy as np

from core.benchmarks.fidelity_report import render, summary
from core.evaluation.intervals import (
    N_BOOTSTRAP,
    TAIL_FACTOR,
    exact_median_loss,
    loss_ratio_interval,
    rate_interval,
    rate_ratio_interval,
    regular_loss,
    split_tail,
    verdict,
)

#: ``summary`` is the report's: ``radartune bench`` calls ``run`` and ``summary`` of this module
__all__ = ["run", "summary", "tracker_parameters"]

#: trajectories per class (a-e) in the full and the quick run (7: the paper's whole set of 35)
PER_CLASS = 7
PER_CLASS_QUICK = 1
QUICK_FRAMES = 60
#: noise seeds per level (the tracking loss is heavy-tailed: one frame on a clutter track moves
#: a trajectory's loss by ~1e-3; with the tuned parameters the seed totals still spread by
#: 35-65 %); the cheaper levels afford more
N_SEEDS = {"exact": 48, "fast": 96, "measurement": 96}
N_SEEDS_QUICK = {"exact": 2, "fast": 2, "measurement": 4}
#: noise seed offset between seeds
OTHER_SEED = 1_000_003
#: tuned tracker parameters (the same tuned parameters on each level's data set)
TUNED_PARAMS = {
    m: Path(__file__).resolve().parents[2] / "docs" / "report" / f"best_{m}.json"
    for m in ("cv", "ca")
}


def tracker_parameters(params_cv=None, params_ca=None) -> tuple[dict, str]:
    """The CV and CA parameters the bench tracks with, and a description of where they come from.

    A given file wins; otherwise ``docs/report/best_<model>.json`` when it exists, else
    ``TrackerParams.default(model)``.
    """
    from core.tracking import TrackerParams

    out, said = {}, []
    for model, given in (("cv", params_cv), ("ca", params_ca)):
        path = Path(given) if given is not None else TUNED_PARAMS[model]
        if given is not None or path.exists():
            prm = TrackerParams.load(path)
            if prm.model != model:
                from core.errors import InputError

                raise InputError(f"model must be {model!r}, got {prm.model!r}", str(path))
            out[model] = prm
            said.append(f"{model.upper()}: {_repo_relative(path)}")
        else:
            out[model] = TrackerParams.default(model)
            said.append(f"{model.upper()}: TrackerParams.default({model!r})")
    return out, "; ".join(said)


def _repo_relative(path: Path) -> str:
    root = Path(__file__).resolve().parents[2]
    try:
        return str(path.resolve().relative_to(root))
    except ValueError:
        return str(path)


def _ks(a: np.ndarray, b: np.ndarray) -> float | None:
    """Two-sample KS distance of two levels' point errors; None below 5 points (the table's
    dash). Kept here: a statistic of the point errors this bench collects, not of the loss."""
    from scipy.stats import ks_2samp

    if len(a) < 5 or len(b) < 5:
        return None
    return float(ks_2samp(a, b).statistic)


def _frames(scene, seed):
    """Reflectors of every frame as the pipeline builds them (same streams as a data set)."""
    from core import pipeline
    from core import simulation as sim

    p = pipeline.plan(scene)
    antenna = sim.AntennaGain.draw(scene.radar, pipeline.stage_rng(seed, "antenna"))
    settings = pipeline.processing_settings(scene)
    # the pipeline's reflector builder (the bench needs the frames without simulating)
    refl = pipeline.Reflectors.build(scene, p, seed, antenna, settings)
    frames = refl.frames()[0]
    return frames, antenna, settings, p.elevation, refl


def _model_arg(person_model: str) -> str:
    """``, person_model='walking'`` for a body, nothing for the paper's point person."""
    return "" if person_model == "point" else f", person_model={person_model!r}"


def _batch_simulator(name: str):
    """The level's all-frames entry point (``core.simulation.LEVELS``) or None."""
    from core.simulation import LEVELS

    return LEVELS[name].simulate_frames


def _warm_up(levels, radar, frame_pair, kw) -> dict[str, float]:
    """One-time set-up per level (compilation, tables, the false-alarm pool), CPU s: not frame
    time."""
    from core.simulation import FIDELITY_LEVELS

    setup_s = {}
    for name in levels:
        t0 = time.process_time()
        FIDELITY_LEVELS[name](radar, frame_pair[0], np.random.default_rng(0), **kw)
        batch = _batch_simulator(name)
        if batch is not None:
            batch(radar, frame_pair[:2], [np.random.default_rng(0)] * 2, **kw)
        setup_s[name] = time.process_time() - t0
    return setup_s


def _simulate_run(run, scene, frames, n_f, kw, a: dict[str, Any], per_frame: dict):
    """One (level, noise seed) run over one trajectory's first ``n_f`` frames, timed into
    ``a["cpu_s"]`` (and, for a batch level's seed 0, its per-frame call into ``per_frame``).
    Returns the merged point cloud and the points per frame."""
    from core import pipeline
    from core.pointcloud import PointCloud
    from core.simulation import FIDELITY_LEVELS

    name, s = run
    radar = scene.radar
    simulate, batch = FIDELITY_LEVELS[name], _batch_simulator(name)
    noise_seed = scene.seed + s * OTHER_SEED
    # the pipeline's per-frame generators, built outside the timing for every level
    rngs = [pipeline.stage_rng(noise_seed, "noise", f) for f in range(n_f)]
    if batch is not None:
        t0 = time.process_time()
        out = batch(radar, frames[:n_f], rngs, **kw)
        a["cpu_s"] += time.process_time() - t0
        merged, counts = out.point_cloud, out.counts
        if s == 0:
            rngs = [pipeline.stage_rng(noise_seed, "noise", f) for f in range(n_f)]
            t0 = time.process_time()
            for f in range(n_f):
                simulate(radar, frames[f], rngs[f], **kw)
            per_frame[name]["cpu_s"] += time.process_time() - t0
            per_frame[name]["frames"] += n_f
    else:
        one = []
        for f in range(n_f):
            t0 = time.process_time()
            res = simulate(radar, frames[f], rngs[f], **kw)
            a["cpu_s"] += time.process_time() - t0
            one.append(res.point_cloud)
        merged = PointCloud.concatenate(one)
        counts = np.array([len(c) for c in one], dtype=np.int64)
    return merged, counts


def _collect_point_errors(merged, counts, frames, n_f, t_mid: float, a: dict[str, Any]) -> None:
    """Append to ``a`` whether each frame detected the person (``hit``), and the range,
    azimuth and radial-velocity errors (``err``) and SNR (``snr``) of its points: against its
    scatterer for the point person, against the mean of its scatterers for a body."""
    edges = np.concatenate(([0], np.cumsum(counts)))
    for f in range(n_f):
        sc = frames[f]
        src = merged.source[edges[f] : edges[f + 1]]
        a["hit"].append(bool(np.any(src == 0)))
        person = np.flatnonzero(sc.source == 0)
        if person.size:
            # the point person's scatterer, or the mean of a body's scatterers
            vel = sc.velocity_mps[person].mean(axis=0)
            pos = sc.position_m[person].mean(axis=0) + vel * t_mid
            r = np.linalg.norm(pos)
            az = np.arctan2(pos[0], pos[1])
            vr = pos @ vel / r
            for j in edges[f] + np.flatnonzero(src == 0):
                a["err"].append(
                    (
                        merged.range_m[j] - r,
                        merged.azimuth_rad[j] - az,
                        merged.radial_velocity_mps[j] - vr,
                    )
                )
                a["snr"].append(merged.snr_db[j])


def _simulate_levels(scenes, levels, runs, stat_runs, quick: bool):
    """Every run (level, noise seed) over every scene, levels interleaved per trajectory.

    Returns the per-run accumulators (CPU time, frames, the point clouds and, for
    ``stat_runs``, the person's point errors), the per-frame call timings of batch levels, the
    truth of every trajectory and each level's set-up time."""
    acc: dict[tuple[str, int], dict[str, Any]] = {
        run: {"cpu_s": 0.0, "frames": 0, "parts": [], "err": [], "snr": [], "hit": []}
        for run in runs
    }
    # the per-frame entry point of levels that have a batch one (the GUI's path), seed 0
    per_frame = {name: {"cpu_s": 0.0, "frames": 0} for name in levels if _batch_simulator(name)}
    truth: dict[str, list[Any]] = {"xy": [], "v": [], "t": [], "traj": [], "cls": []}
    setup_s: dict[str, float] = {}
    for k, scene in enumerate(scenes):
        frames, antenna, settings, elevation, refl = _frames(scene, scene.seed)
        n_f = min(QUICK_FRAMES, len(frames)) if quick else len(frames)
        radar = scene.radar
        t_mid = 0.5 * radar.n_loops * radar.n_tx * radar.chirp_period_s
        kw = {"antenna": antenna, "settings": settings, "elevation": elevation}
        if k == 0:
            setup_s = _warm_up(levels, radar, frames, kw)
        for run in runs:
            a = acc[run]
            merged, counts = _simulate_run(run, scene, frames, n_f, kw, a, per_frame)
            a["frames"] += n_f
            # keep each trajectory's points concatenated (memory stays flat over many seeds)
            a["parts"].append((merged, counts))
            if run in stat_runs:
                _collect_point_errors(merged, counts, frames, n_f, t_mid, a)
        truth["xy"].append(refl.truth_xy_m[:n_f])
        truth["v"].append(refl.truth_v_mps[:n_f])
        truth["t"].append(refl.truth_t_s[:n_f])
        truth["traj"].append(np.full(n_f, k, dtype=np.int32))
        truth["cls"].append(scene.trajectory_class)
    return acc, per_frame, truth, setup_s


def _run_dataset(run, a: dict[str, Any], truth: dict[str, list[Any]], scenes):
    """One run's point clouds over all trajectories as a data set with the truth."""
    from core.dataset import Dataset
    from core.pointcloud import POINT_FIELDS, PointCloud

    merged = PointCloud.concatenate([m for m, _ in a["parts"]])
    counts = np.concatenate([c for _, c in a["parts"]])
    return Dataset(
        frame=np.repeat(np.arange(len(counts)), counts).astype(np.int32),
        **{f: getattr(merged, f).astype(np.float64) for f in POINT_FIELDS},
        source=merged.source.astype(np.int32),
        trajectory=np.concatenate(truth["traj"]),
        truth_t_s=np.concatenate(truth["t"]),
        truth_xy_m=np.concatenate(truth["xy"]),
        truth_v_mps=np.concatenate(truth["v"]),
        trajectory_class=np.asarray(truth["cls"], dtype="U5"),
        scene_json=json.dumps([s.to_dict() for s in scenes]),
        radar_json=json.dumps(scenes[0].radar.to_dict()),
        fidelity=run[0],
        seed=run[1],
    )


def _track_runs(acc, runs, truth, scenes, params) -> dict[tuple[tuple[str, int], str], dict]:
    """Every run's data set tracked with the same parameters per model: loss, its parts and the
    CPU time of one trial's tracking (the tracker is compiled outside the timing). Also counts
    each run's clutter, false and person points into ``acc[run]["points"]``."""
    from core.evaluation import evaluate
    from core.tracking import track_dataset

    tracking: dict[tuple[tuple[str, int], str], dict[str, Any]] = {}
    for run in runs:
        a = acc[run]
        ds = _run_dataset(run, a, truth, scenes)
        src = ds.source
        a["points"] = {
            "clutter": int(np.sum(src == -1)),
            "false": int(np.sum(src == -2)),
            "person": int(np.sum(src >= 0)),
        }
        a["parts"] = []  # the data set holds them now
        for model, prm in params.items():
            if not tracking:
                track_dataset(ds, prm)  # compile the tracker outside the timing
            t0 = time.process_time()
            ev = evaluate(ds, track_dataset(ds, prm))
            dt = time.process_time() - t0
            tracking[(run, model)] = {
                "loss_x1e3": 1e3 * ev.loss_total,
                "trajectory_loss_x1e3": (1e3 * np.asarray(ev.loss)).tolist(),
                "trajectory_n_c": np.asarray(ev.n_c).astype(int).tolist(),
                "median_trajectory_loss_x1e3": 1e3 * float(np.median(ev.loss)),
                "mse_mean_m2": float(np.nanmean(ev.mse)),
                "n_c_mean": float(np.mean(ev.n_c)),
                "rmse_m": ev.rmse_m,
                "confirmed_fraction": ev.confirmed_fraction,
                "far_frames": int(ev.far_frames_total),
                "track_cpu_s": dt,
            }
    return tracking


def _per_trajectory(tracking, n_seeds, name: str, model: str) -> np.ndarray:
    """``(K,)`` each trajectory's loss (x1e-3), mean over the level's noise seeds."""
    return np.mean(
        [tracking[((name, t), model)]["trajectory_loss_x1e3"] for t in range(n_seeds[name])],
        axis=0,
    )


def _split(tracking, n_seeds, name: str, model: str) -> tuple[np.ndarray, np.ndarray]:
    """``(S, K)`` per seed and trajectory: loss (x1e-3) and whether a track was confirmed."""
    runs_here = [tracking[((name, t), model)] for t in range(n_seeds[name])]
    loss = np.array([r["trajectory_loss_x1e3"] for r in runs_here])
    return loss, np.array([r["trajectory_n_c"] for r in runs_here]) > 0


def _exact_yardstick(losses: list[float], loss: np.ndarray, seen: np.ndarray) -> dict[str, Any]:
    """How far exact's own noise seeds differ: each seed's total and regular loss against the
    other seeds', and the bulk of its second half of seeds against its first half."""
    out: dict[str, Any] = {}
    # the yardstick: each exact seed's total against the mean of the other seeds
    tot = np.array(losses)
    others = [(tot.sum() - v) / (len(tot) - 1) for v in tot] if len(tot) > 1 else []
    out["exact_seed_ratio_to_others"] = [float(v / o) for v, o in zip(tot, others)]
    # the same for the regular loss (runs with a confirmed track)
    yard = []
    for t in range(len(tot) if len(tot) > 1 else 0):
        rest = np.arange(len(tot)) != t
        mine = regular_loss(loss[t : t + 1], seen[t : t + 1])
        rest_reg = regular_loss(loss[rest], seen[rest])
        ok = np.isfinite(mine) & np.isfinite(rest_reg)
        yard.append(float(mine[ok].sum() / rest_reg[ok].sum()))
    out["exact_seed_regular_ratio_to_others"] = yard
    # the bulk's yardstick: exact's second half of seeds against its first half,
    # each half with its own median threshold (as a level against exact)
    h = len(tot) // 2
    if h:
        med_a = exact_median_loss(loss[:h], seen[:h])
        bulk_a, _ = split_tail(loss[:h], seen[:h], med_a)
        bulk_b, _ = split_tail(loss[h : 2 * h], seen[h : 2 * h], med_a)
        ok = np.isfinite(bulk_a) & np.isfinite(bulk_b)
        out["exact_half_bulk_ratio"] = list(loss_ratio_interval(bulk_b[ok], bulk_a[ok]))
    return out


def _tracking_row(tracking, n_seeds, name: str, model: str, cpu_level: list[float]) -> dict:
    """A level's tracking figures for one model: the loss against exact's as a whole and split
    into its parts (no-track runs, regular loss, its tail and bulk), with intervals."""
    seeds_here = range(n_seeds[name])
    per_seed = [tracking[((name, t), model)] for t in seeds_here]
    losses = [p["loss_x1e3"] for p in per_seed]
    ratio, lo, hi = loss_ratio_interval(
        _per_trajectory(tracking, n_seeds, name, model),
        _per_trajectory(tracking, n_seeds, "exact", model),
    )
    # the two parts of eq. (14): trajectory runs without any confirmed track (N_c = 0,
    # L = 1 m^2 by SPEC) and the loss of the runs with one ("regular")
    loss, seen = _split(tracking, n_seeds, name, model)
    ex_loss, ex_seen = _split(tracking, n_seeds, "exact", model)
    reg, ex_reg = regular_loss(loss, seen), regular_loss(ex_loss, ex_seen)
    both = np.isfinite(reg) & np.isfinite(ex_reg)
    r_ratio, r_lo, r_hi = loss_ratio_interval(reg[both], ex_reg[both])
    # the regular runs split again: tail events (> TAIL_FACTOR x exact's median of the
    # trajectory) with their rate, and the bulk's mean loss
    ex_med = exact_median_loss(ex_loss, ex_seen)
    bulk, tail = split_tail(loss, seen, ex_med)
    ex_bulk, ex_tail = split_tail(ex_loss, ex_seen, ex_med)
    ok = np.isfinite(bulk) & np.isfinite(ex_bulk)
    b_ratio, b_lo, b_hi = loss_ratio_interval(bulk[ok], ex_bulk[ok])
    n_tail, n_seen = int(tail.sum()), int(seen.sum())
    t_ratio, t_lo, t_hi = rate_ratio_interval(
        n_tail, n_seen, int(ex_tail.sum()), int(ex_seen.sum())
    )
    n_miss = int(np.sum(~seen))
    row = {
        "no_track_runs": n_miss,
        "trajectory_runs": int(seen.size),
        "no_track_rate_ci95": list(rate_interval(n_miss, int(seen.size))),
        "regular_loss_x1e3": float(np.nanmean(reg)),
        "regular_loss_ratio_to_exact": r_ratio,
        "regular_loss_ratio_ci95": [r_lo, r_hi],
        "regular_verdict_within_10pct": "–" if name == "exact" else verdict(r_lo, r_hi),
        "tail_factor": TAIL_FACTOR,
        "tail_events": n_tail,
        "tail_rate_ci95": list(rate_interval(n_tail, max(n_seen, 1))),
        "tail_rate_ratio_to_exact": [t_ratio, t_lo, t_hi],
        "tail_loss_share": float(np.where(tail, loss, 0.0).sum())
        / max(float(np.where(seen, loss, 0.0).sum()), 1e-300),
        "bulk_loss_x1e3": float(np.nanmean(bulk)),
        "bulk_loss_ratio_to_exact": b_ratio,
        "bulk_loss_ratio_ci95": [b_lo, b_hi],
        "bulk_verdict_within_10pct": "–" if name == "exact" else verdict(b_lo, b_hi),
        "loss_x1e3_per_seed": losses,
        # (seeds, trajectories): for analyses the table does not make
        "trajectory_loss_x1e3_per_seed": loss.tolist(),
        "trajectory_confirmed_per_seed": seen.tolist(),
        "loss_x1e3_mean": float(np.mean(losses)),
        "loss_ratio_to_exact": ratio,
        "loss_ratio_ci95": [lo, hi],
        "verdict_within_10pct": "–" if name == "exact" else verdict(lo, hi),
        "median_trajectory_loss_x1e3": float(
            np.mean([p["median_trajectory_loss_x1e3"] for p in per_seed])
        ),
        "mse_mean_m2": float(np.mean([p["mse_mean_m2"] for p in per_seed])),
        "n_c_mean": float(np.mean([p["n_c_mean"] for p in per_seed])),
        "rmse_m": float(np.mean([p["rmse_m"] for p in per_seed])),
        "confirmed_fraction": float(np.mean([p["confirmed_fraction"] for p in per_seed])),
        "far_frames_per_seed": [p["far_frames"] for p in per_seed],
        "track_cpu_s": float(np.mean([p["track_cpu_s"] for p in per_seed])),
        "trial_cpu_s": float(np.mean(cpu_level))
        + float(np.mean([p["track_cpu_s"] for p in per_seed])),
    }
    if name == "exact":
        row.update(_exact_yardstick(losses, loss, seen))
    return row


def _dist(x: np.ndarray) -> dict:
    """Mean, spread and 5–95 % range of a point error."""
    if not len(x):
        return {"mean": None, "sd": None, "robust_sd": None, "p05": None, "p95": None}
    return {
        "mean": float(np.mean(x)),
        "sd": float(np.std(x)),
        # 1.4826 MAD: the sd of a normal core, blind to the rare far-off point that
        # dominates "sd" (one point at 15° moves the azimuth sd by 10 %)
        "robust_sd": float(1.4826 * np.median(np.abs(x - np.median(x)))),
        "p05": float(np.percentile(x, 5)),
        "p95": float(np.percentile(x, 95)),
    }


def _level_row(run, acc, exact_fps: float, per_frame, setup_s, n_seeds, trk) -> dict:
    """One row of the table (a level at noise seed 0, or exact*): speed, the person's point
    errors against exact's, points per frame and the tracking figures ``trk``."""
    name, s = run
    a, exact = acc[run], acc[("exact", 0)]
    err = np.asarray(a["err"]).reshape(-1, 3)
    ex = np.asarray(exact["err"]).reshape(-1, 3)
    snr, ex_snr = np.asarray(a["snr"]), np.asarray(exact["snr"])
    n_frames = a["frames"]
    seeds_here = range(n_seeds[name])
    cpu_level = [acc[(name, t)]["cpu_s"] for t in seeds_here]
    fps = sum(acc[(name, t)]["frames"] for t in seeds_here) / sum(cpu_level)
    return {
        "frames": n_frames,
        "cpu_s_per_seed": cpu_level,
        "setup_cpu_s": setup_s[name],
        "fps": fps,
        "speedup": fps / exact_fps if s == 0 else 1.0,
        "per_frame_call_fps": (
            per_frame[name]["frames"] / per_frame[name]["cpu_s"]
            if name in per_frame and s == 0
            else None
        ),
        "person_pd": float(np.mean(a["hit"])),
        "range_error_m": {**_dist(err[:, 0]), "ks": _ks(err[:, 0], ex[:, 0])},
        "azimuth_error_deg": {
            **_dist(np.degrees(err[:, 1])),
            "ks": _ks(err[:, 1], ex[:, 1]),
        },
        "radial_velocity_error_mps": {**_dist(err[:, 2]), "ks": _ks(err[:, 2], ex[:, 2])},
        "snr_db": {**_dist(snr), "ks": _ks(snr, ex_snr)},
        "noise_seeds": n_seeds[name],
        "clutter_points_per_frame": a["points"]["clutter"] / n_frames,
        "false_points_per_frame": a["points"]["false"] / n_frames,
        "person_points_per_frame": a["points"]["person"] / n_frames,
        "tracking": trk,
    }


def run(quick: bool = False, params_cv=None, params_ca=None, person_model: str = "point") -> dict:
    """Run every level on the same scenes; returns JSON-ready figures (see module docstring).

    ``params_cv`` / ``params_ca``: tracker parameter files (default: the tuned parameters in
    ``docs/report/best_<model>.json`` when present, see :func:`tracker_parameters`).
    ``person_model``: the paper scenes' person (``point``, the paper's; ``walking``; ``blob``).
    The person's point errors are taken from its scatterer for the point person, and from the
    mean of its scatterers (position and velocity, at the frame's middle) for a body.
    """
    from core.scene import paper_scenes
    from core.simulation import FIDELITY_LEVELS

    params, params_said = tracker_parameters(params_cv, params_ca)

    per_class = PER_CLASS_QUICK if quick else PER_CLASS
    seeds = N_SEEDS_QUICK if quick else N_SEEDS
    scenes = paper_scenes(0, 5 * per_class, person_model=person_model)
    levels = list(FIDELITY_LEVELS)
    n_seeds = {name: seeds.get(name, 2) for name in levels}
    runs = [(name, s) for s in range(max(n_seeds.values())) for name in levels if s < n_seeds[name]]
    #: runs whose point errors are collected (the rows of the table)
    stat_runs = {(name, 0) for name in levels} | {("exact", 1)}
    acc, per_frame, truth, setup_s = _simulate_levels(scenes, levels, runs, stat_runs, quick)

    # data sets and tracking: the same parameters on every level's point clouds
    tracking = _track_runs(acc, runs, truth, scenes, params)

    exact = acc[("exact", 0)]
    exact_fps = sum(acc[("exact", t)]["frames"] for t in range(n_seeds["exact"])) / sum(
        acc[("exact", t)]["cpu_s"] for t in range(n_seeds["exact"])
    )
    rows = [(name, 0) for name in levels] + ([("exact", 1)] if n_seeds["exact"] > 1 else [])
    result_levels = {}
    for run in rows:
        name, s = run
        cpu_level = [acc[(name, t)]["cpu_s"] for t in range(n_seeds[name])]
        trk = {model: _tracking_row(tracking, n_seeds, name, model, cpu_level) for model in params}
        label = name if s == 0 else "exact*"
        result_levels[label] = _level_row(run, acc, exact_fps, per_frame, setup_s, n_seeds, trk)
    out = {
        "scenes": f"paper_scenes(seed=0{_model_arg(person_model)}): first {len(scenes)} "
        f"trajectories ({per_class} per class a-e)"
        + (f", first {QUICK_FRAMES} frames each" if quick else ""),
        "person_model": person_model,
        "frames_per_level": exact["frames"],
        "noise_seeds": n_seeds,
        "bootstrap": f"{N_BOOTSTRAP} paired resamples of the {len(scenes)} trajectories",
        "tracker_parameters": params_said,
        "timing": "process CPU time of the simulator call only (for a level with a batch entry "
        "point, LEVELS[...].simulate_frames: the one call for all frames of a trajectory, "
        "as the data-set path runs it; its per-frame call, the GUI's path, is listed too), "
        "levels interleaved per trajectory, after a warm-up call (set-up time listed "
        "separately); the pipeline's per-frame generators and reflectors are built outside "
        "the timing for every level; exact* = exact with the second noise seed, the "
        "yardstick for the distances",
        "levels": result_levels,
    }
    render(out, quick=quick)
    return out

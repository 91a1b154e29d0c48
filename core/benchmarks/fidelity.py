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
false detections per frame; the tracking loss (eq. 14) of the same tracker parameters on each
level's data set for the CV and CA models, with the run time of one trial.

Writes ``docs/fidelity/results.md`` and ``docs/fidelity/error_vs_runtime.png`` (``--quick``:
``bench/results/fidelity-quick.*``).
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

#: trajectories per class (a-e) in the full and the quick run
PER_CLASS = 3
PER_CLASS_QUICK = 1
QUICK_FRAMES = 60
#: noise seeds per level (the tracking loss is heavy-tailed: one frame on a clutter track moves
#: a trajectory's loss by ~1e-3)
N_SEEDS = 4
N_SEEDS_QUICK = 2
#: noise seed offset of the second exact run
OTHER_SEED = 1_000_003


def _ks(a: np.ndarray, b: np.ndarray) -> float | None:
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
    # the pipeline's reflector builder (private: the bench needs the frames without simulating)
    refl = pipeline._Reflectors.build(scene, p, seed, antenna, settings)
    frames = [refl.frame(f)[0] for f in range(scene.n_frames)]
    return frames, antenna, settings, p.elevation, refl


def run(quick: bool = False) -> dict:
    """Run every level on the same scenes; returns JSON-ready figures (see module docstring)."""
    from core import pipeline
    from core.dataset import Dataset
    from core.evaluation import evaluate
    from core.scene import paper_scenes
    from core.simulation import FIDELITY_LEVELS
    from core.tracking import TrackerParams, track_dataset

    per_class = PER_CLASS_QUICK if quick else PER_CLASS
    n_seeds = N_SEEDS_QUICK if quick else N_SEEDS
    scenes = paper_scenes(0, 5 * per_class)
    levels = list(FIDELITY_LEVELS)
    runs = [(name, s) for s in range(n_seeds) for name in levels]
    acc = {
        run: {"cpu_s": 0.0, "frames": 0, "clouds": [], "err": [], "snr": [], "hit": []}
        for run in runs
    }
    truth = {"xy": [], "v": [], "t": [], "traj": [], "cls": []}
    setup_s = {}
    for k, scene in enumerate(scenes):
        frames, antenna, settings, elevation, refl = _frames(scene, scene.seed)
        n_f = min(QUICK_FRAMES, len(frames)) if quick else len(frames)
        radar = scene.radar
        t_mid = 0.5 * radar.n_loops * radar.n_tx * radar.chirp_period_s
        if k == 0:
            # one-time set-up (compilation, tables, the false-alarm pool) is not frame time
            for name in levels:
                t0 = time.process_time()
                FIDELITY_LEVELS[name](
                    radar, frames[0], np.random.default_rng(0), antenna=antenna,
                    settings=settings, elevation=elevation,
                )  # fmt: skip
                setup_s[name] = time.process_time() - t0
        for run in runs:
            name, s = run
            simulate = FIDELITY_LEVELS[name]
            a = acc[run]
            noise_seed = scene.seed + s * OTHER_SEED
            for f in range(n_f):
                sc = frames[f]
                rng = pipeline.stage_rng(noise_seed, "noise", f)
                t0 = time.process_time()
                out = simulate(
                    radar, sc, rng, antenna=antenna, settings=settings, elevation=elevation
                )
                a["cpu_s"] += time.process_time() - t0
                a["frames"] += 1
                pc = out.point_cloud
                a["clouds"].append(pc)
                a["hit"].append(bool(np.any(pc.source == 0)))
                person = np.flatnonzero(sc.source == 0)
                if person.size:
                    i = person[0]
                    pos = sc.position_m[i] + sc.velocity_mps[i] * t_mid
                    r = np.linalg.norm(pos)
                    az = np.arctan2(pos[0], pos[1])
                    vr = pos @ sc.velocity_mps[i] / r
                    for j in np.flatnonzero(pc.source == 0):
                        a["err"].append(
                            (
                                pc.range_m[j] - r,
                                pc.azimuth_rad[j] - az,
                                pc.radial_velocity_mps[j] - vr,
                            )
                        )
                        a["snr"].append(pc.snr_db[j])
        truth["xy"].append(refl.truth_xy_m[:n_f])
        truth["v"].append(refl.truth_v_mps[:n_f])
        truth["t"].append(refl.truth_t_s[:n_f])
        truth["traj"].append(np.full(n_f, k, dtype=np.int32))
        truth["cls"].append(scene.trajectory_class)

    # data sets and tracking: the same parameters on every level's point clouds
    params = {m: TrackerParams.default(m) for m in ("cv", "ca")}
    tracking = {}
    for run in runs:
        a = acc[run]
        ds = Dataset.from_frames(
            clouds=a["clouds"],
            trajectory=np.concatenate(truth["traj"]),
            truth_t_s=np.concatenate(truth["t"]),
            truth_xy_m=np.concatenate(truth["xy"]),
            truth_v_mps=np.concatenate(truth["v"]),
            trajectory_class=truth["cls"],
            scene_json=json.dumps([s.to_dict() for s in scenes]),
            radar_json=json.dumps(scenes[0].radar.to_dict()),
            fidelity=run[0],
            seed=run[1],
        )
        for model, prm in params.items():
            if not tracking:
                track_dataset(ds, prm)  # compile the tracker outside the timing
            t0 = time.process_time()
            ev = evaluate(ds, track_dataset(ds, prm))
            dt = time.process_time() - t0
            tracking[(run, model)] = {
                "loss_x1e3": 1e3 * ev.loss_total,
                "median_trajectory_loss_x1e3": 1e3 * float(np.median(ev.loss)),
                "mse_mean_m2": float(np.nanmean(ev.mse)),
                "n_c_mean": float(np.mean(ev.n_c)),
                "rmse_m": ev.rmse_m,
                "confirmed_fraction": ev.confirmed_fraction,
                "far_frames": int(ev.far_frames_total),
                "track_cpu_s": dt,
            }

    exact = acc[("exact", 0)]
    exact_fps = exact["frames"] / exact["cpu_s"]
    rows = [(name, 0) for name in levels] + ([("exact", 1)] if n_seeds > 1 else [])
    result_levels = {}
    for run in rows:
        name, s = run
        a = acc[run]
        err = np.asarray(a["err"]).reshape(-1, 3)
        ex = np.asarray(exact["err"]).reshape(-1, 3)
        snr, ex_snr = np.asarray(a["snr"]), np.asarray(exact["snr"])
        n_frames = a["frames"]
        src = np.concatenate([c.source for c in a["clouds"]])
        cpu_level = [acc[(name, t)]["cpu_s"] for t in range(n_seeds)]
        fps = sum(acc[(name, t)]["frames"] for t in range(n_seeds)) / sum(cpu_level)
        trk = {}
        for model in params:
            per_seed = [tracking[((name, t), model)] for t in range(n_seeds)]
            losses = [p["loss_x1e3"] for p in per_seed]
            trk[model] = {
                "loss_x1e3_per_seed": losses,
                "loss_x1e3_mean": float(np.mean(losses)),
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

        def dist(x: np.ndarray) -> dict:
            if not len(x):
                return {"mean": None, "sd": None, "p05": None, "p95": None}
            return {
                "mean": float(np.mean(x)),
                "sd": float(np.std(x)),
                "p05": float(np.percentile(x, 5)),
                "p95": float(np.percentile(x, 95)),
            }

        label = name if s == 0 else "exact*"
        result_levels[label] = {
            "frames": n_frames,
            "cpu_s_per_seed": cpu_level,
            "setup_cpu_s": setup_s[name],
            "fps": fps,
            "speedup": fps / exact_fps if s == 0 else 1.0,
            "person_pd": float(np.mean(a["hit"])),
            "range_error_m": {**dist(err[:, 0]), "ks": _ks(err[:, 0], ex[:, 0])},
            "azimuth_error_deg": {
                **dist(np.degrees(err[:, 1])),
                "ks": _ks(err[:, 1], ex[:, 1]),
            },
            "radial_velocity_error_mps": {**dist(err[:, 2]), "ks": _ks(err[:, 2], ex[:, 2])},
            "snr_db": {**dist(snr), "ks": _ks(snr, ex_snr)},
            "clutter_points_per_frame": float(np.sum(src == -1) / n_frames),
            "false_points_per_frame": float(np.sum(src == -2) / n_frames),
            "person_points_per_frame": float(np.sum(src >= 0) / n_frames),
            "tracking": trk,
        }
    out = {
        "scenes": f"paper_scenes(seed=0): first {len(scenes)} trajectories "
        f"({per_class} per class a-e)" + (f", first {QUICK_FRAMES} frames each" if quick else ""),
        "frames_per_level": exact["frames"],
        "noise_seeds": n_seeds,
        "tracker_parameters": "TrackerParams.default('cv') / ('ca') (no tuned parameters "
        "were committed on branch tune when this ran)",
        "timing": "process CPU time of the simulator call only, levels interleaved per "
        "trajectory, after a warm-up call (set-up time listed separately); exact* = exact "
        "with the second noise seed, the yardstick for the distances",
        "levels": result_levels,
    }
    target = Path("bench/results") if quick else Path("docs/fidelity")
    stem = "fidelity-quick" if quick else "results"
    target.mkdir(parents=True, exist_ok=True)
    _write_table(out, target / f"{stem}.md")
    _plot(out, target / ("fidelity-quick.png" if quick else "error_vs_runtime.png"))
    return out


def _fmt(v, spec: str = ".3g") -> str:
    return "–" if v is None else format(v, spec)


def _table(result: dict) -> str:
    lv = result["levels"]
    head = (
        "| level | frames/s | speed-up | Pd person | range err mean/sd (mm) | KS | "
        "az err mean/sd (°) | KS | vr err mean/sd (m/s) | KS | SNR mean (dB) | KS | "
        "clutter pts/frame | false pts/frame | loss CV ×1e-3 (seeds) | loss CA ×1e-3 (seeds) | "
        "median traj. loss CV / CA ×1e-3 | RMSE CV / CA (m) | trial CPU (s) |"
    )
    rows = [head, "|" + "---|" * 19]
    for name, r in lv.items():
        re, ae, ve, sn = (
            r["range_error_m"],
            r["azimuth_error_deg"],
            r["radial_velocity_error_mps"],
            r["snr_db"],
        )
        mean_mm = None if re["mean"] is None else 1e3 * re["mean"]
        sd_mm = None if re["sd"] is None else 1e3 * re["sd"]
        mm = f"{_fmt(mean_mm, '.2f')}/{_fmt(sd_mm, '.2f')}"
        rows.append(
            f"| {name} | {r['fps']:.0f} | {r['speedup']:.1f} | {r['person_pd']:.3f} | {mm} | "
            f"{_fmt(re['ks'], '.3f')} | {_fmt(ae['mean'], '.3f')}/{_fmt(ae['sd'], '.3f')} | "
            f"{_fmt(ae['ks'], '.3f')} | {_fmt(ve['mean'], '.4f')}/{_fmt(ve['sd'], '.4f')} | "
            f"{_fmt(ve['ks'], '.3f')} | {_fmt(sn['mean'], '.2f')} | {_fmt(sn['ks'], '.3f')} | "
            f"{r['clutter_points_per_frame']:.3f} | {r['false_points_per_frame']:.3f} | "
            + (
                "see exact | see exact | see exact | see exact | – |"
                if name == "exact*"
                else f"{_losses(r['tracking']['cv'])} | {_losses(r['tracking']['ca'])} | "
                f"{r['tracking']['cv']['median_trajectory_loss_x1e3']:.4f} / "
                f"{r['tracking']['ca']['median_trajectory_loss_x1e3']:.4f} | "
                f"{r['tracking']['cv']['rmse_m']:.3f} / {r['tracking']['ca']['rmse_m']:.3f} | "
                f"{r['tracking']['cv']['trial_cpu_s']:.2f} |"
            )
        )
    return "\n".join(rows)


def _losses(t: dict) -> str:
    seeds = ", ".join(f"{v:.3f}" for v in t["loss_x1e3_per_seed"])
    return f"{t['loss_x1e3_mean']:.3f} ({seeds})"


def _write_table(result: dict, path: Path) -> None:
    text = (
        "# Fidelity levels: error against run time\n\n"
        f"Command: `radartune bench fidelity` (writes this file, the plot and "
        f"`bench/results/fidelity.json`).\n\n"
        f"- Scenes: {result['scenes']}; {result['frames_per_level']} frames per level.\n"
        f"- Tracker: {result['tracker_parameters']}.\n"
        f"- Timing: {result['timing']}.\n"
        "- KS: two-sample Kolmogorov-Smirnov distance of the person's point errors to `exact`; "
        "`exact*` is the yardstick (same scenes, other noise).\n"
        "- Loss: eq. (14) on the level's own data set (×1e-3), mean over the noise seeds (each "
        "seed in brackets); trial CPU = simulation of the data set + one tracking run.\n\n"
        + _table(result)
        + "\n"
    )
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(text)
    tmp.replace(path)


def _plot(result: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import LogLocator, NullFormatter, ScalarFormatter

    lv = result["levels"]
    names = list(lv)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    # KS distances: every level against exact; exact* (exact, other noise) is the yardstick
    others = [n for n in names if n != "exact"]
    for key, label, mk in (
        ("range_error_m", "range error", "o"),
        ("azimuth_error_deg", "azimuth error", "s"),
        ("radial_velocity_error_mps", "radial-velocity error", "^"),
        ("snr_db", "SNR", "D"),
    ):
        pts = [(lv[n]["fps"], lv[n][key]["ks"]) for n in others if lv[n][key]["ks"] is not None]
        ax1.plot(*zip(*pts), mk, label=label, alpha=0.8)
    top = max(max(lv[n][k]["ks"] or 0 for k in ("range_error_m", "snr_db")) for n in others)
    for n in others:
        label = "exact*\n(other noise)" if n == "exact*" else n
        ax1.annotate(label, (lv[n]["fps"], 1.15 * top), ha="center", fontsize=8)
    for ax in (ax1, ax2):
        ax.set_xscale("log")
        ax.xaxis.set_major_formatter(ScalarFormatter())
        ax.xaxis.set_minor_locator(LogLocator(subs=(2, 5)))
        ax.xaxis.set_minor_formatter(NullFormatter())
    ax1.set_xlabel("frames per second (simulator CPU time)")
    ax1.set_ylabel("KS distance of the person's point errors to exact")
    ax1.set_ylim(0, 1.35 * top)
    ax1.set_title("point errors against run time")
    ax1.legend(fontsize=8, loc="lower right")
    names = [n for n in names if n != "exact*"]
    for model, mk in (("cv", "o"), ("ca", "s")):
        xs = np.array([lv[n]["tracking"][model]["trial_cpu_s"] for n in names])
        ys = np.array([lv[n]["tracking"][model]["loss_x1e3_mean"] for n in names])
        lo = ys - [min(lv[n]["tracking"][model]["loss_x1e3_per_seed"]) for n in names]
        hi = [max(lv[n]["tracking"][model]["loss_x1e3_per_seed"]) for n in names] - ys
        ax2.errorbar(xs, ys, yerr=[lo, hi], fmt=mk, capsize=3, label=model.upper(), alpha=0.8)
        if model == "cv":
            for n, x, y in zip(names, xs, ys):
                ax2.annotate(n, (x, y), textcoords="offset points", xytext=(6, 6), fontsize=8)
    ax2.set_xlabel("CPU time per trial: simulate the data set + track it (s)")
    ax2.set_ylabel("tracking loss L_t (×1e-3), mean and range over seeds")
    ax2.set_title("tracking loss against run time")
    ax2.legend(fontsize=8)
    fig.tight_layout()
    tmp = path.with_name(path.stem + ".tmp.png")
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    tmp.replace(path)


def summary(result: dict) -> str:
    """Terminal summary: the Markdown table."""
    return f"{result['scenes']}\n" + _table(result)

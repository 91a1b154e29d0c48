"""``radartune bench clouds``: person point clouds of each person model against a real recording.

Figures, all from :mod:`core.evaluation.clouds`:

- ``models``: per person model (every entry of :data:`core.scene.scene.PERSON_MODELS`) and per
  fidelity level (exact, fast, measurement), the cloud statistics per range band of the paper
  data set (seed 0, its first 10 trajectories, two per class; ``--quick``: 5), person points
  by their truth labels;
- ``real``: the same statistics of the RadHAR walking recording (IWR1443, one person walking in
  place ~1.7 m from the radar; ``../shared/real/radhar_walk``), person points by the rule of
  :func:`core.evaluation.clouds.rule_person_points` (within 1 m of the moving points' median);
- ``micro_doppler``: per model, one person walking straight away from the radar from 2 m at
  1.2 m/s (exact level): the spectrogram at the person's range
  (:func:`core.processing.micro_doppler.micro_doppler`) and the range-Doppler map of one frame
  around the person, for the plots.

:func:`render` writes the table (``docs/person-models/clouds.md``) and the plots
(``docs/person-models/*.png``) from the stored JSON (``radartune bench clouds --render-only``).
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from core.evaluation.clouds import (
    RANGE_BANDS_M,
    cloud_statistics,
    dataset_person_points,
    rule_person_points,
)
from core.files import save_figure, write_text_atomic

#: The RadHAR walking recording inside the real-data folder.
RADHAR_WALK = Path("radhar_walk") / "__20_walk_6.txt"
#: The levels compared per model.
LEVELS = ("exact", "fast", "measurement")
#: The micro-Doppler scene: start (m), velocity (m/s), frames.
MD_START_M = (0.3, 2.0)
MD_VELOCITY_MPS = (0.0, 1.2)
MD_FRAMES = 60
#: Range bins either side of the person's bin in the RD-map crop stored for the plot.
RD_CROP_BINS = 14


def real_data_dir() -> Path:
    """The folder of real recordings.

    ``$RADARTUNE_REAL_DATA`` (or ``$RADARTUNE_REAL``) if set, else the first of
    ``<repo>/../shared/real`` and ``<repo>/../../shared/real`` that exists (a worktree sits one
    level deeper than the main checkout). The one place every benchmark finds them.
    """
    env = os.environ.get("RADARTUNE_REAL_DATA") or os.environ.get("RADARTUNE_REAL")
    if env:
        return Path(env)
    repo = Path(__file__).resolve().parents[2]
    for cand in (repo.parent / "shared" / "real", repo.parent.parent / "shared" / "real"):
        if cand.is_dir():
            return cand
    return repo.parent / "shared" / "real"


def _bands(stats: list) -> list[dict]:
    return [b.to_dict() for b in stats]


def real_statistics(path: str | os.PathLike | None = None) -> dict:
    """Cloud statistics of the RadHAR walking recording (person points by the 1 m rule)."""
    from core.formats.ros_pointcloud import read_ros_pointcloud

    path = Path(path) if path is not None else real_data_dir() / RADHAR_WALK
    pc = read_ros_pointcloud(path)
    pts = rule_person_points(
        pc.frame,
        pc.x_m,
        pc.y_m,
        pc.radial_velocity_mps,
        pc.n_frames,
        snr_db=pc.intensity_db,
    )
    counts = np.diff(pc.frame_offsets)
    return {
        "file": str(RADHAR_WALK),
        "frames": pc.n_frames,
        "points_per_frame_all": float(counts.mean()),
        "frame_rate_hz": float((pc.n_frames - 1) / (pc.t_s[-1] - pc.t_s[0])),
        "velocity_step_mps": float(
            np.min(np.abs(pc.radial_velocity_mps[pc.radial_velocity_mps != 0]))
        ),
        "reference_median_xy_m": np.median(pts.reference_xy_m, axis=0).tolist(),
        "rule": "points within 1 m of the median (x, y) of the frame's moving points "
        "(velocity != 0); a frame without moving points keeps the last median",
        "snr_is": "the driver's intensity (dB, its own reference), not comparable in level",
        "bands": _bands(cloud_statistics(pts)),
    }


def model_statistics(model: str, fidelity: str, n_trajectories: int, jobs: int | None) -> dict:
    """Cloud statistics of the paper data set (seed 0) with one person model at one level."""
    from core.pipeline import paper_dataset

    ds = paper_dataset(0, n_trajectories, fidelity=fidelity, jobs=jobs, person_model=model)
    return {
        "frames": ds.n_frames,
        "bands": _bands(cloud_statistics(dataset_person_points(ds))),
    }


def micro_doppler_run(model: str) -> dict:
    """Spectrogram and one RD-map crop of a person walking away from the radar (exact level)."""
    from core.pipeline import simulate_scene
    from core.processing.micro_doppler import micro_doppler
    from core.scene.scene import Scene

    scene = Scene.from_dict(
        {
            "schema_version": 1,
            "radar": "paper",
            "seed": 2,
            "clutter_density_per_m2": 0.0,
            "persons": [
                {
                    "model": model,
                    "trajectory": {
                        "initial_position_m": list(MD_START_M),
                        "initial_velocity_mps": list(MD_VELOCITY_MPS),
                        "acceleration_mps2": [0.0, 0.0],
                        "frames": MD_FRAMES,
                    },
                }
            ],
        }
    )
    run = simulate_scene(scene, keep_rd_maps=True)
    assert run.rd_maps_db is not None
    rng = np.hypot(run.truth_xy_m[:, 0, 0], run.truth_xy_m[:, 0, 1])
    md = micro_doppler(run.rd_maps_db, rng, scene.radar)
    f = MD_FRAMES // 2
    c = int(md.range_bin[f])
    lo, hi = max(c - RD_CROP_BINS, 0), c + RD_CROP_BINS + 1
    return {
        "frame_period_s": scene.radar.frame_period_s,
        "range_resolution_m": scene.radar.range_resolution_m,
        "velocity_mps": md.velocity_mps.round(4).tolist(),
        "spectrogram_db": np.round(md.power_db, 2).tolist(),
        "torso_radial_velocity_mps": float(
            np.dot(MD_VELOCITY_MPS, np.array(MD_START_M) / np.hypot(*MD_START_M))
        ),
        "rd_frame": f,
        "rd_first_bin": lo,
        "rd_crop_db": np.round(run.rd_maps_db[f, lo:hi], 2).tolist(),
        "doppler_extent": doppler_extent(md.power_db, md.velocity_mps),
    }


def doppler_extent(power_db: np.ndarray, velocity_mps: np.ndarray, below_db: float = 15.0) -> dict:
    """How far the spectrogram reaches in velocity: per frame, the largest ``|v|`` whose power
    is within ``below_db`` of the frame's peak, against the peak's ``|v|`` (medians and the
    95th percentile over frames)."""
    p = np.asarray(power_db, dtype=np.float64)
    ok = np.all(np.isfinite(p), axis=1)
    p = p[ok]
    peak = np.abs(velocity_mps[np.argmax(p, axis=1)])
    reach = np.array([np.max(np.abs(velocity_mps[row >= row.max() - below_db])) for row in p])
    return {
        "below_peak_db": below_db,
        "peak_abs_velocity_median_mps": float(np.median(peak)),
        "reach_abs_velocity_median_mps": float(np.median(reach)),
        "reach_abs_velocity_p95_mps": float(np.percentile(reach, 95)),
    }


#: The grid of merge cells (range bins, Doppler bins, beams) the fit tries.
FIT_GRID = tuple((k_r, k_d, 1.0) for k_r in (1.0, 2.0, 3.0, 4.0) for k_d in (1.0, 2.0, 3.0))


def fit_merge_cells(models: tuple[str, ...], n_trajectories: int, jobs: int | None) -> dict:
    """The measurement level's merge cells fitted to the exact level's points per person-frame.

    For each cell size of :data:`FIT_GRID`, the measurement level's mean points per person-frame
    per range band against the exact level's, for every many-scatterer model; the figure of
    merit is the RMS over bands and models of ``ln(points_measurement / points_exact)``. The
    chosen cells are :data:`core.simulation.body_cells.MERGE_CELLS` (set by hand from this
    table; the bench reports whether it is still the best).
    """
    from core.pipeline import paper_dataset
    from core.simulation import body_cells

    def points(ds) -> np.ndarray:
        return np.array([b.points_mean for b in cloud_statistics(dataset_person_points(ds))])

    exact = {m: points(paper_dataset(0, n_trajectories, jobs=jobs, person_model=m)) for m in models}
    chosen = body_cells.MERGE_CELLS
    rows: list[dict] = []
    try:
        for cells in FIT_GRID:
            body_cells.MERGE_CELLS = cells
            errs = []
            per_model = {}
            for m in models:
                ds = paper_dataset(
                    0,
                    n_trajectories,
                    fidelity="measurement",
                    jobs=1,
                    person_model=m,
                    use_cache=False,
                )
                p = points(ds)
                per_model[m] = p.round(3).tolist()
                ok = np.isfinite(p) & np.isfinite(exact[m])
                errs.extend(np.log(p[ok] / exact[m][ok]).tolist())
            rows.append(
                {
                    "cells": list(cells),
                    "rms_log_ratio": float(np.sqrt(np.mean(np.square(errs)))),
                    "points": per_model,
                }
            )
    finally:
        body_cells.MERGE_CELLS = chosen
    best = min(rows, key=lambda r: float(r["rms_log_ratio"]))
    return {
        "exact_points": {m: v.round(3).tolist() for m, v in exact.items()},
        "grid": rows,
        "best": best["cells"],
        "chosen": list(chosen),
    }


def run(quick: bool = False, jobs: int | None = 1) -> dict:
    from core.scene.scene import PERSON_MODELS

    n_traj = 5 if quick else 10
    models = {}
    for model in PERSON_MODELS:
        models[model] = {level: model_statistics(model, level, n_traj, jobs) for level in LEVELS}
    many = tuple(m for m in PERSON_MODELS if m != "point")
    fit = fit_merge_cells(many, n_traj, jobs)
    md = {model: micro_doppler_run(model) for model in PERSON_MODELS}
    try:
        real = real_statistics()
    except Exception as exc:  # noqa: BLE001 (the recording is optional: say why it is missing)
        real = {"missing": f"{type(exc).__name__}: {exc}"}
    result = {
        "dataset": f"paper data set, seed 0, {n_traj} trajectories",
        "range_bands_m": [list(b) for b in RANGE_BANDS_M],
        "models": models,
        "real": real,
        "micro_doppler": md,
        "merge_fit": fit,
    }
    render(result, quick=quick)
    return result


# ---- report -----------------------------------------------------------------------------------


def report_dir(quick: bool = False) -> Path:
    return Path("bench/results/clouds-quick") if quick else Path("docs/person-models")


def _f(v, spec: str = ".2f") -> str:
    return "–" if v is None or (isinstance(v, float) and math.isnan(v)) else format(v, spec)


def table(result: dict, level: str = "exact") -> str:
    """Markdown: one row per (band, model) at ``level``, and the real recording's rows."""
    head = (
        "| band (m) | cloud | points/person/frame mean (median) | frames with 0 | "
        "spread x, y (m) | RMS about truth x, y (m) | Doppler std (m/s) | SNR median (dB) |\n"
        "|---|---|---|---|---|---|---|---|"
    )
    rows = [head]
    real = result["real"]
    for i, (lo, hi) in enumerate(result["range_bands_m"]):
        entries = [(m, r[level]["bands"][i]) for m, r in result["models"].items()]
        if "bands" in real:
            entries.append(("RadHAR walk (real, IWR1443)", real["bands"][i]))
        for name, b in entries:
            if not b["person_frames"]:
                continue
            truth = (
                f"{_f(b['rms_x_ref_m'])}, {_f(b['rms_y_ref_m'])}"
                if b["reference_is_truth"]
                else "– (no truth)"
            )
            snr = _f(b["snr_median_db"], ".0f") + ("" if b["reference_is_truth"] else "*")
            count = f"{_f(b['points_mean'])} ({_f(b['points_median'], 'g')})"
            spread = f"{_f(b['spread_x_m'])}, {_f(b['spread_y_m'])}"
            rows.append(
                f"| {lo:g}–{hi:g} | {name} | {count} | {_f(b['empty_fraction'], '.0%')} "
                f"| {spread} | {truth} | {_f(b['doppler_std_mps'])} | {snr} |"
            )
    return "\n".join(rows)


def level_table(result: dict) -> str:
    """Markdown: per model and band, points/frame, spread and Doppler std at each level."""
    rows = [
        "| cloud | band (m) | points/frame exact, fast, measurement | spread x exact, fast, "
        "meas. (m) | Doppler std exact, fast, meas. (m/s) |",
        "|---|---|---|---|---|",
    ]
    for model, r in result["models"].items():
        for i, (lo, hi) in enumerate(result["range_bands_m"]):
            bs = [r[lv]["bands"][i] for lv in LEVELS if lv in r]
            if not bs[0]["person_frames"]:
                continue
            rows.append(
                f"| {model} | {lo:g}–{hi:g} | "
                + " | ".join(
                    ", ".join(_f(b[k], spec) for b in bs)
                    for k, spec in (
                        ("points_mean", ".2f"),
                        ("spread_x_m", ".3f"),
                        ("doppler_std_mps", ".2f"),
                    )
                )
                + " |"
            )
    return "\n".join(rows)


def fit_table(result: dict) -> str:
    """Markdown: the merge-cell fit of the measurement level (points per person-frame)."""
    fit = result.get("merge_fit")
    if not fit:
        return ""
    models = list(fit["exact_points"])
    rows = [
        "Measurement level: merge cells (range bins, Doppler bins, beams) against the exact "
        "level's points per person-frame (bands 1–3, 3–6, 6–10 m); chosen "
        f"{tuple(fit['chosen'])}, best of the grid {tuple(fit['best'])}.",
        "",
        "| cells | RMS ln(meas./exact) | " + " | ".join(models) + " |",
        "|---|---|" + "---|" * len(models),
        "| exact | – | "
        + " | ".join(", ".join(_f(v) for v in fit["exact_points"][m]) for m in models)
        + " |",
    ]
    for r in fit["grid"]:
        cells = ", ".join(f"{c:g}" for c in r["cells"])
        pts = " | ".join(", ".join(_f(v) for v in r["points"][m]) for m in models)
        rows.append(f"| {cells} | {r['rms_log_ratio']:.3f} | {pts} |")
    return "\n".join(rows)


def extent_table(result: dict) -> str:
    """Markdown: how far each model's spectrogram reaches in velocity."""
    rows = [
        "Micro-Doppler (one person walking away at 1.2 m/s from 2 m, exact level): per frame the "
        "largest |v| within 15 dB of the frame's peak.",
        "",
        "| model | peak |v| median (m/s) | reach median (m/s) | reach 95th pct. (m/s) |",
        "|---|---|---|---|",
    ]
    for m, r in result["micro_doppler"].items():
        e = r["doppler_extent"]
        rows.append(
            f"| {m} | {e['peak_abs_velocity_median_mps']:.2f} | "
            f"{e['reach_abs_velocity_median_mps']:.2f} | {e['reach_abs_velocity_p95_mps']:.2f} |"
        )
    return "\n".join(rows)


def render(result: dict, quick: bool = False) -> list[Path]:
    """Write ``clouds.md`` (tables), ``micro_doppler.png`` and ``rd_map.png``."""
    out = report_dir(quick)
    out.mkdir(parents=True, exist_ok=True)
    md = out / "clouds.md"
    real = result["real"]
    note = (
        f"Real: {real['file']}, {real['frames']} frames; person points: {real['rule']}. "
        f"*SNR of the real recording: {real['snr_is']}. Its velocity step is "
        f"{real['velocity_step_mps']:.2f} m/s."
        if "bands" in real
        else f"Real recording missing: {real['missing']}"
    )
    text = (
        "<!-- written by `radartune bench clouds` (core/benchmarks/clouds.py); do not edit -->\n"
        f"Person clouds per range band, exact level, {result['dataset']}.\n\n"
        + table(result)
        + f"\n\n{note}\n\nThe same figures at each fidelity level:\n\n"
        + level_table(result)
        + "\n\n"
        + fit_table(result)
        + "\n\n"
        + extent_table(result)
        + "\n"
    )
    write_text_atomic(md, text)
    return [md, *_plot(result, out)]


def _plot(result: dict, out: Path) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    mds = result["micro_doppler"]
    names = list(mds)
    written = []
    fig, axes = plt.subplots(
        1, len(names), figsize=(3.6 * len(names) + 1, 3.6), squeeze=False, layout="constrained"
    )
    fig.suptitle("Doppler at the person's range (exact chain; dashed: the trajectory's speed)")
    for ax, name in zip(axes[0], names):
        r = mds[name]
        p = np.array(r["spectrogram_db"], dtype=float)
        v = np.array(r["velocity_mps"])
        t = np.arange(p.shape[0]) * r["frame_period_s"]
        top = np.nanmax(p)
        dv = v[1] - v[0]
        im = ax.imshow(
            p.T,
            origin="lower",
            aspect="auto",
            extent=(t[0], t[-1] + r["frame_period_s"], v[0] - dv / 2, v[-1] + dv / 2),
            vmin=top - 40,
            vmax=top,
            cmap="viridis",
        )
        ax.axhline(r["torso_radial_velocity_mps"], color="w", lw=0.6, ls="--")
        ax.set_title(name)
        ax.set_ylim(-6, 6)
        ax.set_xlabel("time (s)")
        ax.set_ylabel("radial velocity (m/s)")
    fig.colorbar(im, ax=axes[0].tolist(), label="power (dB)")
    written.append(save_figure(fig, out / "micro_doppler.png"))
    plt.close(fig)

    fig, axes = plt.subplots(
        1, len(names), figsize=(3.6 * len(names) + 1, 3.6), squeeze=False, layout="constrained"
    )
    fig.suptitle("Range-Doppler map of a person walking away at 1.2 m/s (one frame)")
    for ax, name in zip(axes[0], names):
        r = mds[name]
        crop = np.array(r["rd_crop_db"], dtype=float)
        v = np.array(r["velocity_mps"])
        dr = r["range_resolution_m"]
        r0 = r["rd_first_bin"] * dr
        dv = v[1] - v[0]
        top = np.nanmax(crop)
        im = ax.imshow(
            crop,
            origin="lower",
            aspect="auto",
            extent=(v[0] - dv / 2, v[-1] + dv / 2, r0 - dr / 2, r0 + (len(crop) - 0.5) * dr),
            vmin=top - 40,
            vmax=top,
            cmap="viridis",
        )
        ax.set_title(name)
        ax.set_xlim(-6, 6)
        centre = (r["rd_first_bin"] + RD_CROP_BINS) * dr
        ax.set_ylim(centre - 0.5, centre + 0.5)
        ax.set_xlabel("radial velocity (m/s)")
        ax.set_ylabel("range (m)")
    fig.colorbar(im, ax=axes[0].tolist(), label="power (dB)")
    written.append(save_figure(fig, out / "rd_map.png"))
    plt.close(fig)
    return written


def summary(result: dict) -> str:
    lines = ["person clouds, exact level (points/person/frame mean; spread x m; Doppler std m/s):"]
    for i, (lo, hi) in enumerate(result["range_bands_m"]):
        cells = []
        for m, r in result["models"].items():
            b = r["exact"]["bands"][i]
            cells.append(
                f"{m} {_f(b['points_mean'])}; {_f(b['spread_x_m'])}; {_f(b['doppler_std_mps'])}"
            )
        real = result["real"]
        if "bands" in real and real["bands"][i]["person_frames"]:
            b = real["bands"][i]
            cells.append(
                f"real {_f(b['points_mean'])}; {_f(b['spread_x_m'])}; {_f(b['doppler_std_mps'])}"
            )
        lines.append(f"  {lo:g}-{hi:g} m: " + " | ".join(cells))
    for m, r in result["micro_doppler"].items():
        e = r["doppler_extent"]
        lines.append(
            f"  micro-Doppler {m}: peak |v| {e['peak_abs_velocity_median_mps']:.2f} m/s, reach "
            f"{e['reach_abs_velocity_median_mps']:.2f} (p95 {e['reach_abs_velocity_p95_mps']:.2f})"
        )
    return "\n".join(lines)


def cloud_frames(scene, the_plan, n: int, *, path_order: bool = False) -> list[dict]:
    """The first ``n`` frames of ``scene`` simulated through ``the_plan``, each a dict of the
    point cloud's arrays x, y, z, v, snr (and ``path_order`` when asked)."""
    from core.pipeline.frames import iter_frames

    out = []
    for fr in iter_frames(scene, the_plan=the_plan, frames=range(n)):
        pc = fr.point_cloud
        frame: dict[str, Any] = {
            "x": pc.x_m,
            "y": pc.y_m,
            "z": pc.z_m,
            "v": pc.radial_velocity_mps,
            "snr": pc.snr_db,
        }
        if path_order:
            frame["path_order"] = pc.path_order
        out.append(frame)
    return out

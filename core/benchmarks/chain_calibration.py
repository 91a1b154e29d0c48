"""Point statistics of TI's chains, simulated, against recordings made with that kind of chain.

``radartune bench chain_calibration``: a walking body (the default person model) walks back and
forth between 1.5 and 6 m in front of the radar, simulated through each chain with its own
radar (``resources/radar``), no walls (the open field), and for ``people-counting`` also between
0.6 and 2.2 m (:data:`NEAR`, where the recordings' people are); the recordings are read with the
project's readers. The same estimator is applied to both, since the recordings have no truth:
per frame, the *person* is the moving points (|v| > 0.05 m/s) within 1 m (x-y) of their
median; of them the count, the spread (standard deviation) in x, y and z (z also by the
person's range band, since at a given angular spread it grows with range), the spread of the
elevation angle ``asin(z / r)``, the person's median range, the
Doppler spread and the median SNR; of all points, the zero-Doppler fraction by range band and
the share of zero-Doppler points that recur in the next frame; of the moving points, the ghost
fraction (:mod:`core.benchmarks.wall_loss`). Distributions over frames as median, p10, p90.

Recordings used (``../shared/real``): the 2023 people-counting file (IWR6843ISK, TI's firmware
with static detection; SNR linear in the file) for ``people-counting``; the RadHAR walker
(IWR1443BOOST, TI's out-of-box style chain through the ROS driver; intensity, not SNR) and the
three mmgait walkers (IWR6843, out-of-box style; scores only are kept, the recordings have no
licence) for ``oob``. The walls' loss is fitted on the mmgait walker 002 and checked on the
others (:func:`wall_fit`, docs/decisions/rooms-02-fitted-wall-loss.md).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from core.benchmarks.clouds import cloud_frames, real_data_dir

ROOT = Path(__file__).resolve().parents[2]
RANGE_BANDS_M = ((0.0, 2.0), (2.0, 4.0), (4.0, 6.0), (6.0, 10.0))
MOVING_MPS = 0.05
#: A point is at the edge of the elevation field of view (``fovCfg`` 20 deg in TI's people
#: counting cfgs; its search grid ends at 18-19.5 deg) from this elevation on, deg.
EDGE_DEG = 18.0


def _q(values: list[float] | np.ndarray) -> dict:
    v = np.asarray(values, dtype=np.float64)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return {"median": None, "p10": None, "p90": None, "n": 0}
    p10, med, p90 = np.percentile(v, [10, 50, 90])
    return {"median": float(med), "p10": float(p10), "p90": float(p90), "n": int(v.size)}


def frame_stats(frames: list[dict]) -> dict:
    """Statistics over frames; each frame a dict of arrays x, y, z, v, snr (SNR may be NaN)."""
    from core.benchmarks.wall_loss import ghost_fraction

    n_person, sx, sy, sz, sv, snr = [], [], [], [], [], []
    # the elevation spread (deg) and the person's range: z spread grows with range at a given
    # angular spread, so z is compared by range band too
    sel, rng_p, edge = [], [], [0, 0, 0]
    sz_band: dict[str, list[float]] = {f"{lo:g}-{hi:g} m": [] for lo, hi in RANGE_BANDS_M}
    zero = {f"{lo:g}-{hi:g} m": [0, 0] for lo, hi in RANGE_BANDS_M}
    for f in frames:
        x, y, z, v = f["x"], f["y"], f["z"], f["v"]
        r = np.sqrt(x**2 + y**2 + z**2)
        for lo, hi in RANGE_BANDS_M:
            band = (r >= lo) & (r < hi)
            zero[f"{lo:g}-{hi:g} m"][0] += int(np.sum(band & (v == 0.0)))
            zero[f"{lo:g}-{hi:g} m"][1] += int(np.sum(band))
        moving = np.abs(v) > MOVING_MPS
        if not moving.any():
            n_person.append(0)
            continue
        cx, cy = np.median(x[moving]), np.median(y[moving])
        near = moving & (np.hypot(x - cx, y - cy) < 1.0)
        n_person.append(int(near.sum()))
        if near.sum() >= 2:
            sx.append(np.std(x[near]))
            sy.append(np.std(y[near]))
            sz.append(np.std(z[near]))
            sv.append(np.std(v[near]))
            with np.errstate(invalid="ignore", divide="ignore"):
                el = np.degrees(np.arcsin(np.clip(z[near] / r[near], -1.0, 1.0)))
            sel.append(np.std(el))
            edge[0] += int(np.sum(el >= EDGE_DEG))
            edge[1] += int(np.sum(el <= -EDGE_DEG))
            edge[2] += int(near.sum())
            rng_p.append(float(np.median(r[near])))
            for lo, hi in RANGE_BANDS_M:
                if lo <= rng_p[-1] < hi:
                    sz_band[f"{lo:g}-{hi:g} m"].append(float(np.std(z[near])))
        snr.append(np.nanmedian(f["snr"][near]) if np.isfinite(f["snr"][near]).any() else np.nan)
    return {
        "frames": len(frames),
        "points_per_frame": _q([len(f["x"]) for f in frames]),
        "person_points_per_frame": _q(n_person),
        "spread_x_m": _q(sx),
        "spread_y_m": _q(sy),
        "spread_z_m": _q(sz),
        "spread_elevation_deg": _q(sel),
        "person_range_m": _q(rng_p),
        "spread_z_by_range_m": {k: _q(v) for k, v in sz_band.items()},
        # shares of the person's points at the top / bottom edge of a +-20 deg elevation view
        "elevation_edge_share": (
            {"top": edge[0] / edge[2], "bottom": edge[1] / edge[2]} if edge[2] else None
        ),
        "doppler_spread_mps": _q(sv),
        "person_snr_db": _q(snr),
        "zero_doppler_fraction": {k: (c[0] / c[1] if c[1] else None) for k, c in zero.items()},
        "ghost_fraction": ghost_fraction(frames),
        "static_recurring_fraction": static_recurrence(frames),
        # simulated only: the share of points that came by a wall bounce
        "bounce_share": (
            float(np.mean(np.concatenate([f["path_order"] for f in frames]) > 0))
            if frames and all(f.get("path_order") is not None for f in frames)
            else None
        ),
    }


#: A zero-Doppler point recurs when the next frame has one within this distance (x-y).
RECUR_M = 0.2


def static_recurrence(frames: list[dict]) -> float | None:
    """The share of zero-Doppler points with a zero-Doppler point of the next frame within
    :data:`RECUR_M` (x-y): furniture and still people recur, false alarms mostly do not."""
    from scipy.spatial import cKDTree

    hit = total = 0
    for a, b in zip(frames[:-1], frames[1:]):
        sa, sb = a["v"] == 0.0, b["v"] == 0.0
        total += int(sa.sum())
        if sa.any() and sb.any():
            d, _ = cKDTree(np.column_stack((b["x"][sb], b["y"][sb]))).query(
                np.column_stack((a["x"][sa], a["y"][sa]))
            )
            hit += int(np.sum(d < RECUR_M))
    return hit / total if total else None


def _frames_of_cloud(pc, counts) -> list[dict]:
    out, start = [], 0
    for n in np.asarray(counts, dtype=np.int64):
        sl = slice(start, start + int(n))
        out.append(
            {
                "x": np.asarray(pc.x_m[sl]),
                "y": np.asarray(pc.y_m[sl]),
                "z": np.asarray(pc.z_m[sl]),
                "v": np.asarray(pc.radial_velocity_mps[sl]),
                "snr": np.asarray(pc.snr_db[sl]),
            }
        )
        start += int(n)
    return out


#: The walker's waypoints: between 1.5 and 6 m, 15 deg off boresight; :data:`NEAR`: between
#: 0.6 and 2.2 m, the ranges of the people in the people-counting recordings (median 0.7 m).
FAR = ((0.4, 1.5, 1.1), (1.5, 6.0, 1.1), (0.4, 1.5, 1.1), (1.5, 6.0, 1.1))
NEAR = ((0.1, 0.6, 0.8), (0.5, 2.2, 0.8), (0.1, 0.6, 0.8), (0.5, 2.2, 0.8))


def walker_scene(cfg: Path, frames: int, seed: int, waypoints: tuple = FAR):
    """A walking body back and forth along ``waypoints`` (:data:`FAR` by default)."""
    from core.scene import Scene

    data = {
        "schema_version": 1,
        "radar": str(cfg),
        "seed": seed,
        "clutter_density_per_m2": 0.0,
        "aoi": {"min_range_m": 0.3, "max_range_m": 7.5, "max_azimuth_deg": 60.0},
        "persons": [
            {
                "model": "walking",
                "trajectory": {"waypoints": [list(w) for w in waypoints]},
            }
        ],
    }
    scene = Scene.from_dict(data, source="calibration walker")
    return scene, min(frames, scene.n_frames)


def simulated(cfg_name: str, frames: int, seed: int = 5, waypoints: tuple = FAR) -> dict:
    from core.formats.ti_cfg import read_ti_chain
    from core.pipeline import plan

    cfg = ROOT / "resources" / "radar" / cfg_name
    chain = read_ti_chain(cfg) if cfg_name != "paper.cfg" else None
    scene, n = walker_scene(cfg, frames, seed, waypoints)
    p = plan(scene, chain=chain) if chain is not None else plan(scene)
    return frame_stats(cloud_frames(scene, p, n))


def recorded_people_counting() -> dict | None:
    from core.formats.pointcloud_csv import read_people

    path = real_data_dir() / "pc3_iwr6843" / "pc3_2023-06-21-12-27-01.csv"
    if not path.exists():
        return None
    rec = read_people(path, None)
    return frame_stats(_frames_of_cloud(rec.cloud, rec.counts))


def recording_frames(rel: str) -> list[dict] | None:
    """The frames of a recording under :func:`real_data_dir` read with the project's readers
    (None when absent): dicts of arrays x, y, z, v, snr."""
    from core.formats.recording import to_dataset
    from core.recordings import read_recording

    path = real_data_dir() / rel
    if not path.exists():
        return None
    ds = to_dataset(read_recording(path, fmt=None, cfg=None), source_name=str(path))
    o = ds.frame_offsets
    cols = (ds.x_m, ds.y_m, ds.z_m, ds.radial_velocity_mps, ds.snr_db)
    return [
        dict(zip(("x", "y", "z", "v", "snr"), (np.asarray(c[o[i] : o[i + 1]]) for c in cols)))
        for i in range(len(o) - 1)
    ]


def recorded_radhar_frames() -> list[dict] | None:
    from core.formats.ros_pointcloud import read_ros_pointcloud

    path = real_data_dir() / "radhar_walk" / "__20_walk_6.txt"
    if not path.exists():
        return None
    ros = read_ros_pointcloud(path)
    frames: list[dict] = []
    for f in range(int(ros.frame.max()) + 1):
        sel = ros.frame == f
        frames.append(
            {
                "x": ros.x_m[sel],
                "y": ros.y_m[sel],
                "z": ros.z_m[sel],
                "v": ros.radial_velocity_mps[sel],
                "snr": np.full(int(sel.sum()), np.nan),
            }
        )
    return frames


def recorded_radhar() -> dict | None:
    frames = recorded_radhar_frames()
    return None if frames is None else frame_stats(frames)


MMGAIT = tuple(f"mmgait_walkers/room2_1p_fixed_60GHz_{k}.csv" for k in ("002", "022", "076"))
#: The recording the walls' loss is fitted on; the others are held out.
TRAIN = MMGAIT[0]
PC3 = "pc3_iwr6843/pc3_2023-06-21-12-27-01.csv"
#: The other people-counting recordings (the 2021 ISK file, the overhead AOP one): checks.
PC3_OTHERS = (
    "pc3_iwr6843/pc3_2021-12-19-21-25-28.csv",
    "pc3_iwr6843/pc3Aop2021-04-07-23-52-34.csv",
)
OOB_CFG = "oob_isk.cfg"
PC_CFG = "people_counting_isk_static.cfg"


def wall_fit(quick: bool = False) -> dict:
    """The walls' loss fitted on :data:`TRAIN`'s ghost fraction (:mod:`wall_loss`), the other
    recordings held out: each against the fitted walls simulated with fresh seeds, the ``oob``
    chain for the out-of-box walkers, the people-counting chain for ``pc3``."""
    from core.benchmarks import wall_loss as W

    seeds, check_seeds = ((1,), (3,)) if quick else ((1, 2), (3, 4))
    n = 30 if quick else None
    recs: dict = {}
    for rel in (*MMGAIT, PC3):
        fr = recording_frames(rel)
        if fr is not None:
            recs[rel] = {
                "ghost_fraction": W.ghost_fraction(fr),
                "interval": W.bootstrap_interval(fr),
            }
    radhar = recorded_radhar_frames()
    if radhar is not None:
        recs["radhar_walk/__20_walk_6.txt"] = {
            "ghost_fraction": W.ghost_fraction(radhar),
            "interval": W.bootstrap_interval(radhar),
        }
    out: dict = {"recordings": recs, "train": TRAIN}
    if TRAIN not in recs:
        return out
    oob = str(ROOT / "resources" / "radar" / OOB_CFG)
    pcc = str(ROOT / "resources" / "radar" / PC_CFG)
    out["curve"] = W.curve(oob, seeds, n)["rows"]
    train = recs[TRAIN]
    out["fit"] = W.fit(out["curve"], train["ghost_fraction"], tuple(train["interval"]))
    loss = out["fit"]["reflection_db"]
    if loss is None:
        return out

    def sim(cfg: str, db: float, ss: tuple[int, ...]) -> list[dict]:
        fr: list[dict] = []
        for seed in ss:
            fr += W.simulated_frames(W.fit_scene(cfg, db, seed), cfg, n)
        return fr

    fitted = sim(oob, loss, check_seeds)
    before = sim(oob, -6.0, check_seeds)
    out["oob_fitted"] = frame_stats(fitted)
    out["oob_before"] = frame_stats(before)
    pc_fitted = sim(pcc, loss, check_seeds[:1])
    pc_before = sim(pcc, -6.0, check_seeds[:1])
    out["pc_fitted"] = frame_stats(pc_fitted)
    out["pc_before"] = frame_stats(pc_before)
    held = {}
    for rel, r in recs.items():
        if rel == TRAIN or rel.startswith("radhar"):
            continue
        s = out["pc_fitted" if rel == PC3 else "oob_fitted"]["ghost_fraction"]
        lo, hi = r["interval"]
        held[rel] = {"simulated": s, "recorded": r["ghost_fraction"], "within": lo <= s <= hi}
    out["held_out"] = held
    return out


def run(quick: bool = False) -> dict:
    n = 20 if quick else 120
    fit = wall_fit(quick)
    result: dict[str, Any] = {
        "estimator": "person = moving points within 1 m (x-y) of their median",
        "wall_fit": fit,
        "people-counting": {
            "simulated, static chain on (people_counting_isk_static.cfg)": simulated(PC_CFG, n),
            "simulated, TI's file (static off)": simulated("people_counting_isk.cfg", n),
            "simulated, walker at 0.6-2.2 m (the recordings' ranges)": simulated(
                PC_CFG, n, waypoints=NEAR
            ),
            "recorded: pc3_2023 (IWR6843ISK, TI people counting)": recorded_people_counting(),
        },
        "oob": {
            "simulated (oob_isk.cfg)": simulated(OOB_CFG, n),
            "simulated, paper chain (paper.cfg)": simulated("paper.cfg", n),
            "recorded: RadHAR walk (IWR1443BOOST, out-of-box style)": recorded_radhar(),
        },
    }
    if "oob_fitted" in fit:
        result["people-counting"] = {
            "simulated in a room, walls -6 dB": fit["pc_before"],
            "simulated in a room, fitted walls": fit["pc_fitted"],
            **result["people-counting"],
        }
        result["oob"] = {
            "simulated in a room, walls -6 dB": fit["oob_before"],
            "simulated in a room, fitted walls": fit["oob_fitted"],
            **result["oob"],
        }
    for rel in PC3_OTHERS:
        fr = recording_frames(rel)
        if fr is not None:
            result["people-counting"][f"recorded: {Path(rel).stem}"] = frame_stats(fr)
    for rel in MMGAIT:
        fr = recording_frames(rel)
        if fr is not None:
            result["oob"][f"recorded: mmgait {rel[-7:-4]} (IWR6843, out-of-box style)"] = (
                frame_stats(fr)
            )
    if not quick:
        plot(result, ROOT / "docs" / "chains" / "calibration.png")
        plot_fit(fit, ROOT / "docs" / "chains" / "wall_loss_fit.png")
    return result


METRICS = (
    ("person_points_per_frame", "person points / frame"),
    ("spread_x_m", "spread x (m)"),
    ("spread_y_m", "spread y (m)"),
    ("spread_z_m", "spread z (m)"),
    ("spread_elevation_deg", "elevation spread (deg)"),
    ("person_range_m", "person's range (m)"),
    ("doppler_spread_mps", "Doppler spread (m/s)"),
)


def plot(result: dict, path: Path) -> Path:
    """Medians with p10-p90 bars of each metric, the ghost fraction, and the zero-Doppler
    fraction by range band; one row per chain kind, the runs numbered in its legend."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from core.files import save_figure

    kinds = ("people-counting", "oob")
    n_col = len(METRICS) + 2
    fig, axes = plt.subplots(len(kinds), n_col, figsize=(3.0 * n_col + 4.5, 7.5))
    for row, kind in enumerate(kinds):
        runs = {k: v for k, v in result[kind].items() if v is not None}
        ticks = np.arange(len(runs))
        for col, (key, title) in enumerate(METRICS):
            ax = axes[row, col]
            for i, s in enumerate(runs.values()):
                q = s[key]
                if q["median"] is None:
                    continue
                err = [[q["median"] - q["p10"]], [q["p90"] - q["median"]]]
                ax.errorbar([i], [q["median"]], yerr=err, fmt="o", capsize=4, color=f"C{i}")
            ax.set_xticks(ticks, [str(i + 1) for i in ticks])
            ax.set_title(title, fontsize=9)
        ax = axes[row, -2]
        g = [s.get("ghost_fraction") for s in runs.values()]
        ax.bar(ticks, [np.nan if v is None else v for v in g], color=[f"C{i}" for i in ticks])
        ax.set_xticks(ticks, [str(i + 1) for i in ticks])
        ax.set_title("ghost fraction (moving points)", fontsize=9)
        ax = axes[row, -1]
        bands = list(next(iter(runs.values()))["zero_doppler_fraction"])
        width = 0.8 / max(len(runs), 1)
        for i, (label, s) in enumerate(runs.items()):
            vals = [s["zero_doppler_fraction"][b] for b in bands]
            vals = [np.nan if v is None else v for v in vals]
            ax.bar(np.arange(len(bands)) + i * width, vals, width, label=f"{i + 1}: {label}")
        ax.set_xticks(np.arange(len(bands)) + 0.4 - width / 2, [b.replace(" m", "") for b in bands])
        ax.set_xlabel("range band (m)", fontsize=8)
        ax.set_ylim(0, 1)
        ax.set_title("zero-Doppler fraction", fontsize=9)
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.04, 1.0), title=kind)
        axes[row, 0].set_ylabel(f"{kind} chain", fontsize=11, fontweight="bold")
        for ax in axes[row]:
            ax.tick_params(labelsize=8)
    fig.suptitle(
        "TI chains, simulated walking body against recordings; median and p10-p90 over frames "
        "(radartune bench chain_calibration)",
        fontsize=11,
    )
    fig.tight_layout(rect=(0, 0, 1, 0.96), h_pad=2.0, w_pad=1.2)
    path.parent.mkdir(parents=True, exist_ok=True)
    save_figure(fig, path, bbox_inches="tight")
    plt.close(fig)
    return path


def plot_fit(fit: dict, path: Path) -> Path:
    """The simulated ghost fraction against the walls' loss, the recordings' fractions with
    their 95 % intervals, the fitted loss and its interval."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from core.files import save_figure

    fig, ax = plt.subplots(figsize=(8, 4.6))
    rows = [r for r in fit.get("curve", []) if r["reflection_db"] is not None]
    if rows:
        ax.plot(
            [r["reflection_db"] for r in rows],
            [r["ghost_fraction"] for r in rows],
            "ko-",
            label="simulated, oob chain (fit room walker)",
        )
        floor = next(r for r in fit["curve"] if r["reflection_db"] is None)["ghost_fraction"]
        ax.axhline(floor, color="k", ls=":", lw=1, label="simulated, no bounces")
    for i, (rel, r) in enumerate(fit["recordings"].items()):
        lo, hi = r["interval"]
        # a label starting with "_" is hidden by matplotlib: name the folder too
        name = rel.replace("_iwr6843", "").split("/")[0] + ": " + Path(rel).stem.strip("_")
        name += " (fit)" if rel == fit["train"] else " (held out)"
        ax.axhspan(lo, hi, color=f"C{i}", alpha=0.2)
        ax.axhline(r["ghost_fraction"], color=f"C{i}", lw=1.5, label=name)
    f = fit.get("fit") or {}
    if f.get("reflection_db") is not None:
        ax.axvline(f["reflection_db"], color="k", ls="--", lw=1.5, label="fitted loss")
        lo, hi = f["interval_db"]
        if lo is not None and hi is not None:
            ax.axvspan(min(lo, hi), max(lo, hi), color="k", alpha=0.12)
    ax.set_xlabel("wall reflection loss reflection_db (dB)")
    ax.set_ylabel("ghost fraction of moving points")
    ax.set_title("Walls' loss fitted to a recording's ghost fraction", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0))
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    save_figure(fig, path, bbox_inches="tight")
    plt.close(fig)
    return path


def summary(result: dict) -> str:
    lines = [f"chain calibration ({result['estimator']}); median [p10, p90] over frames"]
    fit = result.get("wall_fit", {})
    for rel, r in fit.get("recordings", {}).items():
        lo, hi = r["interval"]
        lines.append(f"ghost fraction {rel}: {r['ghost_fraction']:.3f} [{lo:.3f}, {hi:.3f}]")
    f = fit.get("fit")
    if f is not None:
        db = f["reflection_db"]
        lines.append(
            f"walls' loss fitted on {fit['train']}: "
            + ("no crossing" if db is None else f"{db:.1f} dB, interval {f['interval_db']}")
            + f" (simulated floor without bounces {f['floor_without_bounces']:.3f})"
        )
    for rel, h in fit.get("held_out", {}).items():
        lines.append(
            f"  held out {rel}: simulated {h['simulated']:.3f}, recorded {h['recorded']:.3f}, "
            f"{'within' if h['within'] else 'outside'} its 95 % interval"
        )
    for kind in ("people-counting", "oob"):
        lines.append(f"{kind}:")
        for label, s in result[kind].items():
            if s is None:
                lines.append(f"  {label}: recording not found")
                continue

            def f(key: str, fmt: str = ".2f", s: dict = s) -> str:
                q = s[key]
                if q["median"] is None:
                    return "-"
                return f"{q['median']:{fmt}} [{q['p10']:{fmt}}, {q['p90']:{fmt}}]"

            zero = ", ".join(
                f"{k} {v:.2f}" if v is not None else f"{k} -"
                for k, v in s["zero_doppler_fraction"].items()
            )
            zb = ", ".join(
                f"{k} {q['median']:.2f} (n {q['n']})"
                for k, q in s["spread_z_by_range_m"].items()
                if q["median"] is not None
            )
            e = s["elevation_edge_share"]
            if e is not None:
                zb += f"; at the elevation edge: top {e['top']:.2f}, bottom {e['bottom']:.2f}"
            g = s["ghost_fraction"]
            ghost = "-" if g is None else f"{g:.3f}"
            rc = s["static_recurring_fraction"]
            ghost += "" if rc is None else f"; zero-Doppler points recurring {rc:.2f}"
            lines.append(
                f"  {label} ({s['frames']} frames): points/frame {f('points_per_frame', '.0f')}, "
                f"person {f('person_points_per_frame', '.0f')}, spread x {f('spread_x_m')} "
                f"y {f('spread_y_m')} z {f('spread_z_m')} m (elevation "
                f"{f('spread_elevation_deg', '.1f')} deg; z by range: {zb}; person at "
                f"{f('person_range_m')} m), Doppler {f('doppler_spread_mps')} "
                f"m/s, SNR {f('person_snr_db', '.1f')} dB; zero-Doppler fraction {zero}; ghost "
                f"fraction {ghost}"
            )
    return "\n".join(lines)


if __name__ == "__main__":  # pragma: no cover
    r = run(quick=True)
    print(summary(r))
    print(json.dumps(r)[:200])

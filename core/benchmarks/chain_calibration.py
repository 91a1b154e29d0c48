"""Point statistics of TI's chains, simulated, against recordings made with that kind of chain.

``radartune bench chain_calibration``: a walking body (the default person model) walks back and
forth between 1.5 and 6 m in front of the radar, simulated through each chain with its own
radar (``resources/radar``), no walls (the open field); the recordings are read with the
project's readers. The same estimator is applied to both, since the recordings have no truth:
per frame, the *person* is the moving points (|v| > 0.05 m/s) within 1 m (x-y) of their
median; of them the count, the spread (standard deviation) in x, y and z, the
Doppler spread and the median SNR; of all points, the zero-Doppler fraction by range band.
Distributions over frames as median, p10, p90.

Recordings used (``../shared/real``): the 2023 people-counting file (IWR6843ISK, TI's firmware
with static detection; SNR linear in the file) for ``people-counting``; the RadHAR walker
(IWR1443BOOST, TI's out-of-box style chain through the ROS driver; intensity, not SNR) for
``oob``.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from core.benchmarks.clouds import real_data_dir

ROOT = Path(__file__).resolve().parents[2]
RANGE_BANDS_M = ((0.0, 2.0), (2.0, 4.0), (4.0, 6.0), (6.0, 10.0))
MOVING_MPS = 0.05


def _q(values: list[float] | np.ndarray) -> dict:
    v = np.asarray(values, dtype=np.float64)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return {"median": None, "p10": None, "p90": None, "n": 0}
    p10, med, p90 = np.percentile(v, [10, 50, 90])
    return {"median": float(med), "p10": float(p10), "p90": float(p90), "n": int(v.size)}


def frame_stats(frames: list[dict]) -> dict:
    """Statistics over frames; each frame a dict of arrays x, y, z, v, snr (SNR may be NaN)."""
    n_person, sx, sy, sz, sv, snr = [], [], [], [], [], []
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
        snr.append(np.nanmedian(f["snr"][near]) if np.isfinite(f["snr"][near]).any() else np.nan)
    return {
        "frames": len(frames),
        "points_per_frame": _q([len(f["x"]) for f in frames]),
        "person_points_per_frame": _q(n_person),
        "spread_x_m": _q(sx),
        "spread_y_m": _q(sy),
        "spread_z_m": _q(sz),
        "doppler_spread_mps": _q(sv),
        "person_snr_db": _q(snr),
        "zero_doppler_fraction": {k: (c[0] / c[1] if c[1] else None) for k, c in zero.items()},
    }


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


def walker_scene(cfg: Path, frames: int, seed: int):
    """A walking body back and forth between 1.5 and 6 m, 15 deg off boresight."""
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
                "trajectory": {
                    "waypoints": [
                        [0.4, 1.5, 1.1],
                        [1.5, 6.0, 1.1],
                        [0.4, 1.5, 1.1],
                        [1.5, 6.0, 1.1],
                    ]
                },
            }
        ],
    }
    scene = Scene.from_dict(data, source="calibration walker")
    return scene, min(frames, scene.n_frames)


def simulated(cfg_name: str, frames: int, seed: int = 5) -> dict:
    from core.formats.ti_cfg import read_ti_chain
    from core.pipeline import plan
    from core.pipeline.frames import iter_frames

    cfg = ROOT / "resources" / "radar" / cfg_name
    chain = read_ti_chain(cfg) if cfg_name != "paper.cfg" else None
    scene, n = walker_scene(cfg, frames, seed)
    p = plan(scene, chain=chain) if chain is not None else plan(scene)
    out = []
    for fr in iter_frames(scene, the_plan=p, frames=range(n)):
        pc = fr.point_cloud
        out.append(
            {
                "x": pc.x_m,
                "y": pc.y_m,
                "z": pc.z_m,
                "v": pc.radial_velocity_mps,
                "snr": pc.snr_db,
            }
        )
    return frame_stats(out)


def recorded_people_counting() -> dict | None:
    from core.formats.pointcloud_csv import read_people

    path = real_data_dir() / "pc3_iwr6843" / "pc3_2023-06-21-12-27-01.csv"
    if not path.exists():
        return None
    rec = read_people(path, None)
    return frame_stats(_frames_of_cloud(rec.cloud, rec.counts))


def recorded_radhar() -> dict | None:
    from core.formats.ros_pointcloud import read_ros_pointcloud

    path = real_data_dir() / "radhar_walk" / "__20_walk_6.txt"
    if not path.exists():
        return None
    ros = read_ros_pointcloud(path)
    frames = []
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
    return frame_stats(frames)


def run(quick: bool = False) -> dict:
    n = 20 if quick else 120
    result = {
        "estimator": "person = moving points within 1 m (x-y) of their median",
        "people-counting": {
            "simulated, static chain on (people_counting_isk_static.cfg)": simulated(
                "people_counting_isk_static.cfg", n
            ),
            "simulated, TI's file (static off)": simulated("people_counting_isk.cfg", n),
            "recorded: pc3_2023 (IWR6843ISK, TI people counting)": recorded_people_counting(),
        },
        "oob": {
            "simulated (oob_isk.cfg)": simulated("oob_isk.cfg", n),
            "simulated, paper chain (paper.cfg)": simulated("paper.cfg", n),
            "recorded: RadHAR walk (IWR1443BOOST, out-of-box style)": recorded_radhar(),
        },
    }
    if not quick:
        plot(result, ROOT / "docs" / "chains" / "calibration.png")
    return result


METRICS = (
    ("person_points_per_frame", "person points / frame"),
    ("spread_x_m", "spread x (m)"),
    ("spread_y_m", "spread y (m)"),
    ("spread_z_m", "spread z (m)"),
    ("doppler_spread_mps", "Doppler spread (m/s)"),
)


def plot(result: dict, path: Path) -> Path:
    """Medians with p10-p90 bars of each metric, and the zero-Doppler fraction by range band,
    one row per chain kind."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from core.files import save_figure

    kinds = ("people-counting", "oob")
    fig, axes = plt.subplots(len(kinds), len(METRICS) + 1, figsize=(18, 6.5))
    for row, kind in enumerate(kinds):
        runs = {k: v for k, v in result[kind].items() if v is not None}
        for col, (key, title) in enumerate(METRICS):
            ax = axes[row, col]
            for i, (label, s) in enumerate(runs.items()):
                q = s[key]
                if q["median"] is None:
                    continue
                err = [[q["median"] - q["p10"]], [q["p90"] - q["median"]]]
                ax.errorbar([i], [q["median"]], yerr=err, fmt="o", capsize=4, label=label)
            ax.set_xticks(range(len(runs)))
            ax.set_xticklabels([str(i + 1) for i in range(len(runs))])
            ax.set_title(f"{kind}: {title}", fontsize=9)
        ax = axes[row, -1]
        bands = list(next(iter(runs.values()))["zero_doppler_fraction"])
        width = 0.8 / max(len(runs), 1)
        for i, (label, s) in enumerate(runs.items()):
            vals = [s["zero_doppler_fraction"][b] for b in bands]
            vals = [np.nan if v is None else v for v in vals]
            ax.bar(np.arange(len(bands)) + i * width, vals, width, label=f"{i + 1}: {label}")
        ax.set_xticks(np.arange(len(bands)) + 0.4 - width / 2)
        ax.set_xticklabels(bands, fontsize=8)
        ax.set_ylim(0, 1)
        ax.set_title(f"{kind}: zero-Doppler fraction", fontsize=9)
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0))
    fig.suptitle(
        "TI chains, simulated walking body (open field) against recordings; "
        "median and p10-p90 over frames (radartune bench chain_calibration)"
    )
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    save_figure(fig, path, bbox_inches="tight")
    plt.close(fig)
    return path


def summary(result: dict) -> str:
    lines = [f"chain calibration ({result['estimator']}); median [p10, p90] over frames"]
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
            lines.append(
                f"  {label} ({s['frames']} frames): points/frame {f('points_per_frame', '.0f')}, "
                f"person {f('person_points_per_frame', '.0f')}, spread x {f('spread_x_m')} "
                f"y {f('spread_y_m')} z {f('spread_z_m')} m, Doppler {f('doppler_spread_mps')} "
                f"m/s, SNR {f('person_snr_db', '.1f')} dB; zero-Doppler fraction {zero}"
            )
    return "\n".join(lines)


if __name__ == "__main__":  # pragma: no cover
    r = run(quick=True)
    print(summary(r))
    print(json.dumps(r)[:200])

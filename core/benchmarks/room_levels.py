"""``radartune bench room_levels``: the three fidelity levels in the shipped rooms, same run.

Every shipped room scene (:data:`SCENES`) runs through the paper's chain at each level
(:data:`LEVELS`) with :data:`SEEDS` noise seeds (the scene's seed plus 0, 1, ...); the exact
level runs once more with other seeds (the scene's seed plus :data:`YARDSTICK_OFFSET`), the
yardstick: how far the exact level is from itself with other noise. Per scene and level, pooled
over its seeds' frames:

- points per frame by path order (direct, one bounce, two bounces, clutter and noise: the
  ``path_order`` and ``source`` labels), the table of docs/rooms.md;
- direct points per person and frame;
- the ghost share: bounce points over the persons' points (labels);
- the ghost fraction of :mod:`core.benchmarks.wall_loss` (moving points more than 1 m behind the
  person within 10 deg of its bearing, over moving points; the statistic the walls' loss was
  fitted with), with its moving-block bootstrap interval;
- the spread of a person's direct points about their median in the frame: robust standard
  deviations (1.4826 x the median absolute deviation) of x, y and radial velocity.

Each level's figure over the exact level's is its error; the yardstick's ratio says how much of
it other noise alone makes. Per scene also: the first-order bounce scatterers a frame and the
share of them that lie within one merge cell (:data:`core.simulation.body_cells.MERGE_CELLS`:
range, Doppler, azimuth beam) of a direct scatterer of the same person: there the exact chain's
tones overlap and may give one peak, while the measurement level, which merges only a source's
own cells, detects each on its own.
Writes ``docs/rooms/levels.md`` (the full run only).
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np

from core.files import write_text_atomic

ROOT = Path(__file__).resolve().parents[2]
SCENES = ("room_walker.json", "room_chair.json", "room_office.json", "room_corridor.json")
LEVELS = ("exact", "fast", "measurement")
SEEDS = 3
YARDSTICK_OFFSET = 1000
#: Robust standard deviation from the median absolute deviation (a normal law's).
MAD_TO_SD = 1.4826
ORDERS = ("direct", "1 bounce", "2 bounces", "clutter / noise")
METRICS = (
    "points_per_frame",
    "direct_points_per_person_frame",
    "ghost_share",
    "ghost_fraction",
    "spread_x_m",
    "spread_y_m",
    "spread_v_mps",
)
DOC = ROOT / "docs" / "rooms" / "levels.md"


def frame_rows(clouds) -> list[dict]:
    """Per frame the arrays the metrics need: x, y (room), radial velocity, source, path order
    (direct paths and clutter without a room label count as order 0 / -1)."""
    rows = []
    for pc in clouds:
        order = pc.path_order
        if order is None:
            order = np.where(pc.source >= 0, 0, -1)
        rows.append(
            {
                "x": np.asarray(pc.x_m, dtype=np.float64),
                "y": np.asarray(pc.y_m, dtype=np.float64),
                "v": np.asarray(pc.radial_velocity_mps, dtype=np.float64),
                "source": np.asarray(pc.source),
                "order": np.asarray(order),
            }
        )
    return rows


def _robust_sd(x: np.ndarray) -> float | None:
    return float(MAD_TO_SD * np.median(np.abs(x))) if len(x) else None


def metrics(rows: list[dict], n_persons: int) -> dict:
    """The figures of the module docstring on pooled frames (``rows`` of :func:`frame_rows`)."""
    from core.benchmarks.wall_loss import bootstrap_interval, ghost_fraction

    n = max(1, len(rows))
    by_order = dict.fromkeys(ORDERS, 0)
    dev: dict[str, list[np.ndarray]] = {"x": [], "y": [], "v": []}
    person = ghost = 0
    for r in rows:
        src, order = r["source"], r["order"]
        mine = src >= 0
        by_order["direct"] += int(np.sum(mine & (order == 0)))
        by_order["1 bounce"] += int(np.sum(mine & (order == 1)))
        by_order["2 bounces"] += int(np.sum(mine & (order == 2)))
        by_order["clutter / noise"] += int(np.sum(~mine))
        person += int(np.sum(mine))
        ghost += int(np.sum(mine & (order > 0)))
        for p in np.unique(src[mine & (order == 0)]):
            sel = (src == p) & (order == 0)
            for k in dev:
                dev[k].append(r[k][sel] - np.median(r[k][sel]))
    frac = ghost_fraction(rows)
    spread = {k: _robust_sd(np.concatenate(v)) if v else None for k, v in dev.items()}
    return {
        "frames": len(rows),
        "points_by_order_per_frame": {k: v / n for k, v in by_order.items()},
        "points_per_frame": sum(by_order.values()) / n,
        "direct_points_per_person_frame": by_order["direct"] / (n * max(1, n_persons)),
        "ghost_share": ghost / person if person else None,
        "ghost_fraction": frac,
        "ghost_fraction_interval": list(bootstrap_interval(rows)) if frac is not None else None,
        "spread_x_m": spread["x"],
        "spread_y_m": spread["y"],
        "spread_v_mps": spread["v"],
    }


def shared_cells(frames, radar) -> dict:
    """First-order bounce scatterers per frame and the share of them closer than one merge cell
    (:data:`~core.simulation.body_cells.MERGE_CELLS`, in all three of range, radial velocity and
    azimuth sine, as :func:`~core.simulation.body_cells.merge_person_cells` measures) to a
    direct scatterer of the same person; ``frames`` are the reflector stage's scatterers."""
    from core.simulation.body_cells import MERGE_CELLS
    from core.simulation.multipath import split_labels

    k_r, k_d, k_u = MERGE_CELLS
    scale = np.array(
        [
            k_r * radar.range_resolution_m,
            k_d * radar.velocity_resolution_mps,
            k_u * 2.0 / len(radar.azimuth_positions),
        ]
    )
    ghosts = near = 0
    for f in frames:
        src, order = split_labels(f.source)
        pos = np.asarray(f.position_m, dtype=np.float64)
        rng = np.linalg.norm(pos, axis=1)
        vr = np.einsum("ij,ij->i", np.asarray(f.velocity_mps, dtype=np.float64), pos) / rng
        u = pos[:, 0] / np.maximum(np.hypot(pos[:, 0], pos[:, 1]), 1e-12)
        coord = np.column_stack((rng, vr, u)) / scale
        for i in np.flatnonzero((src >= 0) & (order == 1)):
            direct = (src == src[i]) & (order == 0)
            ghosts += 1
            near += bool(np.any(np.all(np.abs(coord[direct] - coord[i]) < 1.0, axis=1)))
    return {
        "first_order_scatterers_per_frame": ghosts / max(1, len(frames)),
        "share_in_a_direct_cell": near / ghosts if ghosts else None,
    }


def _reflector_frames(scene):
    """The scene's scatterers of every frame from the pipeline's reflector stage (its seed; the
    antenna drawn as ``radartune bench sim``'s room case draws it)."""
    from core.pipeline.plan import plan, processing_settings
    from core.pipeline.reflectors import Reflectors
    from core.simulation import AntennaGain

    antenna = AntennaGain.draw(scene.radar, np.random.default_rng(7))
    settings = processing_settings(scene)
    frames, _ = Reflectors.build(scene, plan(scene), scene.seed, antenna, settings).frames()
    return frames


def _ratio(a: float | None, b: float | None) -> float | None:
    return None if a is None or b is None or b == 0 else a / b


def run(quick: bool = False) -> dict:
    from core.pipeline.frames import simulate_scene
    from core.scene import Scene

    seeds = 1 if quick else SEEDS
    out: dict = {
        "levels": list(LEVELS),
        "seeds_per_level": seeds,
        "yardstick_seed_offset": YARDSTICK_OFFSET,
        "scenes": {},
    }
    for name in SCENES[:1] if quick else SCENES:
        scene = Scene.from_json(ROOT / "resources" / "scenes" / name)
        runs = [(lv, lv, 0) for lv in LEVELS] + [("exact, other noise", "exact", YARDSTICK_OFFSET)]
        rows_out: dict = {}
        for label, level, offset in runs:
            rows: list[dict] = []
            c0 = time.process_time()
            for k in range(seeds):
                run_ = simulate_scene(scene, fidelity=level, seed=scene.seed + offset + k)
                rows += frame_rows(run_.clouds)
            m = metrics(rows, len(scene.persons))
            m["cpu_s_per_frame"] = (time.process_time() - c0) / max(1, len(rows))
            rows_out[label] = m
        exact = rows_out["exact"]
        for m in rows_out.values():
            m["over_exact"] = {k: _ratio(m[k], exact[k]) for k in METRICS}
        out["scenes"][name] = {
            "persons": len(scene.persons),
            "rows": rows_out,
            "ghost_scatterers": shared_cells(_reflector_frames(scene), scene.radar),
        }
    out["load_average_1min"] = os.getloadavg()[0]
    if not quick:
        out["doc"] = str(write_doc(out).relative_to(ROOT))
    return out


def _f(x: float | None, fmt: str = ".2f") -> str:
    return "–" if x is None else format(x, fmt)


def path_order_table(result: dict) -> list[str]:
    """Markdown: points per frame by path order, every scene and level."""
    lines = [
        "| scene | level | " + " | ".join(ORDERS) + " | all |",
        "|---|---|" + "---|" * (len(ORDERS) + 1),
    ]
    for name, sc in result["scenes"].items():
        for label, m in sc["rows"].items():
            if label not in LEVELS:
                continue
            o = m["points_by_order_per_frame"]
            lines.append(
                f"| `{name}` | {label} | "
                + " | ".join(_f(o[k]) for k in ORDERS)
                + f" | {_f(m['points_per_frame'])} |"
            )
    return lines


def error_table(result: dict) -> list[str]:
    """Markdown: each level's figures and their ratio to the exact level's."""
    lines = [
        "| scene | level | direct points / person / frame | ghost share | ghost fraction (95 %) "
        "| spread x, y (m) | spread v (m/s) | ratios to exact: points, direct, ghost share, "
        "ghost fraction, spread x, y, v |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name, sc in result["scenes"].items():
        for label, m in sc["rows"].items():
            iv = m["ghost_fraction_interval"]
            ci = f" ({iv[0]:.3f}–{iv[1]:.3f})" if iv else ""
            r = m["over_exact"]
            ratios = ", ".join(_f(r[k]) for k in METRICS) if label != "exact" else "1"
            lines.append(
                f"| `{name}` | {label} | {_f(m['direct_points_per_person_frame'])} | "
                f"{_f(m['ghost_share'], '.3f')} | {_f(m['ghost_fraction'], '.3f')}{ci} | "
                f"{_f(m['spread_x_m'], '.3f')}, {_f(m['spread_y_m'], '.3f')} | "
                f"{_f(m['spread_v_mps'], '.3f')} | {ratios} |"
            )
    return lines


def cell_lines(result: dict) -> list[str]:
    """Markdown: first-order bounce scatterers and the share sharing a direct cell."""
    lines = [
        "| scene | first-order bounce scatterers / frame | within one merge cell of a direct one |",
        "|---|---|---|",
    ]
    for name, sc in result["scenes"].items():
        g = sc["ghost_scatterers"]
        lines.append(
            f"| `{name}` | {_f(g['first_order_scatterers_per_frame'], '.1f')} | "
            f"{_f(g['share_in_a_direct_cell'], '.3f')} |"
        )
    return lines


def write_doc(result: dict) -> Path:
    """``docs/rooms/levels.md`` from a full run's figures, replaced whole."""
    text = "\n".join(
        [
            "# The fidelity levels in the shipped rooms",
            "",
            "Made by `radartune bench room_levels` (`bench/results/room_levels.json`; "
            f"{result['seeds_per_level']} noise seeds per scene and level, frames pooled; load "
            f"{result['load_average_1min']:.1f}). What the figures are: "
            "[Rooms](../rooms.md#the-fidelity-levels-in-a-room).",
            "",
            "## Points per frame by path order",
            "",
            *path_order_table(result),
            "",
            "## The levels' error against the exact level",
            "",
            '"exact, other noise" is the yardstick: the exact level with other noise seeds.',
            "",
            *error_table(result),
            "",
            "## Bounce paths that share a direct path's cell",
            "",
            "A first-order bounce scatterer closer than one merge cell (3 range bins, 2 Doppler "
            "bins, one azimuth beam) to a direct scatterer of the same person: there the exact "
            "chain's tones overlap in one spectrum and may give one peak, while the measurement "
            "level, merging a source's own cells only, detects each on its own.",
            "",
            *cell_lines(result),
            "",
        ]
    )
    DOC.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(DOC, text)
    return DOC


def summary(result: dict) -> str:
    lines = [
        f"room_levels: {len(result['scenes'])} room scene(s), levels {', '.join(LEVELS)}, "
        f"{result['seeds_per_level']} seed(s) each (load {result['load_average_1min']:.1f})",
        *path_order_table(result),
        *error_table(result),
        *cell_lines(result),
    ]
    if "doc" in result:
        lines.append(f"written: {result['doc']}")
    return "\n".join(lines)

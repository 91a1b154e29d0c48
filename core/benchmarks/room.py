"""``radartune bench room``: the paper mode and the room mode on real recordings, same run.

Recordings (``$RADARTUNE_REAL_DATA`` or ``../shared/real``, :func:`core.benchmarks.clouds.
real_data_dir`), read with the project's readers (:func:`core.recordings.read_recording`):

- ``pc3_iwr6843/pc3_2023-06-21-12-27-01.csv``: TI's people-counting firmware, one or two people,
  TI's own tracks as the reference layer: the number of counted tracks a frame against TI's, the
  share of frames with as many, the mean GOSPA against TI's tracks
  (:func:`core.evaluation.counting.recording_scores`);
- ``mmgait_walkers/room2_1p_fixed_60GHz_{002,022,076}.csv``: one person walking (head count 1):
  the share of frames with one counted track and its 95 % interval, the confirmed track ids a
  person-minute.

Both modes run with their defaults (CV). The room mode's defaults were chosen on the
people-counting recording and walkers 002 and 022; walker 076 was held out (docs/tracker.md,
"Tracking in rooms"). Writes the per-frame counts on the people-counting recording to
``docs/tracking/room_pc3_counts.png`` (``bench/results/room_pc3_counts-quick.png`` when quick).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from core.files import save_figure

PC3 = "pc3_iwr6843/pc3_2023-06-21-12-27-01.csv"
WALKERS = tuple(f"mmgait_walkers/room2_1p_fixed_60GHz_{k}.csv" for k in ("002", "022", "076"))
#: The recording held out when the room mode's defaults were chosen.
HELD_OUT = WALKERS[2]


def _dataset(rel: str, people: int | None):
    from core.benchmarks.clouds import real_data_dir
    from core.formats.recording import to_dataset
    from core.recordings import read_recording

    path = real_data_dir() / rel
    rec = read_recording(path, fmt=None, cfg=None)
    return to_dataset(rec, truth=None, source_name=str(path), people=people)


def _scores(ds, mode: str, people: int | None) -> tuple[dict, Any]:
    from core.evaluation.counting import recording_scores
    from core.tracking import TrackerParams, track_dataset
    from core.tracking.batch import dataset_frame_period_s

    est = track_dataset(ds, TrackerParams.default("cv", mode=mode), with_tracks=True)
    s = recording_scores(ds, est, dataset_frame_period_s(ds), people=people)
    row: dict = {"mean_counted": float(np.mean(est.n_confirmed))}
    if s.count is not None:
        row.update(
            right=s.count.right,
            right_interval=list(s.count.right_interval),
            ids_per_person_minute=s.count.fragmentation,
        )
    if s.reference is not None:
        r = s.reference
        row.update(
            reference_mean=float(np.mean(r.n_reference)),
            same_count_as_reference=r.count_agreement,
            mean_gospa_m=r.mean_gospa_m,
        )
    return row, est


def run(quick: bool = False) -> dict:
    out: dict = {"modes": ["paper", "room"], "held_out": HELD_OUT, "recordings": {}}
    ds = _dataset(PC3, None)
    counts = {}
    row = {}
    for mode in ("paper", "room"):
        row[mode], est = _scores(ds, mode, None)
        counts[mode] = np.asarray(est.n_confirmed)
    ref = np.bincount(ds.ref_frame, minlength=ds.n_frames)[np.asarray(est.frame_index)]
    out["recordings"][PC3] = row
    out["plot"] = str(_plot(counts, ref, quick))
    for rel in WALKERS[-1:] if quick else WALKERS:
        ds = _dataset(rel, 1)
        out["recordings"][rel] = {mode: _scores(ds, mode, 1)[0] for mode in ("paper", "room")}
    return out


def _plot(counts: dict, ref: np.ndarray, quick: bool) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path = Path(
        "bench/results/room_pc3_counts-quick.png" if quick else "docs/tracking/room_pc3_counts.png"
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(7, 3.6))
    f = np.arange(len(ref))
    ax.step(f, ref, where="mid", color="k", lw=2, label="TI's tracker (reference)")
    ax.step(f, counts["paper"], where="mid", color="tab:red", label="paper mode, defaults")
    ax.step(f, counts["room"], where="mid", color="tab:blue", label="room mode, defaults")
    ax.set_yscale("symlog", linthresh=4)
    ax.set_xlabel("frame (TI people-counting recording pc3_2023, 10 frames/s)")
    ax.set_ylabel("confirmed (counted) tracks")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    plt.close(fig)
    return path


def summary(result: dict) -> str:
    lines = [
        f"room: paper and room modes (CV defaults) on recordings; held out: {result['held_out']}"
    ]
    for rel, rows in result["recordings"].items():
        for mode, r in rows.items():
            text = f"{rel} {mode:>5}: {r['mean_counted']:.2f} counted tracks a frame"
            if "reference_mean" in r:
                text += (
                    f" (TI {r['reference_mean']:.2f}); as many as TI in "
                    f"{r['same_count_as_reference']:.3f} of frames; mean GOSPA against TI "
                    f"{r['mean_gospa_m']:.2f} m"
                )
            if "right" in r:
                lo, hi = r["right_interval"]
                text += (
                    f"; one track (right) in {r['right']:.3f} of frames (95 % {lo:.3f}-{hi:.3f}),"
                    f" {r['ids_per_person_minute']:.1f} ids a person-minute"
                )
            lines.append(text)
    lines.append(f"plot: {result['plot']}")
    return "\n".join(lines)

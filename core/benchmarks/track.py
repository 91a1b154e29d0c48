"""``radartune bench track``: speed of a full tracker pass over a 35-trajectory data set.

Measures, in the same run, the compiled kernel (:func:`core.tracking.track_dataset`, the hot path
of every Optuna trial) and the plain per-frame numpy implementation (the readable reference
:func:`core.tracking.run_tracker`, which the tests hold equal to the kernel to 1e-10), for CV and
CA, and reports frames/s, milliseconds per full pass and the ratio.

Data: the simulated paper data set when the pipeline and a cached copy are available, otherwise
the synthetic paper-like set (35 trajectories, 7 per class, 2.1 clutter points a frame). Since
the paper's trajectories last 6–20 s (mean 162 frames, 5 688 frames for 35), the time of a pass
is also given scaled to 5 688 frames.
"""

from __future__ import annotations

import time

import numpy as np

PAPER_PASS_FRAMES = 35 * (75 + 250) // 2  # 35 trajectories of 6–20 s at 80 ms: 5 687 frames


def _dataset(quick: bool):
    from core.tracking.synthetic import synthetic_dataset

    return (
        synthetic_dataset(0, 7, n_frames=250)
        if not quick
        else synthetic_dataset(0, 1, n_frames=120)
    ), "synthetic paper-like (core.tracking.synthetic, seed 0)"


def _best_of(fn, repeats: int) -> tuple[float, float]:
    """Best wall-clock and best process-CPU time of ``repeats`` calls (s).

    The machine is shared: CPU time excludes the time other processes hold the cores.
    """
    best, best_cpu = np.inf, np.inf
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        fn()
        best = min(best, time.perf_counter() - t0)
        best_cpu = min(best_cpu, time.process_time() - c0)
    return best, best_cpu


def run(quick: bool = False) -> dict:
    from core.evaluation import evaluate
    from core.tracking import TrackerParams, track_dataset

    ds, source = _dataset(quick)
    n_frames = ds.n_frames
    out: dict = {
        "data": source,
        "n_trajectories": int(ds.n_trajectories),
        "n_frames": int(n_frames),
        "n_points": len(ds.frame),
        "plain": "core.tracking.run_tracker (readable per-frame numpy reference, one pass)",
        "models": {},
    }
    for model in ("cv", "ca"):
        p = TrackerParams.default(model)
        t0 = time.perf_counter()
        fast = track_dataset(ds, p)  # first call: loads (or compiles) the kernel
        first = time.perf_counter() - t0
        t_fast, c_fast = _best_of(lambda p=p: track_dataset(ds, p), 3 if quick else 20)
        t0, c0 = time.perf_counter(), time.process_time()
        plain = track_dataset(ds, p, engine="numpy")
        t_plain, c_plain = time.perf_counter() - t0, time.process_time() - c0
        same = bool(
            np.array_equal(fast.has_estimate, plain.has_estimate)
            and np.allclose(fast.estimate_xy, plain.estimate_xy, atol=1e-10, equal_nan=True)
        )
        loss = evaluate(ds, fast).loss_total
        out["models"][model] = {
            "kernel_first_call_s": first,
            "kernel_ms_per_pass": 1e3 * t_fast,
            "kernel_frames_per_s": n_frames / t_fast,
            "kernel_ms_per_paper_pass": 1e3 * t_fast * PAPER_PASS_FRAMES / n_frames,
            "kernel_cpu_ms_per_pass": 1e3 * c_fast,
            "kernel_cpu_ms_per_paper_pass": 1e3 * c_fast * PAPER_PASS_FRAMES / n_frames,
            "plain_cpu_ms_per_pass": 1e3 * c_plain,
            "speedup_cpu": c_plain / c_fast,
            "plain_ms_per_pass": 1e3 * t_plain,
            "plain_frames_per_s": n_frames / t_plain,
            "speedup": t_plain / t_fast,
            "same_result": same,
            "loss_total_x1e3": 1e3 * loss,
            "mean_live_tracks": float(fast.n_tracks.mean()),
        }
    return out


def summary(result: dict) -> str:
    lines = [
        f"track: {result['n_trajectories']} trajectories, {result['n_frames']} frames, "
        f"{result['n_points']} points ({result['data']})",
        "wall clock (best of repeats) and, in brackets, process CPU time (shared machine)",
        f"{'model':>5} {'kernel ms':>16} {'frames/s':>9} {'ms/5687 fr':>16} "
        f"{'plain ms':>16} {'speed-up':>12} {'same':>5}",
    ]
    for model, r in result["models"].items():
        lines.append(
            f"{model:>5} {r['kernel_ms_per_pass']:7.2f} ({r['kernel_cpu_ms_per_pass']:6.2f}) "
            f"{r['kernel_frames_per_s']:9.0f} "
            f"{r['kernel_ms_per_paper_pass']:7.2f} ({r['kernel_cpu_ms_per_paper_pass']:6.2f}) "
            f"{r['plain_ms_per_pass']:7.0f} ({r['plain_cpu_ms_per_pass']:6.0f}) "
            f"{r['speedup']:4.0f}x ({r['speedup_cpu']:4.0f}x) {str(r['same_result']):>5}"
        )
    return "\n".join(lines)

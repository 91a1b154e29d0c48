"""``radartune bench track``: speed of a full tracker pass over a 35-trajectory data set.

Measures, in the same run, the compiled kernel (:func:`core.tracking.track_dataset`, the hot path
of every Optuna trial) against two plain per-frame numpy implementations of the same algorithm:
``plain_track`` below (compact, written here, vectorised over the measurements of a frame) and the
readable reference :func:`core.tracking.run_tracker` (one role module per step). Both must give
the kernel's estimates; frames/s, milliseconds per full pass and the ratios are reported for CV
and CA.

Data: ``$RADARTUNE_TRACK_BENCH_DATA`` (a data set .npz, e.g. the cached simulated paper set) when
set, otherwise the synthetic paper-like set (35 trajectories, 7 per class, 2.1 clutter points a
frame). The paper's trajectories last 6–20 s (mean 162 frames, 5 687 frames for 35), so the time
of a pass is also given scaled to 5 687 frames.
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from core.files import save_figure

PAPER_PASS_FRAMES = 35 * (75 + 250) // 2  # 35 trajectories of 6–20 s at 80 ms: 5 687 frames


def _dataset(quick: bool):
    import os

    from core.dataset import Dataset
    from core.tracking.synthetic import synthetic_dataset

    path = os.environ.get("RADARTUNE_TRACK_BENCH_DATA")
    if path:
        ds = Dataset.load(path)
        if quick:
            ds = _first_trajectories(ds, 5)
        return ds, path
    ds = synthetic_dataset(0, 1 if quick else 7, n_frames=120 if quick else 250)
    return ds, "synthetic paper-like (core.tracking.synthetic, seed 0)"


def _first_trajectories(ds, k: int):
    from dataclasses import replace

    f_end = int(ds.trajectory_offsets[k])
    p_end = int(ds.frame_offsets[f_end])
    per_point: tuple[str, ...] = (
        "frame",
        "range_m",
        "azimuth_rad",
        "elevation_rad",
        "radial_velocity_mps",
    )
    per_point += ("snr_db", "x_m", "y_m", "z_m", "source")
    per_frame = ("trajectory", "truth_t_s", "truth_xy_m", "truth_v_mps")
    return replace(
        ds,
        **{f: getattr(ds, f)[:p_end] for f in per_point},
        **{f: getattr(ds, f)[:f_end] for f in per_frame},
        trajectory_class=ds.trajectory_class[:k],
    )


def plain_track(z_all, f_off, t_off, params, period):
    """The tracker's estimate, plainly in numpy, one frame at a time (benchmark reference).

    Same algorithm as :mod:`core.tracking` (SPEC §4), without the role modules: returns the
    estimate position (F, 2) (NaN where none) and the has-estimate mask (F,).
    """
    from scipy.stats import chi2

    from core.tracking.models import process_noise, transition_matrix

    F = transition_matrix(params.model, period)
    Q = process_noise(params.model, period, params.q_coeff)
    R = np.diag([params.r11**2, params.r22**2, params.r33**2])
    P0 = np.diag(np.square(params.p0))
    g3, g2 = chi2.ppf(params.p_g, 3), chi2.ppf(params.p_g, 2)
    pdpg = params.p_d * params.p_g
    n = params.state_dim
    est = np.full((int(t_off[-1]), 2), np.nan)
    has = np.zeros(int(t_off[-1]), dtype=bool)
    for k in range(len(t_off) - 1):
        X, P, psi, conf, ids, next_id = np.zeros((0, n)), np.zeros((0, n, n)), [], [], [], 0
        for f in range(t_off[k], t_off[k + 1]):
            z = z_all[f_off[f] : f_off[f + 1]]
            n_old = len(psi)
            outside = np.ones(len(z), dtype=bool)
            for t in range(n_old):
                x = F @ X[t]
                Pp = F @ P[t] @ F.T + Q
                pp = min(1.0, max(0.0, params.p11 * psi[t] + params.p21 * (1 - psi[t])))
                r = max(np.hypot(x[0], x[1]), 1e-2)
                px, py = (x[0], x[1]) if np.hypot(x[0], x[1]) >= 1e-2 else (0.0, 1e-2)
                if 0 < np.hypot(x[0], x[1]) < 1e-2:
                    px, py = x[0] * 1e-2 / np.hypot(x[0], x[1]), x[1] * 1e-2 / np.hypot(x[0], x[1])
                H = np.zeros((3, n))
                cr = x[2] * py - x[3] * px
                H[0, :2] = px / r, py / r
                H[1, :2] = py / r**2, -px / r**2
                H[2, :4] = py * cr / r**3, -px * cr / r**3, px / r, py / r
                zp = np.array([r, np.arctan2(px, py), (px * x[2] + py * x[3]) / r])
                S = H @ Pp @ H.T + R
                S = 0.5 * (S + S.T)
                nu = z - zp
                nu[:, 1] = np.mod(nu[:, 1] + np.pi, 2 * np.pi) - np.pi
                Si = np.linalg.inv(S)
                d2 = np.einsum("ij,jk,ik->i", nu, Si, nu)
                gate = d2 <= g3
                outside &= ~gate
                nu, d2 = nu[gate], d2[gate]
                if len(nu) == 0:
                    psi[t] = (1 - pdpg) * pp / (1 - pdpg * pp) if 0 < pp < 1 else pp
                    X[t], P[t] = x, Pp
                    continue
                if params.nonparametric:
                    vol = 4 * np.pi / 3 * g3**1.5 * np.sqrt(np.linalg.det(S))
                    m_hat = len(nu) - pdpg * pp
                    rho = (m_hat if m_hat > 0 else len(nu)) / vol
                else:
                    rho = params.clutter_density
                lr = np.exp(-0.5 * d2) / np.sqrt(np.linalg.det(2 * np.pi * S)) / (params.p_g * rho)
                omd = 1 - pdpg + pdpg * lr.sum()  # 1 − δ
                beta, b0 = pdpg * lr / omd, (1 - pdpg) / omd
                psi[t] = pp if pp in (0.0, 1.0) else omd * pp / ((1 - pp) + omd * pp)
                K = Pp @ H.T @ Si
                nb = beta @ nu
                A = np.eye(n) - K @ H
                d = nu - nb
                spread = (d.T * beta) @ d + b0 * np.outer(nb, nb)
                Pn = b0 * Pp + (1 - b0) * (A @ Pp @ A.T + K @ R @ K.T) + K @ spread @ K.T
                X[t], P[t] = x + K @ nb, 0.5 * (Pn + Pn.T)
            new = z[outside]
            if len(new):
                s, c = np.sin(new[:, 1]), np.cos(new[:, 1])
                x0 = np.zeros((len(new), n))
                x0[:, :4] = np.column_stack(
                    (new[:, 0] * s, new[:, 0] * c, new[:, 2] * s, new[:, 2] * c)
                )
                X = np.concatenate((X, x0))
                P = np.concatenate((P, np.repeat(P0[None], len(new), axis=0)))
                psi += [params.p_te] * len(new)
                conf += [False] * len(new)
                ids += list(range(next_id, next_id + len(new)))
                next_id += len(new)
            psi_a = np.array(psi)
            conf_a = np.array(conf, dtype=bool)
            conf_a[:n_old] |= psi_a[:n_old] >= params.confirm_threshold
            keep = psi_a >= params.delete_threshold
            order = [i for i in np.lexsort((ids, -psi_a)) if keep[i]]
            for ia, a in enumerate(order):
                if keep[a]:
                    for b in order[ia + 1 :]:
                        dp = X[a, :2] - X[b, :2]
                        if keep[b] and dp @ np.linalg.solve(P[a, :2, :2] + P[b, :2, :2], dp) <= g2:
                            keep[b] = False
            ranked = [i for i in np.lexsort((ids, -psi_a)) if keep[i]]
            keep[ranked[params.max_tracks :]] = False
            X, P = X[keep], P[keep]
            psi = list(psi_a[keep])
            conf = list(conf_a[keep])
            ids = list(np.array(ids, dtype=np.int64)[keep])
            cands = [i for i in range(len(psi)) if conf[i]]
            if cands:
                best = min(cands, key=lambda i: (-psi[i], ids[i]))
                est[f], has[f] = X[best, :2], True
    return est, has


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


def _gui_retrack(ds, params, period: float, quick: bool) -> dict:
    """The GUI's re-track of its longest trajectory: every track recorded by the kernel
    (``run_tracker(engine="numba")``) against the readable ``run_tracker``, and whether every
    track of every frame agrees to 1e-10."""
    from core.tracking import run_tracker

    t_off, f_off = ds.trajectory_offsets, ds.frame_offsets
    k = int(np.argmax(np.diff(t_off)))
    a, b = int(t_off[k]), int(t_off[k + 1])
    frames = (ds.measurements()[f_off[a] : f_off[b]], f_off[a : b + 1] - f_off[a])
    fast = run_tracker(frames, params, period, engine="numba")
    t_fast, c_fast = _best_of(
        lambda: run_tracker(frames, params, period, engine="numba"), 3 if quick else 20
    )
    t0, c0 = time.perf_counter(), time.process_time()
    ref = run_tracker(frames, params, period)
    t_ref, c_ref = time.perf_counter() - t0, time.process_time() - c0
    same = all(
        np.array_equal(x.ids, y.ids)
        and np.array_equal(x.confirmed, y.confirmed)
        and np.allclose(x.state, y.state, rtol=1e-10, atol=1e-10)
        and np.allclose(x.covariance, y.covariance, rtol=1e-10, atol=1e-10)
        and np.allclose(x.psi, y.psi, rtol=0, atol=1e-10)
        and np.allclose(x.gate_shape_xy, y.gate_shape_xy, rtol=1e-10, atol=1e-8)
        for x, y in zip(fast.frames, ref.frames)
    )
    return {
        "gui_frames": b - a,
        "gui_record_ms": 1e3 * t_fast,
        "gui_record_cpu_ms": 1e3 * c_fast,
        "gui_reference_ms": 1e3 * t_ref,
        "gui_reference_cpu_ms": 1e3 * c_ref,
        "gui_speedup_cpu": c_ref / max(c_fast, 1e-9),
        "gui_same_every_track": bool(same),
    }


def run(quick: bool = False) -> dict:
    from core.evaluation import evaluate
    from core.tracking import TrackerParams, track_dataset
    from core.tracking.batch import dataset_frame_period_s

    ds, source = _dataset(quick)
    n_frames = ds.n_frames
    out: dict = {
        "data": source,
        "n_trajectories": int(ds.n_trajectories),
        "n_frames": int(n_frames),
        "n_points": len(ds.frame),
        "plain": "plain_track in core/benchmarks/track.py (per-frame numpy, one pass)",
        "reference": "core.tracking.run_tracker (readable role modules, one pass)",
        "models": {},
    }
    for model in ("cv", "ca"):
        # the plain reference implements independent IPDA: compare like with like
        p = replace(TrackerParams.default(model), association="ipda")
        t0 = time.perf_counter()
        fast = track_dataset(ds, p)  # first call: loads (or compiles) the kernel
        first = time.perf_counter() - t0
        t_fast, c_fast = _best_of(lambda p=p: track_dataset(ds, p), 3 if quick else 20)
        z, f_off, t_off = ds.measurements(), ds.frame_offsets, ds.trajectory_offsets
        period = dataset_frame_period_s(ds)
        t0, c0 = time.perf_counter(), time.process_time()
        plain_xy, plain_has = plain_track(z, f_off, t_off, p, period)
        t_plain, c_plain = time.perf_counter() - t0, time.process_time() - c0
        t0, c0 = time.perf_counter(), time.process_time()
        ref = track_dataset(ds, p, engine="numpy")
        t_ref, c_ref = time.perf_counter() - t0, time.process_time() - c0
        same = bool(
            np.array_equal(fast.has_estimate, plain_has)
            and np.allclose(fast.estimate_xy, plain_xy, atol=1e-8, equal_nan=True)
        )
        same_ref = bool(
            np.array_equal(fast.has_estimate, ref.has_estimate)
            and np.allclose(fast.estimate_xy, ref.estimate_xy, atol=1e-10, equal_nan=True)
        )
        loss = evaluate(ds, fast).loss_total
        gui = _gui_retrack(ds, p, period, quick)
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
            "reference_ms_per_pass": 1e3 * t_ref,
            "reference_cpu_ms_per_pass": 1e3 * c_ref,
            "speedup_vs_reference": t_ref / t_fast,
            "same_result_reference": same_ref,
            "loss_total_x1e3": 1e3 * loss,
            "mean_live_tracks": float(fast.n_tracks.mean()),
            **gui,
        }
    out["jipda"] = jipda_bench(ds, quick)
    out["gtrack"] = gtrack_bench(quick)
    out["room"] = room_bench(ds, quick)
    return out


#: gtrack's benchmark frames: four walkers of 25 points and 50 static points (150 a frame).
GTRACK_PEOPLE, GTRACK_POINTS, GTRACK_STATIC, GTRACK_FRAMES = 4, 25, 50, 1000


def gtrack_bench(quick: bool = False) -> dict:
    """gtrack (compiled, TI's default lines) on 150-point frames with four walkers, against the
    paper's tracker (compiled JIPDA, CV defaults) on the same points' [r, az, vr] in the same
    run: CPU time of a pass, best of repeats, and the ratio; the readable gtrack once."""
    from core.tracking import TrackerParams
    from core.tracking.gtrack import GtrackParams, run_gtrack
    from core.tracking.gtrack.compiled import run_gtrack_compiled
    from core.tracking.gtrack.synthetic import people_frames
    from core.tracking.kernel import track_frames

    n_frames = 200 if quick else GTRACK_FRAMES
    gp = GtrackParams()
    pts, off, _ = people_frames(
        np.random.default_rng(0),
        gp,
        n_frames=n_frames,
        n_people=GTRACK_PEOPLE,
        points_per_person=GTRACK_POINTS,
        static_points=GTRACK_STATIC,
    )
    repeats = 3 if quick else 15
    t0 = time.perf_counter()
    res = run_gtrack_compiled(pts, off, gp, frames=False)  # loads (or compiles) the kernel
    first = time.perf_counter() - t0
    _, c_g = _best_of(lambda: run_gtrack_compiled(pts, off, gp, frames=False), repeats)
    z = np.ascontiguousarray(pts[:, [0, 1, 3]])
    t_off = np.array([0, n_frames], dtype=np.int64)
    sel = np.zeros(1, dtype=np.int64)
    pp = TrackerParams.default("cv")
    track_frames(z, off, t_off, sel, pp, gp.frame_period_s, record=False)
    _, c_p = _best_of(
        lambda: track_frames(z, off, t_off, sel, pp, gp.frame_period_s, record=False), repeats
    )
    n_read = min(n_frames, 100)
    c0 = time.process_time()
    run_gtrack(pts[: off[n_read]], off[: n_read + 1], gp)
    c_r = time.process_time() - c0
    return {
        "frames": n_frames,
        "points_per_frame": float(off[-1] / n_frames),
        "scene": "core.tracking.gtrack.synthetic.people_frames: 4 walkers x 25 points, 50 "
        "static points, seed 0; gtrack with TI's default lines (GtrackParams())",
        "first_call_s": first,
        "gtrack_frames_per_s": n_frames / c_g,
        "gtrack_us_per_frame": 1e6 * c_g / n_frames,
        "paper_jipda_frames_per_s": n_frames / c_p,
        "ratio_gtrack_to_paper_time": c_g / c_p,
        "readable_gtrack_frames_per_s": n_read / c_r,
        "compiled_over_readable": (n_read / c_r and (n_frames / c_g) / (n_read / c_r)),
        "mean_active_tracks": float(np.mean(res.n_active)),
    }


#: Frames of the room scene of the room-mode measurement (four people, 150 points a frame).
ROOM_FRAMES = 1000


def room_bench(ds, quick: bool = False) -> dict:
    """The room mode's speed, in the same run as the paper mode: CPU time of a pass over the
    paper data set (room defaults against paper defaults, CV), and frames/s on a room scene of
    four people circling with 150 points a frame (:func:`core.tracking.stability.room_scenes`);
    plus whether the compiled room loop equals its plain-Python run on that scene."""
    from core.tracking import TrackerParams, track_dataset
    from core.tracking.stability import room_scenes

    repeats = 3 if quick else 15
    paper, room = TrackerParams.default("cv"), TrackerParams.default("cv", mode="room")
    # the room defaults need 18 points to start a track: none on a one-point-a-person set; with
    # n_alloc = 1 and SNR_alloc = 1 dB the room mode tracks it (the cost that matters)
    room1 = replace(room, alloc_points=1.0, alloc_snr=1.0)
    row: dict = {}
    for name, p in (("paper", paper), ("room", room), ("room_alloc1", room1)):
        est = track_dataset(ds, p)  # loads (or compiles) the kernel
        _, cpu = _best_of(lambda p=p: track_dataset(ds, p), repeats)
        row[f"{name}_cpu_ms_per_pass"] = 1e3 * cpu
        row[f"{name}_frames_per_s"] = ds.n_frames / cpu
        row[f"{name}_mean_confirmed"] = float(est.n_confirmed.mean())
    row["cpu_ratio_room_to_paper"] = row["room_cpu_ms_per_pass"] / row["paper_cpu_ms_per_pass"]
    row["cpu_ratio_room_alloc1_to_paper"] = (
        row["room_alloc1_cpu_ms_per_pass"] / row["paper_cpu_ms_per_pass"]
    )
    n_frames = 200 if quick else ROOM_FRAMES
    scene = room_scenes(n_frames, seed=0)["room, 4 people circling"]
    scene_row: dict = {"frames": n_frames, "points_per_frame": len(scene.frame) / n_frames}
    for name, p in (("paper", paper), ("room", room)):
        est = track_dataset(scene, p)
        _, cpu = _best_of(lambda p=p: track_dataset(scene, p), repeats)
        scene_row[f"{name}_frames_per_s"] = n_frames / cpu
        scene_row[f"{name}_mean_confirmed"] = float(est.n_confirmed.mean())
    short = room_scenes(100 if quick else 300, seed=0)["room, 4 people circling"]
    a = track_dataset(short, room, engine="numpy")
    b = track_dataset(short, room)
    scene_row["compiled_equals_plain"] = bool(
        np.array_equal(a.n_confirmed, b.n_confirmed)
        and np.allclose(a.estimate_xy, b.estimate_xy, rtol=0, atol=1e-10, equal_nan=True)
    )
    return {"paper_data_set": row, "room_scene": scene_row}


#: People in the cost-against-people measurement.
PEOPLE = (1, 2, 4, 8)
#: Frames of the multi-person scenes (people circling and crossing, paper clutter).
PEOPLE_FRAMES = 1000


def jipda_bench(ds, quick: bool = False) -> dict:
    """JIPDA against IPDA in the same run: on the single-person data set (CPU time of a pass,
    best of repeats, ratio) and on scenes of 1, 2, 4 and 8 people circling and crossing in a
    room for 1 000 frames with the paper's clutter (frames/s). Writes the cost plot to
    docs/tracking/jipda_cost.png (``bench/results/jipda_cost-quick.png`` when quick)."""
    from core.evaluation import evaluate
    from core.tracking import TrackerParams, track_dataset
    from core.tracking.synthetic import circling_paths, people_dataset

    repeats = 3 if quick else 15
    single: dict = {}
    for model in ("cv", "ca"):
        row = {}
        for assoc in ("ipda", "jipda"):
            p = replace(TrackerParams.default(model), association=assoc)
            est = track_dataset(ds, p)
            _, cpu = _best_of(lambda p=p: track_dataset(ds, p), repeats)
            row[f"{assoc}_cpu_ms_per_pass"] = 1e3 * cpu
            row[f"{assoc}_loss_total_x1e3"] = 1e3 * evaluate(ds, est).loss_total
        row["cpu_ratio_jipda_to_ipda"] = row["jipda_cpu_ms_per_pass"] / row["ipda_cpu_ms_per_pass"]
        single[model] = row
    n_frames = 200 if quick else PEOPLE_FRAMES
    people: dict = {}
    for n in PEOPLE:
        pos, vel = circling_paths(n, n_frames)
        scene_ds = people_dataset(pos, vel, seed=n)
        row = {"points_per_frame": len(scene_ds.frame) / n_frames}
        for assoc in ("ipda", "jipda"):
            p = replace(TrackerParams.default("cv"), association=assoc)
            est = track_dataset(scene_ds, p)
            _, cpu = _best_of(lambda p=p, d=scene_ds: track_dataset(d, p), repeats)
            row[f"{assoc}_frames_per_s"] = n_frames / cpu
            row[f"{assoc}_us_per_frame"] = 1e6 * cpu / n_frames
            row[f"{assoc}_mean_confirmed"] = float(est.n_confirmed.mean())
        people[str(n)] = row
    out = {
        "single_person": single,
        "people_scene": f"core.tracking.synthetic.circling_paths, {n_frames} frames, "
        "2.1 clutter points a frame (PAPER_LIKE), CV defaults, CPU time best of repeats",
        "people_frames": n_frames,
        "people": people,
    }
    out["plot"] = str(_plot_people_cost(out, quick))
    return out


def _plot_people_cost(result: dict, quick: bool):
    from pathlib import Path

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path = Path("bench/results/jipda_cost-quick.png" if quick else "docs/tracking/jipda_cost.png")
    path.parent.mkdir(parents=True, exist_ok=True)
    ns = [int(n) for n in result["people"]]
    fig, ax = plt.subplots(figsize=(6, 4))
    for assoc, mk in (("ipda", "o-"), ("jipda", "s-")):
        ys = [result["people"][str(n)][f"{assoc}_us_per_frame"] for n in ns]
        ax.plot(ns, ys, mk, label=assoc.upper())
    ax.axhline(50.0, color="r", ls=":", label="20 000 frames/s")
    ax.set_xscale("log", base=2)
    ax.set_xticks(ns, [str(n) for n in ns])
    ax.set_xlabel("people in the scene (circling and crossing, paper clutter)")
    ax.set_ylabel("CPU time per frame (µs), compiled kernel")
    ax.set_title(f"tracker cost against the number of people ({result['people_frames']} frames)")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    plt.close(fig)
    return path


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
    lines.append("readable reference (core.tracking.run_tracker), same run:")
    for model, r in result["models"].items():
        lines.append(
            f"{model:>5} {r['reference_ms_per_pass']:7.0f} ms "
            f"({r['reference_cpu_ms_per_pass']:6.0f})  kernel "
            f"{r['speedup_vs_reference']:4.0f}x faster, same: {r['same_result_reference']}"
        )
    lines.append("GUI re-track of one trajectory, every track recorded (run_tracker engine=numba):")
    for model, r in result["models"].items():
        lines.append(
            f"{model:>5} {r['gui_frames']} frames: {r['gui_record_ms']:6.2f} ms "
            f"({r['gui_record_cpu_ms']:6.2f}) vs readable {r['gui_reference_ms']:6.0f} ms "
            f"({r['gui_reference_cpu_ms']:6.0f}), {r['gui_speedup_cpu']:4.0f}x (CPU), "
            f"every track same: {r['gui_same_every_track']}"
        )
    j = result.get("jipda")
    if j:
        lines.append("JIPDA against IPDA, same run (CPU ms a pass, loss x1e3):")
        for model, r in j["single_person"].items():
            lines.append(
                f"{model:>5} IPDA {r['ipda_cpu_ms_per_pass']:6.2f} ms  JIPDA "
                f"{r['jipda_cpu_ms_per_pass']:6.2f} ms  ratio {r['cpu_ratio_jipda_to_ipda']:4.2f}"
                f"  loss {r['ipda_loss_total_x1e3']:.4f} / {r['jipda_loss_total_x1e3']:.4f}"
            )
        lines.append(f"people scenes ({j['people_scene']}):")
        for n, r in j["people"].items():
            lines.append(
                f"{n:>5} people {r['points_per_frame']:5.1f} points/frame: IPDA "
                f"{r['ipda_frames_per_s']:8.0f} frames/s, JIPDA {r['jipda_frames_per_s']:8.0f} "
                f"frames/s ({r['jipda_us_per_frame']:6.1f} µs/frame), confirmed tracks "
                f"{r['jipda_mean_confirmed']:.2f}"
            )
        lines.append(f"plot: {j['plot']}")
    g = result.get("gtrack")
    if g:
        lines.append(
            f"gtrack ({g['frames']} frames, {g['points_per_frame']:.0f} points a frame, "
            f"{g['mean_active_tracks']:.2f} ACTIVE tracks): {g['gtrack_frames_per_s']:.0f} "
            f"frames/s ({g['gtrack_us_per_frame']:.0f} µs a frame, CPU); the paper's JIPDA on "
            f"the same points {g['paper_jipda_frames_per_s']:.0f} frames/s (gtrack takes "
            f"{g['ratio_gtrack_to_paper_time']:.2f}x its time); readable gtrack "
            f"{g['readable_gtrack_frames_per_s']:.0f} frames/s ({g['compiled_over_readable']:.0f}x)"
        )
    r = result.get("room")
    if r:
        pr, sc = r["paper_data_set"], r["room_scene"]
        lines.append(
            f"room mode, same run (CV defaults, CPU best of repeats): paper data set "
            f"{pr['paper_cpu_ms_per_pass']:.2f} ms paper mode, {pr['room_cpu_ms_per_pass']:.2f} "
            f"ms room mode a pass, ratio {pr['cpu_ratio_room_to_paper']:.2f} (confirmed "
            f"{pr['room_mean_confirmed']:.2f}); n_alloc = 1: "
            f"{pr['room_alloc1_cpu_ms_per_pass']:.2f} ms, ratio "
            f"{pr['cpu_ratio_room_alloc1_to_paper']:.2f} (confirmed "
            f"{pr['room_alloc1_mean_confirmed']:.2f}, paper {pr['paper_mean_confirmed']:.2f})"
        )
        lines.append(
            f"  room scene, 4 people, {sc['points_per_frame']:.0f} points/frame, "
            f"{sc['frames']} frames: room {sc['room_frames_per_s']:.0f} frames/s "
            f"(confirmed {sc['room_mean_confirmed']:.2f}), paper {sc['paper_frames_per_s']:.0f} "
            f"frames/s (confirmed {sc['paper_mean_confirmed']:.2f}); compiled = plain: "
            f"{sc['compiled_equals_plain']}"
        )
    return "\n".join(lines)

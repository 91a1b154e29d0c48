"""The fidelity bench's report: Markdown tables and the plot, written from its JSON figures.

:func:`render` writes ``results.md`` and the error-against-run-time plot from the dict that
:func:`core.benchmarks.fidelity.run` returns (and ``radartune bench fidelity`` stores in
``bench/results/fidelity.json``), so the report can be re-rendered without re-running the
bench (``radartune bench fidelity --render-only``). Tables stay short (at most 8 columns): the
verdict first, then one table per quantity; every other figure stays in the JSON.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from core.evaluation.intervals import LOSS_TOLERANCE, TAIL_FACTOR
from core.files import save_figure, write_text_atomic

__all__ = ["render", "report_paths", "summary", "tables"]


def _tail(person_model: str) -> str:
    """File-name tail of a person model's report: nothing for the paper's point person."""
    return "" if person_model == "point" else f"-{person_model}"


def result_name(person_model: str = "point", quick: bool = False) -> str:
    """The result's file stem: ``fidelity``, ``fidelity-walking``, ``…-quick``."""
    return f"fidelity{_tail(person_model)}{'-quick' if quick else ''}"


def report_paths(quick: bool = False, person_model: str = "point") -> tuple[Path, Path]:
    """Where the report goes: ``(table.md, plot.png)`` (the quick run's beside its JSON)."""
    if quick:
        stem = Path("bench/results") / result_name(person_model, quick)
        return stem.with_suffix(".md"), stem.with_suffix(".png")
    tail = _tail(person_model)
    return Path(f"docs/fidelity/results{tail}.md"), Path(
        f"docs/fidelity/error_vs_runtime{tail}.png"
    )


def render(result: dict, quick: bool = False) -> tuple[Path, Path]:
    """Write the Markdown tables and the plot of a fidelity result; returns their paths."""
    md, png = report_paths(quick, result.get("person_model", "point"))
    md.parent.mkdir(parents=True, exist_ok=True)
    _write_table(result, md)
    _plot(result, png)
    return md, png


def _fmt(v, spec: str = ".3g") -> str:
    return "–" if v is None else format(v, spec)


def _interval(x: float, ci: list[float], spec: str) -> str:
    """``x (lo–hi)``: a figure and its interval ``ci = [lo, hi]``."""
    lo, hi = ci
    return f"{x:{spec}} ({lo:{spec}}–{hi:{spec}})"


def _main_table(result: dict) -> str:
    """Speed and the verdict per level: the bulk loss ratios, the tail-event rate ratios and
    the false points."""
    lv = result["levels"]
    rows = [
        "| level | frames/s (per-frame call) | speed-up | bulk loss CV / exact (95 %) | "
        "bulk loss CA / exact (95 %) | tail-event rate / exact, CV; CA | false pts/frame |",
        "|---|---|---|---|---|---|---|",
    ]
    for name, r in lv.items():
        pf = r.get("per_frame_call_fps")
        fps = f"{r['fps']:.0f}" + ("" if pf is None else f" ({pf:.0f})")
        if name in ("exact", "exact*"):
            bulk = {m: "1 (reference)" if name == "exact" else "see exact" for m in ("cv", "ca")}
            tail = "–"
        else:
            t = r["tracking"]
            bulk = {
                m: _interval(t[m]["bulk_loss_ratio_to_exact"], t[m]["bulk_loss_ratio_ci95"], ".3f")
                + f" {t[m]['bulk_verdict_within_10pct']}"
                for m in ("cv", "ca")
            }
            tail = "; ".join(
                _interval(
                    t[m]["tail_rate_ratio_to_exact"][0], t[m]["tail_rate_ratio_to_exact"][1:], ".2f"
                )
                for m in ("cv", "ca")
            )
        rows.append(
            f"| {name} | {fps} | {r['speedup']:.1f} | {bulk['cv']} | {bulk['ca']} | {tail} | "
            f"{r['false_points_per_frame']:.3f} |"
        )
    return "\n".join(rows)


def _points_table(result: dict) -> str:
    """The person's point errors (mean/sd, KS distance to exact), Pd and clutter per level."""
    lv = result["levels"]
    rows = [
        "| level | seeds | Pd person | range err mean/sd (mm); KS | "
        "az err mean/sd (robust sd) (°); KS | vr err mean/sd (m/s); KS | SNR mean (dB); KS | "
        "clutter pts/frame |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name, r in lv.items():
        re, ae, ve, sn = (
            r["range_error_m"],
            r["azimuth_error_deg"],
            r["radial_velocity_error_mps"],
            r["snr_db"],
        )
        mean_mm = None if re["mean"] is None else 1e3 * re["mean"]
        sd_mm = None if re["sd"] is None else 1e3 * re["sd"]
        rows.append(
            f"| {name} | {r['noise_seeds'] if name != 'exact*' else 1} | "
            f"{r['person_pd']:.3f} | "
            f"{_fmt(mean_mm, '.2f')}/{_fmt(sd_mm, '.2f')}; {_fmt(re['ks'], '.3f')} | "
            f"{_fmt(ae['mean'], '.3f')}/{_fmt(ae['sd'], '.3f')} "
            f"({_fmt(ae.get('robust_sd'), '.3f')}); {_fmt(ae['ks'], '.3f')} | "
            f"{_fmt(ve['mean'], '.4f')}/{_fmt(ve['sd'], '.4f')}; {_fmt(ve['ks'], '.3f')} | "
            f"{_fmt(sn['mean'], '.2f')}; {_fmt(sn['ks'], '.3f')} | "
            f"{r['clutter_points_per_frame']:.3f} |"
        )
    return "\n".join(rows)


def _tracking_table(result: dict) -> str:
    """The whole loss of eq. (14) per level and model, its ratio to exact, RMSE and run time."""
    lv = result["levels"]
    rows = [
        "| level | model | loss ×1e-3 mean (seed min–max) | ratio to exact (95 %) | "
        "within 10 %? | median traj. loss ×1e-3 | RMSE (m) | trial CPU (s) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name, r in lv.items():
        if name == "exact*":
            continue
        for model in ("cv", "ca"):
            t = r["tracking"][model]
            ratio = (
                "–"
                if name == "exact"
                else _interval(t["loss_ratio_to_exact"], t["loss_ratio_ci95"], ".2f")
            )
            rows.append(
                f"| {name} | {model.upper()} | {_losses(t)} | {ratio} | "
                f"{t['verdict_within_10pct']} | {t['median_trajectory_loss_x1e3']:.4f} | "
                f"{t['rmse_m']:.3f} | {t['trial_cpu_s']:.2f} |"
            )
    return "\n".join(rows)


def _loss_table(result: dict) -> str:
    """The 10 % criterion, the mean loss of eq. (14) taken apart: the runs without a confirmed
    track; of the others, the tail events (rate, their share of the loss) and the bulk (mean
    loss, ratio with its paired bootstrap interval, verdict); then the yardstick."""
    lv = result["levels"]
    rows = [
        "| level | model | runs without a confirmed track (rate, 95 %) | "
        "tail events (rate, 95 %) | tail share of the loss | bulk loss ×1e-3 | "
        "bulk: ratio to exact (95 %) | within 10 %? |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name, r in lv.items():
        if name == "exact*":
            continue
        for model in ("cv", "ca"):
            t = r["tracking"][model]
            q, qlo, qhi = t["no_track_rate_ci95"]
            e, elo, ehi = t["tail_rate_ci95"]
            bulk = (
                "–"
                if name == "exact"
                else _interval(t["bulk_loss_ratio_to_exact"], t["bulk_loss_ratio_ci95"], ".3f")
            )
            rows.append(
                f"| {name} | {model.upper()} | {t['no_track_runs']} of "
                f"{t['trajectory_runs']} ({100 * q:.2f} %, {100 * qlo:.2f}–{100 * qhi:.2f} %) | "
                f"{t['tail_events']} ({100 * e:.2f} %, {100 * elo:.2f}–{100 * ehi:.2f} %) | "
                f"{100 * t['tail_loss_share']:.0f} % | "
                f"{t['bulk_loss_x1e3']:.5f} | {bulk} | {t['bulk_verdict_within_10pct']} |"
            )
    ex = lv["exact"]["tracking"]
    yard = []
    for model in ("cv", "ca"):
        v = ex[model].get("exact_seed_ratio_to_others") or []
        w = ex[model].get("exact_seed_regular_ratio_to_others") or []
        if v:
            yard.append(
                f"{model.upper()}: one exact seed against the mean of the others, loss "
                + ", ".join(f"{x:.2f}" for x in v)
                + "; regular loss "
                + ", ".join(f"{x:.2f}" for x in w)
            )
    for model in ("cv", "ca"):
        half = ex[model].get("exact_half_bulk_ratio")
        if half:
            yard.append(
                f"{model.upper()} bulk, `exact`'s second half of seeds against its first half: "
                f"{half[0]:.3f} ({half[1]:.3f}–{half[2]:.3f})"
            )
    return "\n".join(rows) + ("\n\nYardstick — " + "; ".join(yard) if yard else "")


def _losses(t: dict) -> str:
    v = t["loss_x1e3_per_seed"]
    return f"{t['loss_x1e3_mean']:.3f} ({min(v):.3f}–{max(v):.3f})"


def tables(result: dict) -> str:
    """Every table of the report, in order, with a heading each."""
    return (
        "## Speed and verdict\n\n"
        + _main_table(result)
        + "\n\n## The person's points\n\n"
        + _points_table(result)
        + "\n\n## Tracking loss\n\n"
        + _tracking_table(result)
        + "\n\n## The loss taken apart\n\n"
        + _loss_table(result)
    )


def _write_table(result: dict, path: Path) -> None:
    model = result.get("person_model", "point")
    flag = "" if model == "point" else f" --person-model {model}"
    who = "" if model == "point" else f" ({model} person)"
    text = (
        f"# Fidelity levels: error against run time{who}\n\n"
        f"Command: `{result.get('command', 'radartune bench fidelity' + flag)}` (writes this "
        "file, the plot and "
        f"`bench/results/{result_name(model)}.json`, which holds every figure; "
        f"`radartune bench fidelity{flag} --render-only` re-renders this file and the plot from "
        "it).\n\n"
        f"- Scenes: {result['scenes']}; {result['frames_per_level']} frames per level and seed.\n"
        f"- Noise seeds: {result['noise_seeds']}.\n"
        f"- Tracker: {result['tracker_parameters']}.\n"
        f"- Timing: {result['timing']}.\n"
        "- KS: two-sample Kolmogorov-Smirnov distance of the person's point errors to `exact` "
        "(first seed of each level); `exact*` is the yardstick (same scenes, other noise).\n"
        + (
            ""
            if model == "point"
            else "- Point errors of a body: offsets from the mean of its scatterers (position "
            "and velocity at the frame's middle), so their spread is the body's.\n"
        )
        + "- Loss: eq. (14) on the level's own data set (×1e-3), mean over the noise seeds "
        "(smallest and largest seed in brackets); trial CPU = simulation of the data set + one "
        "tracking run.\n"
        f"- Loss ratio: mean loss of the level over that of `exact`, each trajectory's loss "
        f"averaged over the level's seeds; interval: {result['bootstrap']}. Verdict "
        f"`within` when the whole interval lies in {1 - LOSS_TOLERANCE:g}–"
        f"{1 + LOSS_TOLERANCE:g}, `outside` when it misses that band, else `undecided`.\n"
        "- The mean loss taken apart: runs (one trajectory, one seed) without a "
        "confirmed track (L = 1 m² each); of the others, *tail events*, runs whose loss exceeds "
        f"{TAIL_FACTOR:g}× the exact level's median loss of that trajectory (the estimate sat on "
        "a clutter or ghost track), with their rate, the rate ratio to `exact` (exact "
        "conditional binomial interval) and their share of the regular loss; and the *bulk*, "
        "the mean loss of the remaining runs, whose ratio to `exact` carries the 10 % "
        "verdict (paired bootstrap over the trajectories). The whole mean is decided by a "
        "handful of tail runs and cannot be pinned to 10 % with these seeds.\n\n"
        + tables(result)
        + "\n"
    )
    write_text_atomic(path, text)


def _plot(result: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FormatStrFormatter, LogLocator, NullFormatter, ScalarFormatter

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
    fps = [lv[n]["fps"] for n in names]
    ax1.set_xlim(min(fps) / 1.8, max(fps) * 1.8)  # room for the labels
    ax1.set_title("point errors against run time")
    ax1.legend(fontsize=8, loc="center left")  # clear of the levels' markers and labels
    names = [n for n in names if n != "exact*"]
    for model, mk in (("cv", "o"), ("ca", "s")):
        xs = np.array([lv[n]["tracking"][model]["trial_cpu_s"] for n in names])
        ex = lv["exact"]["tracking"][model]["bulk_loss_x1e3"]
        ys = np.array([lv[n]["tracking"][model]["bulk_loss_ratio_to_exact"] for n in names])
        ci = np.array(
            [
                lv[n]["tracking"][model]["bulk_loss_ratio_ci95"] if n != "exact" else [1, 1]
                for n in names
            ]
        )
        # exact: its second half of seeds against its first half (the bulk's yardstick)
        half = lv["exact"]["tracking"][model].get("exact_half_bulk_ratio") or [1.0, 1.0, 1.0]
        ci[0] = [min(half[1], 1.0), max(half[2], 1.0)]
        ax2.errorbar(
            xs, ys, yerr=[ys - ci[:, 0], ci[:, 1] - ys], fmt=mk, capsize=3,
            label=f"{model.upper()} (exact: {ex:.5f}e-3)", alpha=0.8,
        )  # fmt: skip
        if model == "cv":
            for n, x, y in zip(names, xs, ys):
                ax2.annotate(n, (x, y), textcoords="offset points", xytext=(6, 6), fontsize=8)
    ax2.axhspan(1 - LOSS_TOLERANCE, 1 + LOSS_TOLERANCE, color="g", alpha=0.12, label="±10 %")
    # about one decade: label the 2s and 5s too, or only "1" shows
    ax2.xaxis.set_minor_formatter(FormatStrFormatter("%g"))
    ax2.set_xlabel("CPU time per trial: simulate the data set + track it (s)")
    ax2.set_ylabel(
        "bulk tracking loss / exact's\n(95 % bootstrap interval; exact: half against half)"
    )
    ax2.set_title(f"bulk tracking loss (runs < {TAIL_FACTOR:g}× exact's median) vs run time")
    ax2.legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    plt.close(fig)


def summary(result: dict) -> str:
    """Terminal summary: the main table (speed and verdict)."""
    return f"{result['scenes']}\n" + _main_table(result)

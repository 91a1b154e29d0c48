"""``radartune bench gui``: the desktop app's responsiveness, measured in the real window.

The measurement itself is :mod:`app.bench_gui` (it needs Qt, which ``core`` never imports): it
runs here as a child process (``python -m app.bench_gui``), once with Qt's ``offscreen`` platform
and once under Xvfb with the real ``xcb`` platform when ``xvfb-run`` is installed. Figures: slider
to overlay drawn (median, ms; target ≤ 100 on the paper scene), playback redraws per second at
4× and 8× (target ≥ 45), and the event loop's longest gap and gaps over 100 ms while a study runs
(target: none over 100 ms), with an idle probe of the same run as reference; a live link at 20
frames/s over the sensor emulator (target: last byte to drawn ≤ 50 ms median, no dropped frame);
the 3-D view's redraws per second with 2 000 points, docked and floated at 1280 x 800 px
(target ≥ 30; xcb only, offscreen has no OpenGL).
"""

from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from core.errors import InputError

ROOT = Path(__file__).resolve().parents[2]
#: the Xvfb screen of the ``xcb`` run
XVFB_SCREEN = "1920x1080x24"


def _run_app(platform: str, quick: bool, soak_s: float | None = None) -> dict:
    with tempfile.TemporaryDirectory(prefix="radartune-bench-gui-") as tmp:
        out = Path(tmp) / "gui.json"
        cmd = [sys.executable, "-m", "app.bench_gui", "--json", str(out)]
        if quick:
            cmd.append("--quick")
        if soak_s is not None:
            cmd += ["--soak", repr(float(soak_s))]
        env = dict(os.environ, QT_QPA_PLATFORM=platform)
        env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT), env.get("PYTHONPATH")) if p)
        if platform == "xcb":
            cmd = ["xvfb-run", "-a", "-s", f"-screen 0 {XVFB_SCREEN}", *cmd]
        done = subprocess.run(cmd, cwd=tmp, env=env, capture_output=True, text=True)
        if done.returncode != 0 or not out.exists():
            tail = " ".join(done.stderr.strip().splitlines()[-3:])
            raise InputError(f"the GUI benchmark failed on {platform}: {tail}", "bench gui")
        return json.loads(out.read_text())


def run(quick: bool = False, soak_s: float | None = None) -> dict:
    """All figures; ``soak_s``: the live link alone for that many seconds (offscreen: the link
    and the 2-D views need no OpenGL), written as ``soak``."""
    if soak_s is not None:
        if not (soak_s > 0 and math.isfinite(soak_s)):
            raise InputError(f"--soak must be a positive number of seconds, got {soak_s!r}")
        return {
            "soak": _run_app("offscreen", quick, soak_s)["soak"],
            "targets": {"live_latency_median_ms": 50, "live_dropped_frames": 0},
        }
    result: dict[str, object] = {"offscreen": _run_app("offscreen", quick)}
    if shutil.which("xvfb-run"):
        result["xcb"] = _run_app("xcb", quick)
    else:
        result["xcb"] = None  # Xvfb not installed: `apt-get install xvfb`
    result["targets"] = {
        "slider_to_overlay_median_ms": 100,
        "playback_redraws_per_s": 45,
        "study_gaps_over_100_ms": 0,
        "live_latency_median_ms": 50,
        "live_dropped_frames": 0,
        "cloud3d_redraws_per_s": 30,
    }
    return result


def _live_line(name: str, lv: dict) -> str:
    lat = lv["latency_ms"]
    line = (
        f"{name} ({1e3 / lv['frame_period_ms']:g} frames/s, "
        f"{lv['seconds']} s): last byte→drawn tracked median {lat['median']} ms "
        f"(p90 {lat['p90']}, max {lat['max']}, "
        f"{lv['frames_drawn_tracked']} frames drawn) · "
        f"{lv['frames_received']} of {lv['frames_sent']} frames received, "
        f"{lv['dropped']} dropped, {lv['damaged']} damaged · longest event-loop gap "
        f"{lv['max_gap_ms']} ms"
    )
    if lv.get("rss_start_mb") is not None:
        line += (
            f" · RSS {lv['rss_start_mb']} → {lv['rss_end_mb']} MB "
            f"({lv['rss_growth_kb_per_frame']} kB a frame received)"
        )
    return line


def summary(result: dict) -> str:
    if "soak" in result:
        return _live_line("offscreen live link soak", result["soak"])
    lines = []
    for platform in ("offscreen", "xcb"):
        r = result.get(platform)
        if not r:
            lines.append(f"{platform}: not run (no xvfb-run)")
            continue
        s, pb, st = r["slider_to_overlay_ms"], r["playback"], r["study"]
        lines.append(
            f"{platform}: first track {r['first_track_s']} s · slider→overlay median "
            f"{s['median']} ms ({s['min']}–{s['max']}, n={s['n']}) · playback 4x "
            f"{pb['4x']['redraws_per_s']} / 8x {pb['8x']['redraws_per_s']} redraws/s · study: "
            f"{st.get('n_complete', 0) + st.get('n_pruned', 0)} of {st.get('n_trials', '?')} "
            f"trials, longest gap {st['max_gap_ms']} ms, {st['n_gaps_over_100_ms']} over 100 ms "
            f"(idle: longest {r['idle']['max_gap_ms']} ms)"
        )
        if st.get("errors"):  # a study that did not run measured nothing
            lines.append(f"{platform}: the study did not run: {st['errors'][0]}")
        c3 = r.get("cloud3d")
        if c3:
            lines.append(
                f"{platform} 3-D view: {c3['not_run']}"
                if "not_run" in c3
                else f"{platform} 3-D view, {c3['points']} points, {c3['gl_px'][0]}x"
                f"{c3['gl_px'][1]} px: {c3['snr_redraws_per_s']} redraws/s coloured by SNR "
                f"({c3['snr_cpu_ms_per_redraw']} ms CPU each), {c3['track_redraws_per_s']} by "
                f"track ({c3['track_cpu_ms_per_redraw']} ms CPU)"
            )
            full = c3.get("full")
            if full:
                lines.append(
                    f"{platform} 3-D view at {full['gl_px'][0]}x{full['gl_px'][1]} px: "
                    f"{full['snr_redraws_per_s']} redraws/s by SNR "
                    f"({full['snr_cpu_ms_per_redraw']} ms CPU), {full['track_redraws_per_s']} "
                    f"by track ({full['track_cpu_ms_per_redraw']} ms CPU)"
                )
        lv = r.get("live")
        if lv:
            lines.append(_live_line(f"{platform} live link", lv))
    return "\n".join(lines)

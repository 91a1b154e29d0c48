"""Noise false alarms per frame of the ``exact`` chain and the ``fast`` level, and the model.

``python -m core.benchmarks.false_alarms [--quick] [--frames N]`` (or, once registered,
``radartune bench false_alarms``): noise-only frames of the paper scene's radar and processing
(``pipeline.processing_settings``), for the default settings and variants:

- exact chain: its own stages on white ADC noise (noise cube, range FFT, Doppler FFT with static
  clutter removal, channel sum, ``two_stage_cfar``); the settings that share the windows share
  the maps (the CFAR is the only difference);
- fast level: ``simulate_frames_fast`` with ``Scatterers.empty()``, frame ``f`` seeded by
  ``default_rng(f + 12345)``;
- model: :func:`core.processing.false_alarms.noise_detections_per_frame` with the exact chain's
  thresholds on correlated cells.

Also the cost of the fast level's thresholds on first call (cache cleared), next to the time of
one exact frame of the same run for scale.
"""

from __future__ import annotations

import argparse
import dataclasses
import time

import numpy as np

from core import pipeline
from core.config import ProcessingSettings
from core.processing import doppler_fft, false_alarms, range_doppler_map, range_fft, two_stage_cfar
from core.processing.false_alarms import noise_detections_per_frame
from core.scene import paper_scenes
from core.simulation import AntennaGain, fast_cfar, synthesize_noise
from core.simulation import fast as fast_level
from core.simulation.scatterers import Scatterers


def variants(base: ProcessingSettings) -> dict[str, ProcessingSettings]:
    """The measured settings: the chain's default and one change each."""
    rc, dc = base.range_cfar, base.doppler_cfar
    return {
        "default": base,
        "no peak grouping": dataclasses.replace(base, peak_grouping=False),
        "CA range stage": dataclasses.replace(
            base, range_cfar=dataclasses.replace(rc, method="ca")
        ),
        "pfa x10 both stages": dataclasses.replace(
            base,
            range_cfar=dataclasses.replace(rc, pfa=10 * rc.pfa),
            doppler_cfar=dataclasses.replace(dc, pfa=10 * dc.pfa),
        ),
        "no CFAR noise model": dataclasses.replace(base, cfar_noise_model=False),
        "Blackman / Hamming": dataclasses.replace(
            base, range_window="blackman", doppler_window="hamming"
        ),
        "rect windows": dataclasses.replace(base, range_window="rect", doppler_window="rect"),
    }


def _mean_se(counts) -> tuple[float, float]:
    c = np.asarray(counts, dtype=float)
    return float(c.mean()), float(c.std(ddof=1) / np.sqrt(c.size))


def run(quick: bool = False, n_frames: int | None = None) -> dict:
    """Measure every variant; returns JSON-ready figures."""
    n = n_frames if n_frames is not None else (1000 if quick else 20000)
    scene = paper_scenes(0, 1)[0]
    radar = scene.radar
    base = pipeline.processing_settings(scene)
    settings = variants(base)
    antenna = AntennaGain.draw(radar, pipeline.stage_rng(0, "antenna"))
    L = radar.n_virtual
    rows = {}
    # exact chain: one noise map per frame and window pair, every CFAR setting on it
    groups: dict[tuple, list[str]] = {}
    for name, s in settings.items():
        key = (s.range_window, s.doppler_window, s.static_clutter_removal)
        groups.setdefault(key, []).append(name)
    exact_counts: dict[str, list[int]] = {name: [] for name in settings}
    t_exact = 0.0
    for (rw, dw, removal), names in groups.items():
        rng = np.random.default_rng(12345)
        for _ in range(n):
            t0 = time.perf_counter()
            cube = range_fft(synthesize_noise(radar, rng), rw)
            rd = range_doppler_map(doppler_fft(cube, dw, remove_static=removal))
            for name in names:
                exact_counts[name].append(len(two_stage_cfar(rd, radar, settings[name])))
            t_exact += time.perf_counter() - t0
    for name, s in settings.items():
        fast_cfar._independent_stages.cache_clear()
        fast_cfar.independent_factors.cache_clear()
        fast_cfar.cfar_arguments.cache_clear()
        for cached in (
            "_layout",
            "_grouping_table",
            "_residual_draws",
            "_range_rho",
            "_doppler_covariance",
        ):
            getattr(false_alarms, cached).cache_clear()
        t0 = time.perf_counter()
        fast_cfar.cfar_arguments(radar, s, L, radar.n_samples, radar.n_loops, True)
        t_thresholds = time.perf_counter() - t0
        out = fast_level.simulate_frames_fast(
            radar,
            [Scatterers.empty()] * n,
            [np.random.default_rng(f + 12345) for f in range(n)],
            antenna=antenna,
            settings=s,
            elevation=False,
        )
        f = fast_cfar.chain_factors(radar, s, L)
        m_exact, se_exact = _mean_se(exact_counts[name])
        m_fast, se_fast = _mean_se(out.counts)
        rows[name] = {
            "exact": m_exact,
            "exact_se": se_exact,
            "fast": m_fast,
            "fast_se": se_fast,
            "fast_over_exact": m_fast / m_exact,
            "fast_over_exact_se": float(
                np.hypot(se_fast / m_exact, m_fast * se_exact / m_exact**2)
            ),
            "model_exact": noise_detections_per_frame(radar, s, *f),
            "thresholds_first_call_s": t_thresholds,
        }
    return {
        "frames": n,
        "exact_map_and_cfar_s_per_frame": t_exact / (n * len(groups)),
        "settings": rows,
    }


def summary(result: dict) -> str:
    """Terminal table."""
    lines = [
        f"noise-only frames: {result['frames']} per level and setting "
        f"(exact map + CFAR {1e3 * result['exact_map_and_cfar_s_per_frame']:.1f} ms/frame)",
        f"{'setting':22s} {'exact':>16s} {'fast':>16s} {'fast/exact':>14s} {'model':>7s} "
        f"{'thr. 1st call':>13s}",
    ]
    for name, r in result["settings"].items():
        lines.append(
            f"{name:22s} {r['exact']:8.4f} ± {r['exact_se']:.4f} {r['fast']:8.4f} ± "
            f"{r['fast_se']:.4f} {r['fast_over_exact']:6.3f} ± {r['fast_over_exact_se']:.3f} "
            f"{r['model_exact']:7.4f} {r['thresholds_first_call_s']:11.2f} s"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="1000 frames per level and setting")
    p.add_argument("--frames", type=int, default=None, help="frames per level and setting")
    args = p.parse_args(argv)
    print(summary(run(quick=args.quick, n_frames=args.frames)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

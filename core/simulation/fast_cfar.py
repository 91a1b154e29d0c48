"""The ``fast`` level's CFAR thresholds: the exact chain's two-stage CFAR (its compiled kernel)
with thresholds for independent cells.

Neighbouring cells of the exact chain's noise are correlated through the windows; the ``fast``
level's noise map has independent cells. :func:`independent_cell_stages` scales both stages'
``pfa`` by one factor so that the expected noise detections per frame after both stages and
peak grouping are the exact chain's (``docs/decisions/simulation-12``); :func:`cfar_arguments`
gives the compiled kernel's arguments (:class:`~core.processing.cfar.TwoStageCfarArgs`).
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np
from scipy.optimize import brentq
from scipy.special import betainccinv

from core.config import DEFAULT_PROCESSING, CfarSettings, ProcessingSettings, RadarConfig
from core.processing import Detections, make_cfar
from core.processing.cfar import (
    TwoStageCfarArgs,
    effective_cells_or_none,
    stage_args,
    two_stage_kernel,
)
from core.processing.cfar_thresholds import pfa_caso, threshold_factor
from core.processing.false_alarms import StageFactors, cells_correlated, noise_detections_per_frame
from core.processing.spectrum import clutter_removal_noise_profile

# ---- the exact chain's two-stage CFAR with the fast level's thresholds -------------------------
# The library's compiled kernel (core.processing.cfar.two_stage_kernel: same edge rules, peak
# grouping and output order as core.processing.two_stage_cfar), with thresholds for the fast
# level's independent cells when asked.


def two_stage_cfar_compiled(
    rd_map: np.ndarray,
    radar: RadarConfig,
    settings: ProcessingSettings = DEFAULT_PROCESSING,
    *,
    n_channels: int | None = None,
    independent_cells: bool = False,
) -> Detections:
    """:func:`core.processing.two_stage_cfar`, compiled: the same detections, in the same order.

    Parameters and returns as there (``rd_map`` ``[range bin, Doppler bin]``, Doppler zero
    velocity centred). ``independent_cells=True`` sets the thresholds for independent cells
    (what the ``fast`` level's noise map has) instead of the window-correlated cells of the
    exact chain, with the exact chain's noise false alarms per frame after both stages and
    peak grouping (:func:`independent_cell_stages`).
    """
    rd = np.ascontiguousarray(rd_map)
    L = radar.n_virtual if n_channels is None else n_channels
    args = cfar_arguments(radar, settings, L, rd.shape[0], rd.shape[1], independent_cells)
    if args is None:
        return _no_detections()
    r, d, noise = two_stage_kernel(rd, args)
    return Detections(
        range_bin=r, doppler_index=d, power=rd[r, d].astype(np.float64), noise_power=noise
    )


@functools.lru_cache(maxsize=64)
def cfar_arguments(
    radar: RadarConfig,
    settings: ProcessingSettings,
    n_channels: int,
    n_r: int,
    n_d: int,
    independent_cells: bool,
) -> TwoStageCfarArgs | None:
    """Whitening profile, range limits, training windows and thresholds (cached); ``None`` when
    no range bin lies inside the limits. ``independent_cells``: the thresholds for independent
    cells (:func:`independent_cell_stages`) where the chain's cells are correlated."""
    k = np.arange(n_r) * radar.range_resolution_m
    in_range = (k >= settings.min_range_m) & (k <= settings.max_range_m)
    if not in_range.any():
        return None
    lo, hi = (int(i) for i in np.flatnonzero(in_range)[[0, -1]])
    rc, dc = settings.range_cfar, settings.doppler_cfar
    margin = rc.n_train + rc.n_guard
    a, b = max(0, lo - margin), min(n_r, hi + 1 + margin)
    ne_r = ne_d = None
    profile = np.ones(n_d)
    if settings.cfar_noise_model:
        ne_r = effective_cells_or_none(settings.range_window, radar.n_samples, rc.n_train)
        ne_d = effective_cells_or_none(settings.doppler_window, n_d, dc.n_train)
        if settings.static_clutter_removal:
            profile = clutter_removal_noise_profile(settings.doppler_window, n_d)
    if independent_cells and cells_correlated(radar, settings):
        rc, dc, rf, df = _independent_stages(radar, settings, n_channels, n_r)
    else:
        rf, df = (
            _factors(make_cfar(rc, n_channels, ne_r)),
            _factors(make_cfar(dc, n_channels, ne_d)),
        )
    return TwoStageCfarArgs(
        profile=np.ascontiguousarray(profile, dtype=np.float64),
        lo=lo,
        hi=hi,
        a=a,
        b=b,
        range_stage=stage_args(rc.n_train, rc.n_guard, rc.cyclic, rc.method, rf.both, rf.one),
        doppler_stage=stage_args(dc.n_train, dc.n_guard, dc.cyclic, dc.method, df.both, df.one),
        peak_grouping=settings.peak_grouping,
    )


@functools.lru_cache(maxsize=16)
def cfar_range_bins(radar: RadarConfig, settings: ProcessingSettings) -> int:
    """Range bins the two-stage CFAR reads: up to its range limit plus guard and training."""
    k = np.arange(radar.n_samples) * radar.range_resolution_m
    inside = np.flatnonzero((k >= settings.min_range_m) & (k <= settings.max_range_m))
    if inside.size == 0:
        return 0
    margin = settings.range_cfar.n_train + settings.range_cfar.n_guard
    return int(min(radar.n_samples, inside[-1] + 1 + margin))


def independent_cell_stages(
    radar: RadarConfig, settings: ProcessingSettings, n_channels: int, n_range_bins: int
) -> tuple[CfarSettings, CfarSettings]:
    """CFAR stages for independent cells with the exact chain's noise false alarms per frame.

    The exact chain's cells are window-correlated and its thresholds account for it; the
    ``fast`` level's noise map has independent cells. With the same per-stage ``pfa`` the two
    would differ in their two-stage rate (the stages share the cell under test) and in what peak
    grouping removes (correlated neighbours are rarely all below a noise peak: 12 % of the exact
    chain's false alarms go, 3 % of independent cells'). Both stages' ``pfa`` are scaled by one
    factor ``kappa`` so that the model of
    :func:`core.processing.false_alarms.noise_detections_per_frame` (both stages and peak
    grouping) gives the same expected detections per noise-only frame for independent cells as
    for the exact chain's cells with its own thresholds. ``n_range_bins``: rows of the map.
    """
    return _independent_stages(radar, settings, n_channels, n_range_bins)[:2]


@functools.lru_cache(maxsize=16)
def _independent_stages(
    radar: RadarConfig, settings: ProcessingSettings, n_channels: int, n_range_bins: int
) -> tuple[CfarSettings, CfarSettings, StageFactors, StageFactors]:
    """:func:`independent_cell_stages` and their threshold factors (cached)."""
    L = n_channels
    target = noise_detections_per_frame(
        radar, settings, *chain_factors(radar, settings, L), n_channels=L, n_range_bins=n_range_bins
    )
    rc, dc = settings.range_cfar, settings.doppler_cfar

    def stages(log_kappa: float) -> tuple[CfarSettings, CfarSettings]:
        k = float(np.exp(log_kappa))
        return (
            dataclasses.replace(rc, pfa=min(rc.pfa * k, 0.5)),
            dataclasses.replace(dc, pfa=min(dc.pfa * k, 0.5)),
        )

    def with_factors(log_kappa: float):
        r, d = stages(log_kappa)
        return r, d, independent_factors(r, L), independent_factors(d, L)

    def err(log_kappa: float) -> float:
        fr, fd = with_factors(log_kappa)[2:]
        p = noise_detections_per_frame(
            radar, settings, fr, fd, independent_cells=True, n_channels=L,
            n_range_bins=n_range_bins,
        )  # fmt: skip
        return float(np.log(p) - np.log(target))

    if target <= 0.0:
        return with_factors(0.0)
    # log rate is smooth and nearly linear in log kappa: secant steps from kappa = 1 (four or
    # five evaluations to 1e-7 in the rate), bracketing as a fall-back
    u0, u1 = 0.0, -0.5
    e0, e1 = err(u0), err(u1)
    for _ in range(30):
        if abs(e1) < 1e-7:
            return with_factors(u1)
        if e1 == e0:
            break
        u0, e0, u1 = u1, e1, float(np.clip(u1 - e1 * (u1 - u0) / (e1 - e0), -6.0, 3.0))
        e1 = err(u1)
    return with_factors(brentq(err, -6.0, 3.0, xtol=1e-7))


def _factors(c) -> StageFactors:
    return StageFactors(both=c.alpha(), one=c.alpha_one_side())


@functools.lru_cache(maxsize=256)
def independent_factors(c: CfarSettings, n_channels: int) -> StageFactors:
    """Threshold factors of a stage on independent cells (``make_cfar(c, L)``'s, to 1e-12).

    CASO by a bracketed root search between the one-sided CA factors for ``pfa`` and ``pfa/2``
    (``Pfa_CA1(T) <= Pfa_SO(T) <= 2 Pfa_CA1(T)``: the smaller side is below either side, and
    above the noise peak only if one of them is) instead of the library's scan from ``T = e^-8``
    (one tenth of the evaluations: the threshold search runs a few times per slider move).
    """
    L, n, pfa = n_channels, c.n_train, c.pfa

    def t_ca(cells: float, p: float) -> float:
        # Pfa_CA(T) = 1 - I_{T/(1+T)}(L, N L)  ->  T = b / (1 - b)
        b = float(betainccinv(L, cells * L, p))
        return b / (1.0 - b)

    one = n * t_ca(n, pfa)
    if c.method == "ca":
        return StageFactors(both=2 * n * t_ca(2 * n, pfa), one=one)
    if c.method == "cago":
        return StageFactors(both=threshold_factor("cago", n, pfa, L), one=one)
    lo, hi = np.log(t_ca(n, pfa)), np.log(t_ca(n, pfa / 2))
    log_t = brentq(lambda u: np.log(pfa_caso(np.exp(u), n, L)) - np.log(pfa), lo, hi, xtol=1e-13)
    return StageFactors(both=n * float(np.exp(log_t)), one=one)


def chain_factors(
    radar: RadarConfig, settings: ProcessingSettings, n_channels: int
) -> tuple[StageFactors, StageFactors]:
    """The exact chain's threshold factors (range stage, Doppler stage), as ``two_stage_cfar``."""
    rc, dc = settings.range_cfar, settings.doppler_cfar
    ne_r = ne_d = None
    if settings.cfar_noise_model:
        ne_r = effective_cells_or_none(settings.range_window, radar.n_samples, rc.n_train)
        ne_d = effective_cells_or_none(settings.doppler_window, radar.n_loops, dc.n_train)
    return _factors(make_cfar(rc, n_channels, ne_r)), _factors(make_cfar(dc, n_channels, ne_d))


def _no_detections() -> Detections:
    e = np.zeros(0, dtype=np.int64)
    return Detections(range_bin=e, doppler_index=e, power=np.zeros(0), noise_power=np.zeros(0))

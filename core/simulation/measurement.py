"""``measurement`` fidelity level: detections drawn from a statistical model of the chain.

No signal, no spectrum: every reflector of the frame becomes at most one point, drawn from its
true range, azimuth and radial velocity (at the frame's middle, as the exact chain labels them)
in four steps.

1. **Peak cell and its SNR.** The per-channel signal power in the reflector's peak cell is
   ``rho = A^2 |R(delta_r)|^2 |D(nu)|^2 / s2[d]``: the link budget (eqs. 2-5, antenna gain eq. 1)
   times the windows' responses at the reflector's fractional range bin ``delta_r`` and at its
   Doppler frequency ``nu`` (in bins, aliased), including static clutter removal, divided by the
   cell's noise power (:func:`core.simulation.fast.cell_noise_power_v2`). The responses are
   tabulated once per radar and settings from the ``fast`` level's closed form, together with
   the index of the peak cell and the chain's own peak refinement (log-parabolic interpolation),
   so straddle loss, scalloping, the clutter-removal notch around zero Doppler and the
   refinement's bias are the chain's.
2. **Detection (CFAR, Swerling 0 within the frame).** The cell under test is drawn as the
   exact chain would see it: ``X = |sqrt(L rho) + n|^2 + Gamma(L - 1)`` (in units of ``s2``,
   ``n ~ CN(0, 1)``; the non-coherent sum of ``L = 12`` channels with a fixed amplitude, see
   ``fast_spectrum``); each side's training sum is ``(n / n_eff) Gamma(n_eff L)`` (window-
   correlated cells, the chain's own moment match) plus the reflector's own leakage into those
   cells (tabulated). The point is
   detected when ``X > alpha_r mu_r`` and ``X > alpha_d mu_d`` with the two stages' estimators
   (CA / CASO / CAGO) and thresholds ``alpha`` from :func:`core.processing.make_cfar`; its SNR is
   ``10 log10(X / mu_r)`` as the chain reports it. The RCS fluctuates from frame to frame through
   eq. (5) (drawn by the scene), not within a frame.
3. **Measurement errors (Cramer-Rao).** Range and Doppler: around the refined noiseless
   estimate, Gaussian errors with the Cramer-Rao bound of a tone's frequency at the cell's SNR,
   ``L`` channels combined::

       var(range bin) = var(Doppler bin) = 6 / (4 pi^2 L rho)

   Azimuth (and elevation): the chain's own estimator (:func:`core.simulation.fast.angles_of`:
   TDM compensation with the noisy Doppler estimate, 64-point DFT of the 8-element row,
   log-parabolic refinement) on the peak cell's 12 channel values
   ``rho^(1/2) exp(j pi (p_v u + e_v sin el)) exp(j 2 pi nu k(v) / (Nc Ntx)) + CN(0, 1)``.
   Its spread is the Cramer-Rao bound ``var(u) = 6 / (pi^2 rho M (M^2 - 1))``, ``M = 8``
   (measured: ratio 1.00 +- 0.01 from 15 to 45 dB), and it keeps the chain's biases (the
   residual TDM phase when the refined Doppler is off, the first chirp's direction).
4. **False alarms.** The chain's own false alarms (noise and nothing else) are a Poisson number
   per frame whose rate, and whose joint distribution of Doppler cell, SNR and azimuth, are
   measured once per radar and settings on noise-only frames of the exact chain; their range
   is uniform over the detectable range bins (the noise floor does not depend on range).
   Clutter reflectors (a Poisson number per frame, drawn by the scene) are reflectors like the
   people and go through steps 1-3.

Speed: all four steps run in one compiled kernel over any number of frames
(:func:`simulate_frames_measurement`, the data-set path; :func:`simulate_frame_measurement` is
the same kernel with one frame). The kernel draws from its own xoshiro256** generator, seeded
per frame with four raw draws of that frame's ``rng`` (:func:`frame_seed`), so both entry
points give the same frames bit for bit (``docs/decisions/simulation-09``).

Layout: this module tabulates the chain's responses (:func:`chain_tables`) with the same
conventions (bin offsets, leakage sides) the kernel indexes them by, groups the kernel's
arguments (:class:`ModelConstants`, :class:`KernelTables`, :class:`ArrayLayout`,
:class:`FalseAlarmPool`) and holds the entry points; the compiled kernel with its generator is
:func:`core.simulation.measurement_jit.measure_frames`, and the exact chain's false-alarm pool
is measured by :func:`core.simulation.false_alarm_pool.chain_false_alarms`.

Not modelled (measured against ``exact`` in ``docs/fidelity-models.md``): the extra detections
next to very strong or fast reflectors (window sidelobes, clutter-removal residuals), two reflectors
sharing a cell, the threshold effect of the estimators at very low SNR.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)
from core.config import DEFAULT_PROCESSING, SPEED_OF_LIGHT_MPS, ProcessingSettings, RadarConfig
from core.errors import InputError
from core.pointcloud import SOURCE_OTHER, PointCloud
from core.processing import estimate_angles, make_cfar
from core.processing.angle import log_parabolic_offset
from core.processing.cfar import METHOD_CODE, effective_cells_or_none
from core.processing.points import angle_twiddles, array_rows
from core.processing.spectrum import window
from core.simulation import body_cells
from core.simulation.antenna import AntennaGain
from core.simulation.body_cells import merge_person_cells
from core.simulation.false_alarm_pool import chain_false_alarms
from core.simulation.fast import FramesOutput
from core.simulation.fast_model import cell_noise_power_v2, range_responses
from core.simulation.frame import FrameOutput, needs_elevation
from core.simulation.link import receiver_voltage_scale
from core.simulation.measurement_jit import measure_frames
from core.simulation.rng_kernels import state_from
from core.simulation.scatterers import Scatterers

#: Tabulation steps: range and Doppler in fractions of a bin, azimuth in u = sin(az).
RANGE_STEPS_PER_BIN = 64
DOPPLER_STEPS_PER_BIN = 64
AZIMUTH_STEPS = 4097


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class ChainTables:
    """The chain's noiseless responses, tabulated once per radar and settings.

    Attributes
    ----------
    range_frac
        ``(n_r,)`` fractional range offsets in ``[0, 1]`` (bins).
    range_gain
        ``(n_r,)`` peak-cell ``|R|^2`` per unit amplitude.
    range_est
        ``(n_r,)`` refined peak position minus the integer bin (bins), what the chain reports.
    doppler_nu
        ``(n_d,)`` Doppler frequency in bins, ``[-Nc/2, Nc/2]``.
    doppler_gain
        ``(n_d,)`` peak-cell ``|D|^2`` (after clutter removal and window).
    doppler_index
        ``(n_d,)`` int: zero-velocity-centred Doppler index of the peak cell.
    doppler_est
        ``(n_d,)`` refined Doppler bin (zero velocity = 0) the chain reports.
    range_leak
        ``(n_r, 2)`` the reflector's own ``|R|^2`` summed over the range stage's left and right
        training cells (relative to the peak cell).
    doppler_leak
        ``(n_d, 2)`` the same for the Doppler stage's training cells (cyclic).
    u_grid, u_est
        ``(n_u,)`` true and estimated ``sin(az)`` (noiseless steering vector).
    cell_noise
        ``(Nc,)`` per-channel noise power of a cell, V².
    """

    range_frac: np.ndarray
    range_gain: np.ndarray
    range_est: np.ndarray
    doppler_nu: np.ndarray
    doppler_gain: np.ndarray
    doppler_index: np.ndarray
    doppler_est: np.ndarray
    range_leak: np.ndarray
    doppler_leak: np.ndarray
    u_grid: np.ndarray
    u_est: np.ndarray
    cell_noise: np.ndarray


@functools.lru_cache(maxsize=16)
def chain_tables(radar: RadarConfig, settings: ProcessingSettings) -> ChainTables:
    """Tabulate the chain's responses and refinements (see the module docstring, step 1)."""
    n_r, n_d = radar.n_samples, radar.n_loops
    # range: a tone at bin k0 + f, f in [0, 1]
    k0 = n_r // 2
    frac = np.linspace(0.0, 1.0, RANGE_STEPS_PER_BIN + 1)
    resp = range_responses(radar, (k0 + frac) * radar.range_resolution_m, settings)
    p = np.abs(resp) ** 2
    pk = np.argmax(p, axis=1)
    i = np.arange(len(frac))
    r_off = log_parabolic_offset(p[i, pk - 1], p[i, pk], p[i, pk + 1])
    range_est = pk + r_off - k0
    rc, dcs = settings.range_cfar, settings.doppler_cfar
    g, nt = rc.n_guard, rc.n_train
    # the reflector's own energy in the training cells raises the CFAR's noise estimate
    range_leak = np.column_stack(
        [
            np.array([p[a, pk[a] - g - nt : pk[a] - g].sum() for a in i]),
            np.array([p[a, pk[a] + g + 1 : pk[a] + g + 1 + nt].sum() for a in i]),
        ]
    )
    # Doppler: slow-time tone of nu bins, clutter removal, window, centred DFT
    nu = np.linspace(-n_d / 2, n_d / 2, n_d * DOPPLER_STEPS_PER_BIN + 1)
    m = np.arange(n_d)
    y = np.exp(2j * np.pi * np.outer(nu, m) / n_d)
    if settings.static_clutter_removal:
        y = y - y.mean(axis=1, keepdims=True)
    wd = window(settings.doppler_window, n_d).astype(np.float64)
    d_idx = np.arange(n_d)
    # D[d] = sum_m w_m y_m exp(-j 2 pi (d - Nc/2) m / Nc)
    dft = np.exp(-2j * np.pi * np.outer(m, d_idx - n_d // 2) / n_d)
    big_d = (y * wd) @ dft
    s2 = cell_noise_power_v2(radar, settings)
    pd = np.abs(big_d) ** 2
    dk = np.argmax(pd, axis=1)
    j = np.arange(len(nu))
    d_off = log_parabolic_offset(pd[j, (dk - 1) % n_d], pd[j, dk], pd[j, (dk + 1) % n_d])
    doppler_est = dk - n_d // 2 + d_off
    g, nt = dcs.n_guard, dcs.n_train
    left = (dk[:, None] - g - nt + np.arange(nt)[None, :]) % n_d
    right = (dk[:, None] + g + 1 + np.arange(nt)[None, :]) % n_d
    doppler_leak = np.column_stack(
        [np.take_along_axis(pd, left, 1).sum(1), np.take_along_axis(pd, right, 1).sum(1)]
    )
    # azimuth: noiseless steering vector through the chain's estimator
    u = np.linspace(-1.0, 1.0, AZIMUTH_STEPS)
    az_pos = np.asarray(radar.azimuth_positions, dtype=np.float64)
    steer = np.exp(1j * np.pi * np.outer(u, az_pos))
    az_est, _ = estimate_angles(steer, np.zeros(len(u)), radar, fft_size=settings.angle_fft_size)
    return ChainTables(
        range_frac=frac,
        range_gain=p[i, pk],
        range_est=range_est,
        doppler_nu=nu,
        doppler_gain=pd[j, dk],
        doppler_index=dk.astype(np.int64),
        doppler_est=doppler_est,
        range_leak=range_leak,
        doppler_leak=doppler_leak,
        u_grid=u,
        u_est=np.sin(az_est),
        cell_noise=np.asarray(s2, dtype=np.float64),
    )


#: No false alarms (noise-free frames).


class ModelCfarStage(NamedTuple):
    """One CFAR stage as the compiled model draws it."""

    method: int  # METHOD_CODE of the estimator
    n_train: int  # training cells per side
    n_eff: float  # effective independent cells among them (window correlation)
    alpha: float  # threshold factor, both sides


class ModelConstants(NamedTuple):
    """Per-radar scalars of the compiled model."""

    t_mid: float  # the frame's middle, s
    range_res: float  # m
    vel_res: float  # m/s
    n_loops: int
    doppler_scale: float  # the chain's Doppler reading per true radial velocity
    c_amp2: float  # A^2 = c_amp2 g^2 sigma / R^4
    L: float  # virtual channels
    range_stage: ModelCfarStage
    doppler_stage: ModelCfarStage
    m_az: int  # channels of the azimuth row
    bin_lo: int  # first range bin inside the limits
    bin_hi: int  # last range bin inside the limits (-1: none)


class KernelTables(NamedTuple):
    """The :class:`ChainTables` the compiled model reads (shapes there)."""

    range_gain: np.ndarray
    range_est: np.ndarray
    range_leak: np.ndarray
    doppler_gain: np.ndarray
    doppler_index: np.ndarray
    doppler_est: np.ndarray
    doppler_leak: np.ndarray
    cell_noise: np.ndarray


class ArrayLayout(NamedTuple):
    """The virtual array as the compiled model's angle estimate reads it."""

    az_pos: np.ndarray  # azimuth positions (half wavelengths)
    el_pos: np.ndarray  # elevation positions
    n_tx: int
    n_rx: int
    row_ch: np.ndarray  # azimuth row: channels
    row_pos: np.ndarray  # azimuth row: positions
    upper: np.ndarray  # elevation pairs: upper channels
    lower: np.ndarray  # elevation pairs: lower channels
    tw_a: np.ndarray  # angle FFT twiddles


class FalseAlarmPool(NamedTuple):
    """:class:`~core.simulation.false_alarm_pool.FalseAlarms` as the compiled model resamples
    them."""

    rate_per_frame: float
    doppler_index: np.ndarray
    snr_db: np.ndarray
    azimuth_rad: np.ndarray
    range_frac: np.ndarray


#: The pool of noise-free frames: no false alarms.
_NO_FALSE_ALARM_POOL = FalseAlarmPool(
    rate_per_frame=0.0,
    doppler_index=np.zeros(0, dtype=np.int64),
    snr_db=np.zeros(0),
    azimuth_rad=np.zeros(0),
    range_frac=np.zeros(0),
)


@functools.lru_cache(maxsize=16)
def _setup(radar: RadarConfig, settings: ProcessingSettings) -> tuple[ChainTables, dict]:
    """Tables and constants of a radar and settings (one cache look-up per frame)."""
    tab = chain_tables(radar, settings)
    const = dict(_constants(radar, settings))
    const["tables"] = KernelTables(
        tab.range_gain,
        tab.range_est,
        tab.range_leak,
        tab.doppler_gain,
        tab.doppler_index,
        tab.doppler_est,
        tab.doppler_leak,
        tab.cell_noise,
    )
    return tab, const


@functools.lru_cache(maxsize=16)
def _false_alarm_pool(radar: RadarConfig, settings: ProcessingSettings) -> FalseAlarmPool:
    fa = chain_false_alarms(radar, settings)
    return FalseAlarmPool(
        fa.rate_per_frame, fa.doppler_index, fa.snr_db, fa.azimuth_rad, fa.range_frac
    )


@functools.lru_cache(maxsize=16)
def _constants(radar: RadarConfig, settings: ProcessingSettings):
    """Per-radar constants: eq. (4) factor, CFAR thresholds and shapes, range-bin limits."""
    L = radar.n_virtual
    rs, ds = settings.range_cfar, settings.doppler_cfar
    ne_r = ne_d = None
    if settings.cfar_noise_model:
        # the exact chain's training cells are window-correlated: n_eff independent ones
        ne_r = effective_cells_or_none(settings.range_window, radar.n_samples, rs.n_train)
        ne_d = effective_cells_or_none(settings.doppler_window, radar.n_loops, ds.n_train)
    rc, dc = make_cfar(rs, L, ne_r), make_cfar(ds, L, ne_d)
    pt_w = 10 ** ((radar.tx_power_dbm - 30.0) / 10)
    # A^2 = Pr R 10^(Ge/20) = C g^2 sigma / R^4,  C = Pt lambda^2 / (4 pi)^3 * R 10^(Ge/20)
    c_amp2 = pt_w * radar.wavelength_m**2 / (4 * np.pi) ** 3 * receiver_voltage_scale(radar)
    k = np.arange(radar.n_samples) * radar.range_resolution_m
    ok = np.flatnonzero((k >= settings.min_range_m) & (k <= settings.max_range_m))
    row = np.asarray(radar.elevation_positions)
    n_row = int(np.sum(row == row.min()))
    # the beat tone's drift moves the slow-time phase by theta' dR (Nadc - 1)/2 besides 4 pi dR /
    # lambda: the chain's Doppler reads the radial velocity scaled by 1 + theta' (Nadc-1)/2 / (4 pi
    # / lambda) (the carrier at the middle of the ADC window)
    beat = 2 * np.pi * 2 * radar.slope_hz_per_s / (SPEED_OF_LIGHT_MPS * radar.sample_rate_hz)
    doppler_scale = 1.0 + beat * (radar.n_samples - 1) / 2 / (4 * np.pi / radar.wavelength_m)
    t_mid = 0.5 * radar.n_loops * radar.n_tx * radar.chirp_period_s
    kernel = ModelConstants(
        t_mid, radar.range_resolution_m, radar.velocity_resolution_mps, radar.n_loops,
        doppler_scale, c_amp2, float(L),
        ModelCfarStage(METHOD_CODE[rs.method], rs.n_train, float(ne_r or rs.n_train), rc.alpha()),
        ModelCfarStage(METHOD_CODE[ds.method], ds.n_train, float(ne_d or ds.n_train), dc.alpha()),
        min(n_row, len(set(radar.azimuth_positions))),
        int(ok[0]) if ok.size else 0, int(ok[-1]) if ok.size else -1,
    )  # fmt: skip
    array = ArrayLayout(
        np.asarray(radar.azimuth_positions, dtype=np.float64),
        np.asarray(radar.elevation_positions, dtype=np.float64),
        radar.n_tx,
        radar.n_rx,
        *array_rows(radar),
        angle_twiddles(radar, settings.angle_fft_size),
    )
    return {
        "array": array,
        "kernel": kernel,
        "doppler_scale": doppler_scale,
        "L": L,
        "c_amp2": c_amp2,
        "range_stage": (rs.method, rs.n_train, ne_r or rs.n_train, rc.alpha()),
        "doppler_stage": (ds.method, ds.n_train, ne_d or ds.n_train, dc.alpha()),
        "bin_lo": int(ok[0]) if ok.size else 0,
        "bin_hi": int(ok[-1]) if ok.size else -1,
        "m_az": min(n_row, len(set(radar.azimuth_positions))),
    }


def frame_seed(rng: np.random.Generator | None) -> np.ndarray:
    """The compiled generator's 256-bit state for one frame, drawn from that frame's ``rng``.

    ``(4,)`` uint64 (xoshiro256**; never all zero). ``None`` (noise-free frames) gives a fixed
    state. The per-frame and the batch entry points seed each frame this way, so they agree.
    """
    return state_from(rng)


def simulate_frames_measurement(
    radar: RadarConfig,
    frames: Sequence[Scatterers],
    rngs: Sequence[np.random.Generator | None],
    *,
    antenna: AntennaGain,
    settings: ProcessingSettings = DEFAULT_PROCESSING,
    elevation: bool | None = None,
    noise: bool = True,
) -> FramesOutput:
    """Many frames at the ``measurement`` level in one compiled call (the data-set path).

    Frame ``f`` draws only from ``rngs[f]`` (its 256-bit state seeds the compiled generator,
    :func:`frame_seed`), so the result equals ``simulate_frame_measurement`` of each frame with
    the same generator, bit for bit (tested).

    Parameters
    ----------
    frames
        ``F`` frames' reflectors.
    rngs
        ``F`` generators, one per frame (the pipeline's ``stage_rng(seed, "noise", f)``).
    elevation
        Estimate elevation; ``None``: per frame, when the radar can and the frame is not planar.
    """
    if len(frames) != len(rngs):
        raise InputError(f"rngs: {len(rngs)} generators for {len(frames)} frames")
    n_f = len(frames)
    states = np.stack([frame_seed(r) for r in rngs]) if n_f else np.zeros((0, 4), dtype=np.uint64)
    counts = np.fromiter((len(s) for s in frames), dtype=np.int64, count=n_f)
    start = np.zeros(n_f + 1, dtype=np.int64)
    np.cumsum(counts, out=start[1:])
    if start[-1]:
        pos = np.concatenate([s.position_m for s in frames]).astype(np.float64, copy=False)
        vel = np.concatenate([s.velocity_mps for s in frames]).astype(np.float64, copy=False)
        rcs = np.concatenate([s.rcs_dbsm for s in frames]).astype(np.float64, copy=False)
        source = np.concatenate([s.source for s in frames])
    else:
        pos = vel = np.zeros((0, 3))
        rcs = np.zeros(0)
        source = np.zeros(0, dtype=np.int32)
    if elevation is None:
        elev = np.array([needs_elevation(radar, s) for s in frames], dtype=np.bool_)
    else:
        elev = np.full(n_f, bool(elevation))
    return _run(radar, settings, antenna, states, start, pos, vel, rcs, source, elev, noise)


def _run(radar, settings, antenna, states, start, pos, vel, rcs, source, elev, noise):
    """The compiled kernel over frames ``start[f]:start[f+1]`` of the concatenated reflectors
    (a person's scatterers that share a cell merged first: :mod:`core.simulation.body_cells`)."""
    start, pos, vel, rcs, source = merge_person_cells(
        radar, start, pos, vel, rcs, source, body_cells.MERGE_CELLS
    )
    _, const = _setup(radar, settings)
    fa = _false_alarm_pool(radar, settings) if noise else _NO_FALSE_ALARM_POOL
    g_db = antenna.gain_db(np.arctan2(pos[:, 0], pos[:, 1])) if len(pos) else np.zeros(0)
    counts, f64, i64 = measure_frames(
        states,
        start,
        np.ascontiguousarray(pos),
        np.ascontiguousarray(vel),
        np.asarray(g_db, dtype=np.float64),
        np.ascontiguousarray(rcs),
        elev,
        bool(noise),
        const["kernel"],
        const["tables"],
        const["array"],
        fa,
    )
    ref = i64[:, 0]
    src = np.full(len(ref), SOURCE_OTHER, dtype=np.int32)
    real = ref >= 0
    src[real] = source[ref[real]]
    pc = PointCloud(
        range_m=f64[:, 0],
        azimuth_rad=f64[:, 1],
        elevation_rad=f64[:, 2],
        radial_velocity_mps=f64[:, 3],
        snr_db=f64[:, 4],
        x_m=f64[:, 5],
        y_m=f64[:, 6],
        z_m=f64[:, 7],
        source=src,
    )
    return FramesOutput(point_cloud=pc, counts=counts, detections=i64[:, 1:3])


def simulate_frame_measurement(
    radar: RadarConfig,
    scatterers: Scatterers,
    rng: np.random.Generator | None,
    *,
    antenna: AntennaGain,
    settings: ProcessingSettings = DEFAULT_PROCESSING,
    keep_rd_map: bool = False,
    elevation: bool | None = None,
    noise: bool = True,
) -> FrameOutput:
    """One frame at the ``measurement`` level (see the module docstring).

    Same signature and output as :func:`core.simulation.simulate_frame`. ``rd_map_db``, when
    asked for, is a model map (mean noise floor plus the detected cells), not a spectrum.
    ``noise=False`` gives the noiseless estimates of every reflector in the range limits.
    The random numbers come from a compiled generator seeded by four raw draws of ``rng``
    (:func:`frame_seed`); :func:`simulate_frames_measurement` runs many frames in one call.
    """
    if elevation is None:
        elevation = needs_elevation(radar, scatterers)
    out = _run(
        radar,
        settings,
        antenna,
        frame_seed(rng if noise else None)[None, :],
        np.array([0, len(scatterers)], dtype=np.int64),
        np.asarray(scatterers.position_m, dtype=np.float64),
        np.asarray(scatterers.velocity_mps, dtype=np.float64),
        np.asarray(scatterers.rcs_dbsm, dtype=np.float64),
        scatterers.source,
        np.array([bool(elevation)]),
        noise,
    )
    rd_db = None
    if keep_rd_map:
        rd_db = _model_map(radar, _setup(radar, settings)[0], out.detections, out.point_cloud)
    return FrameOutput(point_cloud=out.point_cloud, rd_map_db=rd_db, detections=out.detections)


def _model_map(radar: RadarConfig, tab: ChainTables, cells: np.ndarray, pc: PointCloud):
    """Model range-Doppler map in dB: mean noise floor ``L s2[d]`` plus the detected cells."""
    floor = radar.n_virtual * tab.cell_noise
    rd = np.repeat(floor[None, :], radar.n_samples, axis=0)
    if len(cells):
        k = np.clip(cells[:, 0].astype(np.int64), 0, radar.n_samples - 1)
        d = cells[:, 1].astype(np.int64)
        # reported SNR is power over the per-cell noise estimate (one cell's mean power)
        rd[k, d] = np.maximum(rd[k, d], 10 ** (pc.snr_db / 10) * floor[d] / radar.n_virtual)
    return (10 * np.log10(rd)).astype(np.float32)

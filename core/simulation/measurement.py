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

Layout: about 950 lines, most of them the one compiled kernel (:func:`_measure_frames`, steps
1-4 with its xoshiro256** generator) and the tables and false-alarm pool it reads, which are
tabulated here with the same conventions (bin offsets, leakage sides) the kernel indexes them
by; its arguments are grouped (:class:`ModelConstants`, :class:`KernelTables`,
:class:`ArrayLayout`, :class:`FalseAlarmPool`). The false-alarm measurement
(:func:`chain_false_alarms`) could move out on its own.

Not modelled (measured against ``exact`` in ``docs/fidelity-models.md``): the extra detections
next to very strong or fast reflectors (window sidelobes, clutter-removal residuals), two reflectors
sharing a cell, the threshold effect of the estimators at very low SNR.
"""

from __future__ import annotations

import functools
import hashlib
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import numba
import numpy as np

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)
from core.config import DEFAULT_PROCESSING, SPEED_OF_LIGHT_MPS, ProcessingSettings, RadarConfig
from core.errors import InputError
from core.files import read_npz, write_npz_atomic
from core.pointcloud import SOURCE_OTHER, PointCloud
from core.processing import estimate_angles, make_cfar
from core.processing.angle import log_parabolic_offset
from core.processing.cfar import METHOD_CODE, effective_cells_or_none
from core.processing.points import angle_twiddles, angles_of, array_rows
from core.processing.spectrum import window
from core.simulation.antenna import AntennaGain
from core.simulation.fast import FramesOutput
from core.simulation.fast_model import cell_noise_power_v2, range_responses
from core.simulation.frame import FrameOutput, needs_elevation
from core.simulation.gaussian import state_from
from core.simulation.link import receiver_voltage_scale
from core.simulation.scatterers import Scatterers

#: Tabulation steps: range and Doppler in fractions of a bin, azimuth in u = sin(az).
RANGE_STEPS_PER_BIN = 64
DOPPLER_STEPS_PER_BIN = 64
AZIMUTH_STEPS = 4097
#: Noise-only exact frames used to measure the chain's own false alarms.
FALSE_ALARM_FRAMES = 300


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


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class FalseAlarms:
    """The chain's own false alarms, measured on noise-only exact frames.

    Attributes
    ----------
    rate_per_frame
        Mean number of false-alarm points per frame.
    doppler_index, snr_db, azimuth_rad, range_frac
        ``(n_pool,)`` the measured points (Doppler index, reported SNR, azimuth, fractional
        part of the range bin), resampled as a pool.
    n_frames
        Frames measured.
    """

    rate_per_frame: float
    doppler_index: np.ndarray
    snr_db: np.ndarray
    azimuth_rad: np.ndarray
    range_frac: np.ndarray
    n_frames: int


@functools.lru_cache(maxsize=16)
def chain_false_alarms(
    radar: RadarConfig, settings: ProcessingSettings, n_frames: int = FALSE_ALARM_FRAMES
) -> FalseAlarms:
    """Run ``n_frames`` noise-only frames through the exact chain (seeded) and pool the points.

    The pool is cached on disk (``<cache>/false_alarms/<key>.npz`` in the data-set cache
    folder; key: radar, settings, ``n_frames`` and the chain's source fingerprint), so a
    worker process loads it instead of spending ~1 s of exact frames; a missing or unreadable
    file is simply recomputed.
    """
    path = _false_alarm_cache_path(radar, settings, n_frames)
    try:
        z = read_npz(path, what="false-alarm cache")
        return FalseAlarms(
            rate_per_frame=float(z["rate_per_frame"]),
            doppler_index=z["doppler_index"].astype(np.int64),
            snr_db=z["snr_db"].astype(np.float64),
            azimuth_rad=z["azimuth_rad"].astype(np.float64),
            range_frac=z["range_frac"].astype(np.float64),
            n_frames=int(z["n_frames"]),
        )
    except (KeyError, ValueError, TypeError):  # InputError is a ValueError
        pass
    fa = _measure_false_alarms(radar, settings, n_frames)
    arrays = {
        "rate_per_frame": np.asarray(fa.rate_per_frame),
        "doppler_index": fa.doppler_index,
        "snr_db": fa.snr_db,
        "azimuth_rad": fa.azimuth_rad,
        "range_frac": fa.range_frac,
        "n_frames": np.asarray(fa.n_frames),
    }
    try:
        write_npz_atomic(path, arrays, compressed=False)  # a reader never sees half a file
    except (OSError, InputError):
        pass  # a read-only cache only costs the recomputation
    return fa


@functools.cache
def _chain_fingerprint() -> str:
    """Hash of the sources the exact chain's false alarms depend on (config, simulation,
    processing), so a changed chain never serves a stale pool."""
    root = Path(__file__).resolve().parent.parent
    files = [root / "config.py", root / "pointcloud.py"]
    for pkg in ("simulation", "processing"):
        files += sorted((root / pkg).rglob("*.py"))
    h = hashlib.sha256()
    for f in files:
        if f.is_file():
            h.update(f.relative_to(root).as_posix().encode() + b"\0" + f.read_bytes() + b"\0")
    return h.hexdigest()[:16]


def _false_alarm_cache_path(radar: RadarConfig, settings: ProcessingSettings, n_frames: int):
    """``<cache>/false_alarms/<key>.npz``; ``<cache>``: ``$RADARTUNE_CACHE`` or
    ``~/.cache/radartune`` (the data-set cache's folder, see ``core.pipeline``)."""
    env = os.environ.get("RADARTUNE_CACHE")
    root = Path(env) if env else Path.home() / ".cache" / "radartune"
    key = hashlib.sha256(
        f"{radar!r}\n{settings!r}\n{n_frames}\n{_chain_fingerprint()}".encode()
    ).hexdigest()[:32]
    return root / "false_alarms" / f"{key}.npz"


def _measure_false_alarms(
    radar: RadarConfig, settings: ProcessingSettings, n_frames: int
) -> FalseAlarms:
    """The pool itself: ``n_frames`` seeded noise-only frames of the exact chain."""
    from core.simulation.frame import simulate_frame

    rng = np.random.default_rng(20_261_121)
    ant = AntennaGain.ideal(radar)
    empty = Scatterers.empty()
    clouds, dets = [], []
    for _ in range(n_frames):
        out = simulate_frame(radar, empty, rng, antenna=ant, settings=settings)
        clouds.append(out.point_cloud)
        dets.append(out.detections)
    pc = PointCloud.concatenate(clouds)
    det = np.concatenate(dets) if dets else np.zeros((0, 2), dtype=np.int64)
    r_bin = pc.range_m / radar.range_resolution_m
    return FalseAlarms(
        rate_per_frame=len(pc) / n_frames,
        doppler_index=det[:, 1].astype(np.int64),
        snr_db=pc.snr_db,
        azimuth_rad=pc.azimuth_rad,
        range_frac=r_bin - np.round(r_bin),
        n_frames=n_frames,
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
    """:class:`FalseAlarms` as the compiled model resamples them."""

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
    """The compiled kernel over frames ``start[f]:start[f+1]`` of the concatenated reflectors."""
    _, const = _setup(radar, settings)
    fa = _false_alarm_pool(radar, settings) if noise else _NO_FALSE_ALARM_POOL
    g_db = antenna.gain_db(np.arctan2(pos[:, 0], pos[:, 1])) if len(pos) else np.zeros(0)
    counts, f64, i64 = _measure_frames(
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


# ---- the compiled generator: xoshiro256** (Blackman & Vigna) and the draws the model needs ------


@numba.njit(inline="always")
def _rotl(x, k):  # pragma: no cover
    return (x << np.uint64(k)) | (x >> np.uint64(64 - k))


@numba.njit(cache=True, nogil=True)
def _next_u64(s):  # pragma: no cover
    """Next 64-bit output of xoshiro256** with state ``s`` (4,) uint64 (advanced in place)."""
    result = _rotl(s[1] * np.uint64(5), 7) * np.uint64(9)
    t = s[1] << np.uint64(17)
    s[2] ^= s[0]
    s[3] ^= s[1]
    s[1] ^= s[2]
    s[0] ^= s[3]
    s[2] ^= t
    s[3] = _rotl(s[3], 45)
    return result


@numba.njit(cache=True, nogil=True)
def _uniform(s):  # pragma: no cover
    """U[0, 1) with 53 random bits."""
    return float(_next_u64(s) >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@numba.njit(cache=True, nogil=True)
def _normal(s):  # pragma: no cover
    """N(0, 1) by Box-Muller: sqrt(-2 ln u1) cos(2 pi u2), u1 in (0, 1]."""
    u1 = 1.0 - _uniform(s)
    return np.sqrt(-2.0 * np.log(u1)) * np.cos(2.0 * np.pi * _uniform(s))


@numba.njit(cache=True, nogil=True)
def _gamma(s, k):  # pragma: no cover
    """Gamma(k, 1) by Marsaglia & Tsang (2000); k < 1 via Gamma(k + 1) U^(1/k)."""
    if k < 1.0:
        return _gamma(s, k + 1.0) * _uniform(s) ** (1.0 / k)
    d = k - 1.0 / 3.0
    c = 1.0 / np.sqrt(9.0 * d)
    while True:
        x = _normal(s)
        v = 1.0 + c * x
        if v <= 0.0:
            continue
        v = v * v * v
        u = 1.0 - _uniform(s)
        # accept when ln u < x^2/2 + d - d v + d ln v
        if np.log(u) < 0.5 * x * x + d - d * v + d * np.log(v):
            return d * v


@numba.njit(cache=True, nogil=True)
def _poisson(s, lam):  # pragma: no cover
    """Poisson(lam) by multiplying uniforms (Knuth; the rates here are well below 1)."""
    limit = np.exp(-lam)
    k = 0
    p = 1.0 - _uniform(s)
    while p > limit:
        k += 1
        p *= 1.0 - _uniform(s)
    return k


@numba.njit(cache=True, nogil=True)
def _randint(s, n):  # pragma: no cover
    """Uniform integer in ``0 .. n-1`` (n >= 1; the bias of the modulo is below 2^-50)."""
    return np.int64(_next_u64(s) % np.uint64(n))


@numba.njit(cache=True, nogil=True)
def _lerp(table, x, x0, step):  # pragma: no cover
    """Linear interpolation in a table on the uniform grid ``x0 + i step`` (clamped)."""
    t = (x - x0) / step
    i = int(np.floor(t))
    i = min(max(i, 0), table.shape[0] - 2)
    w = min(max(t - i, 0.0), 1.0)
    return table[i] * (1.0 - w) + table[i + 1] * w


@numba.njit(cache=True, nogil=True)
def _training_sum(s, method, n_train, n_eff, L, leak_l, leak_r):  # pragma: no cover
    """CFAR noise estimate: each side ``(n / n_eff) Gamma(n_eff L)`` plus the own leakage."""
    z1 = _gamma(s, n_eff * L) * (n_train / n_eff) + leak_l
    z2 = _gamma(s, n_eff * L) * (n_train / n_eff) + leak_r
    if method == 0:
        # CA: (Z1 + Z2) / 2n
        return (z1 + z2) / (2 * n_train)
    if method == 1:
        # CASO: min(Z1, Z2) / n
        return min(z1, z2) / n_train
    # CAGO: max(Z1, Z2) / n
    return max(z1, z2) / n_train


@numba.njit(cache=True, nogil=True)
def _grow(f64, i64, need):  # pragma: no cover
    """The output buffers with room for at least ``need`` rows (doubling)."""
    if need <= f64.shape[0]:
        return f64, i64
    cap = max(need, 2 * f64.shape[0])
    f2 = np.empty((cap, f64.shape[1]))
    i2 = np.empty((cap, i64.shape[1]), dtype=np.int64)
    f2[: f64.shape[0]] = f64
    i2[: i64.shape[0]] = i64
    return f2, i2


@numba.njit(cache=True, nogil=True)
def _measure_frames(
    states, start, pos, vel, gain_db, rcs, elev, noise, const, tables, array, fa
):  # pragma: no cover
    """Steps 1-4 of the module docstring for every frame ``f`` (reflectors
    ``start[f]:start[f+1]``), frame ``f`` drawing from the generator state ``states[f]``.

    Returns ``counts`` ``(F,)``, ``f64`` ``(n, 8)`` (range, azimuth, elevation, radial velocity,
    SNR, x, y, z) and ``i64`` ``(n, 3)`` (reflector index or -1 for a false alarm, range bin,
    Doppler index). ``const``: :class:`ModelConstants`; ``tables``: :class:`KernelTables`;
    ``array``: :class:`ArrayLayout`; ``fa``: :class:`FalseAlarmPool`.
    """
    t_mid, range_res, vel_res, n_loops = const.t_mid, const.range_res, const.vel_res, const.n_loops
    doppler_scale, c_amp2, L = const.doppler_scale, const.c_amp2, const.L
    rmeth, rn, rne, ralpha = const.range_stage
    dmeth, dn, dne, dalpha = const.doppler_stage
    bin_lo, bin_hi = const.bin_lo, const.bin_hi  # (const.m_az: not read here)
    range_gain, range_est, range_leak = tables.range_gain, tables.range_est, tables.range_leak
    doppler_gain, doppler_index = tables.doppler_gain, tables.doppler_index
    doppler_est, doppler_leak, cell_noise = (
        tables.doppler_est,
        tables.doppler_leak,
        tables.cell_noise,
    )
    az_pos, el_pos, n_tx, n_rx = array.az_pos, array.el_pos, array.n_tx, array.n_rx
    row_ch, row_pos, upper, lower, tw_a = (
        array.row_ch, array.row_pos, array.upper, array.lower, array.tw_a
    )  # fmt: skip
    fa_rate, fa_doppler, fa_snr, fa_az, fa_frac = fa
    n_frames = states.shape[0]
    counts = np.zeros(n_frames, dtype=np.int64)
    cap = start[n_frames] + 4 * n_frames + 16
    f64 = np.empty((cap, 8))
    i64 = np.empty((cap, 3), dtype=np.int64)
    n_out = 0
    f_step = 1.0 / (range_gain.shape[0] - 1)
    half = n_loops / 2
    nu_step = n_loops / (doppler_gain.shape[0] - 1)
    n_v = az_pos.shape[0]
    xv = np.empty(n_v, dtype=np.complex128)
    spec = np.empty(tw_a.shape[0])
    s = np.empty(4, dtype=np.uint64)
    for fr in range(n_frames):
        s[:] = states[fr]
        first = n_out
        for i in range(start[fr], start[fr + 1]):
            px = pos[i, 0] + vel[i, 0] * t_mid
            py = pos[i, 1] + vel[i, 1] * t_mid
            pz = pos[i, 2] + vel[i, 2] * t_mid
            r = np.sqrt(px * px + py * py + pz * pz)
            vr = (px * vel[i, 0] + py * vel[i, 1] + pz * vel[i, 2]) / r
            r0 = np.sqrt(pos[i, 0] ** 2 + pos[i, 1] ** 2 + pos[i, 2] ** 2)
            # A^2 = Pt Gt Gr lambda^2 sigma / ((4 pi)^3 R^4) * R 10^(Ge/20)   (eqs. 2-4)
            amp2 = c_amp2 * 10.0 ** ((2.0 * gain_db[i] + rcs[i]) / 10.0) / r0**4
            rb = r / range_res
            k_int = np.floor(rb)
            f = rb - k_int
            nu_true = doppler_scale * vr / vel_res
            nu = (nu_true + half) % n_loops - half
            gr = _lerp(range_gain, f, 0.0, f_step)
            r_est = k_int + _lerp(range_est, f, 0.0, f_step)
            jd = int(np.rint((nu + half) / nu_step))
            jr = int(np.rint(f / f_step))
            dc = doppler_index[jd]
            d_est = _lerp(doppler_est, nu, -half, nu_step)
            # rho = A^2 |R|^2 |D|^2 / s2[d]  (per channel, peak cell)
            rho = max(amp2 * gr * doppler_gain[jd] / cell_noise[dc], 1e-30)
            # the array phase of the exact chain is that of the first chirp's direction
            u0 = pos[i, 0] / r0
            s0 = pos[i, 2] / r0
            if noise:
                # X = |sqrt(L rho) + n|^2 + Gamma(L - 1),  n ~ CN(0, 1)
                a = np.sqrt(L * rho) + _normal(s) / np.sqrt(2.0)
                b = _normal(s) / np.sqrt(2.0)
                x = a * a + b * b + _gamma(s, L - 1.0)
                # training cells: noise plus the reflector's own leakage (units of s2)
                leak = L * amp2 / cell_noise[dc]
                lr = leak * doppler_gain[jd]
                ld = leak * gr
                mu_r = _training_sum(
                    s, rmeth, rn, rne, L, lr * range_leak[jr, 0], lr * range_leak[jr, 1]
                )
                mu_d = _training_sum(
                    s, dmeth, dn, dne, L, ld * doppler_leak[jd, 0], ld * doppler_leak[jd, 1]
                )
                det = x > ralpha * mu_r and x > dalpha * mu_d
                snr = 10.0 * np.log10(x / mu_r)
                # Cramer-Rao: var(bin) = 6 / (4 pi^2 L rho)
                sd_bin = np.sqrt(6.0 / (4.0 * np.pi**2 * L * rho))
                r_est += sd_bin * _normal(s)
                d_est += sd_bin * _normal(s)
            else:
                det = True
                snr = 10.0 * np.log10(L * rho)
            # angles: the chain's estimator on the peak cell's channel values, units of noise:
            # x_v = rho^(1/2) exp(j pi (p_v u + e_v sin el)) exp(j 2 pi nu k(v) / (Nc Ntx)) + n_v
            amp = np.sqrt(rho)
            for v in range(n_v):
                ph = np.pi * (az_pos[v] * u0 + el_pos[v] * s0)
                ph += 2.0 * np.pi * nu_true * (v // n_rx) / (n_loops * n_tx)
                xv[v] = amp * (np.cos(ph) + 1j * np.sin(ph))
                if noise:
                    xv[v] += (_normal(s) + 1j * _normal(s)) / np.sqrt(2.0)
            a_i, e_i = angles_of(
                xv,
                d_est,
                n_tx,
                n_rx,
                n_loops,
                row_ch,
                row_pos,
                upper,
                lower,
                tw_a,
                elev[fr],
                spec,
            )
            if not (det and bin_lo - 0.5 <= r_est <= bin_hi + 0.5):
                continue
            u_est = np.sin(a_i) * np.cos(e_i)
            az = np.arcsin(min(max(u_est / np.cos(e_i), -1.0), 1.0))
            f64, i64 = _grow(f64, i64, n_out + 1)
            rng_m = r_est * range_res
            f64[n_out, 0] = rng_m
            f64[n_out, 1] = az
            f64[n_out, 2] = e_i
            f64[n_out, 3] = ((d_est + half) % n_loops - half) * vel_res
            f64[n_out, 4] = snr
            i64[n_out, 0] = i
            i64[n_out, 1] = int(np.rint(r_est))
            i64[n_out, 2] = dc
            n_out += 1
        if noise and fa_rate > 0.0 and fa_snr.shape[0] > 0:
            # the chain's own false alarms: Poisson count, resampled from the measured pool,
            # range uniform over the detectable bins, Doppler refinement uniform in the cell
            k = _poisson(s, fa_rate)
            f64, i64 = _grow(f64, i64, n_out + k)
            for _ in range(k):
                pick = _randint(s, fa_snr.shape[0])
                rb = bin_lo + _randint(s, bin_hi - bin_lo + 1) + fa_frac[pick]
                db = fa_doppler[pick] - n_loops // 2 + (_uniform(s) - 0.5)
                f64[n_out, 0] = rb * range_res
                f64[n_out, 1] = fa_az[pick]
                f64[n_out, 2] = 0.0
                f64[n_out, 3] = db * vel_res
                f64[n_out, 4] = fa_snr[pick]
                i64[n_out, 0] = -1
                i64[n_out, 1] = int(np.rint(rb))
                i64[n_out, 2] = fa_doppler[pick]
                n_out += 1
        for j in range(first, n_out):
            # x = r cos(el) sin(az), y = r cos(el) cos(az), z = r sin(el)
            horiz = f64[j, 0] * np.cos(f64[j, 2])
            f64[j, 5] = horiz * np.sin(f64[j, 1])
            f64[j, 6] = horiz * np.cos(f64[j, 1])
            f64[j, 7] = f64[j, 0] * np.sin(f64[j, 2])
        counts[fr] = n_out - first
    return counts, f64[:n_out], i64[:n_out]


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

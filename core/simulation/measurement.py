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

Not modelled (measured against ``exact`` in ``docs/fidelity.md``): the extra detections next to
very strong or fast reflectors (window sidelobes, clutter-removal residuals), two reflectors
sharing a cell, the threshold effect of the estimators at very low SNR.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numba
import numpy as np

from core.config import DEFAULT_PROCESSING, SPEED_OF_LIGHT_MPS, ProcessingSettings, RadarConfig
from core.pointcloud import SOURCE_OTHER, PointCloud
from core.processing import estimate_angles, make_cfar
from core.processing.angle import log_parabolic_offset
from core.processing.spectrum import window
from core.simulation.antenna import AntennaGain
from core.simulation.fast import (
    angle_twiddles,
    angles_of,
    array_rows,
    cell_noise_power_v2,
    effective_cells_or_none,
    range_responses,
)
from core.simulation.frame import FrameOutput, needs_elevation
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
    """Run ``n_frames`` noise-only frames through the exact chain (seeded) and pool the points."""
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


@functools.lru_cache(maxsize=16)
def _setup(radar: RadarConfig, settings: ProcessingSettings) -> tuple[ChainTables, dict]:
    """Tables and constants of a radar and settings (one cache look-up per frame)."""
    return chain_tables(radar, settings), _constants(radar, settings)


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
    method = {"ca": 0, "caso": 1, "cago": 2}
    kernel = (
        t_mid, radar.range_resolution_m, radar.velocity_resolution_mps, radar.n_loops,
        doppler_scale, c_amp2, float(L),
        method[rs.method], rs.n_train, float(ne_r or rs.n_train), rc.alpha(),
        method[ds.method], ds.n_train, float(ne_d or ds.n_train), dc.alpha(),
        min(n_row, len(set(radar.azimuth_positions))),
        int(ok[0]) if ok.size else 0, int(ok[-1]) if ok.size else -1,
    )  # fmt: skip
    array = (
        np.asarray(radar.azimuth_positions, dtype=np.float64),
        np.asarray(radar.elevation_positions, dtype=np.float64),
        radar.n_tx,
        radar.n_rx,
        *array_rows(radar),
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


def _noise_estimate(
    method: str, n_train: int, n_eff: float, L: int, rng: np.random.Generator, leak: np.ndarray
) -> np.ndarray:
    """CFAR noise estimates (units of the cell noise), ``(n,)``.

    ``leak`` ``(n, 2)``: the reflector's own power summed over the left and right training
    cells (units of the cell noise). The noise part of each side's sum is
    ``(n_train / n_eff) Gamma(n_eff L)``: mean ``n_train L`` and the variance of
    window-correlated cells (the moment match the CFAR thresholds use).
    """
    z = rng.standard_gamma(float(n_eff * L), (len(leak), 2)) * (n_train / n_eff) + leak
    if method == "ca":
        # mu = (Z_left + Z_right) / 2n
        return z.sum(axis=1) / (2 * n_train)
    # CASO: min(Z1, Z2) / n;  CAGO: max(Z1, Z2) / n
    return (z.min(axis=1) if method == "caso" else z.max(axis=1)) / n_train


def simulate_frame_measurement(
    radar: RadarConfig,
    scatterers: Scatterers,
    rng: np.random.Generator,
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
    """
    tab, const = _setup(radar, settings)
    n = len(scatterers)
    if elevation is None:
        elevation = needs_elevation(radar, scatterers)
    fields = []
    if n:
        p0 = scatterers.position_m
        g_db = antenna.gain_db(np.arctan2(p0[:, 0], p0[:, 1]))
        det, r_bin, d_bin, u, el, snr_db, d_cell = _measure_kernel(
            rng if noise else np.random.default_rng(0),
            np.ascontiguousarray(p0, dtype=np.float64),
            np.ascontiguousarray(scatterers.velocity_mps, dtype=np.float64),
            np.asarray(g_db, dtype=np.float64),
            np.asarray(scatterers.rcs_dbsm, dtype=np.float64),
            *const["kernel"],
            tab.range_gain,
            tab.range_est,
            tab.range_leak,
            tab.doppler_gain,
            tab.doppler_index,
            tab.doppler_est,
            tab.doppler_leak,
            tab.u_est,
            tab.cell_noise,
            bool(noise),
            *const["array"],
            angle_twiddles(radar, settings.angle_fft_size),
            bool(elevation),
        )
        el = el[det]
        fields.append(
            (
                r_bin[det],
                np.arcsin(np.clip(u[det] / np.cos(el), -1.0, 1.0)),
                el,
                d_bin[det],
                snr_db[det],
                scatterers.source[det],
                d_cell[det],
            )
        )
    if noise:
        extra = _false_alarms(radar, settings, const, rng)
        if extra is not None:
            fields.append(extra)
    if len(fields) == 1:
        r_bin, az, el, d_bin, snr_db, source, d_cell = fields[0]
    elif fields:
        r_bin, az, el, d_bin, snr_db, source, d_cell = (np.concatenate(c) for c in zip(*fields))
    else:
        r_bin = az = el = d_bin = snr_db = np.zeros(0)
        source, d_cell = np.zeros(0, dtype=np.int32), np.zeros(0, dtype=np.int64)
    pc = _cloud(
        radar,
        r_bin * radar.range_resolution_m,
        az,
        el,
        d_bin * radar.velocity_resolution_mps,
        snr_db,
        source,
    )
    cells = np.column_stack((np.rint(r_bin), d_cell)).astype(np.int64)
    rd_db = None
    if keep_rd_map:
        rd_db = _model_map(radar, tab, cells, pc)
    return FrameOutput(point_cloud=pc, rd_map_db=rd_db, detections=cells)


@numba.njit(cache=True, nogil=True)
def _lerp(table, x, x0, step):  # pragma: no cover
    """Linear interpolation in a table on the uniform grid ``x0 + i step`` (clamped)."""
    t = (x - x0) / step
    i = int(np.floor(t))
    i = min(max(i, 0), table.shape[0] - 2)
    w = min(max(t - i, 0.0), 1.0)
    return table[i] * (1.0 - w) + table[i + 1] * w


@numba.njit(cache=True, nogil=True)
def _training_sum(rng, method, n_train, n_eff, L, leak_l, leak_r):  # pragma: no cover
    """CFAR noise estimate: each side ``(n / n_eff) Gamma(n_eff L)`` plus the own leakage."""
    z1 = rng.standard_gamma(n_eff * L) * (n_train / n_eff) + leak_l
    z2 = rng.standard_gamma(n_eff * L) * (n_train / n_eff) + leak_r
    if method == 0:
        # CA: (Z1 + Z2) / 2n
        return (z1 + z2) / (2 * n_train)
    if method == 1:
        # CASO: min(Z1, Z2) / n
        return min(z1, z2) / n_train
    # CAGO: max(Z1, Z2) / n
    return max(z1, z2) / n_train


@numba.njit(cache=True, nogil=True)
def _measure_kernel(
    rng,
    pos,
    vel,
    gain_db,
    rcs,
    t_mid,
    range_res,
    vel_res,
    n_loops,
    doppler_scale,
    c_amp2,
    L,
    rmeth,
    rn,
    rne,
    ralpha,
    dmeth,
    dn,
    dne,
    dalpha,
    m_az,
    bin_lo,
    bin_hi,
    range_gain,
    range_est,
    range_leak,
    doppler_gain,
    doppler_index,
    doppler_est,
    doppler_leak,
    u_est_tab,
    cell_noise,
    noise,
    az_pos,
    el_pos,
    n_tx,
    n_rx,
    row_ch,
    row_pos,
    upper,
    lower,
    tw_a,
    elevation,
):  # pragma: no cover
    """Steps 1-3 of the module docstring for every reflector; arrays ``(N,)``."""
    n = pos.shape[0]
    det = np.zeros(n, dtype=np.bool_)
    r_out = np.empty(n)
    d_out = np.empty(n)
    u_out = np.empty(n)
    el_out = np.empty(n)
    snr_out = np.empty(n)
    cell_out = np.empty(n, dtype=np.int64)
    f_step = 1.0 / (range_gain.shape[0] - 1)
    half = n_loops / 2
    nu_step = n_loops / (doppler_gain.shape[0] - 1)
    n_v = az_pos.shape[0]
    xv = np.empty(n_v, dtype=np.complex128)
    spec = np.empty(tw_a.shape[0])
    for i in range(n):
        px = pos[i, 0] + vel[i, 0] * t_mid
        py = pos[i, 1] + vel[i, 1] * t_mid
        pz = pos[i, 2] + vel[i, 2] * t_mid
        r = np.sqrt(px * px + py * py + pz * pz)
        vr = (px * vel[i, 0] + py * vel[i, 1] + pz * vel[i, 2]) / r
        el_out[i] = np.arctan2(pz, np.hypot(px, py))
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
            a = np.sqrt(L * rho) + rng.standard_normal() / np.sqrt(2.0)
            b = rng.standard_normal() / np.sqrt(2.0)
            x = a * a + b * b + rng.standard_gamma(L - 1.0)
            # training cells: noise plus the reflector's own leakage (units of s2)
            leak = L * amp2 / cell_noise[dc]
            lr = leak * doppler_gain[jd]
            ld = leak * gr
            mu_r = _training_sum(
                rng, rmeth, rn, rne, L, lr * range_leak[jr, 0], lr * range_leak[jr, 1]
            )
            mu_d = _training_sum(
                rng, dmeth, dn, dne, L, ld * doppler_leak[jd, 0], ld * doppler_leak[jd, 1]
            )
            det[i] = x > ralpha * mu_r and x > dalpha * mu_d
            snr_out[i] = 10.0 * np.log10(x / mu_r)
            # Cramer-Rao: var(bin) = 6 / (4 pi^2 L rho)
            sd_bin = np.sqrt(6.0 / (4.0 * np.pi**2 * L * rho))
            r_est += sd_bin * rng.standard_normal()
            d_est += sd_bin * rng.standard_normal()
        else:
            det[i] = True
            snr_out[i] = 10.0 * np.log10(L * rho)
        # angles: the chain's estimator on the peak cell's channel values, units of the noise:
        # x_v = rho^(1/2) exp(j pi (p_v u + e_v sin el)) exp(j 2 pi nu k(v) / (Nc Ntx)) + n_v
        amp = np.sqrt(rho)
        for v in range(n_v):
            ph = np.pi * (az_pos[v] * u0 + el_pos[v] * s0)
            ph += 2.0 * np.pi * nu_true * (v // n_rx) / (n_loops * n_tx)
            xv[v] = amp * (np.cos(ph) + 1j * np.sin(ph))
            if noise:
                xv[v] += (rng.standard_normal() + 1j * rng.standard_normal()) / np.sqrt(2.0)
        a_i, e_i = angles_of(
            xv, d_est, n_tx, n_rx, n_loops, row_ch, row_pos, upper, lower, tw_a, elevation, spec
        )
        u_est = np.sin(a_i) * np.cos(e_i)
        el_out[i] = e_i
        det[i] = det[i] and bin_lo - 0.5 <= r_est <= bin_hi + 0.5
        r_out[i] = r_est
        d_out[i] = (d_est + half) % n_loops - half
        u_out[i] = u_est
        cell_out[i] = dc
    return det, r_out, d_out, u_out, el_out, snr_out, cell_out


def _cloud(radar, range_m, az, el, vr, snr_db, source) -> PointCloud:
    horiz = range_m * np.cos(el)
    range_m = np.asarray(range_m, dtype=np.float64)
    return PointCloud(
        range_m=range_m,
        azimuth_rad=az,
        elevation_rad=el,
        radial_velocity_mps=vr,
        snr_db=snr_db,
        x_m=horiz * np.sin(az),
        y_m=horiz * np.cos(az),
        z_m=range_m * np.sin(el),
        source=np.asarray(source, dtype=np.int32),
    )


def _false_alarms(radar, settings, const, rng):
    """A Poisson number of the chain's own false alarms, resampled from the measured pool.

    Returns the point fields ``(range bin, azimuth, elevation, Doppler bin, SNR, source,
    Doppler cell)``, or None when there is none this frame.
    """
    fa = chain_false_alarms(radar, settings)
    k = rng.poisson(fa.rate_per_frame) if fa.rate_per_frame > 0 and len(fa.snr_db) else 0
    if k == 0:
        return None
    pick = rng.integers(0, max(len(fa.snr_db), 1), k)
    r_bin = rng.integers(const["bin_lo"], const["bin_hi"] + 1, k) + fa.range_frac[pick]
    # the pool's Doppler cell with a uniform sub-bin refinement in (-0.5, 0.5)
    d_bin = fa.doppler_index[pick] - radar.n_loops // 2 + rng.uniform(-0.5, 0.5, k)
    return (
        r_bin,
        fa.azimuth_rad[pick],
        np.zeros(k),
        d_bin,
        fa.snr_db[pick],
        np.full(k, SOURCE_OTHER, dtype=np.int32),
        fa.doppler_index[pick],
    )


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

"""``fast`` fidelity level: the exact chain's range-Doppler spectrum in closed form.

The exact level synthesises every ADC sample of every chirp and channel, draws noise for every
sample and runs two FFTs over the whole cube. After the range and Doppler FFTs, a point scatterer
``i`` is separable (for the frame's few centimetres of range migration, see below)::

    X_i[v, k, d] = A_i a_i[v] R_i[k] D_i[slot(v), d]

- ``A_i = Vspp / (2 sqrt 2)``: the complex baseband amplitude (link budget, eqs. 2-4);
- ``a_i[v] = exp(j pi (p_v sin(az) cos(el) + e_v sin(el)))``: the virtual-array phase;
- ``R_i[k] = sum_n w_r[n] exp(j theta_i n) exp(-j 2 pi k n / Nadc)``: the range window's response
  to the beat tone ``theta_i = 2 pi (2 S R_i / c) / Fs`` rad/sample (one 256-point FFT);
- ``D_i[s, d] = sum_m w_d[m] (y_m - mean_m y) exp(-j 2 pi (d - Nc/2) m / Nc)`` with the slow-time
  phase of the chirp of slot ``s`` in loop ``m`` at time ``t_c = (m Ntx + s) Tchirp``::

      y_m = exp(j (4 pi R_i(t_c) / lambda + theta_i' (R_i(t_c) - R_i(t_mid)) (Nadc - 1) / 2))

  (static clutter removal subtracts the loop mean; the second term is the beat tone's phase at the
  middle of the ADC window moving with the range, the exact chain's "carrier at mid-ramp"). The
  slot's delay carries the TDM-MIMO Doppler coupling exactly.

Noise. Per virtual channel and cell, the exact chain's noise after the two windowed FFTs is
circular complex Gaussian with variance (``sigma^2`` per ADC sample)::

    s2[d] = sigma^2 sum_n w_r[n]^2 (sum_m w_d[m]^2 - |W_d(d)|^2 / Nc)        (with clutter removal)

(``W_d(d)`` the Doppler window's DFT at bin ``d``: clutter removal lowers the noise at and next to
zero Doppler). Every cell of the range-Doppler map is the non-coherent
sum of 12 such exponentials, drawn directly as ``s2[d] Gamma(12)``, except in the patches where
some scatterer's energy matters (per-channel signal power above ``-30 dB`` of ``s2``): there the
coherent sum ``s`` of the scatterers (12 channel values) meets the noise, and by the rotation
invariance of circular Gaussian noise the channel sum ``sum_v |s_v + n_v|^2`` is drawn as
``|(|s| + n_1)|^2 + s2 Gamma(11)``. Only the detected cells get their 12 channel values, drawn
from the exact conditional law given those draws (:func:`detected_channels`). The same CFAR,
angle, SNR and labelling stages as the
exact chain then run unchanged.

Scatterers of a frame that share a tone (the same range at every chirp: a wall ghost's two
contributions) are one term with their channel weights summed (:func:`tones`), as the exact
level synthesises them (:func:`core.simulation.baseband.coincident_tones`).

Entry points: :func:`simulate_frame_fast` (one frame, the GUI's) and
:func:`simulate_frames_fast` (all frames of a trajectory, the data-set path: per-scatterer inputs
computed once, then one compiled call for every frame's noise map, patches, CFAR, detected
channels, points and labels). The first is the second with one frame, so both give the same
frames for the same per-frame generators. The draws come from a compiled generator
(:mod:`core.simulation.rng_kernels`) seeded per frame with four raw words of that frame's
generator; the noise map's Gamma(12) is NumPy's float32 algorithm on those words
(``docs/decisions/simulation-11``).

CFAR thresholds. Neighbouring cells of the exact chain's noise are correlated through the
windows (|rho|^2 = 4/9 for Hann), here they are independent. The exact chain's thresholds on
independent cells would give other noise false alarms, both through the two stages (which share
the cell under test) and through peak grouping (a noise peak among correlated neighbours is
less often a local maximum: 12 % of the exact chain's noise detections go, 3 % of independent
cells'). :func:`core.simulation.fast_cfar.independent_cell_stages` scales both stages'
``pfa`` by one factor so that the expected noise detections per frame after both stages and
peak grouping (:func:`core.processing.false_alarms.noise_detections_per_frame`) are the exact
chain's (``docs/decisions/simulation-12``). ``rect`` windows leave independent cells: the
thresholds are then the chain's own.

Layout: the closed-form model and its compiled kernels (responses, noise map, patches) are in
:mod:`core.simulation.fast_model`, the CFAR thresholds in :mod:`core.simulation.fast_cfar`. This
module (about 740 lines, over the house's ~600 on purpose) holds the two entry points with their
compiled batch path (:func:`_frames_kernel` → :func:`_frame_kernel`) next to the per-frame
reference functions it must equal draw for draw (:func:`fast_spectrum`,
:func:`detected_channels`, :func:`points_from_channels`; tested bit for bit), so that a change to
one is made, and seen, beside the other.

Known approximations (measured in ``docs/fidelity-models.md``): the noise cells' correlation is
modelled only through the thresholds (above); the beat tone's drift over the frame (<= 0.2
range bins at 1.8 m/s) is reduced to its phase term.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numba
import numpy as np

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)
from core.config import (
    DEFAULT_PROCESSING,
    ProcessingSettings,
    RadarConfig,
)
from core.errors import InputError
from core.pointcloud import POINT_FIELDS, SOURCE_OTHER, PointCloud
from core.processing import (
    Detections,
    estimate_angles,
    label_sources,
    refine_bins,
)
from core.processing.cfar import (
    CfarStageArgs,
    TwoStageCfarArgs,
    two_stage_kernel,
)
from core.processing.points import (
    angle_twiddles,
    array_rows,
    cloud_from_rows,
    detection_rows,
    point_rows,
    points_kernel,
)
from core.simulation.antenna import AntennaGain
from core.simulation.baseband import merged_tones
from core.simulation.fast_cfar import cfar_arguments, cfar_range_bins
from core.simulation.fast_model import (
    PATCH_THRESHOLD,
    beat_rad_per_sample_per_m,
    cell_noise_power_v2,
    cosine_sum_coefficients,
    doppler_weights,
    noise_map,
    patches_kernel,
    range_envelopes,
    slow_time_sequences,
    twiddles,
)
from core.simulation.frame import FrameOutput
from core.simulation.rng_kernels import (
    fill_normal,
    normal_l,
    state6,
    state_from,
)
from core.simulation.scatterers import Scatterers


class Spectrum(NamedTuple):
    """The ``fast`` level's range-Doppler map and what it needs to rebuild detected cells.

    Attributes
    ----------
    rd_map
        ``[range bin, Doppler bin]`` float32 power (V²) summed over channels, zero velocity
        centred.
    patch
        ``(n_cells, 2)`` int: range bin and Doppler index of the cells where a scatterer's
        energy matters.
    signal
        ``(n_cells, n_virtual)`` complex128 noise-free Doppler-cube values of those cells.
    along
        ``(n_cells,)`` complex128: the noise component along ``signal / |signal|``.
    ortho
        ``(n_cells,)`` float64: noise power orthogonal to the signal (V²).
    state
        ``(4,)`` uint64: the compiled generator's state after these draws
        (:mod:`core.simulation.rng_kernels`); :func:`detected_channels` continues from it.
    """

    rd_map: np.ndarray
    patch: np.ndarray
    signal: np.ndarray
    along: np.ndarray
    ortho: np.ndarray
    state: np.ndarray


def fast_spectrum(
    radar: RadarConfig,
    scatterers: Scatterers,
    rng: np.random.Generator | None,
    *,
    antenna: AntennaGain,
    settings: ProcessingSettings = DEFAULT_PROCESSING,
    noise: bool = True,
    n_range_bins: int | None = None,
) -> Spectrum:
    """Range-Doppler map in closed form (see the module docstring).

    ``n_range_bins``: only the first range bins are drawn (the CFAR never looks beyond its
    range limit plus its training window, :func:`cfar_range_bins`); the rest of the map holds
    the mean noise power. None: the whole map (for display).

    The draws come from the compiled generator seeded with four raw draws of ``rng``
    (:func:`core.simulation.rng_kernels.state_from`): first the noise map row by row, then per
    patch cell the noise along the signal (real, imaginary) and the orthogonal power.

    Circular complex Gaussian noise is invariant under rotations of ``C^L``: in a patch cell
    with signal vector ``s`` the channel sum ``sum_v |s_v + n_v|^2`` has the law of
    ``|(|s| + n_1)|^2 + s2 Gamma(L - 1)`` (``n_1`` the noise along ``s``), so a cell costs one
    complex normal and one Gamma draw instead of ``L`` complex normals; the channel values of
    detected cells are rebuilt from the same draws by :func:`detected_channels`.
    """
    n_r, n_d, n_v = radar.n_samples, radar.n_loops, radar.n_virtual
    n_use = n_r if n_range_bins is None else max(0, min(n_r, int(n_range_bins)))
    spec = spectrum_tables(radar, settings, True)._replace(n_use=n_use)
    state = state6(state_from(rng if noise else None))
    rd = np.zeros((n_r, n_d), dtype=np.float32)
    if noise:
        noise_map(state, rd, spec.s2, n_use, n_v)
    if len(scatterers) == 0:
        e = np.zeros(0)
        return Spectrum(
            rd, np.zeros((0, 2), dtype=np.int64), np.zeros((0, n_v), complex), e, e, state
        )
    amp, theta, slow, slow1, steer, _ = tones(radar, scatterers, antenna, settings)
    k_idx, d_idx, x, along, ortho = patches_kernel(
        state, rd, amp, theta, slow, slow1, spec.wd, spec.b, spec.s2, steer, spec.slot,
        spec.threshold, spec.half_r, spec.tw_d, spec.env, noise, n_use,
    )  # fmt: skip
    return Spectrum(rd, np.column_stack((k_idx, d_idx)).astype(np.int64), x, along, ortho, state)


def tones(
    radar: RadarConfig,
    scatterers: Scatterers,
    antenna: AntennaGain,
    settings: ProcessingSettings,
    frame: np.ndarray | None = None,
):
    """The tones the patches are built from: ``(amp, theta, slow, slow1, steer, keep)``.

    One per scatterer, except that scatterers of one frame (``frame`` ``(N,)``, default all
    one) that share a tone (:func:`core.simulation.baseband.coincident_tones`: a wall ghost's
    two contributions) are one, with their summed channel weights
    (:func:`core.simulation.baseband.merge_tones`); ``keep`` ``(M,)`` the scatterers kept (each
    tone's first). ``amp`` ``(M,)`` V, ``theta`` ``(M,)`` beat tone rad/sample at mid-frame,
    ``slow``/``slow1`` :func:`slow_time_sequences`, ``steer`` ``(M, L)`` complex128.
    """
    keep, amp, steer, scatterers = merged_tones(radar, scatterers, antenna, frame)
    t_mid = 0.5 * radar.n_loops * radar.n_tx * radar.chirp_period_s
    r_mid = np.linalg.norm(scatterers.position_m + scatterers.velocity_mps * t_mid, axis=1)
    # theta = 2 pi (2 S R / c) / Fs   (rad per sample)
    theta = beat_rad_per_sample_per_m(radar) * r_mid
    slow, slow1 = slow_time_sequences(radar, scatterers, settings)
    return amp, theta, slow, slow1, np.ascontiguousarray(steer), keep


def simulate_frame_fast(
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
    """One frame at the ``fast`` level: closed-form spectrum, then the exact chain's detection.

    Same signature and output as :func:`core.simulation.simulate_frame`; see the module
    docstring for the model. ``rng`` seeds the noise (a different stream from the exact
    level's, so the same seed gives statistically equivalent, not identical, frames).
    """
    out, maps = _frames_fast(
        radar, [scatterers], [rng], antenna, settings, elevation, noise, keep_rd_map
    )
    rd_db = None
    if keep_rd_map:
        rd = maps[0]
        rd_db = (10 * np.log10(np.maximum(rd, np.finfo(np.float32).tiny))).astype(np.float32)
    return FrameOutput(point_cloud=out.point_cloud, rd_map_db=rd_db, detections=out.detections)


def detected_channels(radar: RadarConfig, spec: Spectrum, det: Detections) -> np.ndarray:
    """Per-channel values ``(n_det, n_virtual)`` complex128 of the detected cells.

    Patch cell: ``x = s + n_1 u + w`` with ``u = s / |s|`` and ``w`` a uniformly random vector
    orthogonal to ``u`` with ``|w|^2`` the drawn orthogonal power. Noise-only cell: ``P^(1/2)``
    times a uniformly random unit vector of ``C^L`` (``P`` the cell's summed power). Both are the
    exact conditional laws of i.i.d. circular Gaussian channels given the drawn map. The normal
    draws (all real parts, then all imaginary parts) continue ``spec.state`` (advanced).
    """
    rd = spec.rd_map
    n_v = radar.n_virtual
    n_det = len(det)
    # patch cells are sorted by (range bin, Doppler index): look detections up by linear index
    n_d = rd.shape[1]
    lin = spec.patch[:, 0] * n_d + spec.patch[:, 1]
    want = det.range_bin * n_d + det.doppler_index
    j = np.full(n_det, -1, dtype=np.int64)
    if len(lin):
        pos = np.minimum(np.searchsorted(lin, want), len(lin) - 1)
        j = np.where(lin[pos] == want, pos, -1)
    zr = fill_normal(spec.state, n_det * n_v).reshape(n_det, n_v)
    z = zr + 1j * fill_normal(spec.state, n_det * n_v).reshape(n_det, n_v)
    out = np.empty((n_det, n_v), dtype=np.complex128)
    inside = j >= 0
    if np.any(inside):
        s = spec.signal[j[inside]]
        norm = np.linalg.norm(s, axis=1, keepdims=True)
        u = np.where(norm > 0, s / np.where(norm > 0, norm, 1.0), np.eye(1, n_v))
        w = z[inside]
        w -= u * np.sum(np.conj(u) * w, axis=1, keepdims=True)  # project out u
        w *= np.sqrt(spec.ortho[j[inside]] / np.sum(np.abs(w) ** 2, axis=1))[:, None]
        out[inside] = s + spec.along[j[inside], None] * u + w
    if not np.all(inside):
        p = rd[det.range_bin[~inside], det.doppler_index[~inside]].astype(np.float64)
        zo = z[~inside]
        out[~inside] = zo * np.sqrt(p / np.sum(np.abs(zo) ** 2, axis=1))[:, None]
    return out


def points_from_channels(
    radar: RadarConfig,
    settings: ProcessingSettings,
    rd: np.ndarray,
    det: Detections,
    channels: np.ndarray,
    elevation: bool,
) -> PointCloud:
    """Point cloud from detections and their channel values: the exact chain's steps 6-7.

    The same refinement (:func:`core.processing.refine_bins`) and angle estimation
    (:func:`core.processing.estimate_angles`) as :func:`core.processing.build_point_cloud`,
    without building the Doppler cube. ``source`` is left at ``SOURCE_OTHER``.
    """
    r_bin, d_bin = refine_bins(rd, det)
    az, el = estimate_angles(
        channels, d_bin, radar, fft_size=settings.angle_fft_size, elevation=elevation
    )
    rng_m = r_bin * radar.range_resolution_m
    horiz = rng_m * np.cos(el)
    return PointCloud(
        range_m=rng_m,
        azimuth_rad=az,
        elevation_rad=el,
        radial_velocity_mps=d_bin * radar.velocity_resolution_mps,
        snr_db=det.snr_db,
        x_m=horiz * np.sin(az),
        y_m=horiz * np.cos(az),
        z_m=rng_m * np.sin(el),
        source=np.full(len(det), SOURCE_OTHER, dtype=np.int32),
    )


def label_points(radar: RadarConfig, pc: PointCloud, scatterers: Scatterers) -> PointCloud:
    """Ground-truth labels as the exact chain sets them: nearest reflector at mid-frame."""
    if not len(pc) or not len(scatterers):
        return pc
    t_mid = 0.5 * radar.n_loops * radar.n_tx * radar.chirp_period_s
    pos = scatterers.position_m + scatterers.velocity_mps * t_mid
    r_mid = np.linalg.norm(pos, axis=1)
    vr = np.einsum("ij,ij->i", pos, scatterers.velocity_mps) / r_mid
    src = label_sources(pc.range_m, pc.radial_velocity_mps, r_mid, vr, scatterers.source, radar)
    return PointCloud(
        range_m=pc.range_m,
        azimuth_rad=pc.azimuth_rad,
        elevation_rad=pc.elevation_rad,
        radial_velocity_mps=pc.radial_velocity_mps,
        snr_db=pc.snr_db,
        x_m=pc.x_m,
        y_m=pc.y_m,
        z_m=pc.z_m,
        source=src,
    )


def points_compiled(
    radar: RadarConfig,
    settings: ProcessingSettings,
    rd: np.ndarray,
    det: Detections,
    channels: np.ndarray,
    elevation: bool,
) -> PointCloud:
    """:func:`points_from_channels`, compiled: the same point cloud (``source`` = -2)."""
    r_bin, d_bin, az, el = points_kernel(
        rd,
        det.range_bin,
        det.doppler_index,
        np.ascontiguousarray(channels, dtype=np.complex128),
        radar.n_tx,
        radar.n_rx,
        *array_rows(radar),
        angle_twiddles(radar, settings.angle_fft_size),
        bool(elevation),
    )
    rng_m = r_bin * radar.range_resolution_m
    horiz = rng_m * np.cos(el)
    return PointCloud(
        range_m=rng_m,
        azimuth_rad=az,
        elevation_rad=el,
        radial_velocity_mps=d_bin * radar.velocity_resolution_mps,
        snr_db=det.snr_db,
        x_m=horiz * np.sin(az),
        y_m=horiz * np.cos(az),
        z_m=rng_m * np.sin(el),
        source=np.full(len(det), SOURCE_OTHER, dtype=np.int32),
    )


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class FramesOutput:
    """Points of many frames, concatenated (the batch simulators' result).

    Attributes
    ----------
    point_cloud
        Points of every frame in frame order, ``(n_points,)`` per field.
    counts
        ``(F,)`` int64: points per frame.
    detections
        ``(n_points, 2)`` int64: range bin, Doppler index (as :class:`FrameOutput`).
    """

    point_cloud: PointCloud
    counts: np.ndarray
    detections: np.ndarray

    def clouds(self) -> list[PointCloud]:
        """The per-frame point clouds (views into the concatenated arrays)."""
        edges = np.concatenate(([0], np.cumsum(self.counts)))
        pc = self.point_cloud
        names = (*POINT_FIELDS, "source")
        return [
            PointCloud(**{k: getattr(pc, k)[a:b] for k in names})
            for a, b in zip(edges[:-1].tolist(), edges[1:].tolist())
        ]


# ---- all frames of a trajectory: the batch path -------------------------------------------------
# Everything after the noise map in one compiled call per frame (patches, CFAR, detected
# channels, points, labels); the per-scatterer inputs (link budget, slow-time sequences,
# steering) are computed once for all frames. simulate_frame_fast is this path with one frame,
# so the per-frame (GUI) and batch (data set) entry points give the same frames.


@numba.njit(cache=True, nogil=True)
def _detected_channels_kernel(s, rd, r, d, cells_k, cells_d, x, along, ortho):  # pragma: no cover
    """:func:`detected_channels` compiled (same conditional laws, same draw order)."""
    n_det = r.shape[0]
    n_v = x.shape[1]
    n_d = rd.shape[1]
    # z = N(0, 1) + j N(0, 1): all real parts first, then all imaginary parts
    zr = np.empty((n_det, n_v))
    zi = np.empty((n_det, n_v))
    s0, s1, s2, s3 = s[0], s[1], s[2], s[3]  # the generator state in registers
    for i in range(n_det):
        for v in range(n_v):
            zr[i, v], s0, s1, s2, s3 = normal_l(s0, s1, s2, s3)
    for i in range(n_det):
        for v in range(n_v):
            zi[i, v], s0, s1, s2, s3 = normal_l(s0, s1, s2, s3)
    s[0], s[1], s[2], s[3] = s0, s1, s2, s3
    out = np.empty((n_det, n_v), dtype=np.complex128)
    n_c = cells_k.shape[0]
    u = np.empty(n_v, dtype=np.complex128)
    w = np.empty(n_v, dtype=np.complex128)
    for i in range(n_det):
        want = r[i] * n_d + d[i]
        # patch cells are sorted by linear index (range bin, then Doppler index)
        lo, hi = 0, n_c
        while lo < hi:
            mid = (lo + hi) // 2
            if cells_k[mid] * n_d + cells_d[mid] < want:
                lo = mid + 1
            else:
                hi = mid
        j = lo if lo < n_c and cells_k[lo] * n_d + cells_d[lo] == want else -1
        for v in range(n_v):
            w[v] = zr[i, v] + 1j * zi[i, v]
        if j >= 0:
            norm2 = 0.0
            for v in range(n_v):
                norm2 += x[j, v].real ** 2 + x[j, v].imag ** 2
            norm = np.sqrt(norm2)
            for v in range(n_v):
                # u = s / |s| (first unit vector when s = 0)
                u[v] = x[j, v] / norm if norm > 0 else (1.0 + 0j if v == 0 else 0j)
            proj = 0j
            for v in range(n_v):
                proj += np.conj(u[v]) * w[v]
            p2 = 0.0
            for v in range(n_v):
                w[v] -= u[v] * proj  # w orthogonal to u
                p2 += w[v].real ** 2 + w[v].imag ** 2
            scale = np.sqrt(ortho[j] / p2)
            for v in range(n_v):
                # x = s + n_1 u + w,  |w|^2 = drawn orthogonal power
                out[i, v] = x[j, v] + along[j] * u[v] + w[v] * scale
        else:
            p2 = 0.0
            for v in range(n_v):
                p2 += w[v].real ** 2 + w[v].imag ** 2
            # x = P^(1/2) z / |z|
            scale = np.sqrt(np.float64(rd[r[i], d[i]]) / p2)
            for v in range(n_v):
                out[i, v] = w[v] * scale
    return out


class SpectrumTables(NamedTuple):
    """What the compiled frame kernel draws a frame's noise map and patches with."""

    n_use: int  # range bins drawn (the CFAR's reach; all of them when the map is kept)
    n_v: int  # virtual channels L
    wd: np.ndarray  # (n_d,) Doppler window as patches_kernel wants it (doppler_weights)
    b: np.ndarray  # (2J+1,) range window's cosine-sum coefficients
    s2: np.ndarray  # (n_d,) per-channel cell noise power, V²
    slot: np.ndarray  # (L,) TX slot of each virtual channel
    threshold: float  # patch threshold relative to s2 (PATCH_THRESHOLD)
    half_r: np.ndarray  # (2 n_r,) exp(j pi u / n_r): the range responses' half angles
    tw_d: np.ndarray  # Doppler twiddles (see twiddles)
    env: np.ndarray  # (2, Q n_r / 2 + 1) the range responses' far bounds (range_envelopes)


class PointTables(NamedTuple):
    """What the compiled frame kernel turns detections into labelled points with."""

    n_tx: int
    n_rx: int
    row_ch: np.ndarray  # azimuth row: channels
    row_pos: np.ndarray  # azimuth row: positions (half wavelengths)
    upper: np.ndarray  # elevation pairs: upper channels (empty without elevation)
    lower: np.ndarray  # elevation pairs: lower channels
    tw_a: np.ndarray  # angle FFT twiddles
    res_r: float  # range resolution, m
    res_v: float  # velocity resolution, m/s
    t_mid: float  # the frame's middle, s (labels)
    span: float  # unambiguous velocity span 2 v_max, m/s (labels)


def spectrum_tables(
    radar: RadarConfig, settings: ProcessingSettings, keep_rd_map: bool
) -> SpectrumTables:
    """The :class:`SpectrumTables` of a radar and settings."""
    n_r, n_d, n_v = radar.n_samples, radar.n_loops, radar.n_virtual
    half_r, tw_d = twiddles(n_r, n_d)
    return SpectrumTables(
        n_use=n_r if keep_rd_map else max(0, min(n_r, cfar_range_bins(radar, settings))),
        n_v=n_v,
        wd=doppler_weights(settings.doppler_window, n_d),
        b=cosine_sum_coefficients(settings.range_window, n_r),
        s2=cell_noise_power_v2(radar, settings),
        slot=np.arange(n_v) // radar.n_rx,
        threshold=PATCH_THRESHOLD,
        half_r=half_r,
        tw_d=tw_d,
        env=range_envelopes(settings.range_window, n_r),
    )


def point_tables(
    radar: RadarConfig, settings: ProcessingSettings, elevation: bool, t_mid: float
) -> PointTables:
    """The :class:`PointTables` of a radar and settings (elevation pairs only if asked)."""
    row_ch, row_pos, upper, lower = detection_rows(radar, elevation)
    return PointTables(
        n_tx=radar.n_tx,
        n_rx=radar.n_rx,
        row_ch=row_ch,
        row_pos=row_pos,
        upper=upper,
        lower=lower,
        tw_a=angle_twiddles(radar, settings.angle_fft_size),
        res_r=radar.range_resolution_m,
        res_v=radar.velocity_resolution_mps,
        t_mid=t_mid,
        span=2 * radar.max_velocity_mps,
    )


#: Stand-in CFAR arguments when no range bin lies inside the limits (``has_cfar`` False).
_NO_CFAR = TwoStageCfarArgs(
    profile=np.ones(1),
    lo=0,
    hi=0,
    a=0,
    b=0,
    range_stage=CfarStageArgs(1, 0, False, 0, 1.0, 1.0),
    doppler_stage=CfarStageArgs(1, 0, False, 0, 1.0, 1.0),
    peak_grouping=False,
)


@numba.njit(cache=True, nogil=True)
def _frame_kernel(
    s, rd, amp, theta, slow, slow1, steer, pos, vel, source, elevation, noise, spec, has_cfar,
    cfar, pts,
):  # fmt: skip  # pragma: no cover
    """One frame after its noise map: patches, CFAR, detected channels, points, labels.

    ``amp`` … ``source``: the frame's reflectors (see :func:`patches_kernel`); ``spec``:
    :class:`SpectrumTables`; ``cfar``: :class:`~core.processing.cfar.TwoStageCfarArgs` (used
    when ``has_cfar``); ``pts``: :class:`PointTables`. Returns ``(det_r, det_d, f64 (n, 8),
    source)`` with ``f64`` columns range, azimuth, elevation, radial velocity, SNR, x, y, z.
    """
    cells_k, cells_d, x, along, ortho = patches_kernel(
        s, rd, amp, theta, slow, slow1, spec.wd, spec.b, spec.s2, steer, spec.slot,
        spec.threshold, spec.half_r, spec.tw_d, spec.env, noise, spec.n_use,
    )  # fmt: skip
    if has_cfar:
        r, d, nz = two_stage_kernel(rd, cfar)
    else:
        r = np.zeros(0, dtype=np.int64)
        d = np.zeros(0, dtype=np.int64)
        nz = np.zeros(0)
    n_det = r.shape[0]
    if n_det == 0:
        return r, d, np.empty((0, 8)), np.full(0, -2, dtype=np.int32)
    ch = _detected_channels_kernel(s, rd, r, d, cells_k, cells_d, x, along, ortho)
    f64, src = point_rows(
        rd, r, d, nz, ch, pts.n_tx, pts.n_rx, pts.row_ch, pts.row_pos, pts.upper, pts.lower,
        pts.tw_a, elevation, pos, vel, source, pts.t_mid, pts.res_r, pts.res_v, pts.span,
    )  # fmt: skip
    return r, d, f64, src  # fmt: skip


@numba.njit(cache=True, nogil=True)
def _grow(f64, i64, i32, need):  # pragma: no cover
    """The output buffers with room for at least ``need`` rows (doubling)."""
    if need <= f64.shape[0]:
        return f64, i64, i32
    cap = max(need, 2 * f64.shape[0])
    f2 = np.empty((cap, f64.shape[1]))
    i2 = np.empty((cap, i64.shape[1]), dtype=np.int64)
    j2 = np.empty(cap, dtype=np.int32)
    f2[: f64.shape[0]] = f64
    i2[: i64.shape[0]] = i64
    j2[: i32.shape[0]] = i32
    return f2, i2, j2


@numba.njit(cache=True, nogil=True)
def _frames_kernel(
    states, start, t_start, elev, maps, keep, amp, theta, slow, slow1, steer, pos, vel, source,
    noise, spec, has_cfar, cfar, pts,
):  # fmt: skip  # pragma: no cover
    """Every frame: noise map, then :func:`_frame_kernel`; frame ``f`` draws from ``states[f]``
    and has the reflectors ``start[f]:start[f+1]`` (``pos``, ``vel``, ``source``: labels) and
    the tones ``t_start[f]:t_start[f+1]`` (``amp`` … ``steer``: patches; arguments as there).

    Returns ``(det (n, 2), f64 (n, 8), source (n,), counts (F,))`` concatenated in frame order.
    """
    n_f = start.shape[0] - 1
    counts = np.zeros(n_f, dtype=np.int64)
    cap = 8 * n_f + 16
    f64_all = np.empty((cap, 8))
    det_all = np.empty((cap, 2), dtype=np.int64)
    src_all = np.empty(cap, dtype=np.int32)
    n_out = 0
    for f in range(n_f):
        s = states[f].copy()
        rd = maps[f] if keep else maps[0]
        if noise:
            noise_map(s, rd, spec.s2, spec.n_use, spec.n_v)
        else:
            rd[:] = 0.0
        i0, i1 = start[f], start[f + 1]
        j0, j1 = t_start[f], t_start[f + 1]
        r, d, f64, src = _frame_kernel(
            s, rd, amp[j0:j1], theta[j0:j1], slow[j0:j1], slow1[j0:j1], steer[j0:j1],
            pos[i0:i1], vel[i0:i1], source[i0:i1], elev[f], noise, spec, has_cfar, cfar, pts,
        )  # fmt: skip
        n = r.shape[0]
        f64_all, det_all, src_all = _grow(f64_all, det_all, src_all, n_out + n)
        for i in range(n):
            det_all[n_out + i, 0] = r[i]
            det_all[n_out + i, 1] = d[i]
            src_all[n_out + i] = src[i]
            for j in range(8):
                f64_all[n_out + i, j] = f64[i, j]
        n_out += n
        counts[f] = n
    return det_all[:n_out], f64_all[:n_out], src_all[:n_out], counts


def _frames_fast(
    radar: RadarConfig,
    frames: Sequence[Scatterers],
    rngs: Sequence[np.random.Generator | None],
    antenna: AntennaGain,
    settings: ProcessingSettings,
    elevation: bool | None,
    noise: bool,
    keep_rd_map: bool,
):
    """Shared body of :func:`simulate_frames_fast` and :func:`simulate_frame_fast`.

    Returns ``(FramesOutput, rd maps (F, n_r, n_d) float32 or None)``.
    """
    if len(frames) != len(rngs):
        raise InputError(f"rngs: {len(rngs)} generators for {len(frames)} frames")
    n_f = len(frames)
    n_r, n_d, n_v = radar.n_samples, radar.n_loops, radar.n_virtual
    counts = np.fromiter((len(s) for s in frames), dtype=np.int64, count=n_f)
    start = np.zeros(n_f + 1, dtype=np.int64)
    np.cumsum(counts, out=start[1:])
    every = Scatterers.concatenate(list(frames)) if start[-1] else Scatterers.empty()
    # per tone, all frames at once: link budget, beat tone, slow time, steering
    frame = np.repeat(np.arange(n_f), counts)
    amp, theta, slow, slow1, steer, kept = tones(radar, every, antenna, settings, frame)
    t_start = np.searchsorted(kept, start)  # frame f's tones: t_start[f]:t_start[f + 1]
    t_mid = 0.5 * radar.n_loops * radar.n_tx * radar.chirp_period_s
    pos = np.ascontiguousarray(every.position_m, dtype=np.float64)
    vel = np.ascontiguousarray(every.velocity_mps, dtype=np.float64)
    source = np.ascontiguousarray(every.source, dtype=np.int32)
    if elevation is not None:
        elev = np.full(n_f, bool(elevation))
    elif not radar.has_elevation:
        elev = np.zeros(n_f, dtype=bool)
    else:
        # needs_elevation per frame: some scatterer of the frame off the plane z = 0
        off = (every.position_m[:, 2] != 0) | (every.velocity_mps[:, 2] != 0)
        n_off = np.concatenate(([0], np.cumsum(off)))
        elev = n_off[start[1:]] > n_off[start[:-1]]
    cfar = cfar_arguments(radar, settings, n_v, n_r, n_d, True)
    has_cfar = cfar is not None  # None: no range bin inside the limits, nothing is tested
    states = np.zeros((n_f, 6), dtype=np.uint64)  # core.simulation.gaussian's six words
    for f in range(n_f):
        states[f, :4] = state_from(rngs[f] if noise else None)
    maps = np.empty((n_f if keep_rd_map else 1, n_r, n_d), dtype=np.float32)
    det, f64, src, n_out = _frames_kernel(
        states, start, t_start, elev, maps, bool(keep_rd_map), amp, theta, slow, slow1, steer,
        pos, vel, source, bool(noise), spectrum_tables(radar, settings, bool(keep_rd_map)),
        has_cfar, cfar if has_cfar else _NO_CFAR,
        point_tables(radar, settings, bool(elev.any()), t_mid),
    )  # fmt: skip
    pc = cloud_from_rows(f64, src)
    out = FramesOutput(point_cloud=pc, counts=n_out, detections=det)
    return out, (maps if keep_rd_map else None)


def simulate_frames_fast(
    radar: RadarConfig,
    frames: Sequence[Scatterers],
    rngs: Sequence[np.random.Generator | None],
    *,
    antenna: AntennaGain,
    settings: ProcessingSettings = DEFAULT_PROCESSING,
    elevation: bool | None = None,
    noise: bool = True,
) -> FramesOutput:
    """Many frames at the ``fast`` level (the data-set path).

    Frame ``f`` draws only from ``rngs[f]``, in the order :func:`simulate_frame_fast` draws,
    so the result equals the per-frame entry point's frames bit for bit (tested).

    Parameters
    ----------
    frames
        ``F`` frames' reflectors.
    rngs
        ``F`` generators, one per frame (the pipeline's ``stage_rng(seed, "noise", f)``).
    elevation
        Estimate elevation; ``None``: per frame, when the radar can and the frame is not planar.
    """
    return _frames_fast(radar, frames, rngs, antenna, settings, elevation, noise, False)[0]

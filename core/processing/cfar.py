"""Two-stage CFAR for a non-coherent sum of ``L`` channels (SPEC §3, step 5).

The detectors (CA / CASO / CAGO along one axis, :func:`make_cfar`), the two-stage detection of
a range-Doppler map with peak grouping (:func:`two_stage_cfar`, one compiled pass:
:func:`two_stage_kernel`) and the false-alarm rate of the two stages together
(:func:`two_stage_pfa`). The thresholds come from the exact false-alarm probabilities of
:mod:`core.processing.cfar_thresholds` (``X ~ Gamma(L)`` under noise, training sums
``Gamma(N L)``).

Non-cyclic axes (range): where one side's training window leaves the axis, the cell uses the
complete side alone as a CA detector with ``n`` cells (so its false-alarm rate stays the design
value). Cyclic axes (Doppler) wrap around.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import NamedTuple, Protocol

import numba
import numpy as np
from scipy.integrate import quad
from scipy.special import gammainc, gammaln

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)
from core.config import DEFAULT_PROCESSING, CfarSettings, ProcessingSettings, RadarConfig
from core.processing.cfar_thresholds import threshold_factor
from core.processing.spectrum import clutter_removal_noise_profile, effective_cells


# ---- detectors ----------------------------------------------------------------------------------
class Cfar(Protocol):
    """A CFAR detector along one axis of a power map."""

    def detect(self, power: np.ndarray, axis: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """Return ``(mask, noise)``: detected cells and per-cell noise estimate, shape of power."""
        ...


@functools.lru_cache(maxsize=128)
def _window_indices(size: int, n: int, g: int, cyclic: bool):
    """Cumulative-sum indices of the left/right training windows and their validity."""
    idx = np.arange(size)
    if cyclic:
        pad = n + g
        c = idx + pad
        ok = np.ones(size, dtype=bool)
        out = (c - g, c - g - n, c + g + 1 + n, c + g + 1, ok, ok)
    else:
        out = (
            np.clip(idx - g, 0, size),
            np.clip(idx - g - n, 0, size),
            np.clip(idx + g + 1 + n, 0, size),
            np.clip(idx + g + 1, 0, size),
            idx - g - n >= 0,
            idx + g + n <= size - 1,
        )
    for a in out:
        a.flags.writeable = False
    return out


def side_sums(p: np.ndarray, n: int, g: int, cyclic: bool):
    """Left/right training sums along axis 0 of ``p`` (float64) and their validity (N,)."""
    size = p.shape[0]
    l_hi, l_lo, r_hi, r_lo, ok_left, ok_right = _window_indices(size, n, g, cyclic)
    if cyclic:
        pad = n + g
        reps = -(-pad // size)
        tiled = np.concatenate([p] * (2 * reps + 1), axis=0)
        p = tiled[reps * size - pad : reps * size + size + pad]
    cs = np.empty((p.shape[0] + 1, *p.shape[1:]))
    cs[0] = 0.0
    np.cumsum(p, axis=0, out=cs[1:])
    # Z_left = sum of the n cells before the guard;  Z_right = the n cells after it
    return cs[l_hi] - cs[l_lo], cs[r_hi] - cs[r_lo], ok_left, ok_right


@dataclass(frozen=True, slots=True, kw_only=True)
class _SidedCfar:
    n_train: int = 8
    n_guard: int = 4
    pfa: float = 1e-4
    cyclic: bool = False
    n_channels: int = 12
    #: effective independent cells among the ``n_train`` of one side (None: n_train)
    n_effective: float | None = None

    method = "ca"

    def alpha(self) -> float:
        """Threshold factor on the per-cell noise estimate when both sides are available."""
        ne = self.n_effective
        if self.method == "ca":
            # the two sides are independent of each other (guard cells in between)
            ne2 = None if ne is None else 2 * ne
            return threshold_factor("ca", 2 * self.n_train, self.pfa, self.n_channels, ne2)
        return threshold_factor(self.method, self.n_train, self.pfa, self.n_channels, ne)

    def alpha_one_side(self) -> float:
        """Threshold factor at a non-cyclic edge (CA over the one complete side)."""
        return threshold_factor("ca", self.n_train, self.pfa, self.n_channels, self.n_effective)

    def _combine(self, left: np.ndarray, right: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def detect(self, power: np.ndarray, axis: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """CFAR along ``axis`` of ``power``.

        Returns
        -------
        mask : numpy.ndarray of bool
            Cells above threshold, same shape as ``power``.
        noise : numpy.ndarray of float64
            Per-cell noise estimate ``mu_hat`` (mean power of one cell), NaN where no training
            window fits.
        """
        threshold, mu = self.threshold(power, axis)
        p = np.moveaxis(np.asarray(power, dtype=np.float64), axis, 0)
        with np.errstate(invalid="ignore"):
            mask = p > np.moveaxis(threshold, axis, 0)
        return np.moveaxis(mask, 0, axis), mu

    def threshold(self, power: np.ndarray, axis: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """The threshold ``alpha * mu_hat`` each cell of ``power`` is compared with along
        ``axis`` (a cell is detected when its power exceeds it).

        Returns
        -------
        threshold, noise : numpy.ndarray of float64
            Same shape as ``power``: the threshold and the noise estimate ``mu_hat``; NaN where
            no training window fits.
        """
        p = np.moveaxis(np.asarray(power, dtype=np.float64), axis, 0)
        n = self.n_train
        left, right, ok_l, ok_r = side_sums(p, n, self.n_guard, self.cyclic)
        shape = (-1,) + (1,) * (p.ndim - 1)
        both = (ok_l & ok_r).reshape(shape)
        only_l = (ok_l & ~ok_r).reshape(shape)
        only_r = (~ok_l & ok_r).reshape(shape)
        mu = np.where(both, self._combine(left, right), np.nan)
        mu = np.where(only_l, left / n, mu)
        mu = np.where(only_r, right / n, mu)
        alpha = np.where(both, self.alpha(), self.alpha_one_side())
        # T = alpha * mu_hat
        return np.moveaxis(alpha * mu, 0, axis), np.moveaxis(mu, 0, axis)


@dataclass(frozen=True, slots=True, kw_only=True)
class CaCfar(_SidedCfar):
    """Cell-averaging CFAR over ``n_train`` cells each side."""

    method = "ca"

    def _combine(self, left, right):
        # mu_hat = (Z_left + Z_right) / 2n
        return (left + right) / (2 * self.n_train)


@dataclass(frozen=True, slots=True, kw_only=True)
class CasoCfar(_SidedCfar):
    """Smallest-of CFAR: the side with the smaller training sum sets the noise estimate."""

    method = "caso"

    def _combine(self, left, right):
        # mu_hat = min(Z_left, Z_right) / n
        return np.minimum(left, right) / self.n_train


@dataclass(frozen=True, slots=True, kw_only=True)
class CagoCfar(_SidedCfar):
    """Greatest-of CFAR: the side with the larger training sum sets the noise estimate."""

    method = "cago"

    def _combine(self, left, right):
        # mu_hat = max(Z_left, Z_right) / n
        return np.maximum(left, right) / self.n_train


CFAR_CLASSES = {"ca": CaCfar, "caso": CasoCfar, "cago": CagoCfar}


def make_cfar(
    settings: CfarSettings, n_channels: int, n_effective: float | None = None
) -> _SidedCfar:
    """The detector strategy named by ``settings.method`` for ``n_channels`` summed looks.

    ``n_effective``: effective independent cells among the ``n_train`` of one side (window
    correlation, :func:`core.processing.spectrum.effective_cells`); None: independent cells.
    """
    return CFAR_CLASSES[settings.method](
        n_train=settings.n_train,
        n_guard=settings.n_guard,
        pfa=settings.pfa,
        cyclic=settings.cyclic,
        n_channels=n_channels,
        n_effective=n_effective,
    )


# ---- two-stage detection ------------------------------------------------------------------------
@dataclass(frozen=True, slots=True, kw_only=True)
class Detections:
    """Cells of a range-Doppler map that passed both CFAR stages (and peak grouping).

    All arrays have shape ``(n_det,)``. ``doppler_index`` indexes the zero-velocity-centred map
    (Doppler bin ``doppler_index - n_loops // 2``). ``noise_power`` is the range stage's per-cell
    noise estimate, in the map's units (V²).
    """

    range_bin: np.ndarray
    doppler_index: np.ndarray
    power: np.ndarray
    noise_power: np.ndarray

    def __len__(self) -> int:
        return len(self.range_bin)

    @property
    def snr_db(self) -> np.ndarray:
        """Detected cell power over the CFAR noise estimate, dB."""
        return 10 * np.log10(self.power / self.noise_power)


def _local_maxima(rd: np.ndarray, r: np.ndarray, d: np.ndarray) -> np.ndarray:
    """True where ``rd[r, d]`` >= its 8 neighbours (range edges open, Doppler cyclic)."""
    return _local_maxima_kernel(np.asarray(rd), np.asarray(r), np.asarray(d))


@numba.njit(cache=True, nogil=True)
def _local_maxima_kernel(rd, r, d):  # pragma: no cover
    n_r, n_d = rd.shape
    keep = np.ones(len(r), dtype=np.bool_)
    for t in range(len(r)):
        centre = rd[r[t], d[t]]
        for dr in (-1, 0, 1):
            rr = r[t] + dr
            if rr < 0 or rr >= n_r:
                continue
            for dd in (-1, 0, 1):
                if (dr != 0 or dd != 0) and rd[rr, (d[t] + dd) % n_d] > centre:
                    keep[t] = False
    return keep


@functools.lru_cache(maxsize=64)
def effective_cells_or_none(window_name: str, n_fft: int, n_train: int) -> float | None:
    """Effective independent cells of ``n_train`` window-correlated ones (None: independent)."""
    ne = effective_cells(window_name, n_fft, n_train)
    return None if abs(ne - n_train) < 1e-9 else ne


@functools.lru_cache(maxsize=64)
def _cfar_plan(radar: RadarConfig, settings: ProcessingSettings, n_r: int, n_d: int, L: int):
    """What two_stage_cfar needs besides the map (range limits, whitening, thresholds)."""
    k = np.arange(n_r) * radar.range_resolution_m
    inside = np.flatnonzero((k >= settings.min_range_m) & (k <= settings.max_range_m))
    if inside.size == 0:
        return None
    lo, hi = int(inside[0]), int(inside[-1])
    range_cfar, doppler_cfar, profile = _stage_detectors(radar, settings, n_d, L)
    # the range stage needs training cells beyond the limits: run it on a margin around them
    margin = settings.range_cfar.n_train + settings.range_cfar.n_guard
    a, b = max(0, lo - margin), min(n_r, hi + 1 + margin)
    return TwoStageCfarArgs(
        profile=profile,
        lo=lo,
        hi=hi,
        a=a,
        b=b,
        range_stage=cfar_stage_args(range_cfar),
        doppler_stage=cfar_stage_args(doppler_cfar),
        peak_grouping=settings.peak_grouping,
    )


def _stage_detectors(
    radar: RadarConfig, settings: ProcessingSettings, n_d: int, L: int
) -> tuple[_SidedCfar, _SidedCfar, np.ndarray]:
    """The two stages' detectors and the whitening profile ``(n_d,)`` (read-only)."""
    rc, dc = settings.range_cfar, settings.doppler_cfar
    ne_r = ne_d = None
    profile = np.ones(n_d)
    if settings.cfar_noise_model:
        ne_r = effective_cells_or_none(settings.range_window, radar.n_samples, rc.n_train)
        ne_d = effective_cells_or_none(settings.doppler_window, n_d, dc.n_train)
        if settings.static_clutter_removal:
            # whitening profile; bins below 0.01 (rectangular window: zero Doppler) are dead
            profile = np.ascontiguousarray(
                clutter_removal_noise_profile(settings.doppler_window, n_d), dtype=np.float64
            )
    profile.flags.writeable = False
    return make_cfar(rc, L, ne_r), make_cfar(dc, L, ne_d), profile


@dataclass(frozen=True, slots=True, kw_only=True)
class CfarThresholds:
    """The thresholds of :func:`two_stage_cfar`, per cell of a range-Doppler map.

    Both arrays have the map's shape ``[range bin, Doppler bin]``, in the map's units (V²),
    NaN where the stage does not test the cell (outside the range limits; Doppler bins emptied
    by clutter removal). A cell is detected when its power exceeds both (and, with peak
    grouping, it is a local maximum): :attr:`combined`.
    """

    range_stage: np.ndarray
    doppler_stage: np.ndarray

    @property
    def combined(self) -> np.ndarray:
        """The larger of the two stages' thresholds (NaN where either is NaN)."""
        return np.maximum(self.range_stage, self.doppler_stage)


def two_stage_thresholds(
    rd_map: np.ndarray,
    radar: RadarConfig,
    settings: ProcessingSettings = DEFAULT_PROCESSING,
    *,
    n_channels: int | None = None,
) -> CfarThresholds:
    """The threshold every cell of ``rd_map`` meets in each stage of :func:`two_stage_cfar`.

    The same detectors, whitening and range limits as the detection (the range profile with
    its CFAR threshold is drawn from this); the arithmetic of :meth:`CaCfar.threshold` and its
    siblings, which the compiled detection is tested equal to.

    Parameters
    ----------
    rd_map
        ``[range bin, Doppler bin]`` power (V²), as for :func:`two_stage_cfar`.
    n_channels
        Number of summed channels ``L`` (default: ``radar.n_virtual``).
    """
    rd = np.asarray(rd_map, dtype=np.float64)
    L = radar.n_virtual if n_channels is None else n_channels
    n_r, n_d = rd.shape
    out_r = np.full((n_r, n_d), np.nan)
    out_d = np.full((n_r, n_d), np.nan)
    plan = _cfar_plan(radar, settings, n_r, n_d, L)
    if plan is None:
        return CfarThresholds(range_stage=out_r, doppler_stage=out_d)
    range_cfar, doppler_cfar, profile = _stage_detectors(radar, settings, n_d, L)
    lo, hi, a, b = plan.lo, plan.hi, plan.a, plan.b
    dead = profile < 0.01
    # whitened map: equal noise in every Doppler bin (dead bins carry 0)
    sub = np.where(dead[None, :], 0.0, rd[a:b] / np.where(dead, 1.0, profile)[None, :])
    t_r, _ = range_cfar.threshold(sub, axis=0)
    t_d, _ = doppler_cfar.threshold(sub[lo - a : hi - a + 1], axis=1)
    # back to the map's units: T_map = T_whitened * profile
    scale = np.where(dead, np.nan, profile)[None, :]
    out_r[lo : hi + 1] = t_r[lo - a : hi - a + 1] * scale
    out_d[lo : hi + 1] = t_d * scale
    return CfarThresholds(range_stage=out_r, doppler_stage=out_d)


#: The compiled kernels' code of each CFAR estimator.
METHOD_CODE = {"ca": 0, "caso": 1, "cago": 2}


class CfarStageArgs(NamedTuple):
    """One CFAR stage as the compiled kernels read it."""

    n_train: int  # training cells per side
    n_guard: int  # guard cells per side
    cyclic: bool  # the axis wraps around (Doppler)
    method: int  # METHOD_CODE of the estimator
    alpha_both: float  # threshold factor, both sides complete
    alpha_one: float  # threshold factor, one side alone (at a non-cyclic edge)


class TwoStageCfarArgs(NamedTuple):
    """Everything :func:`two_stage_kernel` needs besides the map (one value, written once)."""

    profile: np.ndarray  # (n_d,) whitening profile; bins below 0.01 are dead
    lo: int  # first range bin tested
    hi: int  # last range bin tested
    a: int  # first range bin the range stage reads (lo minus guard and training)
    b: int  # one past the last range bin it reads
    range_stage: CfarStageArgs
    doppler_stage: CfarStageArgs
    peak_grouping: bool


def cfar_stage_args(c: _SidedCfar) -> CfarStageArgs:
    """The compiled kernels' view of a configured stage."""
    return stage_args(c.n_train, c.n_guard, c.cyclic, c.method, c.alpha(), c.alpha_one_side())


def stage_args(
    n_train: int, n_guard: int, cyclic: bool, method: str, alpha_both: float, alpha_one: float
) -> CfarStageArgs:
    """:class:`CfarStageArgs` of a stage with the method by name (``"ca"``, ``"caso"``, ...)."""
    return CfarStageArgs(n_train, n_guard, cyclic, METHOD_CODE[method], alpha_both, alpha_one)


@numba.njit(inline="always")
def cfar_level(left, right, ok_l, ok_r, n, method, a_both, a_one):  # pragma: no cover
    """Noise level and threshold factor of one cell from its training-window sums.

    ``left``/``right`` are the sums of the ``n`` training cells on each side, ``ok_l``/``ok_r``
    whether that side exists; ``method`` 0 CA (mean of both), 1 CASO (smaller), 2 CAGO (greater).
    With one side only, that side's mean and the one-sided factor ``a_one``; with none, NaN (no
    detection). Shared by the library's CFAR and the ``fast`` level's compiled copy.
    """
    if ok_l and ok_r:
        if method == 0:
            return (left + right) / (2 * n), a_both
        if method == 1:
            return min(left, right) / n, a_both
        return max(left, right) / n, a_both
    if ok_l:
        return left / n, a_one
    if ok_r:
        return right / n, a_one
    return np.nan, a_one


@numba.njit(cache=True, nogil=True)
def _cfar_line(p, n, g, cyclic, method, a_both, a_one, mask, noise):  # pragma: no cover
    """One line of a sided CFAR; the same arithmetic as ``_SidedCfar.detect``."""
    size = p.shape[0]
    pad = n + g if cyclic else 0
    cs = np.empty(size + 2 * pad + 1)
    cs[0] = 0.0
    for i in range(size + 2 * pad):
        cs[i + 1] = cs[i] + p[(i - pad) % size]
    for i in range(size):
        c = i + pad
        ok_l = cyclic or i - g - n >= 0
        ok_r = cyclic or i + g + n <= size - 1
        left = cs[c - g] - cs[c - g - n] if ok_l else 0.0
        right = cs[c + g + 1 + n] - cs[c + g + 1] if ok_r else 0.0
        mu, alpha = cfar_level(left, right, ok_l, ok_r, n, method, a_both, a_one)
        noise[i] = mu
        mask[i] = p[i] > alpha * mu


@numba.njit(cache=True, nogil=True)
def two_stage_kernel(rd, cfar):  # pragma: no cover
    """Both CFAR stages and peak grouping on ``rd`` ``[range bin, Doppler bin]`` in one pass.

    The map is whitened (``rd / profile[d]``; bins with ``profile < 0.01``, emptied by clutter
    removal, carry 0 and are never detected) on the range bins ``a .. b-1``; the range stage
    (``n_r`` training and ``g_r`` guard cells, method code ``m_r``, factors ``ab_r`` both sides /
    ``ao_r`` one side) runs on every column, with the prefix sums of all columns built row by row;
    the Doppler stage (``_cfar_line``) on the rows ``lo .. hi`` with a range detection. With
    ``peak`` a detection must be a local maximum of ``rd`` (>= its 8 neighbours, range edges
    open, Doppler cyclic). Returns range bins, Doppler indices and the range stage's noise
    estimate in the map's units, row by row. The same arithmetic, operation for operation, as
    composing :class:`CaCfar`/:class:`CasoCfar`/:class:`CagoCfar` (tested). ``cfar``: a
    :class:`TwoStageCfarArgs`.
    """
    profile, lo, hi, a, b = cfar.profile, cfar.lo, cfar.hi, cfar.a, cfar.b
    n_r, g_r, cyc_r, m_r, ab_r, ao_r = cfar.range_stage
    n_d, g_d, cyc_d, m_d_code, ab_d, ao_d = cfar.doppler_stage
    peak = cfar.peak_grouping
    n_rows, n_cols = rd.shape
    size = b - a
    dead = np.empty(n_cols, dtype=np.bool_)
    for j in range(n_cols):
        dead[j] = profile[j] < 0.01
    # whitened map: equal noise in every Doppler bin
    sub = np.empty((size, n_cols))
    for i in range(size):
        for j in range(n_cols):
            sub[i, j] = 0.0 if dead[j] else rd[a + i, j] / profile[j]
    # range stage: cs[t + 1, j] = cs[t, j] + sub[(t - pad) mod size, j] down every column
    pad = n_r + g_r if cyc_r else 0
    cs = np.empty((size + 2 * pad + 1, n_cols))
    for j in range(n_cols):
        cs[0, j] = 0.0
    for t in range(size + 2 * pad):
        q = t - pad
        while q < 0:
            q += size
        while q >= size:
            q -= size
        for j in range(n_cols):
            cs[t + 1, j] = cs[t, j] + sub[q, j]
    i0 = lo - a
    i1 = hi - a
    mask_r = np.zeros((size, n_cols), dtype=np.bool_)
    noise_r = np.empty((size, n_cols))
    row_hit = np.zeros(size, dtype=np.bool_)
    for i in range(i0, i1 + 1):
        c = i + pad
        ok_l = cyc_r or i - g_r - n_r >= 0
        ok_r = cyc_r or i + g_r + n_r <= size - 1
        for j in range(n_cols):
            if dead[j]:
                continue
            # Z_left = sum of the n cells before the guard;  Z_right = the n cells after it
            left = cs[c - g_r, j] - cs[c - g_r - n_r, j] if ok_l else 0.0
            right = cs[c + g_r + 1 + n_r, j] - cs[c + g_r + 1, j] if ok_r else 0.0
            mu, alpha = cfar_level(left, right, ok_l, ok_r, n_r, m_r, ab_r, ao_r)
            noise_r[i, j] = mu
            if sub[i, j] > alpha * mu:
                mask_r[i, j] = True
                row_hit[i] = True
    out_r = np.empty(16, dtype=np.int64)
    out_d = np.empty(16, dtype=np.int64)
    out_z = np.empty(16)
    n_out = 0
    m_d = np.empty(n_cols, dtype=np.bool_)
    z_d = np.empty(n_cols)
    for i in range(i0, i1 + 1):
        if not row_hit[i]:
            continue
        _cfar_line(sub[i], n_d, g_d, cyc_d, m_d_code, ab_d, ao_d, m_d, z_d)
        r = a + i
        for j in range(n_cols):
            if not (mask_r[i, j] and m_d[j]):
                continue
            if peak:
                centre = rd[r, j]
                keep = True
                for dr in range(-1, 2):
                    rr = r + dr
                    if rr < 0 or rr >= n_rows:
                        continue
                    for dd in range(-1, 2):
                        if (dr != 0 or dd != 0) and rd[rr, (j + dd) % n_cols] > centre:
                            keep = False
                if not keep:
                    continue
            if n_out == out_r.shape[0]:
                out_r = np.concatenate((out_r, np.empty(n_out, dtype=np.int64)))
                out_d = np.concatenate((out_d, np.empty(n_out, dtype=np.int64)))
                out_z = np.concatenate((out_z, np.empty(n_out)))
            out_r[n_out] = r
            out_d[n_out] = j
            # back to the map's units at the cell under test
            out_z[n_out] = noise_r[i, j] * profile[j]
            n_out += 1
    return out_r[:n_out], out_d[:n_out], out_z[:n_out]


def two_stage_cfar(
    rd_map: np.ndarray,
    radar: RadarConfig,
    settings: ProcessingSettings = DEFAULT_PROCESSING,
    *,
    n_channels: int | None = None,
) -> Detections:
    """Two-stage CFAR on a range-Doppler map (TI SDK style).

    A cell is detected if it passes the range-stage CFAR (along axis 0) and the Doppler-stage
    CFAR (along axis 1), lies within ``[min_range_m, max_range_m]`` and, with peak grouping, is
    a local maximum of the map.

    With ``settings.cfar_noise_model`` (default) the thresholds account for what the chain does
    to the noise: window-correlated neighbouring cells (effective cell counts, see
    :func:`~core.processing.spectrum.effective_cells`) and, after static clutter removal, the
    lower noise around zero Doppler (the map is divided by
    :func:`~core.processing.spectrum.clutter_removal_noise_profile` before the CFAR).

    Parameters
    ----------
    rd_map
        ``[range bin, Doppler bin]`` power, non-coherent sum of ``n_channels`` channels; the
        range bins may stop early (bins ``0 .. n-1``, e.g. where the detector stops looking).
    n_channels
        Number of summed channels ``L`` (default: ``radar.n_virtual``).
    """
    rd = np.asarray(rd_map)
    L = radar.n_virtual if n_channels is None else n_channels
    n_r, n_d = rd.shape
    plan = _cfar_plan(radar, settings, n_r, n_d, L)
    if plan is None:
        return _empty_detections()
    # whitening, both stages and peak grouping in one compiled pass (same arithmetic as
    # CaCfar/CasoCfar/CagoCfar.detect composed, then _local_maxima)
    r, d, noise = two_stage_kernel(rd, plan)
    return Detections(
        range_bin=r,
        doppler_index=d,
        power=rd[r, d].astype(np.float64),
        noise_power=noise,
    )


def _training_cdf(cfar: _SidedCfar, x: np.ndarray) -> np.ndarray:
    """P(alpha * mu_hat < x) for noise-only training cells (unit mean cell power per look)."""
    n = cfar.n_train
    ne = float(n if cfar.n_effective is None else cfar.n_effective)
    alpha = cfar.alpha()
    if cfar.method == "ca":
        # Z ~ Gamma(2 n_eff L, scale n / n_eff): P(Z / 2n < x / alpha)
        return gammainc(2 * ne * cfar.n_channels, 2 * ne * x / alpha)
    one = gammainc(ne * cfar.n_channels, ne * x / alpha)
    # min of two sides: 1 - (1 - F)^2;  max: F^2
    return 1 - (1 - one) ** 2 if cfar.method == "caso" else one**2


def two_stage_pfa(
    settings: ProcessingSettings = DEFAULT_PROCESSING,
    n_channels: int = 12,
    *,
    n_range_bins: int = 256,
    n_doppler_bins: int = 32,
) -> float:
    """False-alarm probability of one cell for the two stages together (before peak grouping).

    The stages test the same cell power ``X`` against disjoint training cells, so they are
    independent only given ``X``:
    ``P = int f_X(x) P(alpha_r mu_r < x) P(alpha_d mu_d < x) dx``, ``X ~ Gamma(L)``. It is far
    larger than the product ``Pfa_r Pfa_d`` (default chain: 3.6e-5, not 1e-7).
    """
    L = n_channels
    ne_r = ne_d = None
    if settings.cfar_noise_model:
        ne_r = effective_cells_or_none(
            settings.range_window, n_range_bins, settings.range_cfar.n_train
        )
        ne_d = effective_cells_or_none(
            settings.doppler_window, n_doppler_bins, settings.doppler_cfar.n_train
        )
    cr = make_cfar(settings.range_cfar, L, ne_r)
    cd = make_cfar(settings.doppler_cfar, L, ne_d)

    def integrand(x: float) -> float:
        log_f = (L - 1) * np.log(x) - x - gammaln(L)
        return float(np.exp(log_f) * _training_cdf(cr, x) * _training_cdf(cd, x))

    val, _ = quad(integrand, 0.0, 20.0 * L, points=[L, 3 * L], epsabs=0.0, epsrel=1e-9, limit=400)
    return float(val)


def expected_false_alarms_per_frame(
    radar: RadarConfig, settings: ProcessingSettings = DEFAULT_PROCESSING
) -> float:
    """Expected noise detections per frame inside the range limits (an upper bound: peak
    grouping removes about a further 20 %). Default chain, paper radar: 0.20."""
    k = np.arange(radar.n_samples) * radar.range_resolution_m
    n_range = int(np.count_nonzero((k >= settings.min_range_m) & (k <= settings.max_range_m)))
    p = two_stage_pfa(
        settings, radar.n_virtual, n_range_bins=radar.n_samples, n_doppler_bins=radar.n_loops
    )
    return n_range * radar.n_loops * p


def _empty_detections() -> Detections:
    e = np.zeros(0, dtype=np.int64)
    return Detections(range_bin=e, doppler_index=e, power=np.zeros(0), noise_power=np.zeros(0))

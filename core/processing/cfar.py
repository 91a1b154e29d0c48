"""Two-stage CFAR for a non-coherent sum of ``L`` channels (SPEC §3, step 5).

Under noise only, a cell of the range-Doppler map is the sum of ``L`` (= 12 virtual channels)
independent exponentials of equal mean ``mu``: ``X ~ Gamma(L, mu)``. A training sum of ``N``
cells is ``Z ~ Gamma(N L, mu)``. The thresholds below are exact for this model (the single-look
formula ``(1 + T)^-N`` is the special case ``L = 1``).

A detector declares ``X > alpha * mu_hat`` with ``mu_hat`` the per-cell noise estimate:

- CA (``N = 2n`` cells): ``mu_hat = Z / N``. With ``T = alpha / N``, ``X / (X + Z) ~ Beta(L, NL)``:
  ``Pfa = P(X > T Z) = 1 - I_{T/(1+T)}(L, NL)`` (regularised incomplete beta), inverted in
  closed form with ``betainccinv``.
- CASO (``n`` cells per side, ``M = nL``): ``mu_hat = min(Z1, Z2) / n``, ``T = alpha / n``.
  With ``f_min = 2 f (1 - F)`` and Erlang tails,
  ``Pfa = 2 sum_{j<M} sum_{k<L} T^k Gamma(M+j+k) / (j! k! Gamma(M) (2+T)^(M+j+k))``.
- CAGO: ``f_max = 2 f - f_min``, so ``Pfa_GO(T) = 2 (1 - I_{T/(1+T)}(L, M)) - Pfa_SO(T)``.

Non-cyclic axes (range): where one side's training window leaves the axis, the cell uses the
complete side alone as a CA detector with ``n`` cells (so its false-alarm rate stays the design
value). Cyclic axes (Doppler) wrap around.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from scipy.optimize import brentq
from scipy.special import betaincc, betainccinv, gammaln, logsumexp

from core.config import DEFAULT_PROCESSING, CfarSettings, ProcessingSettings, RadarConfig


# ---- exact false-alarm probabilities ------------------------------------------------------------
def pfa_ca(t: float, n_cells: int, n_channels: int) -> float:
    """Pfa of ``X > T * Z`` with ``X ~ Gamma(L)``, ``Z`` the sum of ``n_cells`` such cells."""
    # Pfa = 1 - I_{T/(1+T)}(L, N L)
    return float(betaincc(n_channels, n_cells * n_channels, t / (1.0 + t)))


def pfa_caso(t: float, n_side: int, n_channels: int) -> float:
    """Pfa of ``X > T * min(Z1, Z2)``, each side the sum of ``n_side`` cells (exact sum)."""
    m, l = n_side * n_channels, n_channels
    j = np.arange(m)[:, None]
    k = np.arange(l)[None, :]
    # log of T^k Gamma(M+j+k) / (j! k! Gamma(M) (2+T)^(M+j+k))
    log_terms = (
        k * np.log(t)
        + gammaln(m + j + k)
        - gammaln(j + 1)
        - gammaln(k + 1)
        - gammaln(m)
        - (m + j + k) * np.log(2.0 + t)
    )
    return float(2.0 * np.exp(logsumexp(log_terms)))


def pfa_cago(t: float, n_side: int, n_channels: int) -> float:
    """Pfa of ``X > T * max(Z1, Z2)``: ``2 P(X > T Z1) - Pfa_SO``."""
    return 2.0 * pfa_ca(t, n_side, n_channels) - pfa_caso(t, n_side, n_channels)


@functools.lru_cache(maxsize=256)
def threshold_factor(method: str, n_train: int, pfa: float, n_channels: int) -> float:
    """``alpha`` such that ``X > alpha * mu_hat`` has false-alarm probability ``pfa``.

    Parameters
    ----------
    method
        ``"ca"`` (``n_train`` is the total number of training cells), ``"caso"`` or ``"cago"``
        (``n_train`` cells on each side).
    n_channels
        ``L``, the number of exponential looks summed per cell (12 virtual channels).
    """
    if method == "ca":
        b = float(betainccinv(n_channels, n_train * n_channels, pfa))
        # T/(1+T) = b  ->  T = b / (1 - b);  alpha = N T
        return n_train * b / (1.0 - b)
    f = {"caso": pfa_caso, "cago": pfa_cago}[method]
    # Pfa(T) decreases monotonically in T: step up in log T until it falls below pfa (small
    # steps keep the bracket where Pfa_GO = 2 P1 - Pfa_SO has no cancellation), then solve
    hi = -8.0
    while f(np.exp(hi), n_train, n_channels) > pfa:
        hi += 0.25
    log_t = brentq(
        lambda u: np.log(f(np.exp(u), n_train, n_channels)) - np.log(pfa),
        hi - 0.25,
        hi,
        xtol=1e-13,
    )
    return n_train * float(np.exp(log_t))


# ---- detectors ----------------------------------------------------------------------------------
class Cfar(Protocol):
    """A CFAR detector along one axis of a power map."""

    def detect(self, power: np.ndarray, axis: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """Return ``(mask, noise)``: detected cells and per-cell noise estimate, shape of power."""
        ...


def _side_sums(p: np.ndarray, n: int, g: int, cyclic: bool):
    """Left/right training sums along axis 0 of ``p`` (float64) and their validity (N,)."""
    size = p.shape[0]
    idx = np.arange(size)
    if cyclic:
        pad = n + g
        reps = -(-pad // size)
        tiled = np.concatenate([p] * (2 * reps + 1), axis=0)
        q = tiled[reps * size - pad : reps * size + size + pad]
        cs = np.concatenate([np.zeros((1, *p.shape[1:])), np.cumsum(q, axis=0)], axis=0)
        c = idx + pad
        left = cs[c - g] - cs[c - g - n]
        right = cs[c + g + 1 + n] - cs[c + g + 1]
        ok = np.ones(size, dtype=bool)
        return left, right, ok, ok
    cs = np.concatenate([np.zeros((1, *p.shape[1:])), np.cumsum(p, axis=0)], axis=0)
    ok_left = idx - g - n >= 0
    ok_right = idx + g + n <= size - 1
    lo = np.clip(idx - g, 0, size)
    left = cs[lo] - cs[np.clip(idx - g - n, 0, size)]
    hi = np.clip(idx + g + 1, 0, size)
    right = cs[np.clip(idx + g + 1 + n, 0, size)] - cs[hi]
    return left, right, ok_left, ok_right


@dataclass(frozen=True, slots=True, kw_only=True)
class _SidedCfar:
    n_train: int = 8
    n_guard: int = 4
    pfa: float = 1e-4
    cyclic: bool = False
    n_channels: int = 12

    method = "ca"

    def alpha(self) -> float:
        """Threshold factor on the per-cell noise estimate when both sides are available."""
        if self.method == "ca":
            return threshold_factor("ca", 2 * self.n_train, self.pfa, self.n_channels)
        return threshold_factor(self.method, self.n_train, self.pfa, self.n_channels)

    def alpha_one_side(self) -> float:
        """Threshold factor at a non-cyclic edge (CA over the one complete side)."""
        return threshold_factor("ca", self.n_train, self.pfa, self.n_channels)

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
        p = np.moveaxis(np.asarray(power, dtype=np.float64), axis, 0)
        n = self.n_train
        left, right, ok_l, ok_r = _side_sums(p, n, self.n_guard, self.cyclic)
        shape = (-1,) + (1,) * (p.ndim - 1)
        both = (ok_l & ok_r).reshape(shape)
        only_l = (ok_l & ~ok_r).reshape(shape)
        only_r = (~ok_l & ok_r).reshape(shape)
        mu = np.where(both, self._combine(left, right), np.nan)
        mu = np.where(only_l, left / n, mu)
        mu = np.where(only_r, right / n, mu)
        alpha = np.where(both, self.alpha(), self.alpha_one_side())
        with np.errstate(invalid="ignore"):
            mask = p > alpha * mu
        return np.moveaxis(mask, 0, axis), np.moveaxis(mu, 0, axis)


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


def make_cfar(settings: CfarSettings, n_channels: int) -> _SidedCfar:
    """The detector strategy named by ``settings.method`` for ``n_channels`` summed looks."""
    return CFAR_CLASSES[settings.method](
        n_train=settings.n_train,
        n_guard=settings.n_guard,
        pfa=settings.pfa,
        cyclic=settings.cyclic,
        n_channels=n_channels,
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
    n_r, n_d = rd.shape
    keep = np.ones(len(r), dtype=bool)
    for dr in (-1, 0, 1):
        rr = r + dr
        inside = (rr >= 0) & (rr < n_r)
        rr = np.clip(rr, 0, n_r - 1)
        for dd in (-1, 0, 1):
            if dr == 0 and dd == 0:
                continue
            neighbour = rd[rr, (d + dd) % n_d]
            keep &= ~inside | (rd[r, d] >= neighbour)
    return keep


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

    Parameters
    ----------
    rd_map
        ``[range bin, Doppler bin]`` power, non-coherent sum of ``n_channels`` channels.
    n_channels
        Number of summed channels ``L`` (default: ``radar.n_virtual``).
    """
    rd = np.asarray(rd_map)
    L = radar.n_virtual if n_channels is None else n_channels
    n_r = rd.shape[0]
    k = np.arange(n_r) * radar.range_resolution_m
    in_range = (k >= settings.min_range_m) & (k <= settings.max_range_m)
    lo, hi = np.flatnonzero(in_range)[[0, -1]] if in_range.any() else (0, -1)
    if hi < lo:
        return _empty_detections()
    # the range stage needs training cells beyond the limits: run it on a margin around them
    margin = settings.range_cfar.n_train + settings.range_cfar.n_guard
    a, b = max(0, lo - margin), min(n_r, hi + 1 + margin)
    sub = rd[a:b]
    mask_r, noise_r = make_cfar(settings.range_cfar, L).detect(sub, axis=0)
    mask_r[: lo - a] = False
    mask_r[hi + 1 - a :] = False
    rows = np.flatnonzero(mask_r.any(axis=1))
    if rows.size == 0:
        return _empty_detections()
    # Doppler stage only on the rows the range stage passed
    mask_d, _ = make_cfar(settings.doppler_cfar, L).detect(sub[rows], axis=1)
    mask = mask_r[rows] & mask_d
    ri, d = np.nonzero(mask)
    r = rows[ri] + a
    if settings.peak_grouping and r.size:
        keep = _local_maxima(rd, r, d)
        r, d, ri = r[keep], d[keep], ri[keep]
    return Detections(
        range_bin=r.astype(np.int64),
        doppler_index=d.astype(np.int64),
        power=rd[r, d].astype(np.float64),
        noise_power=noise_r[rows[ri], d],
    )


def _empty_detections() -> Detections:
    e = np.zeros(0, dtype=np.int64)
    return Detections(range_bin=e, doppler_index=e, power=np.zeros(0), noise_power=np.zeros(0))

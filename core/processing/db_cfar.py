"""CFAR passes with a threshold given in dB (TI's ``cfarCfg`` and range-angle CFAR lines).

The paper's chain sets its CFAR by a false-alarm probability (:mod:`core.processing.cfar`);
TI's chains set a ratio in dB over the noise estimate instead. Both use the same sliding
training windows (:func:`core.processing.cfar.side_sums`): ``n`` training cells a side beyond
``g`` guard cells, combined as the mean of both sides (CA), the smaller (CASO) or the larger
(CAGO) side mean; where a non-cyclic axis leaves one side incomplete, the complete side alone.

- :func:`db_cfar` (out-of-box chain): on the map in dB, the noise estimate is the mean of the
  training cells' dB values (TI's detection matrix is logarithmic; its threshold scale is a
  number of dB above that mean), a cell is detected when ``P_dB > noise_dB + T``.
- :func:`ra_cfar` (people-counting chain): on a linear range-angle map, a cell passes a pass
  when ``P > 10^(T/10) mu_hat``; range first, confirmed along angle.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from core.config import DbCfarSettings, RaCfarSettings
from core.processing.cfar import side_sums


def sided_noise(p: np.ndarray, n_train: int, n_guard: int, method: str, cyclic: bool):
    """Per-cell noise estimate along axis 0 of ``p`` (float64): CA, CASO or CAGO side means.

    Returns ``(n_cells, ...)`` float64, NaN where no training window fits.
    """
    x = np.asarray(p, dtype=np.float64)
    left, right, ok_l, ok_r = side_sums(x, n_train, n_guard, cyclic)
    shape = (-1,) + (1,) * (x.ndim - 1)
    both = (ok_l & ok_r).reshape(shape)
    only_l = (ok_l & ~ok_r).reshape(shape)
    only_r = (~ok_l & ok_r).reshape(shape)
    if method == "ca":
        mu_both = (left + right) / (2 * n_train)
    elif method == "caso":
        mu_both = np.minimum(left, right) / n_train
    else:
        mu_both = np.maximum(left, right) / n_train
    mu = np.where(both, mu_both, np.nan)
    mu = np.where(only_l, left / n_train, mu)
    return np.where(only_r, right / n_train, mu)


def _not_below_neighbours(p: np.ndarray, cyclic: bool) -> np.ndarray:
    """True where a cell is >= both neighbours along axis 0 (open ends unless cyclic)."""
    prev = np.roll(p, 1, axis=0)
    nxt = np.roll(p, -1, axis=0)
    if not cyclic:
        prev[0] = -np.inf
        nxt[-1] = -np.inf
    return (p >= prev) & (p >= nxt)


def db_cfar(power_db: np.ndarray, axis: int, s: DbCfarSettings) -> tuple[np.ndarray, np.ndarray]:
    """One CFAR pass on a map in dB along ``axis``.

    Returns
    -------
    mask : numpy.ndarray of bool
        ``P_dB > noise_dB + threshold_db`` (and, with peak grouping, not below either
        neighbour along the axis), shape of ``power_db``.
    noise_db : numpy.ndarray
        The noise estimate in dB (mean of the training cells' dB values), NaN where none.
    """
    p = np.moveaxis(np.asarray(power_db, dtype=np.float64), axis, 0)
    noise = sided_noise(p, s.n_train, s.n_guard, s.method, s.cyclic)
    with np.errstate(invalid="ignore"):
        mask = p > noise + s.threshold_db
    if s.peak_grouping:
        mask &= _not_below_neighbours(p, s.cyclic)
    return np.moveaxis(mask, 0, axis), np.moveaxis(noise, 0, axis)


@dataclass(frozen=True, slots=True, kw_only=True)
class RaDetections:
    """Cells of a range-angle map that passed :func:`ra_cfar`; arrays ``(n_det,)``."""

    range_bin: np.ndarray
    angle_index: np.ndarray
    power: np.ndarray
    noise_power: np.ndarray

    def __len__(self) -> int:
        return len(self.range_bin)

    @property
    def snr_db(self) -> np.ndarray:
        """Cell power over the range pass's noise estimate, dB."""
        return 10 * np.log10(self.power / self.noise_power)


def ra_cfar(ra_map: np.ndarray, s: RaCfarSettings, lo: int, hi: int) -> RaDetections:
    """Two-pass CASO CFAR on a ``[range bin, angle]`` linear power map.

    Range bins ``lo .. hi`` (inclusive, further limited by the discards) are tested. A cell is
    detected when ``P > 10^(T_r/10) mu_range`` (CASO along range), and, with
    ``second_pass``, ``P > 10^(T_a/10) mu_angle`` (CASO along angle), outside the discarded
    edge cells, ``P >= sidelobe_threshold * max(P[k, :])`` of its range bin, and not below
    either angle neighbour (TI's chain searches the angle spectrum of a range bin for peaks).
    """
    p = np.asarray(ra_map, dtype=np.float64)
    n_r, n_a = p.shape
    lo = max(lo, s.discard_left_range)
    hi = min(hi, n_r - 1 - s.discard_right_range)
    a_lo, a_hi = s.discard_left_angle, n_a - 1 - s.discard_right_angle
    empty = RaDetections(
        range_bin=np.zeros(0, np.int64),
        angle_index=np.zeros(0, np.int64),
        power=np.zeros(0),
        noise_power=np.zeros(0),
    )
    if hi < lo or a_hi < a_lo:
        return empty
    mu_r = sided_noise(p, s.ref_range, s.guard_range, "caso", False)
    with np.errstate(invalid="ignore"):
        mask = p > 10 ** (s.range_threshold_db / 10) * mu_r
        if s.second_pass:
            mu_a = sided_noise(p.T, s.ref_angle, s.guard_angle, "caso", False).T
            mask &= p > 10 ** (s.angle_threshold_db / 10) * mu_a
    keep = np.zeros_like(mask)
    keep[lo : hi + 1, a_lo : a_hi + 1] = True
    mask &= keep
    # side lobes: below sidelobe_threshold x the range bin's strongest cell
    mask &= p >= s.sidelobe_threshold * p.max(axis=1, keepdims=True)
    # the angle peak search: only local maxima along angle
    mask &= _not_below_neighbours(p.T, False).T
    r, a = np.nonzero(mask)
    if r.size == 0:
        return empty
    return RaDetections(range_bin=r, angle_index=a, power=p[r, a], noise_power=mu_r[r, a])

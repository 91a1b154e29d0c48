"""Expected noise false alarms of the two-stage CFAR, after peak grouping (noise-only maps).

The chain's noise after the range and Doppler FFTs is, per virtual channel, circular complex
Gaussian and separable: for white ADC noise of unit variance

    E[y(k, d) y(k', d')^*] = C_r(k - k') C_d(d, d')

with ``C_r(k) = sum_n w_r[n]^2 exp(-j 2 pi k n / N)`` (stationary) and ``C_d = M M^H``, ``M`` the
Doppler step as a matrix (window, DFT, static clutter removal: not stationary near zero
Doppler). The ``L`` channels are independent and identically distributed; a cell of the map is
``P = sum_l |y_l|^2``. The CFAR sees the map divided by its whitening profile ``g[d]``; the
peak grouping compares raw cells.

For one cell under test (CUT) at Doppler index ``d`` with whitened power ``x`` the three parts of
the detection are independent given ``x`` when the guard cells cover the windows' correlation
length (periodic Hann: 2 cells; default guards 4 and 2):

    P_fa(d) = int f_X(x) T_r(x) T_d(x) G(x) dx,     X ~ Gamma(L)

- ``T(x) = P(alpha mu_hat < v_d x)`` for each stage: every side's training sum is a quadratic
  form ``Z = sum_l z_l^H S z_l``, ``z_l ~ CN(0, I)``, i.e. ``Z = sum_j lambda_j Gamma_j(L)``
  with ``lambda`` the eigenvalues of the side's covariance ``S`` (in the CFAR's units). Its CDF
  comes from the characteristic function ``phi(t) = prod_j (1 - i lambda_j t)^-L`` by the
  Gil-Pelaez formula on the midpoint rule (exact up to ``P(|Z - z| > 2 pi / h)``)::

      F(z) = 1/2 - (1/pi) sum_k Im(phi(t_k) exp(-i t_k z)) / (k + 1/2),   t_k = (k + 1/2) h

  CA: one form over both sides; CASO: ``1 - (1 - F_l)(1 - F_r)``; CAGO: ``F_l F_r``; one side
  (non-cyclic edge): that side with the one-sided factor.
- ``G(x) = P(every neighbour's raw power <= the CUT's | X = x)``. The 8 neighbours are jointly
  Gaussian with the CUT (whitened correlation ``K``): per channel ``n_j = a_j c + r_j`` with
  ``a_j = K[j, 0]`` and ``r`` the conditional residual (covariance ``K_nn - a a^H``). By the
  rotation invariance of the i.i.d. channels ``c = sqrt(x) e_1``, so neighbour ``j``'s power is
  ``|a_j sqrt(x) + r_j1|^2 + sum_{l>1} |r_jl|^2`` and the condition ``p_j P_j <= p_d x`` is a
  quadratic inequality in ``s = sqrt(x)``: every residual sample accepts an interval of ``s``.
  ``G`` is the fraction of a fixed-seed sample of residuals (:data:`GROUPING_SAMPLES`) whose
  interval holds ``s``. Independent cells (the ``fast`` level's map): ``G(x) =
  prod_j F_Gamma(L)(q_j x)``, ``q_j = p_d / p_j``, in closed form.

The frame's expectation sums ``P_fa`` over the Doppler bins and the range bins inside the
limits (range bins where a range-stage side or a grouping neighbour leaves the map form their
own classes).

Neglected: the small correlation of grouping neighbours with Doppler training cells two bins
away (periodic Hann ``|rho(2)|^2 = 1/36``) and, for guard cells shorter than the window's
correlation length, that of the training cells with the CUT.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from scipy.special import gammainc, gammaln

from core.config import CfarSettings, ProcessingSettings, RadarConfig
from core.processing.spectrum import clutter_removal_noise_profile, window

#: residual samples of the grouping factor's Monte Carlo (standard error of ``G`` <= 0.4 %)
GROUPING_SAMPLES = 16384
#: its fixed seed (the model is deterministic)
GROUPING_SEED = 20261122
#: most terms of the characteristic-function sum (a slowly decaying phi: few cells, few looks)
MAX_CF_TERMS = 200_000
#: whitening-profile value below which a Doppler bin is dead (as the CFAR kernel)
DEAD_PROFILE = 0.01


@dataclass(frozen=True, slots=True, kw_only=True)
class StageFactors:
    """Threshold factors of one CFAR stage: both sides available / one side (an edge)."""

    both: float
    one: float


# ---- the law of a training sum ------------------------------------------------------------------
def weighted_gamma_cdf(eigenvalues: np.ndarray, n_channels: int, z: np.ndarray) -> np.ndarray:
    """CDF of ``Z = sum_j lambda_j Gamma_j(L)`` (independent ``Gamma(L, 1)``) at ``z``.

    Parameters
    ----------
    eigenvalues
        ``(n,)`` non-negative weights ``lambda_j`` (a covariance matrix's eigenvalues: ``Z`` is
        then the power sum over ``L`` i.i.d. channels of ``n`` correlated cells).
    n_channels
        ``L``.
    z
        Points, any shape.

    Returns
    -------
    numpy.ndarray
        ``P(Z <= z)``, float64, shape of ``z``. Equal weights: ``gammainc(n L, z / lambda)``
        exactly; otherwise characteristic-function inversion (absolute error < 1e-12).
    """
    lam = np.asarray(eigenvalues, dtype=np.float64)
    lam = lam[lam > 1e-12 * max(1.0, float(lam.max(initial=0.0)))]
    z = np.asarray(z, dtype=np.float64)
    L = int(n_channels)
    if lam.size == 0:
        return np.where(z >= 0, 1.0, 0.0)
    if lam.max() - lam.min() <= 1e-12 * lam.max():
        return gammainc(lam.size * L, np.maximum(z, 0.0) / lam.mean())
    return _cf_cdf(tuple(np.round(np.sort(lam), 14)), L, z)


def _cf_cdf(lam: tuple, L: int, z: np.ndarray) -> np.ndarray:
    lam_a = np.asarray(lam)
    mean = L * lam_a.sum()
    sd = np.sqrt(L * np.sum(lam_a**2))
    # beyond z_max the CDF is 1 to double precision; the rule's period 2 pi / h exceeds z_max,
    # the largest |Z - z| that matters
    z_max = mean + 20.0 * sd + 40.0 * lam_a.max()
    h = 2 * np.pi / (1.2 * z_max)
    # truncate where |phi(t)| = prod (1 + lambda^2 t^2)^(-L/2) < 1e-16 (the chain's forms,
    # L = 12: a few hundred terms; at most MAX_CF_TERMS)
    t_hi = 1.0 / lam_a.max()
    while -0.5 * L * np.sum(np.log1p((lam_a * t_hi) ** 2)) > np.log(1e-16):
        t_hi *= 1.25
    n_terms = min(int(np.ceil(t_hi / h)) + 1, MAX_CF_TERMS)
    k = np.arange(n_terms) + 0.5
    t = k * h
    # log phi(t) = -L sum_j log(1 - i lambda_j t)
    log_phi = -L * np.sum(np.log1p(-1j * np.outer(t, lam_a)), axis=1)
    flat = z.ravel()
    out = np.ones(flat.size)
    inside = np.flatnonzero((flat > 0) & (flat < z_max))
    out[flat <= 0] = 0.0
    # F(z) = 1/2 - (1/pi) sum_k Im(phi(t_k) exp(-i t_k z)) / (k + 1/2)
    #      = 1/2 - (1/pi) sum_k |phi(t_k)| sin(arg phi(t_k) - t_k z) / (k + 1/2)
    amp = np.exp(log_phi.real) / k
    step = max(1, 2_000_000 // n_terms)
    for i in range(0, inside.size, step):
        idx = inside[i : i + step]
        arg = log_phi.imag[:, None] - np.outer(t, flat[idx])
        out[idx] = 0.5 - (amp @ np.sin(arg)) / np.pi
    return np.clip(out, 0.0, 1.0).reshape(z.shape)


# ---- the chain's noise covariance ---------------------------------------------------------------
@functools.lru_cache(maxsize=32)
def _range_rho(name: str, n_fft: int, max_lag: int) -> np.ndarray:
    """``rho(k) = sum w^2 exp(-j 2 pi k n / N) / sum w^2`` for ``k = -max_lag .. max_lag``."""
    w2 = window(name, n_fft).astype(np.float64) ** 2
    k = np.arange(-max_lag, max_lag + 1)
    return np.exp(-2j * np.pi * np.outer(k, np.arange(n_fft)) / n_fft) @ w2 / w2.sum()


@functools.lru_cache(maxsize=32)
def _doppler_covariance(name: str, n: int, clutter_removal: bool) -> tuple[np.ndarray, np.ndarray]:
    """Raw per-channel variance ``p`` (relative to no removal) and correlation ``(n, n)``.

    ``C_d = M M^H``, ``M = F diag(w) (I - 1 1' / n)`` (zero velocity centred); ``p = diag C_d /
    sum w^2`` (the clutter-removal profile); the correlation is 0 where ``p`` is.
    """
    w = window(name, n).astype(np.float64)
    j = np.arange(n) - n // 2
    mat = np.exp(-2j * np.pi * np.outer(j, np.arange(n)) / n) * w[None, :]
    if clutter_removal:
        mat = mat - mat.mean(axis=1, keepdims=True)
    cov = mat @ mat.conj().T
    var = np.real(np.diag(cov)).copy()
    alive = var > 1e-12 * var.max()
    s = np.where(alive, np.sqrt(np.where(alive, var, 1.0)), np.inf)
    corr = cov / np.outer(s, s)
    var /= np.sum(w**2)
    var[~alive] = 0.0
    return var, corr


def cells_correlated(radar: RadarConfig, settings: ProcessingSettings) -> bool:
    """Whether the chain's noise cells are correlated (any window but ``rect``).

    ``rect`` windows (with or without static clutter removal) leave independent cells: the
    ``fast`` level's map then has the exact chain's law and needs no other thresholds.
    """
    rho = _range_rho(settings.range_window, radar.n_samples, 1)
    _, corr = _doppler_covariance(
        settings.doppler_window, radar.n_loops, bool(settings.static_clutter_removal)
    )
    off = corr - np.diag(np.diag(corr))
    return bool(abs(rho[0]) > 1e-9 or np.max(np.abs(off)) > 1e-9)


@dataclass(frozen=True, slots=True)
class _Layout:
    """What the model needs of the settings besides the thresholds."""

    L: int
    n_rows: int
    n_d: int
    x: np.ndarray  # whitened CUT power grid
    fx_dx: np.ndarray  # Gamma(L) density times the trapezoid weights
    range_classes: dict  # (ok_l, ok_r, up, down) -> number of range bins
    p: np.ndarray  # raw per-channel variance per Doppler bin
    v: np.ndarray  # variance in the CFAR's (whitened) units per Doppler bin (0: dead)
    range_sides: tuple  # covariance of one range-stage side (unit v), left and right
    grouping: dict  # (d, up, down) -> G(x)


def _x_grid(L: int) -> tuple[np.ndarray, np.ndarray]:
    # beyond x_max the Gamma(L) density is below 1e-9 of the per-cell false-alarm integrand
    x_max = L + 12.0 * np.sqrt(L) + 20.0
    x = np.linspace(0.0, x_max, 1501)[1:]
    dx = x[1] - x[0]
    # f_X(x) = x^(L-1) e^-x / Gamma(L)
    fx = np.exp((L - 1) * np.log(x) - x - gammaln(L))
    w = np.full(x.size, dx)
    w[-1] = 0.5 * dx
    return x, fx * w


def _side_offsets(c: CfarSettings) -> tuple[np.ndarray, np.ndarray]:
    g, n = c.n_guard, c.n_train
    return -np.arange(g + 1, g + n + 1)[::-1], np.arange(g + 1, g + n + 1)


@functools.lru_cache(maxsize=64)
def _layout(
    radar: RadarConfig, settings: ProcessingSettings, L: int, n_rows: int, independent: bool
) -> _Layout | None:
    n_d = radar.n_loops
    k = np.arange(n_rows) * radar.range_resolution_m
    inside = np.flatnonzero((k >= settings.min_range_m) & (k <= settings.max_range_m))
    if inside.size == 0:
        return None
    lo, hi = int(inside[0]), int(inside[-1])
    rc = settings.range_cfar
    margin = rc.n_train + rc.n_guard
    a, b = max(0, lo - margin), min(n_rows, hi + 1 + margin)
    classes: dict = {}
    for kk in range(lo, hi + 1):
        i = kk - a
        key = (
            bool(rc.cyclic or i - rc.n_guard - rc.n_train >= 0),
            bool(rc.cyclic or i + rc.n_guard + rc.n_train <= b - a - 1),
            kk - 1 >= 0,
            kk + 1 <= n_rows - 1,
        )
        classes[key] = classes.get(key, 0) + 1
    p, corr_d = _doppler_covariance(
        settings.doppler_window, n_d, bool(settings.static_clutter_removal)
    )
    if settings.cfar_noise_model and settings.static_clutter_removal:
        prof = np.asarray(clutter_removal_noise_profile(settings.doppler_window, n_d))
    else:
        prof = np.ones(n_d)
    dead = prof < DEAD_PROFILE
    v = np.where(dead, 0.0, p / np.where(dead, 1.0, prof))
    left, right = _side_offsets(rc)
    if independent:
        corr_d = np.eye(n_d)
        range_side = np.eye(rc.n_train)
    else:
        rho = _range_rho(settings.range_window, radar.n_samples, rc.n_guard + 2 * rc.n_train)
        mid = rc.n_guard + 2 * rc.n_train
        # C[i, j] = rho(k_i - k_j)
        range_side = rho[mid + left[:, None] - left[None, :]]
    x, fx_dx = _x_grid(L)
    lay = _Layout(
        L=L,
        n_rows=n_rows,
        n_d=n_d,
        x=x,
        fx_dx=fx_dx,
        range_classes=classes,
        p=p,
        v=v,
        range_sides=(range_side, corr_d),
        grouping={},
    )
    if settings.peak_grouping:
        combos = frozenset((c[2], c[3]) for c in classes)
        lay.grouping.update(
            _grouping_table(
                settings.range_window,
                settings.doppler_window,
                radar.n_samples,
                n_d,
                bool(settings.static_clutter_removal),
                L,
                independent,
                combos,
            )
        )
    return lay


@functools.lru_cache(maxsize=16)
def _grouping_table(
    range_window: str,
    doppler_window: str,
    n_samples: int,
    n_d: int,
    clutter_removal: bool,
    L: int,
    independent: bool,
    combos: frozenset,
) -> dict:
    """``G(x)`` per ``(d, up, down)``: depends on the windows, not on the CFAR (cached)."""
    p, corr_d = _doppler_covariance(doppler_window, n_d, clutter_removal)
    if independent:
        corr_d = np.eye(n_d)
    # rho_r(k), k = -2 .. 2 (neighbours' range lags)
    rho1 = (
        np.array([0.0, 0.0, 1.0, 0.0, 0.0])
        if independent
        else _range_rho(range_window, n_samples, 2)
    )
    x = _x_grid(L)[0]
    memo: dict = {}
    out = {}
    for up, down in combos:
        for d in range(n_d):
            if p[d] > 0:
                out[(d, up, down)] = _grouping_factor(
                    x, L, d, p, corr_d, rho1, up, down, independent, memo
                )
    return out


def _key(a: np.ndarray) -> bytes:
    """Hashable key of an array, equal for values equal to 1e-10 (and for -0.0 and 0.0)."""
    return (np.round(np.asarray(a), 10) + 0.0).tobytes()


# ---- peak grouping ------------------------------------------------------------------------------
@functools.lru_cache(maxsize=8)
def _residual_draws(L: int, n_nb: int) -> tuple[np.ndarray, np.ndarray]:
    """Fixed-seed residual draws for ``n_nb`` neighbours and ``L`` channels.

    Returns ``z1`` ``(M, n_nb)`` complex, the first channel's standard complex normals, and
    ``W`` ``(M, 2 n_nb^2)`` float64, the real and imaginary parts of ``W_ab = sum_{l >= 2}
    z_la conj(z_lb)`` (the other channels enter only through it).
    """
    g = np.random.default_rng(GROUPING_SEED)
    m = GROUPING_SAMPLES
    z1 = (g.standard_normal((m, n_nb)) + 1j * g.standard_normal((m, n_nb))) / np.sqrt(2.0)
    if L - 1 >= n_nb:
        # W ~ complex Wishart(L - 1, I), Bartlett: W = T T^H, T lower triangular with
        # |T_ii|^2 ~ Gamma(L - 1 - i) and T_ij ~ CN(0, 1) below the diagonal
        t = np.zeros((m, n_nb, n_nb), dtype=complex)
        below = np.tril_indices(n_nb, -1)
        n_b = below[0].size
        t[:, below[0], below[1]] = (
            g.standard_normal((m, n_b)) + 1j * g.standard_normal((m, n_b))
        ) / np.sqrt(2.0)
        diag = np.arange(n_nb)
        t[:, diag, diag] = np.sqrt(g.standard_gamma(L - 1 - diag, size=(m, n_nb)))
        w = np.matmul(t, t.conj().transpose(0, 2, 1)).reshape(m, -1)
    else:
        rest = (
            g.standard_normal((m, L - 1, n_nb)) + 1j * g.standard_normal((m, L - 1, n_nb))
        ) / np.sqrt(2.0)
        w = np.matmul(rest.transpose(0, 2, 1), rest.conj()).reshape(m, -1)
    w2 = np.ascontiguousarray(np.concatenate((w.real, w.imag), axis=1))
    z1.flags.writeable = False
    w2.flags.writeable = False
    return z1, w2


def _grouping_factor(x, L, d, p, corr_d, rho1, up, down, independent, memo) -> np.ndarray:
    """``G(x)``: probability that no raw neighbour exceeds the CUT given its whitened power."""
    n_d = p.size
    drs = [dr for dr in (-1, 0, 1) if (dr != -1 or up) and (dr != 1 or down)]
    cells = [(0, 0)] + [
        (dr, dd) for dr in drs for dd in (-1, 0, 1) if (dr, dd) != (0, 0) and p[(d + dd) % n_d] > 0
    ]
    cols = np.array([(d + dd) % n_d for _, dd in cells])
    q = p[d] / p[cols[1:]]  # neighbour j loses when P_j <= q_j x (whitened units)
    # whitened correlation of the CUT and its neighbours: rho_r(dr - dr') corr_d(d, d')
    dr = np.array([c[0] for c in cells])
    k = rho1[2 + dr[:, None] - dr[None, :]] * corr_d[cols[:, None], cols[None, :]]
    key = (_key(k), _key(q))
    if key not in memo:
        memo[key] = _grouping_from(x, L, k, q, independent)
    return memo[key]


def _grouping_from(x, L, k, q, independent) -> np.ndarray:
    if independent or np.max(np.abs(k - np.eye(k.shape[0]))) < 1e-12:
        # G = prod_j F_Gamma(L)(q_j x)
        return np.prod(gammainc(L, np.outer(x, q)), axis=1)
    a = k[1:, 0]
    # residual covariance K_nn - a a^H and a square root of it
    kc = k[1:, 1:] - np.outer(a, a.conj())
    ev, vec = np.linalg.eigh(kc)
    root = vec * np.sqrt(np.clip(ev, 0.0, None))[None, :]
    n_nb = len(a)
    z1, w2 = _residual_draws(L, n_nb)
    # residual of channel 1: r_1 = root z_1
    r1 = z1 @ root.T
    # other channels: sum_{l>=2} |(root z_l)_j|^2 = sum_ab root_ja conj(root_jb) W_ab (real)
    bj = (root[:, :, None] * root.conj()[:, None, :]).reshape(n_nb, -1)
    rest = w2 @ np.concatenate((bj.real, -bj.imag), axis=1).T
    # (q - |a|^2) s^2 - 2 Re(a conj(r1)) s - (|r1|^2 + rest) >= 0
    qa = q[None, :] - np.abs(a)[None, :] ** 2
    bb = -2.0 * np.real(a[None, :] * np.conj(r1))
    cc = -(np.abs(r1) ** 2 + rest)
    disc = np.sqrt(np.maximum(bb * bb - 4 * qa * cc, 0.0))
    lo = np.zeros_like(cc)
    hi = np.full_like(cc, np.inf)
    pos, neg = qa > 1e-14, qa < -1e-14
    lin = ~(pos | neg)
    with np.errstate(divide="ignore", invalid="ignore"):
        # qa > 0: s >= the positive root (stable form for b > 0)
        root_pos = np.where(bb > 0, -2 * cc / (bb + disc), (-bb + disc) / (2 * qa))
        lo = np.where(pos, root_pos, lo)
        # qa = 0: b s + c >= 0
        lo = np.where(lin & (bb > 0), -cc / bb, lo)
        hi = np.where(lin & (bb <= 0), -1.0, hi)
        # qa < 0: between the roots when both are positive (b > 0, discriminant >= 0)
        ok = neg & (bb > 0) & (bb * bb - 4 * qa * cc >= 0)
        r_a = (-bb + disc) / (2 * qa)
        r_b = (-bb - disc) / (2 * qa)
        lo = np.where(neg, np.where(ok, np.minimum(r_a, r_b), np.inf), lo)
        hi = np.where(neg, np.where(ok, np.maximum(r_a, r_b), -1.0), hi)
    s_lo = lo.max(axis=1)
    s_hi = hi.min(axis=1)
    valid = s_lo <= s_hi
    s = np.sqrt(x)
    n_lo = np.searchsorted(np.sort(s_lo[valid]), s, side="right")
    n_hi = np.searchsorted(np.sort(s_hi[valid]), s, side="left")
    # G(s) = #(s_lo <= s <= s_hi) / M
    return (n_lo - n_hi) / GROUPING_SAMPLES


# ---- the CFAR stages ----------------------------------------------------------------------------
def _stage_probability(
    lay: _Layout,
    c: CfarSettings,
    f: StageFactors,
    xc: np.ndarray,
    left_cov: np.ndarray | None,
    right_cov: np.ndarray | None,
    memo: dict,
) -> np.ndarray:
    """``P(alpha mu_hat < xc)`` on the CUT grid ``xc`` (CFAR units); a side None is missing.

    ``xc`` is a multiple of the model's grid; ``memo`` keeps the CDFs already evaluated.
    """
    n, L = c.n_train, lay.L

    def cdf(cov, zz):
        lam = np.linalg.eigvalsh(cov)
        key = (_key(lam), round(float(zz[-1]), 12))
        if key not in memo:
            memo[key] = weighted_gamma_cdf(lam, L, zz)
        return memo[key]

    if left_cov is not None and right_cov is not None:
        if c.method == "ca":
            both = _block(left_cov, right_cov)
            # mu = (Z_l + Z_r) / 2n
            return cdf(both, 2 * n * xc / f.both)
        fl, fr = cdf(left_cov, n * xc / f.both), cdf(right_cov, n * xc / f.both)
        # min of the sides below the level: 1 - (1 - F_l)(1 - F_r);  max: F_l F_r
        return 1 - (1 - fl) * (1 - fr) if c.method == "caso" else fl * fr
    side = left_cov if left_cov is not None else right_cov
    if side is None:
        return np.zeros_like(xc)
    return cdf(side, n * xc / f.one)


def _block(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Both sides as one form; the sides' cross-covariance is negligible (guard cells)."""
    out = np.zeros((a.shape[0] + b.shape[0],) * 2, dtype=complex)
    out[: a.shape[0], : a.shape[0]] = a
    out[a.shape[0] :, a.shape[0] :] = b
    return out


def _doppler_side(lay: _Layout, c: CfarSettings, d: int, offs: np.ndarray) -> np.ndarray | None:
    """Covariance (CFAR units) of the Doppler training cells ``d + offs``; None off the axis."""
    idx = d + offs
    if c.cyclic:
        idx = idx % lay.n_d
    elif idx.min() < 0 or idx.max() >= lay.n_d:
        return None
    corr = lay.range_sides[1][idx[:, None], idx[None, :]]
    sv = np.sqrt(lay.v[idx])
    return sv[:, None] * corr * sv[None, :]


def noise_detections_per_frame(
    radar: RadarConfig,
    settings: ProcessingSettings,
    range_factors: StageFactors,
    doppler_factors: StageFactors,
    *,
    independent_cells: bool = False,
    n_channels: int | None = None,
    n_range_bins: int | None = None,
) -> float:
    """Expected detections per noise-only frame: both CFAR stages and peak grouping.

    Parameters
    ----------
    range_factors, doppler_factors
        The stages' threshold factors (``alpha`` on the per-cell noise estimate).
    independent_cells
        False: the exact chain's window-correlated cells; True: independent cells with the same
        per-Doppler-bin variance (the ``fast`` level's map).
    n_channels
        ``L`` (default ``radar.n_virtual``).
    n_range_bins
        Rows of the map the CFAR gets (default ``radar.n_samples``).

    Returns
    -------
    float
        Expected number of detections per frame inside ``[min_range_m, max_range_m]``.
    """
    L = radar.n_virtual if n_channels is None else int(n_channels)
    n_rows = radar.n_samples if n_range_bins is None else int(n_range_bins)
    lay = _layout(radar, settings, L, n_rows, bool(independent_cells))
    if lay is None:
        return 0.0
    rc, dc = settings.range_cfar, settings.doppler_cfar
    rs = lay.range_sides[0]
    x = lay.x
    # the range stage's law does not depend on the column (scale v_d cancels)
    memo: dict = {}
    t_range = {
        (ok_l, ok_r): _stage_probability(
            lay, rc, range_factors, x, rs if ok_l else None, rs if ok_r else None, memo
        )
        for ok_l, ok_r in {(c[0], c[1]) for c in lay.range_classes}
    }
    left, right = _side_offsets(dc)
    total = 0.0
    for d in range(lay.n_d):
        if lay.v[d] <= 0 or lay.p[d] <= 0:
            continue  # dead bin: never detected
        t_dopp = _stage_probability(
            lay,
            dc,
            doppler_factors,
            lay.v[d] * x,
            _doppler_side(lay, dc, d, left),
            _doppler_side(lay, dc, d, right),
            memo,
        )
        for (ok_l, ok_r, up, down), count in lay.range_classes.items():
            g = lay.grouping.get((d, up, down), 1.0)
            # P_fa(d) = int f_X(x) T_r(x) T_d(x) G(x) dx
            total += count * float(np.sum(lay.fx_dx * t_range[(ok_l, ok_r)] * t_dopp * g))
    return total

"""Small drawing geometry (Qt-free): NaN-separated polylines for ellipses, trails and the AOI.

One NaN-separated curve per kind of item is ~3× faster to draw than one item per track.
"""

from __future__ import annotations

import numpy as np

_N_ELLIPSE = 33
_THETA = np.linspace(0.0, 2.0 * np.pi, _N_ELLIPSE)
_UNIT = np.stack([np.cos(_THETA), np.sin(_THETA)], axis=1)  # (33, 2)


def ellipse_polyline(xy_m: np.ndarray, cov_m2: np.ndarray, gamma: float) -> np.ndarray:
    """Gate ellipses {p : (p − μ)ᵀ Σ⁻¹ (p − μ) = γ} as one NaN-separated polyline.

    Parameters
    ----------
    xy_m
        ``(n, 2)`` centres μ in m.
    cov_m2
        ``(n, 2, 2)`` covariances Σ in m² (symmetric, positive semi-definite).
    gamma
        Gate threshold γ (squared Mahalanobis radius).

    Returns
    -------
    ``(n * 34, 2)`` polyline: 33 points per ellipse followed by a NaN row.
    """
    n = len(xy_m)
    if n == 0:
        return np.zeros((0, 2))
    cov = 0.5 * (cov_m2 + np.swapaxes(cov_m2, 1, 2))
    # Σ = V diag(w) Vᵀ ; p = μ + sqrt(γ) V diag(sqrt(w)) u  for unit u
    w, v = np.linalg.eigh(cov)
    scale = np.sqrt(np.clip(w, 0.0, None) * gamma)  # (n, 2)
    a = v * scale[:, None, :]  # (n, 2, 2): columns scaled
    pts = np.einsum("kj,nij->nki", _UNIT, a) + xy_m[:, None, :]  # (n, 33, 2)
    out = np.full((n, _N_ELLIPSE + 1, 2), np.nan)
    out[:, :_N_ELLIPSE] = pts
    return out.reshape(-1, 2)


def aoi_polyline(
    min_range_m: float, max_range_m: float, max_azimuth_deg: float, n: int = 64
) -> np.ndarray:
    """Outline of the AOI sector (x = r·sin az, y = r·cos az), shape ``(2n + 1, 2)``."""
    az = np.deg2rad(np.linspace(-max_azimuth_deg, max_azimuth_deg, n))
    outer = np.stack([max_range_m * np.sin(az), max_range_m * np.cos(az)], axis=1)
    inner = np.stack([min_range_m * np.sin(az[::-1]), min_range_m * np.cos(az[::-1])], axis=1)
    return np.vstack([outer, inner, outer[:1]])


def trails_polyline(
    trail_id: np.ndarray,
    trail_t_index: np.ndarray,
    trail_xy_m: np.ndarray,
    frame: int,
    length: int,
    live_ids: np.ndarray,
) -> np.ndarray:
    """Trails of the live tracks over the last ``length`` frames, as one NaN-separated polyline.

    ``trail_*`` are the positions of every track at every frame, sorted by (id, frame).
    """
    if len(trail_id) == 0 or len(live_ids) == 0:
        return np.zeros((0, 2))
    keep = (trail_t_index <= frame) & (trail_t_index > frame - length)
    keep &= np.isin(trail_id, live_ids)
    ids = trail_id[keep]
    xy = trail_xy_m[keep]
    if len(ids) == 0:
        return np.zeros((0, 2))
    breaks = np.flatnonzero(np.diff(ids)) + 1
    return np.insert(xy, breaks, np.nan, axis=0)

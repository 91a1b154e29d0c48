"""Clutter reflectors (SPEC §2): a Poisson number per frame, uniform over the AOI.

Each clutter reflector is a point whose post-processing SNR is uniform in 15–30 dB (its RCS is
found later with ``core.simulation.rcs_for_snr_db``, which needs the antenna realisation) and
whose radial velocity is uniform over ``±v_max`` with ``|v| >= 2`` velocity bins, so that static
clutter removal keeps it. Clutter goes through the whole radar chain; it is never added to the
point cloud directly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from core.config import RadarConfig
from core.errors import InputError
from core.scene.aoi import AOI

CLUTTER_SNR_DB = (15.0, 30.0)
MIN_CLUTTER_SPEED_BINS = 2.0


@dataclass(frozen=True, slots=True, kw_only=True)
class ClutterDraw:
    """Clutter reflectors of one frame.

    Attributes
    ----------
    position_m
        ``[x, y]``, shape ``(N, 2)``, m (z = 0).
    radial_velocity_mps
        Shape ``(N,)``, m/s; the velocity vector points along the line of sight.
    snr_db
        Target post-processing SNR per virtual channel, shape ``(N,)``, dB.
    """

    position_m: np.ndarray
    radial_velocity_mps: np.ndarray
    snr_db: np.ndarray

    def __len__(self) -> int:
        return len(self.snr_db)

    @property
    def velocity_mps(self) -> np.ndarray:
        """``v = vr · p/|p|``, shape ``(N, 2)``, m/s."""
        r = np.hypot(self.position_m[:, 0], self.position_m[:, 1])
        return self.position_m / r[:, None] * self.radial_velocity_mps[:, None]


def min_loops_for_clutter() -> int:
    """Smallest ``n_loops`` for which clutter can be drawn.

    ``v_max = n_loops/2 · Δv`` (Δv = λ/(2 N_tx N_c T_c), v_max = λ/(4 N_tx T_c)), and clutter
    needs ``2 Δv <= |v| < v_max``: a non-empty range only for ``n_loops > 4``.
    """
    return int(2 * MIN_CLUTTER_SPEED_BINS) + 1


def check_clutter_radar(radar: RadarConfig, density_per_m2: float) -> None:
    """Raise :class:`InputError` naming ``n_loops`` when clutter cannot move fast enough.

    Clutter (density > 0) must move at ``|v| >= 2`` velocity bins inside ``±v_max`` to survive
    static clutter removal, which needs ``n_loops >= 5`` (see :func:`min_loops_for_clutter`).
    """
    if density_per_m2 > 0 and radar.n_loops < min_loops_for_clutter():
        raise InputError(
            f"radar n_loops={radar.n_loops} is too small for clutter "
            f"(clutter_density_per_m2={density_per_m2}): clutter moves at >= "
            f"{MIN_CLUTTER_SPEED_BINS:g} velocity bins within ±v_max = n_loops/2 bins, which "
            f"needs n_loops >= {min_loops_for_clutter()}; raise n_loops or set "
            "clutter_density_per_m2 to 0"
        )


def expected_clutter_count(aoi: AOI, density_per_m2: float) -> float:
    """Mean number of clutter reflectors per frame, ``λ · area(AOI)``."""
    return density_per_m2 * aoi.area_m2


def draw_clutter(
    aoi: AOI, density_per_m2: float, radar: RadarConfig, rng: np.random.Generator
) -> ClutterDraw:
    """Draw the clutter reflectors of one frame.

    Parameters
    ----------
    aoi
        Where the reflectors are placed (uniform over its area).
    density_per_m2
        λ, m⁻²; the count is Poisson with mean ``λ · area(AOI)``.
    radar
        Gives ``v_max`` and the velocity bin ``Δv``.
    rng
        The only source of randomness.

    Raises
    ------
    InputError
        When ``density_per_m2 > 0`` and ``radar.n_loops < 5`` (no speed range for clutter).
    """
    check_clutter_radar(radar, density_per_m2)
    n = int(rng.poisson(expected_clutter_count(aoi, density_per_m2)))
    pos = aoi.sample_uniform(n, rng)
    if n == 0:  # nothing to draw (and no speed range needed, e.g. density 0 with few loops)
        return ClutterDraw(position_m=pos, radial_velocity_mps=np.zeros(0), snr_db=np.zeros(0))
    v_max = radar.max_velocity_mps
    v_min = MIN_CLUTTER_SPEED_BINS * radar.velocity_resolution_mps
    # |v| uniform in [v_min, v_max), sign uniform: uniform over ±v_max without the centre
    speed = rng.uniform(v_min, v_max, n)
    sign = np.where(rng.random(n) < 0.5, -1.0, 1.0)
    snr = rng.uniform(*CLUTTER_SNR_DB, n)
    return ClutterDraw(position_m=pos, radial_velocity_mps=sign * speed, snr_db=snr)

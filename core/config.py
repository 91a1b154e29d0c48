"""Radar configuration (SPEC §1) with the paper's defaults; derived values are properties."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

from core.errors import InputError
from core.limits import MAX_CUBE_SAMPLES

SPEED_OF_LIGHT_MPS = 299_792_458.0
BOLTZMANN_J_PER_K = 1.380649e-23

#: IWR6843ISK virtual array, channel index = tx * 4 + rx, positions in units of lambda/2.
ISK_AZIMUTH_POSITIONS = (0, 1, 2, 3, 2, 3, 4, 5, 4, 5, 6, 7)
ISK_ELEVATION_POSITIONS = (0, 0, 0, 0, 1, 1, 1, 1, 0, 0, 0, 0)
#: IWR6843AOP virtual array (antenna-on-package, 12 channels on a 4 x 4 grid less one 2 x 2
#: corner), channel index = tx * 4 + rx, units of lambda/2. From TI's people-counting
#: configuration for the AOP board, ``antGeometry0 -1 -1 0 0 -3 -3 -2 -2 -1 -1 0 0`` (azimuth
#: index) and ``antGeometry1 -1 0 -1 0 -3 -2 -3 -2 -3 -2 -3 -2`` (elevation index): azimuth
#: = -antGeometry0, elevation = antGeometry1 - min, the same mapping that turns the ISK's
#: ``antGeometry0 0 -1 -2 -3 -2 -3 -4 -5 -4 -5 -6 -7`` / ``antGeometry1 -1 -1 -1 -1 0 0 0 0
#: -1 -1 -1 -1`` into the ISK tuples above (docs/radar-chain.md, "Antenna layouts").
AOP_AZIMUTH_POSITIONS = (1, 1, 0, 0, 3, 3, 2, 2, 1, 1, 0, 0)
AOP_ELEVATION_POSITIONS = (2, 3, 2, 3, 0, 1, 0, 1, 0, 1, 0, 1)
#: Antenna layouts by board: (azimuth positions, elevation positions) of the 12 virtual
#: channels (3 TX x 4 RX, TDM order TX0, TX1, TX2).
ANTENNA_LAYOUTS: dict[str, tuple[tuple[int, ...], tuple[int, ...]]] = {
    "IWR6843ISK": (ISK_AZIMUTH_POSITIONS, ISK_ELEVATION_POSITIONS),
    "IWR6843AOP": (AOP_AZIMUTH_POSITIONS, AOP_ELEVATION_POSITIONS),
}


@dataclass(frozen=True, slots=True, kw_only=True)
class RadarConfig:
    """FMCW TDM-MIMO radar configuration. SI units throughout.

    The defaults are the paper's (TI IWR6843 class). Derived values (resolutions, limits,
    wavelength) are properties computed from the fields, never stored.
    """

    start_frequency_hz: float = 60e9
    ramp_time_s: float = 50.5e-6
    idle_time_s: float = 7e-6
    bandwidth_hz: float = 3.099e9
    n_tx: int = 3
    n_rx: int = 4
    n_loops: int = 32
    n_samples: int = 256
    sample_rate_hz: float = 5.9e6
    frame_period_s: float = 0.080
    tx_power_dbm: float = 12.0
    antenna_gain_db: float = 12.0
    receiver_gain_db: float = 36.0
    noise_figure_db: float = 12.0
    receiver_bandwidth_hz: float = 5.9e6
    temperature_k: float = 290.0
    impedance_ohm: float = 50.0
    #: TX antenna of each chirp slot within one loop (TDM order), e.g. (0, 1, 2).
    tx_order: tuple[int, ...] = (0, 1, 2)
    #: Virtual channel positions in units of lambda/2, channel index = slot * n_rx + rx.
    azimuth_positions: tuple[int, ...] = ISK_AZIMUTH_POSITIONS
    elevation_positions: tuple[int, ...] = ISK_ELEVATION_POSITIONS
    name: str = field(default="paper", compare=False)

    def __post_init__(self) -> None:
        positive = (
            "start_frequency_hz",
            "ramp_time_s",
            "bandwidth_hz",
            "n_tx",
            "n_rx",
            "n_loops",
            "n_samples",
            "sample_rate_hz",
            "frame_period_s",
            "receiver_bandwidth_hz",
            "temperature_k",
            "impedance_ohm",
        )
        for name in positive:
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
                raise InputError(f"{name} must be a positive number, got {name}={value!r}")
        if self.idle_time_s < 0:
            raise InputError(f"idle_time_s must be >= 0, got idle_time_s={self.idle_time_s!r}")
        if len(self.tx_order) != self.n_tx:
            raise InputError(
                f"tx_order must list one TX per chirp slot ({self.n_tx}), got {self.tx_order!r}"
            )
        n_virtual = self.n_tx * self.n_rx
        for name in ("azimuth_positions", "elevation_positions"):
            if len(getattr(self, name)) != n_virtual:
                raise InputError(
                    f"{name} must have n_tx*n_rx={n_virtual} entries, "
                    f"got {len(getattr(self, name))}"
                )
        cube = n_virtual * self.n_loops * self.n_samples
        if cube > MAX_CUBE_SAMPLES:
            raise InputError(
                f"n_tx*n_rx*n_loops*n_samples = {cube} samples a frame exceeds the limit "
                f"{MAX_CUBE_SAMPLES}"
            )
        if self.chirp_period_s * self.n_tx * self.n_loops > self.frame_period_s:
            raise InputError(
                "frame_period_s is shorter than the chirps of one frame "
                f"({self.chirp_period_s * self.n_tx * self.n_loops:.6g} s), "
                f"got frame_period_s={self.frame_period_s!r}"
            )

    # ---- derived values -------------------------------------------------------------------
    @property
    def wavelength_m(self) -> float:
        """lambda = c / Fc."""
        return SPEED_OF_LIGHT_MPS / self.start_frequency_hz

    @property
    def slope_hz_per_s(self) -> float:
        """S = BW / Tc."""
        return self.bandwidth_hz / self.ramp_time_s

    @property
    def chirp_period_s(self) -> float:
        """Tchirp = Tc + Tidle."""
        return self.ramp_time_s + self.idle_time_s

    @property
    def n_virtual(self) -> int:
        return self.n_tx * self.n_rx

    @property
    def range_resolution_m(self) -> float:
        """Range bin spacing c*Fs / (2*S*Nadc)."""
        return SPEED_OF_LIGHT_MPS * self.sample_rate_hz / (2 * self.slope_hz_per_s * self.n_samples)

    @property
    def max_range_m(self) -> float:
        """Fs*c / (2*S) (complex sampling)."""
        return self.sample_rate_hz * SPEED_OF_LIGHT_MPS / (2 * self.slope_hz_per_s)

    @property
    def max_velocity_mps(self) -> float:
        """Maximum unambiguous radial speed lambda / (4*Ntx*Tchirp)."""
        return self.wavelength_m / (4 * self.n_tx * self.chirp_period_s)

    @property
    def velocity_resolution_mps(self) -> float:
        """Doppler bin spacing lambda / (2*Ntx*Nc*Tchirp)."""
        return self.wavelength_m / (2 * self.n_tx * self.n_loops * self.chirp_period_s)

    @property
    def noise_power_w(self) -> float:
        """Input-referred noise power per sample k*T*F*Be."""
        return (
            BOLTZMANN_J_PER_K
            * self.temperature_k
            * 10 ** (self.noise_figure_db / 10)
            * self.receiver_bandwidth_hz
        )

    @property
    def has_elevation(self) -> bool:
        """True when the virtual array has elements at more than one elevation."""
        return len(set(self.elevation_positions)) > 1

    def derived(self) -> dict[str, float | int]:
        """Derived values as a plain dict (for ``radartune radar --json`` and the GUI)."""
        return {
            "wavelength_m": self.wavelength_m,
            "slope_hz_per_s": self.slope_hz_per_s,
            "chirp_period_s": self.chirp_period_s,
            "range_resolution_m": self.range_resolution_m,
            "max_range_m": self.max_range_m,
            "max_velocity_mps": self.max_velocity_mps,
            "velocity_resolution_mps": self.velocity_resolution_mps,
            "n_tx": self.n_tx,
            "n_rx": self.n_rx,
            "n_virtual": self.n_virtual,
            "n_loops": self.n_loops,
            "n_samples": self.n_samples,
            "frame_period_s": self.frame_period_s,
        }

    def to_dict(self) -> dict:
        """All fields as JSON-ready values."""
        out = {}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            out[f.name] = list(value) if isinstance(value, tuple) else value
        return out

    @classmethod
    def from_dict(cls, data: dict, source: str | None = None) -> RadarConfig:
        """Build from a dict of fields; unknown keys are an error naming them."""
        known = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(data) - known)
        if unknown:
            raise InputError(
                f"unknown radar field(s) {unknown}; expected some of {sorted(known)}", source
            )
        kwargs = {k: tuple(v) if isinstance(v, list) else v for k, v in data.items()}
        try:
            return cls(**kwargs)
        except InputError as exc:
            raise InputError(exc.message, source) from None
        except TypeError as exc:
            raise InputError(str(exc), source) from None


PAPER_RADAR = RadarConfig()


# ---- the paper's scene --------------------------------------------------------------------------
# The one statement of the paper's scene (SPEC §2); the scene's AOI defaults, the synthetic
# tracker scene, the benchmarks and the app all derive from it.

#: Area of interest: ``PAPER_MIN_RANGE_M <= r <= PAPER_MAX_RANGE_M`` and
#: ``|az| <= PAPER_MAX_AZIMUTH_DEG`` (radar at the origin, boresight +y, ``az = atan2(x, y)``).
PAPER_MIN_RANGE_M = 0.5
PAPER_MAX_RANGE_M = 10.0
PAPER_MAX_AZIMUTH_DEG = 60.0
#: Clutter density λ in m⁻²: Poisson clutter points per m² of the area of interest, every frame.
#: Also the value a scene file without ``clutter_density_per_m2`` takes.
PAPER_CLUTTER_DENSITY_PER_M2 = 0.02


def sector_area_m2(min_range_m: float, max_range_m: float, max_azimuth_deg: float) -> float:
    """Area of the annular sector ``min_range_m <= r <= max_range_m``, ``|az| <= max_azimuth_deg``
    in m²: ``A = az_max · (r_max² − r_min²)`` with ``az_max`` in rad (half of the span 2·az_max
    times ``r_max² − r_min²``)."""
    # A = (2 az_max)/2 * (r_max^2 - r_min^2)
    return math.radians(max_azimuth_deg) * (max_range_m**2 - min_range_m**2)


#: The paper's area of interest in m² (104.46 m²).
PAPER_AOI_AREA_M2 = sector_area_m2(PAPER_MIN_RANGE_M, PAPER_MAX_RANGE_M, PAPER_MAX_AZIMUTH_DEG)


# ---- processing settings ------------------------------------------------------------------------

#: Window names understood by :func:`core.processing.window`.
WINDOWS = ("rect", "hann", "hamming", "blackman")
#: CFAR variants: cell averaging, smallest-of and greatest-of cell averaging.
CFAR_METHODS = ("ca", "caso", "cago")


@dataclass(frozen=True, slots=True, kw_only=True)
class CfarSettings:
    """One CFAR stage (along range or along Doppler).

    Parameters
    ----------
    method
        ``"ca"`` (cell averaging over both sides), ``"caso"`` (smallest of the two sides) or
        ``"cago"`` (greatest of the two sides).
    n_train, n_guard
        Training and guard cells on each side of the cell under test.
    pfa
        Design false-alarm probability of this stage, in (0, 1).
    cyclic
        Wrap around the axis (Doppler) instead of using one side at the edges (range).
    """

    method: str = "caso"
    n_train: int = 8
    n_guard: int = 4
    pfa: float = 1e-4
    cyclic: bool = False

    def __post_init__(self) -> None:
        if self.method not in CFAR_METHODS:
            raise InputError(f"method must be one of {CFAR_METHODS}, got method={self.method!r}")
        if not (isinstance(self.n_train, int) and self.n_train >= 1):
            raise InputError(f"n_train must be an integer >= 1, got n_train={self.n_train!r}")
        if not (isinstance(self.n_guard, int) and self.n_guard >= 0):
            raise InputError(f"n_guard must be an integer >= 0, got n_guard={self.n_guard!r}")
        if not (isinstance(self.pfa, int | float) and 0.0 < self.pfa < 1.0):
            raise InputError(f"pfa must be in (0, 1), got pfa={self.pfa!r}")

    def to_dict(self) -> dict:
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}

    @classmethod
    def from_dict(cls, data: dict, source: str | None = None) -> CfarSettings:
        return _from_dict(cls, data, source)


#: SPEC §3 defaults (the TI SDK's): CASO along range, cyclic CA along Doppler.
RANGE_CFAR = CfarSettings(method="caso", n_train=8, n_guard=4, pfa=1e-4, cyclic=False)
DOPPLER_CFAR = CfarSettings(method="ca", n_train=4, n_guard=2, pfa=1e-3, cyclic=True)


@dataclass(frozen=True, slots=True, kw_only=True)
class ProcessingSettings:
    """Settings of the processing chain (SPEC §3). SI units.

    Parameters
    ----------
    range_window, doppler_window
        Window before the range / Doppler FFT: one of :data:`WINDOWS` (Hann by default).
    static_clutter_removal
        Subtract the mean over loops per range bin and virtual channel.
    range_cfar, doppler_cfar
        The two CFAR stages; a cell is detected only if it passes both.
    cfar_noise_model
        Let the CFAR thresholds account for window-correlated cells and the noise notch that
        static clutter removal leaves around zero Doppler (otherwise: independent cells).
    peak_grouping
        Keep only detections that are local maxima of the range-Doppler map (3 x 3, Doppler
        cyclic).
    min_range_m, max_range_m
        Detections are reported only between these ranges (default 0.3 m to the AOI's 10 m).
    angle_fft_size
        Zero-padded length of the azimuth FFT over the azimuth row of the virtual array.
    """

    range_window: str = "hann"
    doppler_window: str = "hann"
    static_clutter_removal: bool = True
    range_cfar: CfarSettings = RANGE_CFAR
    doppler_cfar: CfarSettings = DOPPLER_CFAR
    cfar_noise_model: bool = True
    peak_grouping: bool = True
    min_range_m: float = 0.3
    max_range_m: float = 10.0
    angle_fft_size: int = 64

    def __post_init__(self) -> None:
        for name in ("range_window", "doppler_window"):
            if getattr(self, name) not in WINDOWS:
                raise InputError(f"{name} must be one of {WINDOWS}, got {getattr(self, name)!r}")
        for name in ("range_cfar", "doppler_cfar"):
            if not isinstance(getattr(self, name), CfarSettings):
                raise InputError(f"{name} must be CfarSettings, got {getattr(self, name)!r}")
        if not (math.isfinite(self.min_range_m) and self.min_range_m >= 0):
            raise InputError(f"min_range_m must be >= 0, got min_range_m={self.min_range_m!r}")
        if not (math.isfinite(self.max_range_m) and self.max_range_m > self.min_range_m):
            raise InputError(
                f"max_range_m must be > min_range_m={self.min_range_m!r}, "
                f"got max_range_m={self.max_range_m!r}"
            )
        n = self.angle_fft_size
        if not (isinstance(n, int) and n >= 8 and n & (n - 1) == 0):
            raise InputError(f"angle_fft_size must be a power of two >= 8, got {n!r}")

    def to_dict(self) -> dict:
        out = {}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            out[f.name] = value.to_dict() if isinstance(value, CfarSettings) else value
        return out

    @classmethod
    def from_dict(cls, data: dict, source: str | None = None) -> ProcessingSettings:
        data = dict(data)
        for name in ("range_cfar", "doppler_cfar"):
            if isinstance(data.get(name), dict):
                data[name] = CfarSettings.from_dict(data[name], source)
        return _from_dict(cls, data, source)


def _from_dict(cls, data: dict, source: str | None):
    known = {f.name for f in dataclasses.fields(cls)}
    unknown = sorted(set(data) - known)
    if unknown:
        raise InputError(
            f"unknown {cls.__name__} field(s) {unknown}; expected some of {sorted(known)}", source
        )
    try:
        return cls(**data)
    except InputError as exc:
        raise InputError(exc.message, source) from None
    except TypeError as exc:
        raise InputError(str(exc), source) from None


#: The SPEC §3 processing defaults (module-level singleton for argument defaults).
DEFAULT_PROCESSING = ProcessingSettings()


# ---- TI detection chains ------------------------------------------------------------------------

#: The detection chains: the paper's (section 3), TI's out-of-box demo and TI's 3-D people
#: counting (docs/radar-chain.md, "Chains"). A TI ``.cfg`` selects one (core.formats.ti_cfg).
CHAINS = ("paper", "oob", "people-counting")


def _check_int(obj: object, name: str, low: int) -> None:
    value = getattr(obj, name)
    if not (isinstance(value, int) and not isinstance(value, bool) and value >= low):
        raise InputError(f"{name} must be an integer >= {low}, got {name}={value!r}")


def _check_real(obj: object, name: str, low: float, high: float) -> None:
    value = getattr(obj, name)
    if not (isinstance(value, int | float) and math.isfinite(value) and low <= value <= high):
        raise InputError(f"{name} must be in [{low}, {high}], got {name}={value!r}")


@dataclass(frozen=True, slots=True, kw_only=True)
class DbCfarSettings:
    """One CFAR pass whose threshold is a ratio in dB over the noise estimate (TI's ``cfarCfg``).

    Parameters
    ----------
    method
        ``"ca"``, ``"cago"`` or ``"caso"`` (TI's averageMode 0, 1, 2).
    n_train, n_guard
        Training (noiseWin) and guard (guardLen) cells on each side.
    threshold_db
        A cell is detected when it exceeds the noise estimate by this many dB.
    cyclic
        Wrap around the axis (TI's cyclic mode).
    peak_grouping
        Keep only cells not below their two neighbours along this axis.
    """

    method: str = "ca"
    n_train: int = 8
    n_guard: int = 4
    threshold_db: float = 15.0
    cyclic: bool = False
    peak_grouping: bool = True

    def __post_init__(self) -> None:
        if self.method not in CFAR_METHODS:
            raise InputError(f"method must be one of {CFAR_METHODS}, got method={self.method!r}")
        _check_int(self, "n_train", 1)
        _check_int(self, "n_guard", 0)
        _check_real(self, "threshold_db", 0.0, 100.0)


@dataclass(frozen=True, slots=True, kw_only=True)
class OobSettings:
    """TI's out-of-box demo chain (mmWave SDK 3.x ``cfarCfg``, ``cfarFovCfg``, ``aoaFovCfg``,
    ``multiObjBeamForming``, ``clutterRemoval``). Angles in degrees as in the ``.cfg``.

    ``multi_object_threshold``: a second azimuth peak above this fraction of the first gives
    a second point at the same range and Doppler (None: off).
    """

    range_cfar: DbCfarSettings = DbCfarSettings(method="caso", n_train=8, n_guard=4)
    doppler_cfar: DbCfarSettings = DbCfarSettings(method="ca", n_train=4, n_guard=2, cyclic=True)
    static_clutter_removal: bool = False
    min_range_m: float = 0.0
    max_range_m: float = math.inf
    min_velocity_mps: float = -math.inf
    max_velocity_mps: float = math.inf
    azimuth_fov_deg: tuple[float, float] = (-90.0, 90.0)
    elevation_fov_deg: tuple[float, float] = (-90.0, 90.0)
    multi_object_threshold: float | None = 0.5

    def __post_init__(self) -> None:
        for name in ("range_cfar", "doppler_cfar"):
            if not isinstance(getattr(self, name), DbCfarSettings):
                raise InputError(f"{name} must be DbCfarSettings, got {getattr(self, name)!r}")
        if not self.min_range_m < self.max_range_m:
            raise InputError(
                f"min_range_m must be < max_range_m, got {self.min_range_m}, {self.max_range_m}"
            )
        if not self.min_velocity_mps < self.max_velocity_mps:
            raise InputError(
                "min_velocity_mps must be < max_velocity_mps, got "
                f"{self.min_velocity_mps}, {self.max_velocity_mps}"
            )
        for name in ("azimuth_fov_deg", "elevation_fov_deg"):
            lo, hi = getattr(self, name)
            if not -90.0 <= lo < hi <= 90.0:
                raise InputError(f"{name} must satisfy -90 <= min < max <= 90, got {(lo, hi)}")
        t = self.multi_object_threshold
        if t is not None and not (math.isfinite(t) and 0.0 < t <= 1.0):
            raise InputError(f"multi_object_threshold must be in (0, 1], got {t!r}")


@dataclass(frozen=True, slots=True, kw_only=True)
class RaCfarSettings:
    """CFAR on a range-angle map (TI people counting ``dynamicRACfarCfg`` / ``staticRACfarCfg``).

    A first pass along range (CASO, ``ref_range`` training and ``guard_range`` guard cells a
    side, threshold ``range_threshold_db``), confirmed by a second pass along angle (CASO,
    ``angle_threshold_db``) when ``second_pass``; ``discard_*`` cells at either end of each
    axis are not tested; a detection below ``sidelobe_threshold`` times the strongest cell of
    its range bin is dropped.
    """

    discard_left_range: int = 4
    discard_right_range: int = 4
    discard_left_angle: int = 2
    discard_right_angle: int = 2
    ref_range: int = 8
    ref_angle: int = 12
    guard_range: int = 4
    guard_angle: int = 8
    range_threshold_db: float = 5.0
    angle_threshold_db: float = 8.0
    sidelobe_threshold: float = 0.4
    second_pass: bool = True

    def __post_init__(self) -> None:
        for name in (
            "discard_left_range",
            "discard_right_range",
            "discard_left_angle",
            "discard_right_angle",
            "guard_range",
            "guard_angle",
        ):
            _check_int(self, name, 0)
        _check_int(self, "ref_range", 1)
        _check_int(self, "ref_angle", 1)
        _check_real(self, "range_threshold_db", 0.0, 100.0)
        _check_real(self, "angle_threshold_db", 0.0, 100.0)
        _check_real(self, "sidelobe_threshold", 0.0, 1.0)


@dataclass(frozen=True, slots=True, kw_only=True)
class PeopleCountingSettings:
    """TI's 3-D people counting chain (``dynamicRangeAngleCfg``, ``dynamicRACfarCfg``,
    ``dynamic2DAngleCfg``, ``staticRangeAngleCfg``, ``staticRACfarCfg``, ``fovCfg``).

    Parameters
    ----------
    dynamic_cfar, static_cfar
        CFAR on the moving (clutter-removed, Capon) and static (zero-Doppler, Bartlett) maps.
    angle_step_deg, diagonal_loading
        Azimuth grid step of the Capon range-azimuth map and its diagonal loading, relative to
        the mean channel power (``R + loading * tr(R)/N * I``).
    elevation_step_deg, elevation_loading
        Elevation grid step and loading of the per-point Capon elevation search.
    static_enabled
        Run the static chain (no clutter removal; points with zero Doppler).
    static_azimuth_decimation, static_elevation_decimation
        The static chain's angle grids are these many times coarser.
    azimuth_fov_deg, elevation_fov_deg
        Half-widths of the angle grids (``fovCfg``).
    """

    dynamic_cfar: RaCfarSettings = RaCfarSettings()
    static_cfar: RaCfarSettings = RaCfarSettings(
        discard_left_range=6,
        discard_right_range=2,
        discard_left_angle=2,
        discard_right_angle=2,
        ref_range=8,
        ref_angle=8,
        guard_range=6,
        guard_angle=4,
        range_threshold_db=8.0,
        angle_threshold_db=15.0,
        sidelobe_threshold=0.3,
        second_pass=False,
    )
    angle_step_deg: float = 0.75
    diagonal_loading: float = 0.001
    elevation_step_deg: float = 1.5
    elevation_loading: float = 0.03
    static_enabled: bool = True
    static_azimuth_decimation: int = 8
    static_elevation_decimation: int = 8
    azimuth_fov_deg: float = 70.0
    elevation_fov_deg: float = 20.0

    def __post_init__(self) -> None:
        for name in ("dynamic_cfar", "static_cfar"):
            if not isinstance(getattr(self, name), RaCfarSettings):
                raise InputError(f"{name} must be RaCfarSettings, got {getattr(self, name)!r}")
        _check_real(self, "angle_step_deg", 0.01, 45.0)
        _check_real(self, "elevation_step_deg", 0.01, 45.0)
        _check_real(self, "diagonal_loading", 0.0, 1e3)
        _check_real(self, "elevation_loading", 0.0, 1e3)
        _check_int(self, "static_azimuth_decimation", 1)
        _check_int(self, "static_elevation_decimation", 1)
        _check_real(self, "azimuth_fov_deg", 1.0, 90.0)
        _check_real(self, "elevation_fov_deg", 0.0, 90.0)


@dataclass(frozen=True, slots=True, kw_only=True)
class ChainConfig:
    """Which detection chain a radar runs and its settings (one of :data:`CHAINS`).

    ``ignored`` names the ``.cfg`` commands the chain was read with but does not model.
    """

    name: str = "paper"
    oob: OobSettings | None = None
    people_counting: PeopleCountingSettings | None = None
    ignored: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if self.name not in CHAINS:
            raise InputError(f"chain must be one of {list(CHAINS)}, got chain={self.name!r}")
        if self.name == "oob" and not isinstance(self.oob, OobSettings):
            raise InputError("chain 'oob' needs its OobSettings (oob=...)")
        if self.name == "people-counting" and not isinstance(
            self.people_counting, PeopleCountingSettings
        ):
            raise InputError("chain 'people-counting' needs PeopleCountingSettings")


PAPER_CHAIN = ChainConfig()


def default_chain(name: str) -> ChainConfig:
    """The chain ``name`` (one of :data:`CHAINS`) with TI's default settings (the values of
    ``resources/radar/oob_isk.cfg`` and ``people_counting_isk.cfg`` with static detection on);
    :class:`InputError` naming the chains for an unknown name."""
    if name not in CHAINS:
        raise InputError(f"chain must be one of {list(CHAINS)}, got {name!r}")
    if name == "oob":
        return ChainConfig(name="oob", oob=OobSettings())
    if name == "people-counting":
        return ChainConfig(name="people-counting", people_counting=PeopleCountingSettings())
    return PAPER_CHAIN

"""Radar configuration (SPEC §1) with the paper's defaults; derived values are properties."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

from core.errors import InputError

SPEED_OF_LIGHT_MPS = 299_792_458.0
BOLTZMANN_J_PER_K = 1.380649e-23

#: IWR6843ISK virtual array, channel index = tx * 4 + rx, positions in units of lambda/2.
ISK_AZIMUTH_POSITIONS = (0, 1, 2, 3, 2, 3, 4, 5, 4, 5, 6, 7)
ISK_ELEVATION_POSITIONS = (0, 0, 0, 0, 1, 1, 1, 1, 0, 0, 0, 0)


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

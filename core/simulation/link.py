"""Link budget: radar equation (4), receiver eqs. (2)-(3), RCS eq. (5) and the SNR a point reports.

Receiver, as the paper writes it: ``Vspp = sqrt(8 Ps R 10^(Ge/20))``,
``Vnpp = sqrt(8 k T F Be R 10^(Ge/20))``. In complex baseband a scatterer's sample amplitude is
``Vspp / (2 sqrt 2) = sqrt(Ps R 10^(Ge/20))`` and the noise is circular complex Gaussian with
``E|n|^2 = Vnpp^2 / 8 = k T F Be R 10^(Ge/20)``; the SNR per sample is ``Ps / (k T F Be)``.
"""

from __future__ import annotations

import numpy as np

from core.config import DEFAULT_PROCESSING, ProcessingSettings, RadarConfig
from core.processing.spectrum import window_loss_db
from core.simulation.antenna import AntennaGain

#: eq. (5): RCS of a person ~ N(-8 dBsm, 16 dB²).
PERSON_RCS_MEAN_DBSM = -8.0
PERSON_RCS_VARIANCE_DB2 = 16.0


def draw_person_rcs_dbsm(rng: np.random.Generator, size: int | tuple[int, ...]) -> np.ndarray:
    """RCS draws of eq. (5), dBsm: mean -8, variance 16 dB²."""
    return rng.normal(PERSON_RCS_MEAN_DBSM, np.sqrt(PERSON_RCS_VARIANCE_DB2), size)


def received_power_w(
    radar: RadarConfig,
    range_m: np.ndarray,
    azimuth_rad: np.ndarray,
    rcs_dbsm: np.ndarray,
    antenna: AntennaGain,
) -> np.ndarray:
    """Received power, eq. (4): ``Pr = Pt Gt Gr lambda^2 sigma / ((4 pi)^3 R^4)``, watts."""
    pt_w = 10 ** ((radar.tx_power_dbm - 30.0) / 10)
    g = 10 ** (antenna.gain_db(azimuth_rad) / 10)  # Gt = Gr
    sigma = 10 ** (np.asarray(rcs_dbsm, dtype=np.float64) / 10)
    r = np.asarray(range_m, dtype=np.float64)
    # Pr = Pt Gt Gr lambda^2 sigma / ((4 pi)^3 R^4)
    return pt_w * g * g * radar.wavelength_m**2 * sigma / ((4 * np.pi) ** 3 * r**4)


def receiver_voltage_scale(radar: RadarConfig) -> float:
    """``R 10^(Ge/20)``: output voltage power (V²) per watt of input power, eqs. (2)-(3)."""
    return radar.impedance_ohm * 10 ** (radar.receiver_gain_db / 20)


def signal_amplitude_v(radar: RadarConfig, power_w: np.ndarray) -> np.ndarray:
    """Complex baseband amplitude ``Vspp / (2 sqrt 2)`` with ``Vspp = sqrt(8 Ps R 10^(Ge/20))``."""
    # Vspp = sqrt(8 Ps R 10^(Ge/20));  A = Vspp / (2 sqrt 2)
    vspp = np.sqrt(8 * np.asarray(power_w) * receiver_voltage_scale(radar))
    return vspp / (2 * np.sqrt(2))


def noise_power_v2(radar: RadarConfig) -> float:
    """Noise power per complex sample ``E|n|^2 = Vnpp^2 / 8`` (V²), eq. (3)."""
    # Vnpp = sqrt(8 k T F Be R 10^(Ge/20))
    vnpp2 = 8 * radar.noise_power_w * receiver_voltage_scale(radar)
    return vnpp2 / 8


def processing_gain_db(radar: RadarConfig, settings: ProcessingSettings) -> float:
    """SNR gain of range and Doppler FFTs with the settings' windows, dB.

    ``10 log10(Nadc Nc)`` plus the two window losses (Hann: -1.761 dB each).
    """
    return float(
        10 * np.log10(radar.n_samples * radar.n_loops)
        + window_loss_db(settings.range_window, radar.n_samples)
        + window_loss_db(settings.doppler_window, radar.n_loops)
    )


def post_processing_snr_db(
    radar: RadarConfig,
    range_m: np.ndarray,
    azimuth_rad: np.ndarray,
    rcs_dbsm: np.ndarray,
    antenna: AntennaGain,
    settings: ProcessingSettings = DEFAULT_PROCESSING,
) -> np.ndarray:
    """Per-virtual-channel SNR after range and Doppler FFTs, dB (on-bin target).

    ``SNR = Pr / (k T F Be) * Nadc * Nc * L_range * L_doppler``. The non-coherent sum over
    channels scales signal and noise alike, so this is also the SNR a detected point reports.
    """
    pr = received_power_w(radar, range_m, azimuth_rad, rcs_dbsm, antenna)
    return 10 * np.log10(pr / radar.noise_power_w) + processing_gain_db(radar, settings)


def rcs_for_snr_db(
    radar: RadarConfig,
    range_m: np.ndarray,
    azimuth_rad: np.ndarray,
    snr_db: np.ndarray,
    antenna: AntennaGain,
    settings: ProcessingSettings = DEFAULT_PROCESSING,
) -> np.ndarray:
    """RCS (dBsm) that gives ``snr_db`` post-processing SNR: inverse of post_processing_snr_db."""
    snr_0dbsm = post_processing_snr_db(radar, range_m, azimuth_rad, 0.0, antenna, settings)
    return np.asarray(snr_db) - snr_0dbsm

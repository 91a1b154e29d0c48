"""Radar simulation (SPEC §2): antenna gain, link budget, exact baseband synthesis, one frame."""

from core.simulation.antenna import AntennaGain
from core.simulation.baseband import (
    chirp_ranges_m,
    steering_vectors,
    synthesize_baseband,
    synthesize_noise,
    synthesize_signal,
)
from core.simulation.frame import FrameOutput, needs_elevation, simulate_frame
from core.simulation.link import (
    draw_person_rcs_dbsm,
    noise_power_v2,
    post_processing_snr_db,
    processing_gain_db,
    rcs_for_snr_db,
    received_power_w,
    receiver_voltage_scale,
    signal_amplitude_v,
)
from core.simulation.scatterers import Scatterers

__all__ = [
    "AntennaGain",
    "FrameOutput",
    "Scatterers",
    "chirp_ranges_m",
    "draw_person_rcs_dbsm",
    "needs_elevation",
    "noise_power_v2",
    "post_processing_snr_db",
    "processing_gain_db",
    "rcs_for_snr_db",
    "received_power_w",
    "receiver_voltage_scale",
    "signal_amplitude_v",
    "simulate_frame",
    "steering_vectors",
    "synthesize_baseband",
    "synthesize_noise",
    "synthesize_signal",
]

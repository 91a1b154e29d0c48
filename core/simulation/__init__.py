"""Radar simulation (SPEC §2): antenna gain, link budget, exact baseband synthesis, one frame."""

from core.simulation.antenna import AntennaGain
from core.simulation.baseband import (
    chirp_ranges_m,
    steering_vectors,
    synthesize_baseband,
    synthesize_noise,
    synthesize_signal,
)
from core.simulation.fast import simulate_frame_fast
from core.simulation.frame import FrameOutput, needs_elevation, simulate_frame
from core.simulation.levels import (
    LEVELS,
    FidelityLevel,
    FrameSimulator,
    FramesSimulator,
    fidelity_level,
)
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
from core.simulation.measurement import simulate_frame_measurement
from core.simulation.scatterers import Scatterers

#: Frame simulators by fidelity level (derived from :data:`LEVELS`), cheapest last.
FIDELITY_LEVELS = {name: level.simulate_frame for name, level in LEVELS.items()}

__all__ = [
    "FIDELITY_LEVELS",
    "LEVELS",
    "AntennaGain",
    "FidelityLevel",
    "FrameSimulator",
    "FramesSimulator",
    "FrameOutput",
    "Scatterers",
    "chirp_ranges_m",
    "draw_person_rcs_dbsm",
    "fidelity_level",
    "needs_elevation",
    "noise_power_v2",
    "post_processing_snr_db",
    "processing_gain_db",
    "rcs_for_snr_db",
    "received_power_w",
    "receiver_voltage_scale",
    "signal_amplitude_v",
    "simulate_frame",
    "simulate_frame_fast",
    "simulate_frame_measurement",
    "steering_vectors",
    "synthesize_baseband",
    "synthesize_noise",
    "synthesize_signal",
]

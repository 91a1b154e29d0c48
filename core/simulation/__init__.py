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

# fidelity levels (docs/fidelity.md): every simulator has the signature of simulate_frame
#: Frame simulators by fidelity level, cheapest last; ``exact`` is the reference.
FIDELITY_LEVELS = {
    "exact": simulate_frame,
    "fast": simulate_frame_fast,
    "measurement": simulate_frame_measurement,
}

__all__ = [
    "FIDELITY_LEVELS",
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
    "simulate_frame_fast",
    "simulate_frame_measurement",
    "steering_vectors",
    "synthesize_baseband",
    "synthesize_noise",
    "synthesize_signal",
]

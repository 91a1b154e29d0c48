"""Processing chain (SPEC §3): range FFT, static clutter removal, Doppler FFT, range-Doppler map,
two-stage CFAR, angle of arrival and point cloud. Each stage is a small function callable on its
own (the cheaper fidelity levels reuse the CFAR, angle and point-cloud stages)."""

from core.processing.angle import estimate_angles, tdm_compensate
from core.processing.cfar import (
    CaCfar,
    CagoCfar,
    CasoCfar,
    Cfar,
    CfarThresholds,
    Detections,
    expected_false_alarms_per_frame,
    make_cfar,
    two_stage_cfar,
    two_stage_pfa,
    two_stage_thresholds,
)
from core.processing.cfar_thresholds import pfa_ca, pfa_cago, pfa_caso, threshold_factor
from core.processing.points import build_point_cloud, label_sources, refine_bins
from core.processing.range_azimuth import azimuth_sines, range_azimuth_map
from core.processing.spectrum import (
    doppler_fft,
    range_doppler_map,
    range_fft,
    remove_static_clutter,
    window,
    window_loss_db,
)

__all__ = [
    "CaCfar",
    "CagoCfar",
    "CasoCfar",
    "Cfar",
    "CfarThresholds",
    "Detections",
    "expected_false_alarms_per_frame",
    "azimuth_sines",
    "build_point_cloud",
    "doppler_fft",
    "estimate_angles",
    "label_sources",
    "make_cfar",
    "pfa_ca",
    "pfa_cago",
    "pfa_caso",
    "range_azimuth_map",
    "range_doppler_map",
    "range_fft",
    "refine_bins",
    "remove_static_clutter",
    "tdm_compensate",
    "threshold_factor",
    "two_stage_cfar",
    "two_stage_pfa",
    "two_stage_thresholds",
    "window",
    "window_loss_db",
]

"""IPDA people tracker (SPEC §4): one role per module, :mod:`core.tracking.tracker` composes them.

- :mod:`~core.tracking.space` — the optimised parameters: one table (eq. 15) of names, symbols,
  units, bounds, scales, models and defaults
- :mod:`~core.tracking.params` — :class:`TrackerParams` (JSON in/out, validation)
- :mod:`~core.tracking.models` — CV / CA direct discrete-time kinematic models
- :mod:`~core.tracking.ekf` — h(x), analytic Jacobian, prediction, Joseph form
- :mod:`~core.tracking.gating` — S, Cholesky, Mahalanobis gate, gate volume
- :mod:`~core.tracking.ipda` — existence, likelihood ratios, δ, ψ, β, PDA update
- :mod:`~core.tracking.jipda` — joint IPDA: clusters of tracks sharing measurements, joint
  events, marginal association probabilities and existence
- :mod:`~core.tracking.initiation`, :mod:`~core.tracking.management` — birth, confirmation,
  deletion, merging, cap, estimate
- :mod:`~core.tracking.inputs` — measurement frames validated once, derived constants
- :mod:`~core.tracking.results` — :class:`TrackerResult`, :class:`FrameTracks`, the kernel's
  :class:`~core.tracking.results.TrackRecord`
- :mod:`~core.tracking.tracker` — :func:`run_tracker` (readable reference, every track) and
  :class:`~core.tracking.tracker.StreamTracker` (the same, one frame at a time: a live sensor)
- :mod:`~core.tracking.kernel` — the same algorithm compiled with numba (hot path); the
  ``@njit`` code itself in :mod:`~core.tracking.kernel_jit`
- :mod:`~core.tracking.batch` — :func:`track_dataset` over a :class:`core.dataset.Dataset`
- :mod:`~core.tracking.synthetic` — synthetic measurements for tests and the stability sweep
"""

from core.tracking.batch import DatasetEstimates, estimate_track_ids, track_dataset
from core.tracking.params import TrackerParams
from core.tracking.results import FrameTracks, TrackerResult
from core.tracking.space import SEARCH_SPACE
from core.tracking.tracker import run_tracker

__all__ = [
    "SEARCH_SPACE",
    "DatasetEstimates",
    "FrameTracks",
    "TrackerParams",
    "TrackerResult",
    "estimate_track_ids",
    "run_tracker",
    "track_dataset",
]

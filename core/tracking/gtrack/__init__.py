"""TI's people tracker (gtrack), rebuilt from TI's documentation beside the paper's IPDA.

- :mod:`~core.tracking.gtrack.params` — :class:`GtrackParams` and the one mapping to and from
  the ``.cfg`` tracker lines
- :mod:`~core.tracking.gtrack.geometry` — sensor pose, constant-acceleration model, spherical
  measurement and Jacobian (shares :mod:`core.tracking.ekf`)
- :mod:`~core.tracking.gtrack.tracker` — :func:`run_gtrack`, the readable tracker
- :mod:`~core.tracking.gtrack.kernel` — the same, compiled (``@njit``), tested equal;
  :mod:`~core.tracking.gtrack.compiled` its Python side
- :mod:`~core.tracking.gtrack.batch` — gtrack over a data set's trajectories
"""

from core.tracking.gtrack.params import GtrackParams, cfg_lines, params_from_cfg
from core.tracking.gtrack.tracker import GtrackResult, run_gtrack

__all__ = ["GtrackParams", "GtrackResult", "cfg_lines", "params_from_cfg", "run_gtrack"]

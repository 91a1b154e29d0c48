"""Loading the compiled tracker before timing it.

The first call of the compiled kernel loads its machine code from numba's disk cache (or compiles
it, the first time after an install): a fixed start-up cost of a process, not tracking time.
:func:`load_compiled` pays it on a few synthetic frames, so what is timed afterwards is tracking.
"""

from __future__ import annotations

import time

import numpy as np

from core.tracking.batch import track_dataset
from core.tracking.params import TrackerParams
from core.tracking.synthetic import synthetic_dataset


def load_compiled(params: TrackerParams) -> float:
    """Run the compiled tracker once on 5 synthetic frames with ``params``; seconds it took.

    The kernels are specialised on the argument types only, which every data set shares (float64
    arrays), so later calls on any data set find them loaded.
    """
    t0 = time.perf_counter()
    # one person walking away at 1 m/s from (0, 3) m, with the synthetic scene's clutter
    v = np.tile([0.0, 1.0], (5, 1))
    p = np.array([0.0, 3.0]) + np.arange(5)[:, None] * 0.1 * v
    track_dataset(synthetic_dataset(seed=0, paths=[(p, v)]), params)
    return time.perf_counter() - t0


__all__ = ["load_compiled"]

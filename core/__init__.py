"""RadarTune core: radar simulation, processing, IPDA tracking, evaluation and optimisation.

Nothing in this package imports Qt (``tests/test_architecture.py`` proves it).
"""

__version__ = "0.1.0"

import os

# RadarTune parallelises over processes (data sets, studies, the GUI's workers); BLAS threads on
# top only oversubscribe the cores. Measured on the 2-core development machine under load: the
# Doppler step's 32 x 32 matrix product 0.5 ms single-threaded against 3-4 ms with OpenBLAS
# threads; the tracker's small-matrix algebra 0.15 s against 0.75 s per re-track. Effective
# when core (or app) is imported before numpy: the CLI, the app and the workers; a user's own
# setting wins.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

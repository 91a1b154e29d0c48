"""RadarTune desktop application (PySide6 + pyqtgraph) on top of :mod:`core`.

Layout of the package:

- :mod:`app.data` — frozen, Qt-free snapshots handed from workers to the GUI thread;
- :mod:`app.engine` — the only module that calls :mod:`core` for simulation, tracking and
  studies (adapts core results into :mod:`app.data` snapshots);
- :mod:`app.models` — QObject models with signals (the single source of truth of each panel);
- :mod:`app.workers` — simulation / re-tracking threads; :mod:`app.study` — study processes;
- :mod:`app.views` — pyqtgraph views (items created once, updated with ``setData``);
- :mod:`app.panels` — editor panels bound both ways to the models;
- :mod:`app.window` — the main window, playback and persistence.
"""

import os

# The tracker's small-matrix linear algebra gets ~5x slower when OpenBLAS spins threads on a
# busy machine (measured: 0.15 s vs 0.75 s per re-track); the GUI gains nothing from them.
# Effective only when app is imported before numpy (radartune gui, python -m app, tests).
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

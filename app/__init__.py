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

# core sets single-threaded BLAS before numpy loads (see core/__init__.py); import it first
import core  # noqa: F401

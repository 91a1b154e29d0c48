"""App test fixtures: temporary QSettings, a shared 250-frame simulated scene, a main window."""

from __future__ import annotations

from pathlib import Path

import pytest

import app  # noqa: F401  (sets the BLAS thread variables before numpy is imported)


def pytest_configure(config) -> None:
    """One OpenGL share group, as app.main sets it (before the QApplication exists): the 3-D
    views of several tests share pyqtgraph's per-class shader programs."""
    from PySide6 import QtCore

    QtCore.QCoreApplication.setAttribute(QtCore.Qt.AA_ShareOpenGLContexts)


#: A 250-frame scene (20 s of class c at 80 ms): the size the re-track budget is specified for.
LONG_SCENE = {
    "schema_version": 1,
    "radar": "paper",
    "seed": 7,
    "clutter_density_per_m2": 0.02,
    "aoi": {"min_range_m": 0.5, "max_range_m": 10.0, "max_azimuth_deg": 60.0},
    "static_reflectors": [],
    "persons": [{"trajectory": {"class": "c", "seed": 3, "duration_s": 20.0}}],
}


@pytest.fixture(scope="session")
def long_scene_frames():
    """(scene, frames) of LONG_SCENE, simulated once through the real radar chain."""
    from app import engine

    scene = engine.scene_from_document(LONG_SCENE, Path.cwd())
    frames = list(engine.simulate(scene))
    return scene, frames


@pytest.fixture
def settings(tmp_path):
    from PySide6 import QtCore

    return QtCore.QSettings(str(tmp_path / "settings.ini"), QtCore.QSettings.IniFormat)


def _fill_cache(window, scene_doc: dict, frames) -> None:
    """Adopt a scene without simulating it and put already simulated frames into the cache."""
    window.scene_model.set_document(scene_doc)
    window._scene_timer.stop()  # no re-simulation: the frames are given
    info = window.engine.scene_info(window.scene_model.scene)
    window.cache.clear(expected=info.n_frames, truth_paths=info.truth_paths)
    for f in frames:
        window.cache.append(f)
    window.cache.mark_complete()


@pytest.fixture
def window(qtbot, settings):
    """A main window without a scene (tests load what they need)."""
    from app.window import MainWindow

    w = MainWindow(settings, load_scene=False)
    qtbot.addWidget(w)
    w.resize(1400, 900)
    yield w
    w.shutdown()


@pytest.fixture
def fill_cache():
    """``fill_cache(window, doc, frames)``: adopt a scene and cache given frames."""
    return _fill_cache


@pytest.fixture
def long_scene_doc() -> dict:
    return dict(LONG_SCENE)

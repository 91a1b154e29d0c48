"""Defects of issue 17, each with the test that failed before its fix."""

from __future__ import annotations

import subprocess
from pathlib import Path

from app import engine
from app.data import StudyForm


def test_dashboard_opens_the_guis_storage_by_absolute_path(tmp_path, monkeypatch) -> None:
    """A relative storage is the file in the GUI's working folder, named absolutely; the
    dashboard process never starts in (so never writes into) the install folder."""
    gui_cwd = tmp_path / "work"
    gui_cwd.mkdir()
    monkeypatch.chdir(gui_cwd)
    (gui_cwd / "radartune-studies.db").write_bytes(b"")  # an existing storage
    calls = []

    class FakePopen:
        def __init__(self, cmd, cwd=None, **_kw) -> None:
            calls.append((cmd, cwd))

        def poll(self):
            return 0

    monkeypatch.setattr(subprocess, "Popen", FakePopen)
    engine.serve_dashboard(StudyForm(storage="radartune-studies.db"))
    (cmd, cwd), = calls
    url = cmd[cmd.index("--storage") + 1]
    assert url == f"sqlite:///{gui_cwd / 'radartune-studies.db'}"
    assert Path(cwd).resolve() != engine.ROOT
    assert not Path(cwd).resolve().is_relative_to(engine.ROOT)


def test_storage_url_is_absolute_for_the_study_service(tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    assert engine.storage_url("s.db") == f"sqlite:///{tmp_path / 's.db'}"
    assert engine.storage_url("runs/j.log") == f"journal:///{tmp_path / 'runs' / 'j.log'}"
    assert engine.storage_url("postgresql://u@h:5/d") == "postgresql+psycopg2://u@h:5/d"

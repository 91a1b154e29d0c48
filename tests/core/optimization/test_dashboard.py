"""The dashboard serves a storage from a thread, also an empty SQLite file."""

from __future__ import annotations

import json
import urllib.request
from pathlib import Path

from core.optimization import StudySettings, prepare_study
from core.optimization.dashboard import serve_dashboard


def test_dashboard_lists_the_studies_of_an_sqlite_file(tmp_path: Path) -> None:
    url = f"sqlite:///{tmp_path}/d.db"
    empty = serve_dashboard(url, port=0)  # an empty file must not crash it
    try:
        with urllib.request.urlopen(
            empty.url.replace("/dashboard/", "/api/studies"), timeout=30
        ) as r:
            assert json.load(r)["study_summaries"] == []
    finally:
        empty.stop()
    prepare_study(StudySettings(model="ca", storage=url, study_name="x", objective="quadratic"))
    server = serve_dashboard(url, port=0)
    try:
        assert server.url.startswith("http://127.0.0.1:")
        with urllib.request.urlopen(
            server.url.replace("/dashboard/", "/api/studies"), timeout=30
        ) as r:
            names = [s["study_name"] for s in json.load(r)["study_summaries"]]
        assert names == ["x"]
        with urllib.request.urlopen(server.url, timeout=30) as r:
            assert r.status == 200
    finally:
        server.stop()

"""``gui --scene FILE`` with a file that is not a scene: the scene loader refuses it with one line
naming the file (the window shows it; a traceback is never the answer)."""

from __future__ import annotations

from pathlib import Path

import pytest

from app import engine
from app.models import SceneModel
from core.errors import InputError


@pytest.mark.parametrize(
    ("content", "needle"),
    [
        (bytes(range(256)), "not UTF-8"),  # UnicodeDecodeError before the fix
        (b'{"schema_version": 1, "persons": ' + b"[" * 1000 + b"]" * 1000 + b"}", "nested"),
        (b'{"schema_version": 1, "radar": "\\u0000"}', "NUL"),
        (b'{"schema_version": 1, "radar": "\\ud800"}', "surrogate"),
    ],
)
def test_scene_loader_refuses_binary_deep_nul_surrogate(tmp_path: Path, content, needle) -> None:
    path = tmp_path / "bad.json"
    path.write_bytes(content)
    model = SceneModel(engine)
    with pytest.raises(InputError, match=needle) as err:
        model.load(path)
    assert "bad.json" in str(err.value) and "\n" not in str(err.value)

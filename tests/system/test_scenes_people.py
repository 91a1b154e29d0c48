"""Every shipped scene simulates and tracks end to end: exit 0, no NaN in the text or
the JSON, one metrics entry per person, GOSPA within its bound."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from core.cli import main
from core.limits import MAX_PERSONS
from core.scene import Scene

SCENES = sorted((Path(__file__).resolve().parents[2] / "resources" / "scenes").glob("*.json"))
MULTI = {"crossing", "meet_and_part", "side_by_side", "walker_and_stander", "four_in_room"}


def test_the_hard_cases_are_shipped() -> None:
    names = {p.stem for p in SCENES}
    assert MULTI <= names
    assert Scene.from_json(SCENES[[p.stem for p in SCENES].index("four_in_room")]).n_persons == 4
    for p in SCENES:
        assert 1 <= Scene.from_json(p).n_persons <= MAX_PERSONS


@pytest.mark.slow
@pytest.mark.parametrize("path", SCENES, ids=[p.stem for p in SCENES])
def test_shipped_scene_simulated_then_tracked(path: Path, tmp_path, capsys) -> None:
    data = tmp_path / "x.npz"
    assert main(["simulate", "--scene", str(path), "--out", str(data), "--fidelity", "fast"]) == 0
    out = tmp_path / "r.json"
    assert main(["track", "--data", str(data), "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "nan" not in text.lower() and "GOSPA (c=1 m, p=2)" in text
    doc = json.loads(out.read_text())
    json.dumps(doc, allow_nan=False)
    n = Scene.from_json(path).n_persons
    assert len(doc["persons"]) == n
    # GOSPA² ≤ c²/2 · (persons present + confirmed tracks) in every frame, so its mean is bounded
    assert 0.0 <= doc["gospa"]["gospa_m"] <= math.sqrt(0.5 * (n + 200))
    assert math.isfinite(doc["loss_total"]) and doc["identity_switches"] >= 0


@pytest.mark.parametrize(("n", "needle"), [(0, "persons lists none"), (9, "persons lists 9")])
def test_scene_of_none_or_too_many_persons_is_one_line(n, needle, tmp_path, capsys) -> None:
    person = {"trajectory": {"class": "a", "seed": 1}}
    doc = {"schema_version": 1, "persons": [person] * n}
    path = tmp_path / "s.json"
    path.write_text(json.dumps(doc))
    out = tmp_path / "x.npz"
    assert main(["simulate", "--scene", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and needle in err[0] and "s.json" in err[0], err
    assert not out.exists()

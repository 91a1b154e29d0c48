"""Scene JSON (SPEC §6): loads as written, round-trips, and bad input names file/line/field."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from core.config import PAPER_RADAR
from core.errors import InputError
from core.scene import Scene

ROOT = Path(__file__).resolve().parents[3]
SPEC_EXAMPLE = {
    "schema_version": 1,
    "radar": "paper",
    "seed": 7,
    "clutter_density_per_m2": 0.02,
    "aoi": {"min_range_m": 0.5, "max_range_m": 10.0, "max_azimuth_deg": 60.0},
    "static_reflectors": [{"x_m": 2.0, "y_m": 6.0, "rcs_dbsm": 10.0}],
    "persons": [
        {"trajectory": {"class": "c", "seed": 3}},
        {"trajectory": {"waypoints": [[-2.0, 3.0, 1.2], [1.0, 6.0, 1.0], [2.5, 4.0, 0.8]]}},
        {
            "trajectory": {
                "initial_position_m": [1.0, 5.0],
                "initial_velocity_mps": [0.0, -1.2],
                "acceleration_mps2": [0.0, 0.0],
                "frames": 100,
            },
            "rcs_dbsm": -8.0,
        },
    ],
}


def write(tmp_path: Path, data, name: str = "scene.json") -> Path:
    path = tmp_path / name
    path.write_text(data if isinstance(data, str) else json.dumps(data, indent=2))
    return path


def test_spec_example_loads(tmp_path: Path) -> None:
    scene = Scene.from_json(write(tmp_path, SPEC_EXAMPLE))
    assert scene.radar == PAPER_RADAR
    assert scene.seed == 7 and scene.clutter_density_per_m2 == 0.02
    assert [p.trajectory.trajectory_class for p in scene.persons] == ["c", "drawn", "profile"]
    assert scene.persons[2].rcs_dbsm == -8.0 and scene.persons[0].rcs_dbsm is None
    assert scene.static_reflectors[0].rcs_dbsm == 10.0
    assert scene.n_frames == max(p.trajectory.n_frames for p in scene.persons)
    t, xy, v = scene.truth()
    assert xy.shape == (scene.n_frames, 3, 2)
    # the profile person ends after 100 frames: NaN afterwards
    assert np.isnan(xy[100:, 2]).all() and not np.isnan(xy[:100, 2]).any()
    np.testing.assert_allclose(t[1], 0.08)


def test_round_trip_gives_the_same_scene(tmp_path: Path) -> None:
    scene = Scene.from_json(write(tmp_path, SPEC_EXAMPLE))
    out = tmp_path / "again.json"
    scene.to_json(out)
    again = Scene.from_json(out)
    assert again.canonical_json() == scene.canonical_json()
    assert again == scene
    assert dataclasses.replace(again, seed=8) != scene
    for p, q in zip(scene.persons, again.persons):
        np.testing.assert_array_equal(p.trajectory.position_m, q.trajectory.position_m)
    assert [f.name for f in tmp_path.iterdir() if f.name.startswith(".")] == []


def test_radar_as_object_of_fields(tmp_path: Path) -> None:
    data = dict(SPEC_EXAMPLE, radar={"n_loops": 64, "frame_period_s": 0.1})
    scene = Scene.from_json(write(tmp_path, data))
    assert scene.radar.n_loops == 64
    assert scene.persons[2].trajectory.frame_period_s == 0.1


@pytest.mark.parametrize("path", sorted((ROOT / "resources" / "scenes").glob("*.json")))
def test_sample_scenes_load(path: Path) -> None:
    scene = Scene.from_json(path)
    assert scene.n_persons >= 1
    for p in scene.persons:
        assert scene.aoi.contains(p.trajectory.position_m).all()


def test_sample_scenes_are_the_promised_ones() -> None:
    names = {p.name for p in (ROOT / "resources" / "scenes").glob("*.json")}
    assert {"paper_class_c.json", "two_persons.json", "waypoints_static.json"} <= names
    assert Scene.from_json(ROOT / "resources/scenes/two_persons.json").n_persons == 2
    assert Scene.from_json(ROOT / "resources/scenes/waypoints_static.json").static_reflectors


def test_json_syntax_error_names_file_and_line(tmp_path: Path) -> None:
    path = write(tmp_path, '{\n  "schema_version": 1,\n  "seed": 7\n  "radar": "paper"\n}\n')
    with pytest.raises(InputError) as exc:
        Scene.from_json(path)
    assert exc.value.source == f"{path}:4"
    assert "\n" not in str(exc.value)


def modified(**changes):
    data = json.loads(json.dumps(SPEC_EXAMPLE))
    for dotted, value in changes.items():
        keys = dotted.split("__")
        obj = data
        for k in keys[:-1]:
            obj = obj[int(k)] if isinstance(obj, list) else obj[k]
        obj[keys[-1]] = value
    return data


@pytest.mark.parametrize(
    ("data", "expected"),
    [
        (modified(persons__0__trajectory__class="x"), "persons[0].trajectory.class"),
        (modified(clutter_density_per_m2=2.0), "clutter_density_per_m2"),
        (modified(colour="red"), "['colour']"),
        (modified(persons__1__weight_kg=80), "persons[1]: unknown key(s) ['weight_kg']"),
        (modified(aoi__max_azimuth_deg=120), "aoi.max_azimuth_deg"),
        (modified(persons__2__rcs_dbsm="loud"), "persons[2].rcs_dbsm"),
        (modified(persons__0__trajectory__speed_mps=7), "persons[0].trajectory.speed_mps"),
        (modified(schema_version=2), "schema_version"),
        (modified(static_reflectors__0__y_m=None), "static_reflectors[0].y_m"),
        (modified(radar={"n_loopz": 3}), "n_loopz"),
        (modified(radar="missing.cfg"), "missing.cfg"),
        (modified(seed=-1), "seed"),
        (modified(static_reflectors__0__x_m=0.0, static_reflectors__0__y_m=0.0), "range 0"),
        (modified(static_reflectors__0__y_m=30.0), "maximum range"),
        (modified(persons__2__trajectory__initial_position_m=[0.0, 4.0]), "within 0.0"),
        (modified(persons__0__model="stick-figure"), "persons[0].model"),
    ],
)
def test_bad_scene_names_the_field(tmp_path: Path, data, expected: str) -> None:
    path = write(tmp_path, data)
    with pytest.raises(InputError) as exc:
        Scene.from_json(path)
    assert expected in exc.value.message
    assert exc.value.source == str(path)
    assert "\n" not in str(exc.value)


def test_waypoint_outside_the_aoi(tmp_path: Path) -> None:
    data = modified()
    data["persons"][1]["trajectory"]["waypoints"][2] = [0.0, 12.0, 1.0]
    with pytest.raises(InputError, match=r"persons\[1\].trajectory.waypoints\[2\]"):
        Scene.from_json(write(tmp_path, data))


def test_radar_from_a_ti_cfg_relative_to_the_scene(tmp_path: Path) -> None:
    from core.formats.ti_cfg import read_ti_cfg

    cfg = ROOT / "resources" / "radar" / "long_range.cfg"
    (tmp_path / "radar").mkdir()
    (tmp_path / "radar" / "lr.cfg").write_text(cfg.read_text())
    (tmp_path / "scenes").mkdir()
    data = dict(SPEC_EXAMPLE, radar="../radar/lr.cfg")
    scene = Scene.from_json(write(tmp_path / "scenes", data))
    assert scene.radar == read_ti_cfg(cfg)
    assert scene.persons[0].trajectory.frame_period_s == scene.radar.frame_period_s
    assert json.loads(scene.to_json())["radar"] == "../radar/lr.cfg"


def test_malformed_ti_cfg_names_its_line(tmp_path: Path) -> None:
    lines = (ROOT / "resources" / "radar" / "paper.cfg").read_text().splitlines()
    n = next(i for i, ln in enumerate(lines) if ln.startswith("profileCfg"))
    fields = lines[n].split()
    fields[2] = "sixty"  # startFreq
    lines[n] = " ".join(fields)
    (tmp_path / "bad.cfg").write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError) as exc:
        Scene.from_json(write(tmp_path, dict(SPEC_EXAMPLE, radar="bad.cfg")))
    assert f"bad.cfg:{n + 1}" in str(exc.value)
    assert "\n" not in str(exc.value)

"""TrackerParams: defaults inside eq. (15), JSON round trip, errors that name the field."""

import json

import pytest

from core.errors import InputError
from core.tracking.params import TrackerParams
from core.tracking.space import SEARCH_SPACE


@pytest.mark.parametrize("model", ["cv", "ca"])
def test_defaults_lie_inside_the_search_space(model):
    p = TrackerParams.default(model)
    flat = p.to_dict()
    for i, v in enumerate(p.p0):
        flat[f"p0_{i}{i}"] = v
    for name, (lo, hi) in ((b.name, (b.low, b.high)) for b in SEARCH_SPACE):
        if name in flat:
            assert lo <= flat[name] <= hi, name
    assert p.state_dim == len(p.p0) == {"cv": 4, "ca": 6}[model]


def test_json_round_trip(tmp_path):
    p = TrackerParams(model="ca", p0=(1, 2, 3, 4, 5, 6), clutter_density="nonparametric")
    path = p.save(tmp_path / "p.json")
    assert TrackerParams.load(path) == p
    assert json.loads(path.read_text())["p0"] == [1, 2, 3, 4, 5, 6]
    assert list(tmp_path.iterdir()) == [path]  # no temporary file left behind


def test_missing_keys_take_defaults_and_p0_keys_are_accepted():
    p = TrackerParams.from_dict({"model": "ca", "q_coeff": 2.5})
    assert p.q_coeff == 2.5 and len(p.p0) == 6
    q = TrackerParams.from_dict({"p0_00": 1, "p0_11": 2, "p0_22": 3, "p0_33": 4})
    assert q.p0 == (1.0, 2.0, 3.0, 4.0)


@pytest.mark.parametrize(
    ("data", "needle"),
    [
        ({"q_coef": 1.0}, "q_coef"),
        ({"p_d": 1.5}, "p_d"),
        ({"r22": -0.1}, "r22"),
        ({"model": "ct"}, "model"),
        ({"p0": [1, 2, 3]}, "p0"),
        ({"clutter_density": "auto"}, "clutter_density"),
        ({"clutter_density": 0.0}, "clutter_density"),
        ({"max_tracks": 0}, "max_tracks"),
        ({"p_g": 1.0}, "p_g"),
    ],
)
def test_bad_values_name_the_field(data, needle):
    with pytest.raises(InputError, match=needle):
        TrackerParams.from_dict(data, source="params.json")


def test_bad_file_names_the_file(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"model": "cv",\n "p_d": }')
    with pytest.raises(InputError, match="bad.json.*line 2"):
        TrackerParams.load(bad)

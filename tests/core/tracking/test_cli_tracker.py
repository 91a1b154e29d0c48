"""``radartune track`` and ``radartune stability`` end to end."""

import json

from core.cli import main
from core.tracking import TrackerParams
from core.tracking.synthetic import synthetic_dataset


def test_track_prints_table_and_writes_json(tmp_path, capsys):
    data = synthetic_dataset(0, 1, n_frames=80).save(tmp_path / "d.npz")
    params = TrackerParams.default("ca").save(tmp_path / "p.json")
    out = tmp_path / "r.json"
    code = main(["track", "--data", str(data), "--params", str(params), "--out", str(out)])
    assert code == 0
    text = capsys.readouterr().out
    assert "total" in text and "OSPA" in text
    doc = json.loads(out.read_text())
    assert doc["params"]["model"] == "ca"
    assert [r["class"] for r in doc["table"]] == ["A", "B", "C", "D", "E", "total"]
    assert len(doc["trajectories"]) == 5 and doc["loss_total"] > 0


def test_track_bad_params_exit_2_and_leave_nothing(tmp_path, capsys):
    data = synthetic_dataset(0, 1, classes="a", n_frames=60).save(tmp_path / "d.npz")
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"model": "cv", "r33": "fast"}))
    out = tmp_path / "r.json"
    code = main(["track", "--data", str(data), "--params", str(bad), "--out", str(out)])
    assert code == 2
    err = capsys.readouterr().err
    assert "bad.json" in err and "r33" in err and err.count("\n") == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.json", "d.npz"]


def test_stability_quick(capsys):
    assert main(["stability", "--quick", "--frames", "100"]) == 0
    out = capsys.readouterr().out
    assert "cv: 256 corners" in out and "stability: OK" in out
    assert "4 people circling, ca: 128 corners" in out


def test_track_association_option(tmp_path, capsys):
    """--association overrides the parameters' association; the JSON records it; a bad value
    exits 2."""
    import pytest

    data = synthetic_dataset(0, 1, classes="ab", n_frames=60).save(tmp_path / "d.npz")
    for assoc in ("ipda", "jipda"):
        out = tmp_path / f"{assoc}.json"
        assert main(["track", "--data", str(data), "--association", assoc, "--out", str(out)]) == 0
        assert f"association {assoc}" in capsys.readouterr().out
        assert json.loads(out.read_text())["params"]["association"] == assoc
    with pytest.raises(SystemExit) as exc:
        main(["track", "--data", str(data), "--association", "jpda"])
    assert exc.value.code == 2
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"association": "jpda"}))
    assert main(["track", "--data", str(data), "--params", str(bad)]) == 2
    assert "association must be one of" in capsys.readouterr().err

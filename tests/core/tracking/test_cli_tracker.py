"""``radartune track`` and ``radartune stability`` end to end."""

import json

import numpy as np

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


def _synthetic_paper(monkeypatch):
    """core.pipeline.paper_dataset replaced by a small synthetic set (no simulation here)."""
    import core.pipeline

    calls = []

    def fake(seed=0, *args, person_model="point", **kwargs):
        calls.append((seed, person_model))
        return synthetic_dataset(seed, 1, n_frames=80)

    monkeypatch.setattr(core.pipeline, "paper_dataset", fake)
    return calls


def test_stability_quick(capsys, monkeypatch, tmp_path):
    calls = _synthetic_paper(monkeypatch)
    out_json = tmp_path / "s.json"
    assert main(["stability", "--quick", "--frames", "100", "--json", str(out_json)]) == 0
    out = capsys.readouterr().out
    assert "cv: 256 corners" in out and "stability: OK" in out
    assert "4 people circling, ca: 128 corners" in out
    # the consistency section: tuned parameters of both person models and the defaults
    assert calls == [(0, "point"), (0, "walking")]
    assert "best_cv.json" in out and "walking-campaign/best_ca.json" in out and "defaults" in out
    doc = json.loads(out_json.read_text())
    assert doc["ok"] is True and len(doc["sweep"]) == 10  # 8 paper, 2 room scenes
    assert [r["mode"] for r in doc["sweep"]].count("room") == 2
    cons = doc["consistency"]
    assert [(c["person_model"], c["model"]) for c in cons] == [
        ("point", "cv"), ("point", "ca"), *[("walking", "cv"), ("walking", "ca")] * 3
    ]  # fmt: skip
    # the last case tracks with R = the spread of the person's points
    from core.evaluation.consistency import measurement_spread

    spread = measurement_spread(synthetic_dataset(0, 1, n_frames=80))
    assert cons[-1]["params"] == "spread"
    np.testing.assert_allclose(cons[-1]["r_std"], spread, rtol=1e-12)
    for c in cons:
        assert list(c["rows"]) == ["a", "b", "c", "d", "e", "total"]
        total = c["rows"]["total"]
        assert 0 < total["frames_paired"] <= total["frames_present"] <= 400
        assert total["nees_position"]["n"] == total["frames_paired"]


def test_stability_consistency_only_with_plot(capsys, monkeypatch, tmp_path):
    _synthetic_paper(monkeypatch)
    png = tmp_path / "c.png"
    assert main(["stability", "--no-sweep", "--paper-seed", "3", "--plot", str(png)]) == 0
    out = capsys.readouterr().out
    assert "corners" not in out and "paper data set seed 3" in out
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert main(["stability", "--no-sweep", "--paper-seed", "-1"]) == 2
    assert "--paper-seed must be >= 0" in capsys.readouterr().err


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

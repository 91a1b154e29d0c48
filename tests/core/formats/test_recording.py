"""Industrial Visualizer replays, truth CSVs, and `radartune import` / `export` end to end:
simulate -> write -> read gives the same points; tracking an imported set with truth gives the
simulated set's result; studies refuse a set without truth."""

from __future__ import annotations

import json

import numpy as np
import pytest

from core.cli import main
from core.dataset import Dataset
from core.errors import InputError
from core.formats.recording import read_truth_csv, truth_on_frames
from core.formats.ti_replay import read as read_replay
from core.recordings import FORMATS
from tests.scenes import small_scene


def test_replay_document_is_read(tmp_path) -> None:
    """A replay as the visualizer writes it (two files of a folder, 7-column rows, extra keys)."""
    for n, frames in ((1, (1, 2)), (2, (4,))):
        doc = {
            "cfg": ["% comment", "sensorStart"],
            "demo": "3D People Tracking",
            "device": "xWR6843",
            "data": [
                {
                    "frameData": {
                        "error": 0,
                        "frameNum": fn,
                        "pointCloud": [[0.5, 2.0, 0.0, -0.3, 12.5, 3.0, 255], [1, 1, 0, 0.1]],
                        "numDetectedPoints": 2,
                        "trackData": [],
                    },
                    "timestamp": 1700000000000 + 55 * fn,
                }
                for fn in frames
            ],
        }
        (tmp_path / f"replay_{n}.json").write_text(json.dumps(doc))
    rec = read_replay(tmp_path, None)
    assert rec.counts.tolist() == [2, 2, 0, 2]  # frame 3 missing: an empty frame
    np.testing.assert_allclose(rec.cloud.x_m[:2], [0.5, 1.0])
    np.testing.assert_allclose(rec.cloud.snr_db[:2], [12.5, 0.0])
    assert "1 dropped" in rec.notes[0]
    assert any("cfg was not usable" in n for n in rec.notes)  # no profileCfg: paper radar


@pytest.mark.parametrize(
    ("doc", "message"),
    [
        ([], "must hold a JSON object"),
        ({"data": 3}, "'data' must be a list"),
        ({"data": [{"frameData": {"frameNum": -1}}]}, r"data\[0\].frameData.frameNum"),
        (
            {"data": [{"frameData": {"frameNum": 1, "pointCloud": [[1, 2]]}}]},
            r"pointCloud\[0\] must be 4 to 7 numbers",
        ),
        (
            {"data": [{"frameData": {"frameNum": 1, "pointCloud": [], "numDetectedPoints": 3}}]},
            "numDetectedPoints must be an integer in",
        ),
    ],
)
def test_bad_replay_is_one_line(tmp_path, doc, message) -> None:
    path = tmp_path / "replay_1.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(InputError, match=message):
        read_replay(path, None)


def test_truth_csv_errors_name_line_and_field(tmp_path) -> None:
    p = tmp_path / "t.csv"
    for text, message in (
        ("t,person,x,y\n", r"t.csv:1: the first line must name the columns"),
        ("time_s,person,x_m,y_m\n0,0,1\n", r"t.csv:2: expected 4 fields"),
        ("time_s,person,x_m,y_m\n0,0,1,2\n0.1,0,abc,2\n", r"t.csv:3: x_m must be a number"),
        ("time_s,person,x_m,y_m\n0,1.5,1,2\n", r"t.csv:2: person must be an integer"),
        ("time_s,person,x_m,y_m\n-1,0,1,2\n", r"t.csv:2: time_s must be >= 0"),
        ("time_s,person,x_m,y_m\n0,0,nan,2\n", r"t.csv:2: x_m must be finite"),
        ("", r"no header line"),
    ):
        p.write_text(text)
        with pytest.raises(InputError, match=message):
            read_truth_csv(p)


def test_truth_is_interpolated_on_frames_and_absent_outside() -> None:
    truth = np.array(
        [(0.0, 0, 0.0, 1.0), (1.0, 0, 1.0, 1.0), (0.5, 1, 2.0, 2.0), (0.7, 1, 2.0, 2.2)],
        dtype=[("time_s", "f8"), ("person", "i4"), ("x_m", "f8"), ("y_m", "f8")],
    )
    xy, v = truth_on_frames(truth, np.array([0.0, 0.25, 0.6, 1.2]), 0.1)
    np.testing.assert_allclose(xy[:3, 0, 0], [0.0, 0.25, 0.6])
    assert np.isnan(xy[3, 0]).all()  # after the last sample by more than half a period
    np.testing.assert_allclose(v[1, 0], [1.0, 0.0])
    assert np.isnan(xy[:2, 1]).all() and np.allclose(xy[2, 1], [2.0, 2.1])


def run_cli(*argv: str) -> int:
    return main([str(a) for a in argv])


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    folder = tmp_path_factory.mktemp("export")
    doc = small_scene(frames=15)
    doc["clutter_density_per_m2"] = 0.05
    scene = folder / "scene.json"
    scene.write_text(json.dumps(doc))
    sim = folder / "sim.npz"
    assert run_cli("simulate", "--scene", scene, "--out", sim, "--fidelity", "fast") == 0
    ds = Dataset.load(sim)
    truth = folder / "truth.csv"
    rows = [
        f"{float(t)!r},0,{float(xy[0, 0])!r},{float(xy[0, 1])!r}"
        for t, xy in zip(ds.truth_t_s, ds.truth_xy_m)
    ]
    truth.write_text("time_s,person,x_m,y_m\n" + "\n".join(rows) + "\n")
    return folder, scene, ds, truth


@pytest.mark.parametrize(("fmt", "variant"), [("uart", "sdk3"), ("uart", "sdk5"), ("replay", None)])
def test_export_import_round_trip(simulated, fmt, variant, capsys) -> None:
    folder, scene, sim, truth = simulated
    out = folder / f"{fmt}-{variant}.out"
    argv = ["export", "--scene", scene, "--format", fmt, "--out", out, "--fidelity", "fast"]
    assert run_cli(*argv, *(["--variant", variant] if variant else [])) == 0
    cfg = out.with_suffix(".cfg")
    data = folder / f"{fmt}-{variant}.npz"
    extra = ["--cfg", cfg] if fmt == "uart" else []
    assert run_cli("import", out, *extra, "--truth", truth, "--out", data) == 0
    assert "0 dropped" in capsys.readouterr().out
    ds = Dataset.load(data)
    np.testing.assert_array_equal(ds.frame, sim.frame)
    tol = 2.0**-11 * 1.01 if variant == "sdk5" else 1e-6  # float32, or half of 2^-10 m
    for f in ("x_m", "y_m", "z_m"):
        np.testing.assert_allclose(getattr(ds, f), getattr(sim, f), atol=tol)
    np.testing.assert_allclose(ds.truth_xy_m, sim.truth_xy_m, atol=1e-9)
    # the tracker sees the same scene: the same loss as the simulated set, to the precision
    res = {}
    for name, path in (("sim", folder / "sim.npz"), ("imp", data)):
        assert run_cli("track", "--data", path, "--out", folder / f"{name}.json") == 0
        res[name] = json.loads((folder / f"{name}.json").read_text())
    # float32 points: the same loss to round-off; sdk5's 1 mm / 4 mm/s steps move it slightly
    rel = 5e-2 if variant == "sdk5" else 1e-3
    assert res["imp"]["loss_total"] == pytest.approx(res["sim"]["loss_total"], rel=rel)
    assert res["imp"]["rmse_m"] == pytest.approx(res["sim"]["rmse_m"], rel=rel)


def test_import_without_truth_tracks_and_refuses_a_position_study(simulated, capsys) -> None:
    folder, scene, _, _ = simulated
    log = folder / "plain.dat"
    assert (
        run_cli("export", "--scene", scene, "--format", "uart", "--out", log, "--fidelity", "fast")
        == 0
    )
    data = folder / "plain.npz"
    assert run_cli("import", log, "--out", data) == 0
    assert "no --cfg" in capsys.readouterr().out
    assert run_cli("track", "--data", data) == 0
    assert "no ground truth" in capsys.readouterr().out
    # an objective on positions needs truth (a recording is tuned without positions: --loss
    # count, fragmentation, nis; tests/core/optimization/test_objectives_without_positions.py)
    code = run_cli(
        "tune", "--model", "cv", "--dataset", data, "--trials", "1", "--storage",
        folder / "s.db", "--loss", "paper",
    )  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1 and "no ground truth" in err
    assert "--loss nis" in err
    assert not (folder / "s.db").exists()


def test_import_refuses_unknown_and_empty_files(tmp_path, capsys) -> None:
    (tmp_path / "e.dat").write_bytes(b"")
    (tmp_path / "j.xyz").write_bytes(b"\x00" * 1000)
    # raw ADC samples carry no signature: a .bin without the UART magic word is taken as a
    # DCA1000 capture, which cannot be read without its .cfg
    (tmp_path / "j.bin").write_bytes(b"\x00" * 1000)
    for name, message in (
        ("e.dat", "empty file"),
        ("j.xyz", "format not recognised"),
        ("j.bin", "DCA1000 capture holds raw ADC samples only: give --cfg"),
    ):
        code = run_cli("import", tmp_path / name, "--out", tmp_path / "o.npz")
        err = capsys.readouterr().err
        assert code == 2 and message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "o.npz").exists()


def test_format_table_rows() -> None:
    for name, row in FORMATS.items():
        assert row.name == name and row.read is not None and row.description

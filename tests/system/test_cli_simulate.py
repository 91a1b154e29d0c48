"""``radartune simulate`` / ``radartune dataset`` end to end: output, plan, bad input."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from core.cli import main
from core.dataset import Dataset
from tests.scenes import small_scene

ROOT = Path(__file__).resolve().parents[2]

SCENE = small_scene()


def write(tmp_path: Path, data, name: str = "scene.json") -> Path:
    path = tmp_path / name
    path.write_text(data if isinstance(data, str) else json.dumps(data, indent=2))
    return path


def test_simulate_writes_a_dataset_and_prints_elapsed(tmp_path: Path) -> None:
    scene = write(tmp_path, SCENE)
    out = tmp_path / "run.npz"
    proc = subprocess.run(
        [sys.executable, "-m", "core.cli", "simulate", "--scene", str(scene), "--out", str(out)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        env={**os.environ, "RADARTUNE_CACHE": str(tmp_path / "cache")},
    )
    assert proc.returncode == 0, proc.stderr
    assert "elapsed" in proc.stdout
    ds = Dataset.load(out)
    assert ds.n_frames == 6 and ds.n_trajectories == 1
    assert list(ds.trajectory_class) == ["drawn"]
    np.testing.assert_allclose(ds.truth_xy_m[0, 0], [1.0, 5.0])
    assert json.loads(ds.scene_json)["seed"] == 2 and ds.seed == 2
    # the person is seen: a point labelled 0 near (1, 5 - 1.2 t)
    assert np.sum(ds.source == 0) >= 5
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.npz", "scene.json"]


def test_seed_option_changes_the_noise(tmp_path: Path) -> None:
    scene = write(tmp_path, SCENE)
    outs = []
    for seed in ("2", "2", "9"):
        out = tmp_path / f"s{len(outs)}.npz"
        assert main(["simulate", "--scene", str(scene), "--out", str(out), "--seed", seed]) == 0
        outs.append(Dataset.load(out))
    np.testing.assert_array_equal(outs[0].snr_db, outs[1].snr_db)
    assert outs[0].seed == 2 and outs[2].seed == 9
    assert len(outs[0].snr_db) != len(outs[2].snr_db) or not np.array_equal(
        outs[0].snr_db, outs[2].snr_db
    )


def test_explain_prints_every_stage_run_or_skipped(tmp_path: Path, capsys) -> None:
    scene = write(tmp_path, SCENE)
    assert main(["simulate", "--scene", str(scene), "--explain"]) == 0
    out = capsys.readouterr().out
    assert "skip  clutter" in out and "clutter_density_per_m2 = 0" in out
    assert "skip  elevation" in out and "planar" in out
    assert "skip  keep_rd_map" in out
    assert "run   baseband" in out and "run   cfar" in out
    assert not list(tmp_path.glob("*.npz"))


BAD = [
    ('{\n  "schema_version": 1,\n  "seed": 2\n  "persons": []\n}\n', ":4", "invalid JSON"),
    ({**SCENE, "persons": [{"trajectory": {"class": "f"}}]}, "persons[0].trajectory.class", "f"),
    ({**SCENE, "clutter_density_per_m2": -0.5}, "clutter_density_per_m2", "[0, 1]"),
    ({**SCENE, "wind_mps": 3}, "unknown key", "wind_mps"),
    ({**SCENE, "aoi": {"max_range_m": 40.0}}, "aoi.max_range_m", "maximum range"),
]


@pytest.mark.parametrize(("data", "names", "what"), BAD)
def test_bad_scene_one_line_exit_2_no_output(tmp_path: Path, capsys, data, names, what) -> None:
    scene = write(tmp_path, data)
    out = tmp_path / "out.npz"
    code = main(["simulate", "--scene", str(scene), "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and str(scene) in err
    assert names in err and what in err
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.json"]


def test_bad_scene_exit_code_through_the_real_command(tmp_path: Path) -> None:
    scene = write(tmp_path, {**SCENE, "persons": [{"trajectory": {"class": "z"}}]})
    out = tmp_path / "out.npz"
    proc = subprocess.run(
        [sys.executable, "-m", "core.cli", "simulate", "--scene", str(scene), "--out", str(out)],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "persons[0].trajectory.class" in proc.stderr
    assert not out.exists()


def test_dataset_command_writes_the_paper_subset(tmp_path: Path, monkeypatch, capsys) -> None:
    monkeypatch.setenv("RADARTUNE_CACHE", str(tmp_path / "cache"))
    out = tmp_path / "set.npz"
    code = main(["dataset", "--out", str(out), "--seed", "3", "--trajectories", "1", "--jobs", "1"])
    captured = capsys.readouterr()
    assert code == 0
    assert "elapsed" in captured.out and "dataset [" in captured.err  # progress bar
    ds = Dataset.load(out)
    assert list(ds.trajectory_class) == ["a"] and ds.seed == 3
    # the default person model is the walking body (decision scene-07)
    scene = ds.scene()
    scene = scene[0] if isinstance(scene, list) else scene
    assert scene["persons"][0]["model"] == "walking"
    assert len(list((tmp_path / "cache" / "datasets").glob("*.npz"))) == 1


@pytest.mark.parametrize(
    ("args", "field"),
    [(["--trajectories", "0"], "--trajectories"), (["--seed", "-1"], "--seed"),
     (["--jobs", "0"], "--jobs"), (["--fidelity", "perfect"], "fidelity")],
)  # fmt: skip
def test_dataset_bad_options(tmp_path: Path, capsys, args, field) -> None:
    out = tmp_path / "set.npz"
    assert main(["dataset", "--out", str(out), *args]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and field in err
    assert not out.exists()

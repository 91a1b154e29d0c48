"""``radartune simulate --cfg`` / ``--chain``: TI's detection chains from the command line."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from core.cli import main
from core.dataset import Dataset
from tests.scenes import small_scene

ROOT = Path(__file__).resolve().parents[2]
RADAR = ROOT / "resources" / "radar"


def _scene(tmp_path: Path) -> Path:
    data = small_scene(velocity_mps=(0.0, -0.8))
    data["aoi"] = {"max_range_m": 7.5}
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(data))
    return path


def test_simulate_with_a_people_counting_cfg(tmp_path: Path, capsys) -> None:
    out = tmp_path / "pc.npz"
    cfg = RADAR / "people_counting_isk_static.cfg"
    assert (
        main(["simulate", "--scene", str(_scene(tmp_path)), "--cfg", str(cfg), "--out", str(out)])
        == 0
    )
    err = capsys.readouterr().err
    assert "chain people-counting" in err and "antPhaseRot (line 26)" in err
    ds = Dataset.load(out)
    # the radar of the cfg: 55 ms frames sample the trajectory
    assert json.loads(ds.radar_json)["frame_period_s"] == pytest.approx(0.055)
    assert np.sum(ds.source == 0) >= 6  # the walker is seen in every frame


@pytest.mark.parametrize(
    ("argv_tail", "expected"),
    [
        (["--chain", "pplcount"], "--chain must be one of ['paper', 'oob', 'people-counting']"),
        (["--chain", "oob", "--cfg", str(RADAR / "oob_isk.cfg")], "give --cfg or --chain"),
    ],
)
def test_bad_chain_options_one_line_exit_2(tmp_path: Path, capsys, argv_tail, expected) -> None:
    argv = ["simulate", "--scene", str(_scene(tmp_path)), "--out", str(tmp_path / "x.npz")]
    assert main(argv + argv_tail) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and expected in err
    assert not (tmp_path / "x.npz").exists()


def test_bad_chain_line_in_cfg_one_line_exit_2(tmp_path: Path, capsys) -> None:
    text = (RADAR / "people_counting_isk.cfg").read_text()
    bad = tmp_path / "bad.cfg"
    bad.write_text(
        text.replace(
            "staticRACfarCfg -1 6 2 2 2 8 8 6 4 8.00", "staticRACfarCfg -1 6 2 2 2 8 8 6 4 8.0q"
        )
    )
    argv = [
        "simulate",
        "--scene",
        str(_scene(tmp_path)),
        "--cfg",
        str(bad),
        "--out",
        str(tmp_path / "x.npz"),
    ]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "bad.cfg:20" in err and "staticRACfarCfg field 10 'rangeThre'" in err
    assert not (tmp_path / "x.npz").exists()

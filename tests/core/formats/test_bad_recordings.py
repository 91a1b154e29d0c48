"""Bad recordings found by the seeded campaign of bad inputs: each is one line (or a note), exit
code 2 where the input cannot be read, never a traceback or a raw Python warning."""

from __future__ import annotations

import dataclasses
import json
import re
import warnings
from pathlib import Path

import numpy as np
import pytest

from core.cli import main
from core.dataset import Dataset
from core.pipeline.capture import write_capture
from core.scene import Scene
from tests.scenes import small_scene


@pytest.mark.parametrize(
    ("frame_num", "point", "message"),
    [
        (99999999999999999999, [1, 1, 0, 0], r"frameNum must be an integer in \[0, 2\^32\)"),
        (1, [10**400, 1, 0, 0], r"pointCloud\[0\] holds a number beyond the float range"),
    ],
)
def test_replay_with_huge_integers(tmp_path: Path, capsys, frame_num, point, message) -> None:
    f = tmp_path / "replay_1.json"
    f.write_text(
        json.dumps({"data": [{"frameData": {"frameNum": frame_num, "pointCloud": [point]}}]})
    )
    out = tmp_path / "d.npz"
    assert main(["import", str(f), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "replay_1.json" in err

    assert re.search(message, err) and not out.exists()
    # 99999999999999999999 as a coordinate is a (far) number, read as such
    f.write_text(
        json.dumps(
            {
                "data": [
                    {"frameData": {"frameNum": 1, "pointCloud": [[99999999999999999999, 1, 0, 0]]}}
                ]
            }
        )
    )
    assert main(["import", str(f), "--out", str(out)]) == 0
    assert Dataset.load(out).x_m[0] == pytest.approx(1e20)


@pytest.mark.parametrize("radar_json", ["-1", "null", "[]", '"x"'])
def test_data_set_whose_radar_json_is_not_an_object(tmp_path: Path, capsys, radar_json) -> None:
    ds = Dataset.from_frames(
        clouds=[],
        trajectory=np.zeros(0, dtype=np.int32),
        truth_t_s=np.zeros(0),
        truth_xy_m=np.zeros((0, 0, 2)),
        truth_v_mps=np.zeros((0, 0, 2)),
        trajectory_class=[],
        scene_json="{}",
        radar_json="{}",
    )
    bad = dataclasses.replace(ds, radar_json=radar_json)
    bad.save(tmp_path / "d.npz")
    assert main(["track", "--data", str(tmp_path / "d.npz")]) == 2
    err = capsys.readouterr().err.strip()
    assert "d.npz: radar_json must be a JSON object" in err and len(err.splitlines()) == 1


@pytest.fixture(scope="module")
def capture(tmp_path_factory) -> tuple[Path, Path]:
    folder = tmp_path_factory.mktemp("cap")
    b, c = write_capture(Scene.from_dict(small_scene(frames=3)), folder / "cap.bin")
    return b, c


def test_saturated_capture_is_a_note_not_a_crash(tmp_path: Path, capsys, capture) -> None:
    """Every word 0x7fff or 0x8000: the noise estimate is 0 and the SNR infinite; those points
    are dropped and the note names the saturation (100 % of the words)."""
    b, c = capture
    n = b.stat().st_size // 2
    sat = np.where(np.arange(n) % 2 == 0, 32767, -32768).astype("<i2")
    (tmp_path / "sat.bin").write_bytes(sat.tobytes())
    out = tmp_path / "d.npz"
    code = main(["import", str(tmp_path / "sat.bin"), "--cfg", str(c), "--out", str(out)])
    assert code == 0
    text = capsys.readouterr().out
    assert "100.0% of the capture's words are at full scale" in text
    assert np.all(np.isfinite(Dataset.load(out).snr_db))


def test_partial_capture_frame_note_printed_once(tmp_path: Path, capsys, capture) -> None:
    b, c = capture
    data = b.read_bytes()
    chirp = 4096  # 4 RX x 256 complex samples x 2 bytes
    (tmp_path / "part.bin").write_bytes(data[: len(data) - chirp])
    out = tmp_path / "d.npz"
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a raw Python warning fails the test
        code = main(["import", str(tmp_path / "part.bin"), "--cfg", str(c), "--out", str(out)])
    assert code == 0
    cap = capsys.readouterr()
    assert (cap.out + cap.err).count("partial frame") == 1
    assert Dataset.load(out).n_frames == 2

"""ROS ``rostopic echo`` point clouds: parsing, axes, frames and one-line errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from core.benchmarks.clouds import RADHAR_WALK, real_data_dir
from core.errors import InputError
from core.formats.ros_pointcloud import read_ros_pointcloud

REAL = real_data_dir() / RADHAR_WALK


def _block(pid: int, x: float, y: float, v: float = 0.0, secs: int = 10, nsecs: int = 0) -> str:
    return (
        f"header: \n  seq: {pid}\n  stamp: \n    secs: {secs}\n    nsecs: {nsecs}\n"
        f'  frame_id: "ti_mmwave"\npoint_id: {pid}\nx: {x}\ny: {y}\nz: 0.0\n'
        f"range: {np.hypot(x, y)}\nvelocity: {v}\ndoppler_bin: 8\nbearing: 0.0\n"
        "intensity: 30.0\n---\n"
    )


def test_frames_axes_and_stamps(tmp_path: Path) -> None:
    f = tmp_path / "walk.txt"
    text = _block(0, 2.0, 0.5) + _block(1, 2.1, -0.5, 0.6) + _block(0, 1.0, 0.0, nsecs=500_000_000)
    f.write_text(text)
    pc = read_ros_pointcloud(f)
    np.testing.assert_array_equal(pc.frame, [0, 0, 1])
    # ROS x forward, y left -> RadarTune y forward, x right
    np.testing.assert_allclose(pc.y_m, [2.0, 2.1, 1.0])
    np.testing.assert_allclose(pc.x_m, [-0.5, 0.5, 0.0])
    np.testing.assert_allclose(pc.radial_velocity_mps, [0.0, 0.6, 0.0])
    np.testing.assert_allclose(pc.t_s, [10.0, 10.5])
    np.testing.assert_array_equal(pc.frame_offsets, [0, 2, 3])


@pytest.mark.parametrize(
    ("text", "line", "message"),
    [
        (_block(0, 1, 1).replace("x: 1\n", "x: one\n"), 8, "x must be a number"),
        (_block(0, 1, 1).replace("x: 1\n", "x: nan\n"), 8, "x must be finite"),
        (_block(0, 1, 1).replace("velocity: 0.0\n", ""), 15, "without field(s) ['velocity']"),
        (_block(0, 1, 1).replace("bearing", "colour"), 14, "unknown field 'colour'"),
        (_block(0, 1, 1).replace("  seq", "  sequence"), 2, "unknown header field"),
        (_block(0, 1, 1)[:-4], 15, "ends inside a point block"),
        (_block(1, 1, 1), 16, "point_id 1 after -1"),
        (_block(0, 1, 1) + _block(2, 1, 1) + _block(2, 1, 1), 48, "point_id 2 after 2"),
        (_block(0, 1, 1).replace("x: 1\n", "x 1\n"), 8, "expected 'key: value'"),
        (_block(0, 1, 1).replace("---\n", "") + _block(1, 1, 1), 22, "twice in one block"),
        ("", None, "no point blocks"),
    ],
)
def test_bad_input_is_one_line_with_file_and_line(
    tmp_path: Path, text: str, line: int | None, message: str
) -> None:
    f = tmp_path / "bad.txt"
    f.write_text(text)
    with pytest.raises(InputError) as err:
        read_ros_pointcloud(f)
    where = f"{f}:{line}" if line else str(f)
    assert err.value.source == where
    assert message in err.value.message
    assert "\n" not in str(err.value)


def test_not_utf8_and_missing_file(tmp_path: Path) -> None:
    f = tmp_path / "bin.txt"
    f.write_bytes(_block(0, 1, 1).encode() + b"\xff\xfe\n")
    with pytest.raises(InputError, match="not UTF-8") as err:
        read_ros_pointcloud(f)
    assert err.value.source == f"{f}:17"
    with pytest.raises(InputError, match="cannot read"):
        read_ros_pointcloud(tmp_path / "missing.txt")


@pytest.mark.skipif(not REAL.exists(), reason="shared real recordings not present")
def test_radhar_recording_decodes() -> None:
    pc = read_ros_pointcloud(REAL)
    # the file holds 13 755 point blocks in 603 frames (grep -c '^---', '^point_id: 0')
    assert len(pc.frame) == 13_755 and pc.n_frames == 603
    assert np.all(np.diff(pc.frame) >= 0)
    # ROS x (forward) became y: the person stands in front of the radar, about 1.5 m away
    assert 1.0 < np.median(pc.y_m[pc.radial_velocity_mps != 0]) < 2.0
    # the driver reports range in whole range bins (0.04358 m here); its x, y, z are rounded
    # separately, and their norm is 4-7 % below that range
    ratio = np.sqrt(pc.x_m**2 + pc.y_m**2 + pc.z_m**2) / pc.range_m
    assert 0.9 < np.median(ratio) < 1.0

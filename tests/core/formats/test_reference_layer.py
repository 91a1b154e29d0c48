"""TI's own tracks as a data set's reference layer: from UART logs (TLVs 1010/1011) and the
vendor CSV, saved and loaded with the data set (old files without it still load), validated,
and compared with estimated positions (GOSPA, count difference)."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from core.benchmarks.clouds import real_data_dir
from core.dataset import REF_FIELDS, Dataset
from core.errors import InputError
from core.evaluation.reference import compare_with_reference
from core.files import write_npz_atomic
from core.formats import ti_uart
from core.formats.recording import to_dataset
from core.formats.ti_uart_import import read as read_uart
from core.pointcloud import SOURCE_OTHER, PointCloud
from core.recordings import read_recording


def _cloud(xy: list[tuple[float, float]]) -> PointCloud:
    x = np.array([p[0] for p in xy], dtype=np.float64)
    y = np.array([p[1] for p in xy], dtype=np.float64)
    r = np.hypot(x, y)
    return PointCloud(
        range_m=r,
        azimuth_rad=np.arctan2(x, y),
        elevation_rad=np.zeros(len(x)),
        radial_velocity_mps=np.full(len(x), 0.5),
        snr_db=np.full(len(x), 12.0),
        x_m=x,
        y_m=y,
        z_m=np.zeros(len(x)),
        source=np.full(len(x), SOURCE_OTHER, dtype=np.int32),
    )


def _targets(rows: list[tuple[int, float, float, float, float]]) -> bytes:
    t = np.zeros(len(rows), ti_uart.TARGET_3D)
    for i, (tid, x, y, vx, vy) in enumerate(rows):
        t[i]["tid"] = tid
        t[i]["pos"] = (x, y, 1.0)
        t[i]["vel"] = (vx, vy, 0.0)
    return t.tobytes()


@pytest.mark.parametrize("fmt", ["sdk3", "tracking"])
def test_uart_tracks_and_target_index_become_the_reference_layer(tmp_path: Path, fmt: str) -> None:
    """Packet 1: two points, no track; packet 2: one point, track 5 and the index [5, 255] of
    packet 1's points; packet 4 (3 lost): tracks 5 and 9, an index of the wrong length."""
    packets = [
        ti_uart.encode_frame(_cloud([(1.0, 2.0), (-1.0, 3.0)]), 1, fmt=fmt),
        ti_uart.encode_frame(
            _cloud([(0.5, 2.0)]),
            2,
            fmt=fmt,
            extra_tlvs=[
                (ti_uart.TARGET_LIST_3D, _targets([(5, 1.1, 2.1, 0.1, -0.2)])),
                (ti_uart.TARGET_INDEX, bytes([5, 255])),
            ],
        ),
        ti_uart.encode_frame(
            _cloud([(0.5, 2.0)]),
            4,
            fmt=fmt,
            extra_tlvs=[
                (ti_uart.TARGET_LIST_3D, _targets([(5, 1.2, 2.2, 0, 0), (9, -2.0, 4.0, 0, 0)])),
                (ti_uart.TARGET_INDEX, bytes([5, 5, 5])),
            ],
        ),
    ]
    log = tmp_path / "log.dat"
    log.write_bytes(b"".join(packets))
    rec = read_uart(log, None)
    ds = to_dataset(rec, source_name=str(log))
    assert ds.n_frames == 4  # frame 3 filled
    assert ds.ref_frame.tolist() == [1, 3, 3]
    assert ds.ref_track_id.tolist() == [5, 5, 9]
    np.testing.assert_allclose(ds.ref_x_m, [1.1, 1.2, -2.0], rtol=1e-6)
    np.testing.assert_allclose(ds.ref_vy_mps, [-0.2, 0, 0], atol=1e-7)
    np.testing.assert_allclose(ds.ref_z_m, 1.0)
    assert ds.ref_point_track.tolist() == [5, -1, -1, -1]
    assert not any("targets" in n for n in rec.notes if n.startswith("auxiliary"))
    # saved and loaded whole
    ds.save(tmp_path / "ds.npz")
    back = Dataset.load(tmp_path / "ds.npz")
    for name in (*REF_FIELDS, "ref_point_track"):
        np.testing.assert_array_equal(getattr(back, name), getattr(ds, name))


def _small_dataset() -> Dataset:
    return Dataset.from_frames(
        clouds=[_cloud([(1.0, 2.0)]), _cloud([]), _cloud([(0.0, 3.0)])],
        trajectory=np.zeros(3, dtype=np.int32),
        truth_t_s=np.arange(3) * 0.1,
        truth_xy_m=np.zeros((3, 0, 2)),
        truth_v_mps=np.zeros((3, 0, 2)),
        trajectory_class=["real"],
        scene_json="{}",
        radar_json="{}",
    )


def test_old_data_sets_load_and_the_layer_is_validated(tmp_path: Path) -> None:
    ds = _small_dataset()
    assert not ds.has_reference and len(ds.ref_point_track) == 0 and len(ds.people_count) == 0
    ds.save(tmp_path / "old.npz")  # no ref arrays written when empty: as an old file
    with np.load(tmp_path / "old.npz") as z:
        assert "ref_frame" not in z.files
    assert not Dataset.load(tmp_path / "old.npz").has_reference
    ref = {
        "ref_frame": np.array([0, 2]),
        "ref_track_id": np.array([1, 1]),
        **{k: np.zeros(2) for k in ("ref_x_m", "ref_y_m", "ref_z_m", "ref_vx_mps", "ref_vy_mps")},
    }
    ok = dataclasses.replace(ds, **ref)
    assert ok.has_reference
    with pytest.raises(ValueError, match="ref_frame must be sorted"):
        dataclasses.replace(ds, **{**ref, "ref_frame": np.array([2, 0])})
    with pytest.raises(ValueError, match="ref_frame must index the 3 frames"):
        dataclasses.replace(ds, **{**ref, "ref_frame": np.array([0, 3])})
    with pytest.raises(ValueError, match="ref_y_m must have shape"):
        dataclasses.replace(ds, **{**ref, "ref_y_m": np.zeros(3)})
    with pytest.raises(ValueError, match="ref_x_m must be finite"):
        dataclasses.replace(ds, **{**ref, "ref_x_m": np.array([0.0, np.inf])})
    with pytest.raises(ValueError, match="ref_point_track must have shape"):
        dataclasses.replace(ds, ref_point_track=np.zeros(5, dtype=np.int64))
    # a file with half a reference layer is one line naming it
    ok.save(tmp_path / "ok.npz")
    with np.load(tmp_path / "ok.npz") as z:
        arrays = {k: z[k] for k in z.files if k != "ref_vy_mps"}
    write_npz_atomic(tmp_path / "half.npz", arrays)
    with pytest.raises(InputError, match=r"half.npz: the reference layer is incomplete"):
        Dataset.load(tmp_path / "half.npz")


def test_gospa_and_count_against_the_reference() -> None:
    """Frame 0: reference (0, 2), estimate 0.3 m off: GOSPA 0.3; frame 1: no reference, one
    estimate: (c²/2)^(1/2) = 0.7071; frame 2: reference, no estimate: the same."""
    ds = dataclasses.replace(
        _small_dataset(),
        ref_frame=np.array([0, 2]),
        ref_track_id=np.array([1, 1]),
        ref_x_m=np.array([0.0, 1.0]),
        ref_y_m=np.array([2.0, 3.0]),
        ref_z_m=np.zeros(2),
        ref_vx_mps=np.zeros(2),
        ref_vy_mps=np.zeros(2),
    )
    cmp = compare_with_reference(
        ds, np.array([0, 1, 1]), np.array([[0.3, 2.0], [5.0, 5.0], [np.nan, 0.0]])
    )
    np.testing.assert_allclose(cmp.gospa_m, [0.3, math.sqrt(0.5), math.sqrt(0.5)])
    assert cmp.count_difference.tolist() == [0, 1, -1]
    assert cmp.count_agreement == pytest.approx(1 / 3)
    with pytest.raises(ValueError, match="no reference layer"):
        compare_with_reference(_small_dataset(), np.zeros(0), np.zeros((0, 2)))


PC3 = real_data_dir() / "pc3_iwr6843" / "pc3_2023-06-21-12-27-01.csv"


@pytest.mark.skipif(not PC3.is_file(), reason="../shared/real/pc3_iwr6843 absent")
def test_real_vendor_csv_reference_layer_agrees_with_itself() -> None:
    """The 2023 file's 125 TI track rows are the layer; the layer compared with itself has
    GOSPA 0 and count difference 0 in every frame; points labelled by a track lie near it."""
    ds = to_dataset(read_recording(PC3, fmt=None, cfg=None), source_name=str(PC3))
    assert len(ds.ref_frame) == 125 and set(np.unique(ds.ref_track_id)) == {0, 1}
    cmp = compare_with_reference(ds, ds.ref_frame, np.column_stack((ds.ref_x_m, ds.ref_y_m)))
    assert np.all(cmp.gospa_m == 0) and np.all(cmp.count_difference == 0)
    labelled = np.flatnonzero(ds.ref_point_track >= 0)
    assert len(labelled) > 500
    # a point of frame f labelled by the index sent with frame f+1: near that track there
    dist = []
    for i in labelled:
        row = np.flatnonzero(
            (ds.ref_frame == ds.frame[i] + 1) & (ds.ref_track_id == ds.ref_point_track[i])
        )
        if len(row):
            dist.append(np.hypot(ds.x_m[i] - ds.ref_x_m[row[0]], ds.y_m[i] - ds.ref_y_m[row[0]]))
    assert len(dist) > 500 and np.median(dist) < 0.5  # measured: 0.24 m (595 points)

"""Cloud statistics on constructed clouds whose figures follow by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

from core.evaluation.clouds import (
    PersonPoints,
    cloud_statistics,
    dataset_person_points,
    rule_person_points,
)


def _points(owner, x, y, v, ref, snr=None, truth=True):
    return PersonPoints(
        owner=np.asarray(owner),
        x_m=np.asarray(x, dtype=float),
        y_m=np.asarray(y, dtype=float),
        radial_velocity_mps=np.asarray(v, dtype=float),
        snr_db=None if snr is None else np.asarray(snr, dtype=float),
        reference_xy_m=np.asarray(ref, dtype=float),
        reference_is_truth=truth,
    )


def test_counts_spread_and_doppler_of_two_frames() -> None:
    # person-frame 0 at (0, 2): points at x = ±0.1 around 0.05 offset; frame 1 at (0, 2): none;
    # person-frame 2 at (0, 4) (other band): three points.
    owner = [0, 0, 2, 2, 2]
    x = [0.15, -0.05, 0.0, 0.3, -0.3]
    y = [2.0, 2.0, 4.1, 4.1, 4.1]
    v = [1.0, -1.0, 0.0, 0.0, 3.0]
    snr = [10.0, 20.0, 5.0, 6.0, 7.0]
    ref = [[0.0, 2.0], [0.0, 2.0], [0.0, 4.0]]
    near, far, empty = cloud_statistics(_points(owner, x, y, v, ref, snr))
    assert near.person_frames == 2 and far.person_frames == 1 and empty.person_frames == 0
    assert near.points_mean == 1.0 and near.points_median == 1.0 and near.empty_fraction == 0.5
    # frame 0: deviations ±0.1 about the centroid 0.05, 1 degree of freedom: s² = 0.02
    assert near.spread_x_m == pytest.approx(math.sqrt(0.02))
    assert near.spread_y_m == 0.0
    # Doppler: ±1 about 0: s² = 2 / 1
    assert near.doppler_std_mps == pytest.approx(math.sqrt(2.0))
    # about the truth: x errors 0.15, -0.05 -> RMS sqrt((0.0225 + 0.0025) / 2)
    assert near.rms_x_ref_m == pytest.approx(math.sqrt(0.0125))
    assert near.centroid_error_m == pytest.approx(0.05)
    assert near.snr_median_db == 15.0
    # far: x deviations 0, 0.3, -0.3 about 0: s² = 0.18 / 2; v: mean 1, dev -1, -1, 2: 6 / 2
    assert far.spread_x_m == pytest.approx(math.sqrt(0.09))
    assert far.doppler_std_mps == pytest.approx(math.sqrt(3.0))
    assert far.rms_y_ref_m == pytest.approx(0.1)
    assert far.centroid_error_m == pytest.approx(0.1)
    assert math.isnan(empty.points_mean) and math.isnan(empty.spread_x_m)
    assert empty.to_dict()["spread_x_m"] is None


def test_single_point_frames_have_no_spread() -> None:
    (band, *_) = cloud_statistics(_points([0, 1], [0.0, 1.0], [2.0, 2.0], [0, 0], [[0, 2], [1, 2]]))
    assert band.points_mean == 1.0
    assert math.isnan(band.spread_x_m) and math.isnan(band.doppler_std_mps)
    assert math.isnan(band.snr_median_db)


def test_pooled_spread_matches_the_gaussian_sigma() -> None:
    rng = np.random.default_rng(1)
    n_frames, per = 400, 6
    owner = np.repeat(np.arange(n_frames), per)
    centre = rng.uniform(-1, 1, n_frames)  # moving centroids do not enter the pooled spread
    x = centre[owner] + rng.normal(0, 0.15, owner.size)
    ref = np.column_stack((centre, np.full(n_frames, 4.5)))
    (_, band, _) = cloud_statistics(_points(owner, x, ref[owner, 1], np.zeros(owner.size), ref))
    assert band.spread_x_m == pytest.approx(0.15, rel=0.05)
    assert band.rms_x_ref_m == pytest.approx(0.15, rel=0.05)
    assert band.points_mean == per


def test_bad_shapes_are_rejected() -> None:
    with pytest.raises(ValueError, match="owner"):
        _points([0, 3], [0, 0], [0, 0], [0, 0], [[0, 2]])
    with pytest.raises(ValueError, match="shape"):
        _points([0], [0, 0], [0], [0], [[0, 2]])


def test_rule_takes_points_near_the_moving_median() -> None:
    # frame 0: two moving points at (0, 2) and (0.2, 2), a static one at (0.5, 2.5) (near), a
    # static one at (3, 3) (far); frame 1: no moving point, keeps frame 0's reference
    frame = [0, 0, 0, 0, 1, 1]
    x = [0.0, 0.2, 0.5, 3.0, 0.1, 2.0]
    y = [2.0, 2.0, 2.5, 3.0, 2.0, 2.0]
    v = [0.5, -0.5, 0.0, 0.0, 0.0, 0.0]
    pts = rule_person_points(frame, x, y, v, 2)
    np.testing.assert_allclose(pts.reference_xy_m, [[0.1, 2.0], [0.1, 2.0]])
    np.testing.assert_array_equal(pts.owner, [0, 0, 0, 1])
    assert not pts.reference_is_truth
    with pytest.raises(ValueError, match="moving"):
        rule_person_points([0], [0.0], [1.0], [0.0], 1)


def test_dataset_points_follow_the_labels() -> None:
    from core.dataset import Dataset

    # two frames, two persons; person 1 absent in frame 1; a clutter point (-1) left out
    truth = np.array([[[0.0, 2.0], [1.0, 5.0]], [[0.0, 2.1], [np.nan, np.nan]]])
    src = np.array([0, 1, -1, 0])
    n = len(src)
    ds = Dataset(
        frame=np.array([0, 0, 0, 1]),
        range_m=np.ones(n),
        azimuth_rad=np.zeros(n),
        elevation_rad=np.zeros(n),
        radial_velocity_mps=np.zeros(n),
        snr_db=np.array([20.0, 15.0, 9.0, 21.0]),
        x_m=np.array([0.0, 1.0, 9.0, 0.0]),
        y_m=np.array([2.0, 5.0, 9.0, 2.1]),
        z_m=np.zeros(n),
        source=src,
        trajectory=np.zeros(2, dtype=int),
        truth_t_s=np.array([0.0, 0.1]),
        truth_xy_m=truth,
        truth_v_mps=np.where(np.isnan(truth), np.nan, 0.0),
        trajectory_class=np.array(["a"]),
        scene_json="",
        radar_json="",
    )
    pts = dataset_person_points(ds)
    assert pts.n_person_frames == 3
    np.testing.assert_array_equal(pts.owner, [0, 1, 2])
    np.testing.assert_allclose(pts.reference_xy_m, [[0.0, 2.0], [1.0, 5.0], [0.0, 2.1]])
    near, mid, _ = cloud_statistics(pts)
    assert near.person_frames == 2 and mid.person_frames == 1
    assert near.rms_x_ref_m == 0.0 and near.snr_median_db == 20.5

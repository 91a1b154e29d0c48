"""The paper data set with the extended person model: same trajectories, only the model changes."""

from __future__ import annotations

import numpy as np
import pytest

from core.dataset import Dataset
from core.errors import InputError
from core.evaluation import person_point_spread
from core.optimization.data import resolve_dataset
from core.pipeline import dataset_key
from core.scene.scene import paper_scenes


def test_extended_paper_scenes_change_only_the_person_model() -> None:
    point = paper_scenes(0, 5)
    ext = paper_scenes(0, 5, person_model="extended")
    assert [p.persons[0].model for p in point] == ["point"] * 5
    assert [p.persons[0].model for p in ext] == ["extended"] * 5
    for a, b in zip(point, ext, strict=True):
        assert a.seed == b.seed
        assert a.clutter_density_per_m2 == b.clutter_density_per_m2
        assert a.persons[0].spec == b.persons[0].spec
        np.testing.assert_array_equal(
            a.persons[0].trajectory.position_m, b.persons[0].trajectory.position_m
        )
    # the cache key must tell the two sets apart, or one would be served for the other
    seeds = [s.seed for s in point]
    assert dataset_key(point, fidelity="exact", seed=0, seeds=seeds) != dataset_key(
        ext, fidelity="exact", seed=0, seeds=seeds
    )


def test_walking_and_blob_paper_scenes_keep_the_trajectories() -> None:
    point = paper_scenes(0, 5)
    for model in ("blob", "walking"):
        other = paper_scenes(0, 5, person_model=model)
        assert [p.persons[0].kind for p in other] == [model] * 5
        for a, b in zip(point, other, strict=True):
            assert a.seed == b.seed
            np.testing.assert_array_equal(
                a.persons[0].trajectory.position_m, b.persons[0].trajectory.position_m
            )


def test_bad_person_model_is_rejected() -> None:
    with pytest.raises(InputError, match="person_model"):
        paper_scenes(0, 5, person_model="stick-figure")
    with pytest.raises(InputError, match="person model"):
        resolve_dataset("paper:0:stick-figure")
    with pytest.raises(InputError, match="paper:SEED"):
        resolve_dataset("paper:0:extended:x")
    with pytest.raises(InputError, match="--person-model"):
        resolve_dataset("paper:0:extended", person_model="point")


def _dataset(points_xy: np.ndarray, vr: np.ndarray, source: np.ndarray) -> Dataset:
    n = len(source)
    frame = np.zeros(n, dtype=np.int64)
    r = np.hypot(points_xy[:, 0], points_xy[:, 1])
    return Dataset(
        frame=frame,
        range_m=r,
        azimuth_rad=np.arctan2(points_xy[:, 0], points_xy[:, 1]),
        elevation_rad=np.zeros(n),
        radial_velocity_mps=vr,
        snr_db=np.full(n, 20.0),
        x_m=points_xy[:, 0],
        y_m=points_xy[:, 1],
        z_m=np.zeros(n),
        source=source,
        trajectory=np.zeros(1, dtype=np.int64),
        truth_t_s=np.zeros(1),
        truth_xy_m=np.array([[[0.0, 4.0]]]),
        truth_v_mps=np.array([[[0.0, 1.0]]]),
        trajectory_class=np.array(["a"]),
        scene_json="{}",
        radar_json="{}",
    )


def test_person_point_spread_against_hand_numbers() -> None:
    # person at (0, 4) m moving +y at 1 m/s: line of sight = +y, v_r,gt = 1 m/s.
    # errors: 0.3 m in range, 0.4 m cross-range; a clutter point (source -1) is ignored.
    xy = np.array([[0.0, 4.3], [0.4, 4.0], [2.0, 2.0]])
    vr = np.array([1.5, 0.5, 0.0])
    ds = _dataset(xy, vr, np.array([0, 0, -1], dtype=np.int32))
    s = person_point_spread(ds)
    assert s.n_points == 2
    assert s.points_per_frame == 2.0
    assert s.rms_position_m == pytest.approx(np.sqrt((0.09 + 0.16) / 2))
    assert s.rms_range_m == pytest.approx(np.sqrt(0.09 / 2))
    assert s.rms_cross_range_m == pytest.approx(np.sqrt(0.16 / 2))
    assert s.rms_radial_velocity_mps == pytest.approx(0.5)
    assert s.median_position_m == pytest.approx(0.35)


def test_paper_sets_of_the_cli_default_to_the_walking_body(monkeypatch, tmp_path) -> None:
    """``paper`` / ``paper:SEED`` without a model is the walking body (the CLI default); a set
    made like a training set takes the training set's model, read from its scenes."""
    import core.pipeline
    from core.optimization.data import like_training, person_model_of
    from core.pipeline import build_dataset
    from core.scene.scene import DEFAULT_PERSON_MODEL

    asked = []
    monkeypatch.setattr(
        core.pipeline,
        "paper_dataset_file",
        lambda seed, n, *, person_model: asked.append((seed, n, person_model)) or "x.npz",
    )
    resolve_dataset(None)
    resolve_dataset("paper:7")
    resolve_dataset("paper:7", person_model="point")
    assert DEFAULT_PERSON_MODEL == "walking"
    assert asked == [(0, 35, "walking"), (7, 35, "walking"), (7, 35, "point")]
    path = str(tmp_path / "point.npz")
    build_dataset(paper_scenes(3, 1), fidelity="measurement", jobs=1, use_cache=False).save(path)
    assert person_model_of(path) == "point"
    assert like_training("paper:1000", path) == "paper:1000:point"
    assert like_training("paper:1000:walking", path) == "paper:1000:walking"
    assert like_training("other.npz", path) == "other.npz"
    assert like_training(None, path) is None

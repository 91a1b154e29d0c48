"""Each limit of core.limits: the limit itself is accepted, one step past it is refused with a
line naming the field and the limit."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from core import limits
from core.config import RadarConfig
from core.dataset import Dataset
from core.errors import InputError
from core.files import read_json, read_npz
from core.scene import Scene
from core.tracking import TrackerParams


def profile(frames: int) -> dict:
    return {
        "trajectory": {
            "initial_position_m": [1.0, 5.0],
            "initial_velocity_mps": [0.0, 0.0],
            "acceleration_mps2": [0.0, 0.0],
            "frames": frames,
        }
    }


def scene(**fields) -> Scene:
    """A scene of these fields (one standing person unless ``persons`` is given)."""
    doc = {"schema_version": 1, "clutter_density_per_m2": 0.0, "persons": [profile(2)]}
    return Scene.from_dict({**doc, **fields})


def test_persons() -> None:
    assert scene(persons=[profile(2)] * limits.MAX_PERSONS).n_persons == limits.MAX_PERSONS
    with pytest.raises(
        InputError, match=f"persons lists 9, more than the limit {limits.MAX_PERSONS}"
    ):
        scene(persons=[profile(2)] * (limits.MAX_PERSONS + 1))
    # and at least one: a scene of nobody is one line too (1–8 persons)
    with pytest.raises(
        InputError, match=f"persons lists none; a scene holds 1 to {limits.MAX_PERSONS}"
    ):
        scene(persons=[])


def test_static_reflectors() -> None:
    n = limits.MAX_STATIC_REFLECTORS
    assert len(scene(static_reflectors=[{"x_m": 1.0, "y_m": 2.0}] * n).static_reflectors) == n
    with pytest.raises(InputError, match="static_reflectors lists"):
        scene(static_reflectors=[{"x_m": 1.0, "y_m": 2.0}] * (n + 1))


def test_frames_and_person_frames() -> None:
    assert scene(persons=[profile(limits.MAX_FRAMES)]).n_frames == limits.MAX_FRAMES
    with pytest.raises(InputError, match="frames must be in"):
        scene(persons=[profile(limits.MAX_FRAMES + 1)])
    per = limits.MAX_PERSON_FRAMES // 2
    assert scene(persons=[profile(per)] * 2).n_frames == per
    with pytest.raises(InputError, match="persons x frames = 3 x"):
        scene(persons=[profile(per)] * 3)


def test_class_trajectory_frames_checked_before_building() -> None:
    fast_frames = {"n_loops": 1, "frame_period_s": 0.001}  # 600 s would be 600 000 frames
    with pytest.raises(InputError, match="would last 600000 frames"):
        scene(radar=fast_frames, persons=[{"trajectory": {"class": "c", "duration_s": 600.0}}])


def radar_4ch(n_samples: int, **kw) -> RadarConfig:
    return RadarConfig(
        n_tx=1,
        n_rx=4,
        tx_order=(0,),
        azimuth_positions=(0, 1, 2, 3),
        elevation_positions=(0, 0, 0, 0),
        n_loops=256,
        n_samples=n_samples,
        **kw,
    )


def test_radar_cube() -> None:
    assert radar_4ch(1024).n_virtual * 256 * 1024 == limits.MAX_CUBE_SAMPLES
    with pytest.raises(InputError, match=f"exceeds the limit {limits.MAX_CUBE_SAMPLES}"):
        radar_4ch(2048)


def test_simulated_samples() -> None:
    radar = {
        "n_tx": 1,
        "n_rx": 4,
        "tx_order": [0],
        "azimuth_positions": [0, 1, 2, 3],
        "elevation_positions": [0, 0, 0, 0],
        "n_loops": 256,
        "n_samples": 1024,
    }
    frames = limits.MAX_SIMULATED_SAMPLES // limits.MAX_CUBE_SAMPLES
    assert scene(radar=radar, persons=[profile(frames)]).n_frames == frames
    with pytest.raises(InputError, match="frames x radar cube"):
        scene(radar=radar, persons=[profile(frames + 1)])


def test_tracker_params() -> None:
    lo, hi = limits.VARIANCE_RANGE
    assert (
        TrackerParams(max_tracks=limits.MAX_TRACKS, r22=hi, r11=lo).max_tracks == limits.MAX_TRACKS
    )
    for bad in ({"max_tracks": limits.MAX_TRACKS + 1}, {"r22": hi * 1.01}, {"q_coeff": lo / 2}):
        with pytest.raises(InputError, match=f"{next(iter(bad))} must be in"):
            TrackerParams(**bad)
    with pytest.raises(InputError, match=r"p0\[1\] must be in"):
        TrackerParams(p0=(1.0, hi * 2, 1.0, 1.0))
    c_lo, c_hi = limits.CLUTTER_DENSITY_RANGE
    assert TrackerParams(clutter_density=c_hi).clutter_density == c_hi
    with pytest.raises(InputError, match="clutter_density must be in"):
        TrackerParams(clutter_density=c_hi * 2)


def test_input_bytes(tmp_path: Path) -> None:
    path = tmp_path / "sparse.json"
    with open(path, "wb") as fh:  # a sparse file: no disk used, never read
        fh.truncate(limits.MAX_INPUT_BYTES + 1)
    with pytest.raises(InputError, match=f"more than the limit {limits.MAX_INPUT_BYTES}"):
        read_json(path)
    os.remove(path)


def test_npz_members_and_elements(tmp_path: Path) -> None:
    np.savez(
        tmp_path / "many.npz", **{f"a{i}": np.zeros(1) for i in range(limits.MAX_NPZ_MEMBERS + 1)}
    )
    with pytest.raises(InputError, match=f"more than the limit {limits.MAX_NPZ_MEMBERS}"):
        read_npz(tmp_path / "many.npz")
    np.savez(tmp_path / "two.npz", a=np.zeros(60), b=np.zeros(60))
    assert len(read_npz(tmp_path / "two.npz", max_elements=120)) == 2
    with pytest.raises(InputError, match="limited to 100 elements in all"):
        read_npz(tmp_path / "two.npz", max_elements=100)


def dataset(n_frames: int, n_persons: int = 1) -> Dataset:
    empty = np.zeros(0)
    return Dataset(
        frame=np.zeros(0, dtype=np.int32),
        **{f: empty for f in ("range_m", "azimuth_rad", "elevation_rad", "radial_velocity_mps")},
        **{f: empty for f in ("snr_db", "x_m", "y_m", "z_m")},
        source=np.zeros(0, dtype=np.int32),
        trajectory=np.zeros(n_frames, dtype=np.int32),
        truth_t_s=np.zeros(n_frames),
        truth_xy_m=np.zeros((n_frames, n_persons, 2)),
        truth_v_mps=np.zeros((n_frames, n_persons, 2)),
        trajectory_class=np.array(["a"]),
        scene_json="{}",
        radar_json="{}",
    )


def test_dataset_frames_and_persons() -> None:
    assert dataset(limits.MAX_DATASET_FRAMES).n_frames == limits.MAX_DATASET_FRAMES
    with pytest.raises(ValueError, match=f"more than the limit {limits.MAX_DATASET_FRAMES}"):
        dataset(limits.MAX_DATASET_FRAMES + 1)
    assert dataset(3, limits.MAX_PERSONS).n_persons == limits.MAX_PERSONS
    with pytest.raises(ValueError, match=f"more than the limit {limits.MAX_PERSONS}"):
        dataset(3, limits.MAX_PERSONS + 1)


def test_table_lists_every_limit() -> None:
    names = {n for n in dir(limits) if n.isupper() and n != "LIMITS"}
    assert names == set(limits.LIMITS)


def test_scatterer_frames() -> None:
    """frames x (persons' scatterers + reflectors + expected clutter) bounds a scene's work."""
    n_refl = 999
    frames = limits.MAX_SCATTERER_FRAMES // (n_refl + 1)
    refl = [{"x_m": 1.0, "y_m": 2.0}] * n_refl
    assert scene(static_reflectors=refl, persons=[profile(frames)]).n_frames == frames
    with pytest.raises(InputError, match=r"frames x scatterers = 101 x 1000"):
        scene(static_reflectors=refl, persons=[profile(frames + 1)])


def test_person_height() -> None:
    lo, hi = limits.PERSON_HEIGHT_RANGE_M
    slow = {"class": "a", "seed": 1, "speed_mps": 1.0}
    for h in (lo, hi):
        walker = {"model": "walking", "height_m": h, "trajectory": slow}
        assert scene(persons=[walker]).persons[0].height_m == h
    for h in (lo - 0.01, hi + 0.01):
        walker = {"model": "walking", "height_m": h, "trajectory": slow}
        with pytest.raises(InputError, match=rf"persons\[0\]\.height_m must be in \[{lo}, {hi}\]"):
            scene(persons=[walker])


def test_person_distance() -> None:
    """A person 1e300 m away is refused at the field (it was simulated with overflow warnings);
    at the limit it is accepted, and a walk that leaves the limit is refused at its frame."""
    far = limits.MAX_PERSON_DISTANCE_M
    p = profile(2)
    p["trajectory"]["initial_position_m"] = [far, 0.0]
    assert scene(persons=[p]).persons[0].trajectory.position_m[0, 0] == far
    p["trajectory"]["initial_position_m"] = [1e300, 5.0]
    with pytest.raises(InputError, match=r"persons\[0\]\.trajectory\.initial_position_m\[0\]"):
        scene(persons=[p])
    # 900 m/s from x = 1 m: 1 + 0.08·900·k passes 1000 m between frames 13 and 14
    p["trajectory"].update(initial_position_m=[1.0, 0.0], initial_velocity_mps=[900.0, 0.0])
    p["trajectory"]["frames"] = 20
    with pytest.raises(InputError, match=r"persons\[0\]\.trajectory is 1\.01e\+03 m from the "
                       r"radar at frame 14 \(at most 1000 m\)"):  # fmt: skip
        scene(persons=[p])

"""Numerical stability on stiff and extreme cases (SPEC §4): no NaN/Inf ever leaves the tracker
and every live covariance stays symmetric positive definite. The full corner sweep is
``radartune stability`` (run by ``make stability`` in CI); here a sample of corners."""

import math

import numpy as np
import pytest

from core.tracking.kernel import track_frames
from core.tracking.params import TrackerParams
from core.tracking.stability import (
    all_corners,
    condition_number,
    corner_params,
    stability_scene,
    sweep,
)
from core.tracking.synthetic import SyntheticScene, synthetic_dataset
from core.tracking.tracker import run_tracker


def run_checked(ds, params, period=0.08):
    out = track_frames(
        ds.measurements(),
        ds.frame_offsets,
        ds.trajectory_offsets,
        np.arange(ds.n_trajectories),
        params,
        period,
        check=True,
    )
    est_xy, has, psi, conf_xy, n_conf, n_tr, est_x, est_P, n_bad = out
    assert n_bad.sum() == 0, f"{n_bad.sum()} unhealthy track-frames"
    assert np.all(np.isfinite(est_xy[has])) and np.all(np.isfinite(est_P[has]))
    assert np.all((psi[has] >= 0) & (psi[has] <= 1))
    assert np.all(np.isnan(est_xy[~has]))
    return out


def path_dataset(p0, v, n, scene=None, seed=0, period=0.08):
    scene = scene or SyntheticScene(clutter_per_frame=0.0, frame_period_s=period)
    t = np.arange(n)[:, None] * period
    pos = np.asarray(p0, float) + t * np.asarray(v, float)
    vel = np.broadcast_to(np.asarray(v, float), pos.shape).copy()
    return synthetic_dataset(seed, scene=scene, paths=[(pos, vel)])


@pytest.fixture(scope="module")
def scene():
    return stability_scene(300)


@pytest.mark.parametrize(("model", "n"), [("cv", 96), ("ca", 64)])
def test_sample_of_search_space_corners(scene, model, n):
    rep = sweep(model, all_corners(model, n, seed=1), scene)
    assert rep.n_frames == 300 and rep.n_corners == n
    assert rep.ok, rep.failures
    assert rep.max_tracks_seen <= 20  # immortal corners stay bounded by the cap


def test_corner_enumeration():
    cv = all_corners("cv")
    assert len(cv) == 4096 and len(set(cv)) == 4096
    ca = all_corners("ca", 2000, seed=3)
    assert len(set(ca)) == 2000 and all(len(b) == 14 for b in ca)


@pytest.mark.parametrize("model", ["cv", "ca"])
def test_tiny_r_with_huge_p0(scene, model):
    n = 4 if model == "cv" else 6
    p0 = (1e4, 1e4) + (1e-3,) * (n - 2)
    p = TrackerParams(model=model, r11=1e-4, r22=1e-5, r33=1e-3, p0=p0, q_coeff=0.1)
    assert condition_number(np.diag(np.square(p0))) > 1e12
    run_checked(scene, p)


@pytest.mark.parametrize("model", ["cv", "ca"])
def test_walk_through_range_zero(model):
    # straight through the radar's position: r passes 0 (x = 0 exactly at frame 25)
    ds = path_dataset((-2.0, 0.0), (1.0, 0.0), 60)
    assert np.min(ds.range_m) < 0.05
    out = run_checked(ds, TrackerParams.default(model))
    assert out[1].sum() > 40  # tracked through
    ref = run_tracker((ds.measurements(), ds.frame_offsets), TrackerParams.default(model))
    assert np.all(np.isfinite(ref.estimate_xy[ref.has_estimate]))


def test_azimuth_near_90_degrees_and_across_180():
    p = TrackerParams()
    # along x = 5 m crossing the ±90° line (y from 1 to −1 m)
    ds = path_dataset((5.0, 1.0), (0.0, -1.0), 40)
    assert np.max(np.abs(ds.azimuth_rad)) > math.radians(89)
    run_checked(ds, p)
    # behind the radar: azimuth jumps from +180° to −180°; the wrapped innovation keeps the track
    ds = path_dataset((1.0, -3.0), (-1.0, 0.0), 40)
    out = run_checked(ds, p)
    has, xy = out[1], out[0]
    err = np.hypot(*(xy[has] - ds.truth_xy_m[has, 0]).T)
    assert has[5:].all() and err.max() < 0.5


def test_radial_speed_near_aliasing():
    # 7.2 m/s radially (v_max = 7.241 m/s): noisy measurements alias to about −7.2 m/s
    ds = path_dataset((0.0, 1.0), (0.0, 7.2), 25)
    z = ds.radial_velocity_mps
    vmax = 7.241
    aliased = (z + vmax) % (2 * vmax) - vmax
    ds = ds.__class__(
        **{**{f: getattr(ds, f) for f in ds.__slots__}, "radial_velocity_mps": aliased}
    )
    assert np.any(aliased < 0)
    run_checked(ds, TrackerParams.default("ca"))


def test_existence_exactly_zero_and_one(scene):
    # ψ⁻ = 1 always: P_te = 1 with p11 = 1 (immortal tracks, the cap keeps them bounded)
    out = run_checked(scene, TrackerParams(p_te=1.0, p11=1.0, p21=0.0))
    assert np.all(out[2][out[1]] == 1.0) and 10 < out[5].max() <= 20
    # ψ⁻ = 0 always: p11 = p21 = 0, nothing deleted
    p = TrackerParams(p11=0.0, p21=0.0, confirm_threshold=0.0, delete_threshold=0.0)
    out = run_checked(scene, p)
    assert np.all(out[2][out[1]] == 0.0)


@pytest.mark.parametrize("rho", [1e-12, 1e-6, 1e-2, 1.0, 1e3, "nonparametric"])
def test_clutter_density_extremes(scene, rho):
    run_checked(scene, TrackerParams(clutter_density=rho))


@pytest.mark.parametrize("period", [1e-4, 1e-2, 0.08, 0.5, 2.0])
@pytest.mark.parametrize("model", ["cv", "ca"])
def test_time_step_extremes(model, period):
    scene = SyntheticScene(clutter_per_frame=1.0, frame_period_s=period)
    ds = path_dataset((1.0, 3.0), (0.3, 0.2), 200, scene=scene, period=period)
    run_checked(ds, TrackerParams.default(model), period)


@pytest.mark.parametrize("model", ["cv", "ca"])
def test_10000_frames_keep_the_condition_number_bounded(model):
    n = 10_000
    dt = 0.08
    phi = 1.2 / 2.0 * dt * np.arange(n)
    pos = np.array([0.0, 5.0]) + 2.0 * np.column_stack((np.cos(phi), np.sin(phi)))
    vel = 1.2 * np.column_stack((-np.sin(phi), np.cos(phi)))
    ds = synthetic_dataset(4, paths=[(pos, vel)], scene=SyntheticScene(clutter_per_frame=0.5))
    out = run_checked(ds, TrackerParams.default(model))
    has, est_P = out[1], out[7]
    assert has.mean() > 0.95
    cond = np.array([condition_number(P) for P in est_P[has][::10]])
    assert np.all(np.isfinite(cond))
    # bounded: the last thousand frames are no worse than the second thousand, and small
    k = len(cond) // 10
    assert cond[-k:].max() <= 2 * cond[k : 2 * k].max() and cond.max() < 1e6, cond.max()


@pytest.mark.parametrize("model", ["cv", "ca"])
def test_reference_tracker_on_a_sample_of_corners(model):
    ds = stability_scene(40)
    z, f_off = ds.measurements(), ds.frame_offsets
    for bits in all_corners(model, 4, seed=7):
        res = run_tracker((z, f_off), corner_params(model, bits))
        for ft in res.frames:
            assert np.all(np.isfinite(ft.state)) and np.all((ft.psi >= 0) & (ft.psi <= 1))
            for P in ft.covariance:
                np.testing.assert_array_equal(P, P.T)
                np.linalg.cholesky(P)  # raises unless positive definite


@pytest.mark.parametrize("model", ["cv", "ca"])
def test_multi_person_scenes_sample_of_corners(model):
    """The crossing scenes (JIPDA clusters, joint events): no NaN, no non-PD covariance."""
    from core.tracking.stability import multi_person_scenes

    for name, ds in multi_person_scenes(150).items():
        rep = sweep(model, all_corners(model, 24, seed=2), ds)
        assert rep.ok, (name, rep.failures)
        assert rep.nonfinite_outputs == 0 and rep.bad_track_frames == 0


def test_room_mode_corners_stay_healthy():
    """A sample of the room mode's corners (its 12 rows with the paper's) on the four-people room
    scene: no unhealthy track, no non-finite output; the sweep notices a corrupted record."""
    from core.tracking.stability import _room_health, room_scenes

    ds = room_scenes(60, seed=0)["room, 4 people circling"]
    assert len(ds.frame) / ds.n_frames == 150  # four people, 25 points each, 50 clutter
    corners = all_corners("cv", 24, seed=1, mode="room")
    assert len(corners[0]) == 24
    rep = sweep("cv", corners, ds, mode="room")
    assert rep.ok and rep.bad_track_frames == 0 and rep.nonfinite_outputs == 0
    assert rep.max_tracks_seen >= 1
    # the health check itself fails on a non-PD covariance
    from core.tracking.batch import room_points_of
    from core.tracking.room import track_room_arrays

    p = corner_params("cv", corners[0], "room")
    rec = track_room_arrays(
        room_points_of(ds), ds.frame_offsets, ds.trajectory_offsets, np.zeros(1, np.int64),
        p, 0.1, record=True,
    )[8]  # fmt: skip
    f = int(np.argmax(rec.n_tracks))
    assert _room_health(rec)[0] == 0
    rec.covariance[f, 0] = -np.eye(rec.covariance.shape[-1])
    assert _room_health(rec)[0] == 1

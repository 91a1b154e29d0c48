"""gtrack: states and counters, allocation and gating thresholds, geometry, cfg lines."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from core.cli import main
from core.errors import InputError
from core.formats.ti_cfg import TRACKER_COMMAND_FIELDS, parse_ti_cfg, replace_tracker_lines
from core.tracking import ekf
from core.tracking.gtrack import GtrackParams, cfg_lines, params_from_cfg, run_gtrack
from core.tracking.gtrack import geometry as geo
from core.tracking.gtrack.synthetic import people_frames
from core.tracking.gtrack.tracker import ACTIVE, DETECT, GtrackTracker, _Track

RESOURCE = Path(__file__).resolve().parents[3] / "resources/gtrack/ti_people_counting_isk.cfg"


def cluster(p: GtrackParams, c, v, n=25, spread=0.05, snr=5.0):
    """n points (r, az, el, vr, snr) of a body at world centre c moving at world velocity v."""
    M = geo.pose_matrix(p.sensor_azimuth_tilt_deg, p.sensor_elevation_tilt_deg)
    k = np.arange(n)
    offs = spread * np.column_stack([np.cos(k), np.sin(k), np.cos(2 * k)]) * (k % 3 == 1)[:, None]
    w = np.asarray(c, float) + offs
    ps = (w - [0, 0, p.sensor_height_m]) @ M
    r = np.linalg.norm(ps, axis=1)
    vs = M.T @ np.asarray(v, float)
    return np.column_stack(
        [
            r,
            np.arctan2(ps[:, 0], ps[:, 1]),
            np.arcsin(ps[:, 2] / r),
            ps @ vs / r,
            np.full(n, snr),
        ]  # fmt: skip
    )


def step(tr: GtrackTracker, pts: np.ndarray):
    pts = np.asarray(pts, float).reshape(-1, 5)
    return tr.step(pts[:, 0], pts[:, 1], pts[:, 2], pts[:, 3], pts[:, 4])


def walk(p, n_frames, v=(0.0, 0.5, 0.0), start=(0.0, 3.0, 1.0), present=None):
    """Frames of one walker (offsets for run_gtrack); ``present[f]`` False: no points."""
    T = p.frame_period_s
    frames = []
    for f in range(n_frames):
        c = np.asarray(start) + np.asarray(v) * f * T
        ok = present is None or present[f]
        frames.append(cluster(p, c, v) if ok else np.zeros((0, 5)))
    off = np.concatenate(([0], np.cumsum([len(x) for x in frames])))
    return np.concatenate(frames), off


# -- states and counters -------------------------------------------------------------------


@pytest.mark.parametrize("det2act", [1, 2, 4])
def test_active_after_det2act_consecutive_hits(det2act):
    p = replace(GtrackParams(), det2act=det2act)
    pts, off = walk(p, 6)
    res = run_gtrack(pts, off, p)
    assert [len(ft) for ft in res.frames] == [1] * 6  # one track from the first frame on
    # allocation is the first hit: ACTIVE from frame det2act − 1 on
    assert [bool(ft.confirmed[0]) for ft in res.frames] == [f >= det2act - 1 for f in range(6)]


def test_detect_freed_after_det2free_misses():
    p = replace(GtrackParams(), det2act=10, det2free=3)
    present = [True, True] + [False] * 5
    pts, off = walk(p, 7, present=present)
    res = run_gtrack(pts, off, p)
    # frames 2, 3 miss (kept), frame 4 is the third miss: freed
    assert [len(ft) for ft in res.frames] == [1, 1, 1, 1, 0, 0, 0]


@pytest.mark.parametrize(
    ("in_static_box", "speed", "expected_misses"),
    [(False, 0.5, 4), (True, 0.5, 30), (True, 4.0, 5)],
)  # exit2free outside the static box; inside it a lost track's speed halves each miss, and
# stops below 0.1 m/s: 0.5 m/s stops at the 4th miss (static2free), 4 m/s needs 7 (active2free 5)
def test_active_freed_after_misses_depends_on_static_box(in_static_box, speed, expected_misses):
    p = replace(GtrackParams(), det2act=2, exit2free=4, active2free=5, static2free=30)
    if not in_static_box:
        p = replace(p, static_y_min_m=6.0, static_y_max_m=7.5)
    n = 3 + 35
    present = [True] * 3 + [False] * 35
    pts, off = walk(p, n, v=(0.0, speed, 0.0), present=present)
    res = run_gtrack(pts, off, p)
    alive = [len(ft) for ft in res.frames]
    assert res.frames[2].confirmed[0]
    # the k-th miss frame (k = 1..) is frame 2 + k: freed at k = expected_misses
    assert alive[: 3 + expected_misses - 1] == [1] * (3 + expected_misses - 1)
    assert alive[3 + expected_misses - 1 :] == [0] * (n - 3 - expected_misses + 1)


def test_a_track_without_moving_points_slows_by_half_and_stops_below_a_tenth():
    p = replace(GtrackParams(), det2act=2, static2free=50, active2free=50)
    n = 3 + 6
    pts, off = walk(p, n, v=(0.0, 0.8, 0.0), present=[True] * 3 + [False] * 6)
    tr = GtrackTracker(p)
    speeds, still = [], []
    for f in range(n):
        q = pts[off[f] : off[f + 1]]
        tr.step(q[:, 0], q[:, 1], q[:, 2], q[:, 3], q[:, 4])
        t = tr.tracks[0]
        speeds.append(float(np.linalg.norm(t.x[3:6])))
        still.append(t.still)
        if f >= 3:
            assert np.all(t.x[6:9] == 0.0)  # no acceleration while lost
    # each miss halves the predicted speed (the first one's prediction still carries the last
    # acceleration): about 0.8 → 0.4 → 0.2 → 0.1 (just below), and that one (< 0.1) stops it
    assert speeds[3] == pytest.approx(speeds[2] / 2, rel=0.01)
    np.testing.assert_allclose(speeds[4:6], np.array(speeds[3]) / [2, 4], rtol=1e-9)
    assert speeds[5] < 0.1 and speeds[6:] == [0.0] * 3
    assert still == [False] * 6 + [True] * 3


def _still_track(tr: GtrackTracker, pos, vel) -> _Track:
    d = tr.dims
    x = np.zeros(3 * d)
    x[:d], x[d : 2 * d] = pos, vel
    t = _Track(id=0, x=x, P=tr.P0.copy(), D=np.zeros(tr.m), state=ACTIVE, birth=0)
    t.still = bool(np.linalg.norm(vel) == 0.0)  # as after TI's erasure stopped it
    return t


@pytest.mark.parametrize(
    ("pos", "vel", "limit"),
    [
        ((0.0, 3.0, 1.0), (0.0, 0.0, 0.0), "static2free"),  # stopped, in the static box
        ((0.0, 3.0, 1.0), (0.0, 0.05, 0.0), "active2free"),  # moving in it: obscured
        ((3.5, 3.0, 1.0), (0.0, 0.0, 0.0), "exit2free"),  # outside it
    ],
)
def test_active_miss_rules_on_constructed_tracks(pos, vel, limit):
    p = replace(GtrackParams(), active2free=7, static2free=11, exit2free=3)
    tr = GtrackTracker(p)
    t = _still_track(tr, pos, vel)
    n = getattr(p, limit)
    kept = [tr._transition(t, 0, np.zeros(0, bool)) for _ in range(n)]
    assert kept == [True] * (n - 1) + [False]


def test_sleep2free_counts_static_only_hits_in_static_box_and_a_moving_hit_resets():
    p = replace(GtrackParams(), sleep2free=5)
    tr = GtrackTracker(p)
    t = _still_track(tr, (0.0, 3.0, 1.0), (0.0, 0.0, 0.0))
    static, moving = np.ones(3, bool), np.array([True, False])
    assert [tr._transition(t, 3, static) for _ in range(4)] == [True] * 4
    assert tr._transition(t, 2, moving) and t.sleeps == 0  # a moving point resets the count
    assert [tr._transition(t, 3, static) for _ in range(5)] == [True] * 4 + [False]
    outside = _still_track(tr, (3.5, 3.0, 1.0), (0.0, 0.0, 0.0))
    assert all(tr._transition(outside, 3, static) for _ in range(20))


# -- allocation thresholds -------------------------------------------------------------------


def _allocated(p, pts) -> int:
    tr = GtrackTracker(p)
    ft, _, _ = step(tr, pts)
    return len(ft)


# TI's comparisons are strict: more than pointsThre points, an SNR sum and |v̄| above their
# thresholds, each point nearer than maxDistanceThre (squared) and maxVelThre to the centroid


def test_allocation_point_count_threshold_exact():
    p = GtrackParams()
    c, v = (0.0, 3.0, 1.0), (0.0, 0.5, 0.0)
    assert _allocated(p, cluster(p, c, v, n=p.points_thre + 1)) == 1
    assert _allocated(p, cluster(p, c, v, n=p.points_thre)) == 0


def test_allocation_snr_threshold_exact():
    p = replace(GtrackParams(), points_thre=19, snr_thre=40.0)
    c, v = (0.0, 3.0, 1.0), (0.0, 0.5, 0.0)
    assert _allocated(p, cluster(p, c, v, n=20, snr=2.001)) == 1  # sum 40.02
    assert _allocated(p, cluster(p, c, v, n=20, snr=2.0)) == 0  # sum 40.0: not above


def test_allocation_velocity_threshold_exact():
    p = replace(GtrackParams(), velocity_thre_mps=0.1)
    pts = cluster(p, (0.0, 3.0, 1.0), (0.0, 0.0, 0.0), n=25)
    pts[:, 3] = 0.1001
    assert _allocated(p, pts) == 1
    pts[:, 3] = 0.1
    assert _allocated(p, pts) == 0


def test_allocation_distance_threshold_exact():
    p = replace(GtrackParams(), points_thre=19, max_distance_thre_m2=0.5)
    base = cluster(p, (0.0, 3.0, 1.0), (0.0, 0.5, 0.0), n=19, spread=0.0)
    for factor, expected in ((0.999, 1), (1.001, 0)):
        # the 20th point √0.5·factor from the others along world x
        far = cluster(p, (np.sqrt(0.5) * factor, 3.0, 1.0), (0.0, 0.5, 0.0), n=1, spread=0.0)
        far[:, 3] = base[0, 3]
        assert _allocated(p, np.vstack([base, far])) == expected


def test_allocation_velocity_spread_threshold():
    p = replace(GtrackParams(), points_thre=19, max_vel_thre_mps=0.3)
    pts = cluster(p, (0.0, 3.0, 1.0), (0.0, 0.5, 0.0), n=20, spread=0.0)
    pts[:, 3] = 0.5
    pts[-1, 3] = 0.5 + 0.299
    assert _allocated(p, pts) == 1
    pts[-1, 3] = 0.5 + 0.301
    assert _allocated(p, pts) == 0


def test_obscured_snr_threshold_behind_a_track():
    p = replace(GtrackParams(), points_thre=19, snr_thre=40.0, snr_thre_obscured=100.0)
    v = (0.0, 0.5, 0.0)
    near = cluster(p, (0.0, 2.0, 1.0), v, n=25, snr=5.0)
    for snr, expected in ((5.0, 1), (5.01, 2)):  # sums 100 (not above 100) and 100.2
        tr = GtrackTracker(p)
        step(tr, near)
        behind = cluster(p, (0.0, 4.5, 1.0), v, n=20, snr=snr)
        near2 = cluster(p, (0.0, 2.0 + 0.5 * p.frame_period_s, 1.0), v, n=25, snr=5.0)
        ft, _, _ = step(tr, np.vstack([near2, behind]))
        assert len(ft) == expected
        # the same set beside the track (not behind it) needs only snr_thre
    tr = GtrackTracker(p)
    step(tr, near)
    beside = cluster(p, (2.5, 4.5, 1.0), v, n=20, snr=4.0)
    ft, _, _ = step(tr, np.vstack([near2, beside]))
    assert len(ft) == 2


def test_static_points_never_start_a_track():
    p = GtrackParams()
    pts = cluster(p, (0.0, 3.0, 1.0), (0.0, 0.0, 0.0), n=60, snr=50.0)
    assert np.all(pts[:, 3] == 0.0)
    assert _allocated(replace(p, velocity_thre_mps=0.0), pts) == 0


def _active_track(p, speed=0.5):
    """A tracker with one ACTIVE track walking at (0, 3, 1) along y."""
    tr = GtrackTracker(p)
    v = (0.0, speed, 0.0)
    for f in range(p.det2act):
        step(tr, cluster(p, (0.0, 3.0 + speed * f * p.frame_period_s, 1.0), v, n=25))
    assert tr.tracks[0].state == ACTIVE
    return tr, (0.0, 3.0 + speed * p.det2act * p.frame_period_s, 1.0)


@pytest.mark.parametrize(("static_y", "taken"), [((0.5, 7.5), True), ((5.0, 7.5), False)])
def test_static_points_count_only_inside_the_static_box(static_y, taken):
    # TI's gtrack: a zero-Doppler point in the boundary box is used only inside a static box
    p = replace(GtrackParams(), det2act=2, static_y_min_m=static_y[0], static_y_max_m=static_y[1])
    tr, c = _active_track(p, speed=0.15)  # slow: the still points' Doppler is in its gate
    still = cluster(p, c, (0.0, 0.0, 0.0), n=10)
    _, owner, _ = step(tr, still)
    assert np.all(owner == (tr.tracks[0].id if taken else -1))


def test_detect_track_needs_moving_points_to_go_active():
    # static points keep no DETECT track alive: a hit needs a moving point
    p = replace(GtrackParams(), det2act=3, det2free=2)
    tr = GtrackTracker(p)
    step(tr, cluster(p, (0.0, 3.0, 1.0), (0.0, 0.5, 0.0), n=25))
    still = cluster(p, (0.0, 3.0, 1.0), (0.0, 0.0, 0.0), n=25)
    ft, owner, _ = step(tr, still)
    assert np.all(owner == tr.tracks[0].id) and tr.tracks[0].misses == 1
    assert tr.tracks[0].state == DETECT
    ft, _, _ = step(tr, still)
    assert len(ft) == 0  # the second miss: det2free


def test_radial_velocity_unrolled_to_the_prediction():
    from core.tracking.gtrack.tracker import unroll

    assert unroll(-4.0, 4.5, 4.6) == pytest.approx(5.2)  # -4.0 + 9.2
    assert unroll(4.0, -4.5, 4.6) == pytest.approx(-5.2)
    assert unroll(1.0, 0.8, 4.6) == pytest.approx(1.0)
    # an aliased point (vr − 2 v_max) is gated and updates the track as the true one
    p = replace(GtrackParams(), det2act=2)
    runs = []
    for alias in (0.0, -2 * p.max_radial_velocity_mps):
        tr, c = _active_track(p)
        pts = cluster(p, c, (0.0, 0.5, 0.0), n=25)
        pts[::2, 3] += alias
        ft, owner, _ = step(tr, pts)
        assert np.all(owner == tr.tracks[0].id)
        runs.append(ft.state[0])
    np.testing.assert_allclose(runs[0], runs[1], atol=1e-9)


# -- a new track's radial velocity in stages ------------------------------------------------


def _flat(**kw):
    """TI's lines with the sensor at the origin looking along +y (range = distance)."""
    return replace(GtrackParams(), sensor_height_m=0.0, sensor_elevation_tilt_deg=0.0,
                   boundary_z_min_m=-3.0, boundary_z_max_m=3.0, static_z_min_m=-3.0,
                   static_z_max_m=3.0, **kw)  # fmt: skip


def test_velocity_stages_advance_when_the_range_rate_settles():
    from core.tracking.gtrack.tracker import LOCKED, RATE_FILTER, TRACKING

    # a walker receding at 1.5 m/s, vr aliased to 1.5 − 2·1 = −0.5 (v_max 1 m/s)
    p = _flat(max_radial_velocity_mps=1.0, velocity_thre_mps=0.1)
    T, v = p.frame_period_s, 1.5
    tr = GtrackTracker(p)
    stages, rates = [], []
    for k in range(20):
        pts = cluster(p, (0.0, 3.0 + v * k * T, 0.0), (0.0, v, 0.0), spread=0.0)
        pts[:, 3] -= 2.0  # what the radar measures
        step(tr, pts)
        assert len(tr.tracks) == 1
        stages.append(tr.tracks[0].vstate)
        rates.append(tr.tracks[0].rate)
    # born at the aliased vr; the filtered rate halves its error each frame: ρ_k = 1.5 − 2/2^k
    assert rates[0] == pytest.approx(-0.5)
    np.testing.assert_allclose(rates[1:5], [0.5, 1.0, 1.25, 1.375], atol=1e-9)
    # RATE_FILTER until |ṙ − ρ| < 0.1 |ρ|: 2/2^k < 0.1 (1.5 − 2/2^k) first at k = 4
    assert stages[:4] == [RATE_FILTER] * 4 and stages[4] == TRACKING
    assert LOCKED in stages and stages == sorted(stages)
    # the track follows the true (unrolled) velocity
    np.testing.assert_allclose(tr.tracks[0].x[3:6], (0.0, v, 0.0), atol=0.1)


def test_without_unrolling_by_range_rate_an_aliased_walker_is_lost():
    """The same walker locked to its prediction from birth (no stages) keeps the aliased
    velocity: the stages are what recovers it."""
    from core.tracking.gtrack.tracker import LOCKED

    p = _flat(max_radial_velocity_mps=1.0, velocity_thre_mps=0.1)
    T, v = p.frame_period_s, 1.5
    tr = GtrackTracker(p)
    for k in range(20):
        pts = cluster(p, (0.0, 3.0 + v * k * T, 0.0), (0.0, v, 0.0), spread=0.0)
        pts[:, 3] -= 2.0
        step(tr, pts)
        for t in tr.tracks:
            t.vstate = LOCKED
    vy = [t.x[4] for t in tr.tracks if t.id == 0]
    assert not vy or abs(vy[0] - v) > 0.5


def test_new_track_on_a_standing_cluster_keeps_about_zero_velocity():
    # a person stands: micro-Doppler ±0.3 m/s about zero, the first frame's mean 0.2 m/s
    p = _flat(velocity_thre_mps=0.1)
    tr = GtrackTracker(p)
    rng = np.random.default_rng(0)
    for k in range(40):
        pts = cluster(p, (0.5, 2.5, 0.0), (0.0, 0.0, 0.0), spread=0.1)
        pts[:, 3] = np.where(np.arange(len(pts)) % 2, 0.3, -0.3) + rng.normal(0, 0.02, len(pts))
        if k == 0:
            pts[:, 3] += 0.2
        step(tr, pts)
    t = tr.tracks[0]
    assert t.id == 0 and t.state == ACTIVE
    assert np.linalg.norm(t.x[3:6]) < 0.1
    np.testing.assert_allclose(t.x[:2], (0.5, 2.5), atol=0.1)


# -- gating ----------------------------------------------------------------------------------


def _probe_setup(p):
    tr = GtrackTracker(p)
    step(tr, cluster(p, (0.0, 3.0, 1.0), (0.0, 0.5, 0.0), n=25))
    t = tr.tracks[0]
    x_pred, P_pred = ekf.predict(t.x, t.P, tr.F, tr.Q)
    H = geo.jacobian(x_pred, p.dims, tr.M, tr.h)
    zp = geo.measure(x_pred, p.dims, tr.M, tr.h)
    C = H @ P_pred @ H.T + tr.R + np.diag(t.D)
    return tr, x_pred, zp, C


@pytest.mark.parametrize(("factor", "taken"), [(0.999, True), (1.001, False)])
def test_gate_gain_threshold_exact(factor, taken):
    p = replace(GtrackParams(), gating_width_m=50, gating_depth_m=50, gating_height_m=50)
    tr, _, zp, C = _probe_setup(p)
    e = np.array([1.0, 0.0, 0.0, 0.0])  # along range
    s = p.gating_gain / np.sqrt(e @ np.linalg.inv(C) @ e) * factor
    z = zp + s * e
    _, owner, _ = step(tr, np.array([[z[0], z[1], z[2], z[3], 5.0]]))
    assert (owner[0] == tr.tracks[0].id) == taken


def test_gate_leaves_doppler_out_but_the_score_keeps_it():
    # TI's gate is the partial distance over range and angles; Doppler only scores
    p = replace(GtrackParams(), gating_velocity_mps=0.0)
    tr, _, zp, C = _probe_setup(p)
    e = np.array([0.0, 0.0, 0.0, 1.0])
    far = 3.0 * p.gating_gain / np.sqrt(e @ np.linalg.inv(C) @ e)  # 3 gates away in Doppler
    z = zp + far * e
    _, owner, _ = step(tr, np.array([[z[0], z[1], z[2], z[3], 5.0]]))
    assert owner[0] == tr.tracks[0].id


@pytest.mark.parametrize(("factor", "taken"), [(1.001, True), (0.999, False)])
def test_gate_depth_limit_exact(factor, taken):
    p = replace(GtrackParams(), gating_gain=50.0)
    tr, x_pred, zp, _ = _probe_setup(p)
    z = zp + np.array([0.3, 0.0, 0.0, 0.0])
    pw = geo.sensor_to_world(geo.spherical_to_sensor(z[0], z[1], z[2])[None], tr.M, tr.h)[0]
    dy = abs(pw[1] - x_pred[1])
    assert abs(pw[0] - x_pred[0]) < 0.5 and abs(pw[2] - x_pred[2]) < 0.5
    tr.p = replace(p, gating_depth_m=2 * dy * factor)
    _, owner, _ = step(tr, np.array([[z[0], z[1], z[2], z[3], 5.0]]))
    assert (owner[0] == tr.tracks[0].id) == taken


@pytest.mark.parametrize(
    ("row", "axis", "field"), [(1, 0, "gating_width_m"), (2, 2, "gating_height_m")]
)
@pytest.mark.parametrize(("factor", "taken"), [(1.001, True), (0.999, False)])
def test_gate_width_and_height_limits_exact(row, axis, field, factor, taken):
    p = replace(GtrackParams(), gating_gain=50.0)
    tr, x_pred, zp, _ = _probe_setup(p)
    z = zp.copy()
    z[row] += 0.08  # azimuth moves the point along x, elevation along z
    pw = geo.sensor_to_world(geo.spherical_to_sensor(z[0], z[1], z[2])[None], tr.M, tr.h)[0]
    off = abs(pw[axis] - x_pred[axis])
    assert off > 0.1 and all(abs(pw[k] - x_pred[k]) < 0.9 for k in range(3))
    tr.p = replace(p, **{field: 2 * off * factor})
    _, owner, _ = step(tr, np.array([[z[0], z[1], z[2], z[3], 5.0]]))
    assert (owner[0] == tr.tracks[0].id) == taken


@pytest.mark.parametrize(("factor", "taken"), [(1.001, True), (0.999, False)])
def test_gate_velocity_limit_exact(factor, taken):
    p = replace(GtrackParams(), gating_gain=50.0)
    tr, _, zp, _ = _probe_setup(p)
    z = zp + np.array([0.0, 0.0, 0.0, 0.4])
    tr.p = replace(p, gating_velocity_mps=2 * 0.4 * factor)
    _, owner, _ = step(tr, np.array([[z[0], z[1], z[2], z[3], 5.0]]))
    assert (owner[0] == tr.tracks[0].id) == taken


def test_points_outside_boundary_box_are_not_used():
    p = GtrackParams()
    pts = cluster(p, (0.0, 3.0, 1.0), (0.0, 0.5, 0.0), n=30)
    assert _allocated(replace(p, boundary_y_max_m=2.5), pts) == 0
    assert _allocated(p, pts) == 1


# -- geometry and the whole tracker ----------------------------------------------------------


@pytest.mark.parametrize("dims", [2, 3])
def test_jacobian_matches_finite_differences(dims):
    M = geo.pose_matrix(10.0, 15.0 if dims == 3 else 0.0)
    h = 2.0 if dims == 3 else 0.0
    rng = np.random.default_rng(1)
    x = rng.normal(0, 1, 3 * dims)
    x[1] += 4.0
    H = geo.jacobian(x, dims, M, h)
    num = np.zeros_like(H)
    for i in range(3 * dims):
        dx = np.zeros(3 * dims)
        dx[i] = 1e-6
        num[:, i] = (geo.measure(x + dx, dims, M, h) - geo.measure(x - dx, dims, M, h)) / 2e-6
    np.testing.assert_allclose(H, num, atol=1e-6)


def test_measurement_inverts_the_pose():
    p = GtrackParams()
    M = geo.pose_matrix(p.sensor_azimuth_tilt_deg, p.sensor_elevation_tilt_deg)
    x = np.array([0.7, 3.2, 1.1, 0, 0, 0, 0, 0, 0])
    z = geo.measure(x, 3, M, p.sensor_height_m)
    back = geo.sensor_to_world(geo.spherical_to_sensor(z[0], z[1], z[2])[None], M, 2.0)[0]
    np.testing.assert_allclose(back, x[:3], atol=1e-12)
    # boresight of a sensor tilted 15° down at 2 m meets the floor at 2 / tan 15°
    floor = geo.sensor_to_world(geo.spherical_to_sensor(2 / np.sin(np.radians(15)), 0, 0)[None],
                                M, 2.0)[0]  # fmt: skip
    np.testing.assert_allclose(floor, [0, 2 / np.tan(np.radians(15)), 0], atol=1e-12)


def test_four_walkers_give_four_active_tracks_on_them():
    p = GtrackParams()
    pts, off, truth = people_frames(
        np.random.default_rng(3), p, n_frames=60, n_people=4, points_per_person=25,
        static_points=50, speed_mps=0.5,
    )  # fmt: skip
    res = run_gtrack(pts, off, p)
    assert np.all(res.n_active[5:] == 4)
    for f in range(5, 60):
        ft = res.frames[f]
        xy = ft.state[ft.confirmed, :2]
        d = np.linalg.norm(xy[:, None] - truth[f][None, :, :2], axis=2)
        assert d.min(axis=0).max() < 0.25
    assert DETECT != ACTIVE


# -- cfg lines -----------------------------------------------------------------------------


def test_resource_cfg_is_the_default_params():
    cmds = parse_ti_cfg(RESOURCE.read_text(), str(RESOURCE))
    assert params_from_cfg(cmds, str(RESOURCE)) == GtrackParams()


def test_cfg_round_trip_keeps_other_lines_and_values():
    base = "% head\nsensorStop\nchannelCfg 15 7 0\n" + RESOURCE.read_text() + "sensorStart\n"
    p = replace(GtrackParams(), gating_gain=2.5, det2act=7, max_distance_thre_m2=0.812345,
                max_radial_velocity_mps=5.3, frame_period_s=0.1, static_y_max_m=6.25)  # fmt: skip
    text = replace_tracker_lines(base, cfg_lines(p))
    assert params_from_cfg(parse_ti_cfg(text)) == replace(p, max_radial_velocity_mps=5.3)

    def others(t):
        return [ln for ln in t.splitlines() if ln.split()[0] not in TRACKER_COMMAND_FIELDS]

    assert others(text) == others(base) and "channelCfg 15 7 0" in others(text)
    assert "gatingParam 2.5 2 2 2 4" in text and "allocationParam 40 100 0.1 20 0.812345 20" in text
    # without changes: the same lines back
    again = replace_tracker_lines(base, cfg_lines(params_from_cfg(parse_ti_cfg(base))))
    assert again == base


def test_export_cfg_cli_round_trip(tmp_path):
    base = tmp_path / "base.cfg"
    base.write_text("sensorStop\nchannelCfg 15 7 0\n" + RESOURCE.read_text() + "sensorStart\n")
    out = tmp_path / "out.cfg"
    assert main(["export-cfg", "--cfg", str(base), "--out", str(out)]) == 0
    assert out.read_text() == base.read_text()
    pj = tmp_path / "p.json"
    pj.write_text('{"gating_gain": 4.5, "exit2free": 9}')
    assert main(["export-cfg", "--cfg", str(base), "--params", str(pj), "--out", str(out)]) == 0
    got = params_from_cfg(parse_ti_cfg(out.read_text()))
    assert got == replace(GtrackParams(), gating_gain=4.5, exit2free=9)


@pytest.mark.parametrize(
    ("line", "needle"),
    [
        ("gatingParam 3 2 x 2 4", "gatingParam field 3 'depthLimit'"),
        ("stateParam 0 3 12 500 5 6000", "stateParam field 1 'det2actThre'"),
        ("allocationParam 40 100 0.1 20 0.5", "field 6 'maxVelThre' missing"),
        ("allocationParam 40 100 0.1 2.5 0.5 20", "allocationParam field 4 'pointsThre'"),
        ("boundaryBox -4 -5 0 8 0 3", "boundaryBox field"),
        ("maxAcceleration 0.1 nan 0.1", "maxAcceleration field 2 'maxAccelY'"),
    ],
)
def test_bad_tracker_line_one_line_exit_2(tmp_path, capsys, line, needle):
    base = tmp_path / "bad.cfg"
    base.write_text("sensorStop\n" + line + "\nsensorStart\n")
    out = tmp_path / "o.cfg"
    assert main(["export-cfg", "--cfg", str(base), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "bad.cfg:2" in err and needle in err
    assert not out.exists()


def test_params_json_unknown_key_is_refused():
    with pytest.raises(InputError, match="unknown gtrack parameter"):
        GtrackParams.from_dict({"gain": 3})


# -- the compiled form ---------------------------------------------------------------------


@pytest.mark.parametrize(
    ("dims", "seed", "overrides"),
    [
        (3, 1, {}),
        (3, 2, {"det2act": 1, "max_tracks": 5, "points_thre": 8, "exit2free": 2}),
        (2, 3, {"sensor_azimuth_tilt_deg": 10.0, "gating_velocity_mps": 0.0}),
        # walkers at 1 m/s with v_max 0.6 m/s: aliased vr, the stages matter
        (3, 4, {"max_radial_velocity_mps": 0.6, "velocity_thre_mps": 0.1}),
    ],
)
def test_compiled_equals_readable(dims, seed, overrides):
    from core.tracking.gtrack.compiled import run_gtrack_compiled

    p = replace(GtrackParams(), dims=dims, **overrides)
    pts, off, _ = people_frames(
        np.random.default_rng(seed), p, n_frames=80, n_people=4, points_per_person=25,
        static_points=40,
    )  # fmt: skip
    a, b = run_gtrack_compiled(pts, off, p), run_gtrack(pts, off, p)
    np.testing.assert_array_equal(a.point_track, b.point_track)
    np.testing.assert_array_equal(a.presence, b.presence)
    assert len(a.frames) == len(b.frames) == 80
    assert sum(len(ft) for ft in b.frames) > 80  # tracks to compare
    if p.max_radial_velocity_mps < 1.0:
        # the stages ran: the readable tracker's live tracks went through all three
        tr = GtrackTracker(p)
        seen = set()
        for f in range(len(off) - 1):
            q = pts[off[f] : off[f + 1]]
            tr.step(q[:, 0], q[:, 1], q[:, 2], q[:, 3], q[:, 4])
            seen |= {t.vstate for t in tr.tracks}
        assert seen == {1, 2, 3}
    for fa, fb in zip(a.frames, b.frames):
        for k in ("ids", "confirmed", "birth_frame", "n_associated"):
            np.testing.assert_array_equal(getattr(fa, k), getattr(fb, k))
        for k in ("state", "covariance", "gate_center_xy", "gate_shape_xy", "nis"):
            np.testing.assert_allclose(getattr(fa, k), getattr(fb, k), rtol=1e-9, atol=1e-9)
        assert fa.estimate == fb.estimate


def test_track_cli_gtrack_runs_and_refuses_bad_cfg(tmp_path, capsys):
    import json

    from core.tracking.synthetic import synthetic_dataset

    data = synthetic_dataset(0, 1, classes="a", n_frames=40).save(tmp_path / "d.npz")
    out = tmp_path / "r.json"
    args = ["track", "--data", str(data), "--tracker", "gtrack", "--engine", "numpy"]
    assert main([*args, "--cfg", str(RESOURCE), "--out", str(out)]) == 0
    doc = json.loads(out.read_text())
    assert doc["tracker"] == "gtrack" and doc["params"]["gating_gain"] == 3.0
    # one point a frame never reaches TI's 20-point allocation: no track, and it says so
    assert max(doc["active_per_frame"]) == 0
    bad = tmp_path / "bad.cfg"
    bad.write_text("allocationParam 40 100 0.1 twenty 0.5 20\n")
    capsys.readouterr()
    assert main([*args, "--cfg", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "bad.cfg:1" in err and "'pointsThre'" in err
    assert main(["track", "--data", str(data), "--cfg", str(RESOURCE)]) == 2


def test_track_cli_gtrack_tracks_csv_and_people(tmp_path, capsys):
    import csv
    import json

    from core.formats.tracks_csv import TRACKS_HEADER
    from core.tracking.synthetic import synthetic_dataset

    ds = synthetic_dataset(0, 2, classes="a", n_frames=40)
    data = ds.save(tmp_path / "d.npz")
    # one point a frame: TI's pointsThre 0 and snrThre 0 let it start a track
    params = tmp_path / "p.json"
    params.write_text(json.dumps({"points_thre": 0, "snr_thre": 0.0, "det2act": 2}))
    out, tracks = tmp_path / "r.json", tmp_path / "t.csv"
    args = ["track", "--data", str(data), "--tracker", "gtrack", "--params", str(params)]
    assert main([*args, "--out", str(out), "--tracks", str(tracks), "--people", "1"]) == 0
    doc = json.loads(out.read_text())
    per = doc["per_frame"]
    assert per["frame"] == list(range(ds.n_frames))
    assert per["confirmed"] == doc["active_per_frame"] and max(per["confirmed"]) >= 1
    assert doc["without_positions"]["count"]["frames"] == ds.n_frames
    assert doc["without_positions"]["nis"]["dof"] == 4  # [r, az, el, vr]
    with tracks.open() as fh:
        rows = list(csv.reader(fh))
    assert tuple(rows[0]) == TRACKS_HEADER
    body = rows[1:]
    # one row per live track and frame; confirmed rows are the ACTIVE counts
    assert len(body) == sum(per["confirmed"]) + sum(per["tentative"])
    by_frame = np.bincount([int(r[0]) for r in body if r[3] == "confirmed"], minlength=ds.n_frames)
    assert by_frame.tolist() == per["confirmed"]
    assert all(r[9] == "" and r[6] != "" for r in body)  # no existence; gtrack's height
    # ids unique over the file: the two trajectories' tracks do not share ids
    runs = {}
    for r in body:
        runs.setdefault(int(r[2]), set()).add(int(r[0]) >= 40)
    assert all(len(v) == 1 for v in runs.values())
    assert main([*args, "--people", "-1"]) == 2


def test_gtrack_search_space_rows_are_params_fields_with_ti_defaults():
    from dataclasses import fields

    from core.tracking.space import GTRACK, SEARCH_SPACE, search_space

    rows = search_space(GTRACK)
    names = {f.name: f for f in fields(GtrackParams)}
    default = GtrackParams()
    assert len(rows) == 20 and len({r.name for r in rows}) == 20
    for r in rows:
        assert r.name in names and r.models == (GTRACK,)
        assert r.default == getattr(default, r.name)  # TI's default lines
        assert r.low <= r.default <= r.high
        assert r.integer == (names[r.name].type == "int")
    # the paper's rows are not among them, and theirs not among the paper's (the room mode's
    # allocation rows share two names with gtrack's, in their own table and JSON:
    # TrackerParams there, GtrackParams here)
    paper_rows = {p.name for p in SEARCH_SPACE if "paper" in p.modes}
    assert not {r.name for r in rows} & paper_rows
    assert [p.name for p in search_space("cv")][:3] == ["q_coeff", "r11", "r22"]


def _walker_dataset(path, n_traj=5, n_frames=30):
    """A data set of walkers seen as gtrack sees people (25 points each a frame), with truth."""
    import json

    from core.dataset import Dataset

    p = GtrackParams()
    cols: dict[str, list] = {k: [] for k in ("frame", "r", "az", "el", "vr", "snr")}
    truth, traj = [], []
    f0 = 0
    for k in range(n_traj):
        pts, off, tr = people_frames(
            np.random.default_rng(10 + k), p, n_frames=n_frames, n_people=1,
            points_per_person=25, speed_mps=0.6,
        )  # fmt: skip
        cols["frame"].append(f0 + np.repeat(np.arange(n_frames), np.diff(off)))
        for i, key in enumerate(("r", "az", "el", "vr", "snr")):
            cols[key].append(pts[:, i])
        truth.append(tr[:, :, :2])
        traj += [k] * n_frames
        f0 += n_frames
    c = {k: np.concatenate(v) for k, v in cols.items()}
    xyz = geo.spherical_to_sensor(c["r"], c["az"], c["el"])
    t = np.concatenate(truth)
    ds = Dataset(
        frame=c["frame"].astype(np.int64), range_m=c["r"], azimuth_rad=c["az"],
        elevation_rad=c["el"], radial_velocity_mps=c["vr"], snr_db=10 * np.log10(c["snr"]),
        x_m=xyz[:, 0], y_m=xyz[:, 1], z_m=xyz[:, 2], source=np.zeros(len(c["r"]), np.int64),
        trajectory=np.asarray(traj, np.int64),
        truth_t_s=np.arange(f0) * p.frame_period_s, truth_xy_m=t,
        truth_v_mps=np.zeros_like(t), trajectory_class=np.array(list("abcde"[:n_traj])),
        scene_json="{}", radar_json=json.dumps({"frame_period_s": p.frame_period_s}),
    )  # fmt: skip
    return ds.save(path)


def test_tune_tracker_gtrack_runs_a_study_and_gives_gtrack_params(tmp_path, capsys):
    import json

    data = _walker_dataset(tmp_path / "w.npz")
    storage = f"sqlite:///{tmp_path / 's.db'}"
    code = main(["tune", "--tracker", "gtrack", "--dataset", str(data), "--trials", "4",
                 "--storage", storage, "--pruner", "none", "--no-progress"])  # fmt: skip
    assert code == 0
    out = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    got = GtrackParams.from_dict({**GtrackParams().to_dict(), **out["params"]})
    assert isinstance(got.det2act, int) and isinstance(got.points_thre, int)
    assert np.isfinite(out["best_loss"]) and out["best_loss"] > 0
    # the chosen parameters track the walkers: the loss is the one gtrack gives them
    from core.dataset import Dataset
    from core.evaluation import evaluate
    from core.tracking.gtrack.batch import gtrack_dataset

    ds = Dataset.load(data)
    ev = evaluate(ds, gtrack_dataset(ds, got)[0])
    assert ev.loss_total == pytest.approx(out["best_loss"], rel=1e-9)
    assert main(["tune", "--tracker", "gtrack", "--model", "cv", "--dataset", str(data)]) == 2


@pytest.mark.parametrize(
    ("line", "needle"),
    [
        ("stateParam 3 3 12 500 5 60000000000", "'sleep2freeThre': sleep2free must be <="),
        ("trackingCfg 1 2 800 99999 46 96 55", "'maxNumTracks': max_tracks must be <="),
        ("trackingCfg 1 2 800 30 46 96 0", "'deltaT': frame_period_s must be"),
        ("sensorPosition 2 0 95", "'elevationTilt'"),
    ],
)
def test_out_of_range_tracker_fields_name_line_and_field(line, needle):
    with pytest.raises(InputError) as exc:
        params_from_cfg(parse_ti_cfg("% x\n" + line + "\n"), "t.cfg")
    assert needle in str(exc.value) and "t.cfg:2" in str(exc.value)

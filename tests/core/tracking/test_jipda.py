"""Joint IPDA (core/tracking/jipda.py) and the tracker with ``association="jipda"``.

- the joint association probabilities and ψ against a brute-force enumeration written here
  from the definition (every assignment of tracks to measurements, exclusive ones kept);
- exactly the IPDA tracker where no two gates share a measurement (to 1e-10);
- the compiled kernel equal to the readable tracker on crossing scenes of 2–4 people;
- identities kept through a crossing; the track cap never exceeded under a flood of clutter.
"""

import itertools
import math

import numpy as np
import pytest

from core.tracking import jipda
from core.tracking.kernel import track_frames
from core.tracking.params import TrackerParams
from core.tracking.synthetic import SyntheticScene, crossing_paths, people_dataset
from core.tracking.tracker import run_tracker

PDPG = 0.9 * 0.99


def _brute_force(psi_pred, lr, gated, pdpg):
    """Marginals β'_τ0, β'_τi (over all m measurements), ψ and β given existence, by listing
    every map track → {none} ∪ measurements and keeping the exclusive ones."""
    n, m = gated.shape
    weights, events = [], []
    for e in itertools.product(range(-1, m), repeat=n):
        taken = [j for j in e if j >= 0]
        if len(taken) != len(set(taken)):
            continue  # a measurement to two tracks
        if any(j >= 0 and not gated[t, j] for t, j in enumerate(e)):
            continue  # a track takes a measurement outside its gate
        w = 1.0
        for t, j in enumerate(e):
            w *= (1 - pdpg * psi_pred[t]) if j < 0 else pdpg * psi_pred[t] * lr[t, j]
        weights.append(w)
        events.append(e)
    weights = np.array(weights) / np.sum(weights)
    m0, mi = np.zeros(n), np.zeros((n, m))
    for e, w in zip(events, weights):
        for t, j in enumerate(e):
            if j < 0:
                m0[t] += w
            else:
                mi[t, j] += w
    q = (1 - pdpg) * psi_pred / (1 - pdpg * psi_pred)
    psi = mi.sum(axis=1) + m0 * q
    return m0, mi, psi, m0 * q / psi, mi / psi[:, None], len(events)


@pytest.mark.parametrize("n_tracks, n_meas", [(2, 2), (2, 3), (2, 4), (3, 2), (3, 3), (3, 4)])
@pytest.mark.parametrize("seed", range(4))
def test_joint_probabilities_equal_brute_force(n_tracks, n_meas, seed):
    rng = np.random.default_rng(100 * n_tracks + 10 * n_meas + seed)
    gated = rng.random((n_tracks, n_meas)) < 0.7
    gated[:, 0] = True  # every track shares measurement 0: one cluster
    psi_pred = rng.uniform(0.05, 0.99, n_tracks)
    lr = np.exp(rng.normal(1.0, 2.0, (n_tracks, n_meas)))
    options = [np.flatnonzero(g) for g in gated]
    ja = jipda.joint_associate(
        psi_pred, [np.log(lr[t, o]) for t, o in enumerate(options)], options, PDPG
    )
    m0, mi, psi, b0, b, n_ev = _brute_force(psi_pred, lr, gated, PDPG)
    assert ja.n_events == n_ev
    np.testing.assert_allclose(ja.marginal0, m0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(ja.psi, psi, rtol=0, atol=1e-12)
    np.testing.assert_allclose(ja.beta0, b0, rtol=0, atol=1e-12)
    for t, o in enumerate(options):
        np.testing.assert_allclose(ja.marginal[t], mi[t, o], rtol=0, atol=1e-12)
        np.testing.assert_allclose(ja.beta[t], b[t, o], rtol=0, atol=1e-12)
        assert ja.beta0[t] + ja.beta[t].sum() == pytest.approx(1.0, abs=1e-12)
        # a shared measurement is counted once: Σ_τ β'_τj ≤ 1
    assert np.all(mi.sum(axis=0) <= 1 + 1e-12)


def test_one_track_cluster_is_the_ipda_update():
    """A cluster of one: ψ and β of the JIPDA equations are the IPDA ones (ipda.py)."""
    from core.tracking import ipda

    log_lr = np.array([0.3, -1.2, 2.5])
    for psi_pred in (0.01, 0.5, 0.97, 1.0):
        ja = jipda.joint_associate(np.array([psi_pred]), [log_lr], [np.arange(3)], PDPG)
        a = ipda.associate(log_lr, PDPG)
        assert ja.psi[0] == pytest.approx(ipda.update_existence(psi_pred, a, PDPG, 3), abs=1e-14)
        assert ja.beta0[0] == pytest.approx(a.beta0, abs=1e-14)
        np.testing.assert_allclose(ja.beta[0], a.beta, rtol=0, atol=1e-14)


def test_clusters_are_connected_components():
    gated = np.array(
        [
            [1, 0, 0, 0, 0],
            [1, 1, 0, 0, 0],  # shares z0 with track 0
            [0, 0, 0, 1, 0],
            [0, 1, 0, 0, 0],  # shares z1 with track 1: joins 0 and 1 transitively
            [0, 0, 0, 1, 1],  # shares z3 with track 2
            [0, 0, 1, 0, 0],  # alone
        ],
        dtype=bool,
    )
    np.testing.assert_array_equal(jipda.clusters(gated), [0, 0, 2, 0, 2, 5])
    assert jipda.event_bound(np.array([1, 2, 1])) == 2 * 3 * 2


def _frames(ds):
    return ds.measurements(), ds.frame_offsets


def _equal_tracks(a, b, tol=1e-10):
    assert len(a.frames) == len(b.frames)
    for x, y in zip(a.frames, b.frames):
        np.testing.assert_array_equal(x.ids, y.ids)
        np.testing.assert_array_equal(x.confirmed, y.confirmed)
        np.testing.assert_allclose(x.state, y.state, rtol=tol, atol=tol)
        np.testing.assert_allclose(x.covariance, y.covariance, rtol=tol, atol=tol)
        np.testing.assert_allclose(x.psi, y.psi, rtol=0, atol=tol)
        np.testing.assert_array_equal(x.n_associated, y.n_associated)
        np.testing.assert_allclose(x.nis, y.nis, rtol=tol, atol=tol)  # NaN where NaN


def _shared_gate_frames(ds, params):
    """Frames in which two tracks validate a common measurement (readable tracker, IPDA)."""
    from core.tracking import ekf, gating
    from core.tracking.inputs import TrackerConstants

    c = TrackerConstants.build(params, 0.08)
    z, f_off = _frames(ds)
    res = run_tracker((z, f_off), params)
    n = 0
    for f in range(1, len(f_off) - 1):
        zf = z[f_off[f] : f_off[f + 1]]
        prev = res.frames[f - 1]
        gated = []
        for x, P in zip(prev.state, prev.covariance):
            xp, Pp = ekf.predict(x, P, c.F, c.Q)
            L = gating.cholesky(gating.innovation_covariance(ekf.jacobian(xp), Pp, c.R))
            gated.append(gating.mahalanobis_squared(ekf.innovation(zf, ekf.measure(xp)), L))
        if len(gated) > 1 and len(zf):
            n += int(np.any(np.sum(np.array(gated) <= c.gamma, axis=0) > 1))
    return n


def test_no_shared_gates_gives_exactly_ipda():
    """Two people 6 m apart, no clutter: no measurement in two gates, JIPDA = IPDA to 1e-10
    (state, covariance, ψ of every track of every frame)."""
    n_f = 120
    t = np.arange(n_f) * 0.08
    pos = np.stack(
        [np.column_stack((-3 + 0 * t, 3 + 0.8 * t)), np.column_stack((3 + 0 * t, 7 - 0.8 * t))],
        axis=1,
    )
    vel = np.stack([np.tile([0.0, 0.8], (n_f, 1)), np.tile([0.0, -0.8], (n_f, 1))], axis=1)
    ds = people_dataset(pos, vel, seed=4, scene=SyntheticScene(clutter_per_frame=0.0))
    ipda_p, jipda_p = TrackerParams(association="ipda"), TrackerParams(association="jipda")
    assert _shared_gate_frames(ds, ipda_p) == 0
    a, b = run_tracker(_frames(ds), ipda_p), run_tracker(_frames(ds), jipda_p)
    assert max(len(f) for f in a.frames) >= 2  # several tracks at once
    _equal_tracks(a, b, tol=1e-10)


def test_shared_gates_change_the_update_and_fallback_restores_ipda(monkeypatch):
    """Two people walking side by side 0.8 m apart share gates: the associations differ; with
    an event cap of 1 every cluster falls back to the IPDA update and the tracker equals the
    IPDA tracker to 1e-10 (up to the first frame where the merge rules, which differ for two
    confirmed tracks, give different track sets)."""
    n_f = 80
    t = np.arange(n_f) * 0.08
    pos = np.stack([np.column_stack((x + 0 * t, 3 + 0.8 * t)) for x in (-0.4, 0.4)], axis=1)
    vel = np.stack([np.tile([0.0, 0.8], (n_f, 1))] * 2, axis=1)
    ds = people_dataset(pos, vel, seed=1, scene=SyntheticScene(clutter_per_frame=0.5))
    ipda_p, jipda_p = TrackerParams(association="ipda"), TrackerParams(association="jipda")
    assert _shared_gate_frames(ds, ipda_p) >= 10
    a, b = run_tracker(_frames(ds), ipda_p), run_tracker(_frames(ds), jipda_p)
    monkeypatch.setattr(jipda, "MAX_JOINT_EVENTS", 1)
    c = run_tracker(_frames(ds), jipda_p)
    k = next(
        (f for f, (x, y) in enumerate(zip(a.frames, c.frames)) if not np.array_equal(x.ids, y.ids)),
        n_f,
    )
    assert k >= 40
    for x, y in zip(a.frames[:k], c.frames[:k]):
        np.testing.assert_allclose(x.state, y.state, rtol=1e-10, atol=1e-10)
        np.testing.assert_allclose(x.covariance, y.covariance, rtol=1e-10, atol=1e-10)
        np.testing.assert_allclose(x.psi, y.psi, rtol=0, atol=1e-10)
    diff = max(
        float(np.max(np.abs(x.state - y.state), initial=0.0))
        for x, y in zip(a.frames[:k], b.frames[:k])
        if np.array_equal(x.ids, y.ids)
    )
    assert diff > 1e-6  # without the fallback the joint update differs


@pytest.mark.parametrize("n_people", [2, 3, 4])
@pytest.mark.parametrize("model", ["cv", "ca"])
def test_kernel_equals_readable_on_crossings(n_people, model):
    pos, vel = crossing_paths(n_people, 90)
    ds = people_dataset(pos, vel, seed=n_people, scene=SyntheticScene(clutter_per_frame=3.0))
    p = TrackerParams.default(model)
    assert p.association == "jipda"
    ref = run_tracker(_frames(ds), p)
    fast = run_tracker(_frames(ds), p, engine="numba")
    _equal_tracks(ref, fast)
    np.testing.assert_array_equal(ref.estimate_id, fast.estimate_id)
    assert max(int(f.confirmed.sum()) for f in ref.frames) >= n_people - 1
    # the hot path (no recording) gives the same estimates
    z, f_off = _frames(ds)
    out = track_frames(z, f_off, np.array([0, len(f_off) - 1]), np.zeros(1, int), p, 0.08)
    np.testing.assert_allclose(out[0], ref.estimate_xy, rtol=0, atol=1e-10)
    np.testing.assert_array_equal(out[5], ref.n_tracks)


def _person_track_ids(res, pos, near_m=0.6, apart_m=0.5):
    """Per person the set of confirmed track IDs closest to it (within near_m), over the frames
    where every two people are more than apart_m from each other."""
    from scipy.optimize import linear_sum_assignment

    n = pos.shape[1]
    ids = [set() for _ in range(n)]
    for f, ft in enumerate(res.frames):
        sep = [np.hypot(*(pos[f, i] - pos[f, j])) for i in range(n) for j in range(i + 1, n)]
        c = np.flatnonzero(ft.confirmed)
        if min(sep) <= apart_m or len(c) == 0:
            continue
        D = np.linalg.norm(ft.state[c, None, :2] - pos[f][None], axis=2)
        for a, i in zip(*linear_sum_assignment(D)):
            if D[a, i] < near_m:
                ids[i].add(int(ft.ids[c[a]]))
    return ids


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_identities_kept_through_a_crossing(seed):
    """Two people cross at 90° at frame 75 (paper clutter): each keeps one track ID from its
    confirmation to the end, and the two IDs differ. (The IPDA tracker with its position-only
    merge loses one of them on these seeds.)"""
    pos, vel = crossing_paths(2, 150, spread_rad=math.pi / 2)
    ds = people_dataset(pos, vel, seed=seed)
    res = run_tracker(_frames(ds), TrackerParams(association="jipda"), engine="numba")
    ids = _person_track_ids(res, pos)
    assert [len(s) for s in ids] == [1, 1], ids
    assert ids[0] != ids[1]
    old = run_tracker(_frames(ds), TrackerParams(association="ipda"), engine="numba")
    assert max(len(s) for s in _person_track_ids(old, pos)) > 1


@pytest.mark.parametrize("association", ["ipda", "jipda"])
def test_track_cap_holds_under_a_clutter_flood(association):
    """200 clutter points a frame (~100× the paper's): the number of live tracks never exceeds
    max_tracks, in both engines, and the cap is reached."""
    pos, vel = crossing_paths(4, 40)
    ds = people_dataset(pos, vel, seed=7, scene=SyntheticScene(clutter_per_frame=200.0))
    p = TrackerParams(association=association, max_tracks=12, p_te=0.6, delete_threshold=0.05)
    for engine in ("numba", "numpy"):
        res = run_tracker(_frames(ds), p, engine=engine)
        assert res.n_tracks.max() == p.max_tracks
        assert all(len(f) <= p.max_tracks for f in res.frames)

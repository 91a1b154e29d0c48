"""The compiled kernel and the readable numpy tracker agree to 1e-10 on the same input
(estimates, and with recording on every live track of every frame)."""

import numpy as np
import pytest

from core.errors import InputError
from core.tracking.kernel import track_frames
from core.tracking.params import TrackerParams
from core.tracking.stability import corner_params
from core.tracking.synthetic import SyntheticScene, synthetic_dataset
from core.tracking.tracker import run_tracker

CASES = {
    "cv-default": TrackerParams.default("cv"),
    "ca-default": TrackerParams.default("ca"),
    "cv-ipda": TrackerParams(association="ipda"),
    "ca-nonparametric-ipda": TrackerParams(
        model="ca", clutter_density="nonparametric", association="ipda"
    ),
    "cv-nonparametric": TrackerParams(clutter_density="nonparametric"),
    "ca-nonparametric-p21": TrackerParams(
        model="ca", p0=(1, 1, 2, 2, 1, 1), p21=0.3, p11=0.9, clutter_density="nonparametric"
    ),
    # a stiff corner: all lower bounds except P_te = 1, p11 = 1 (immortal tracks, hits the cap)
    "cv-corner-immortal": corner_params("cv", (0,) * 9 + (1, 1, 0)),
    "ca-corner-upper": corner_params("ca", (1,) * 14),
}


@pytest.fixture(scope="module")
def dataset():
    scene = SyntheticScene(clutter_per_frame=3.0)
    return synthetic_dataset(11, n_per_class=1, classes="ce", scene=scene, n_frames=50)


_REFERENCE: dict = {}


def _reference(dataset, name, k):
    """The readable tracker on trajectory k with case ``name`` (every track kept), run once."""
    if (name, k) not in _REFERENCE:
        z, f_off, t_off = dataset.measurements(), dataset.frame_offsets, dataset.trajectory_offsets
        a, b = t_off[k], t_off[k + 1]
        frames = (z[f_off[a] : f_off[b]], f_off[a : b + 1] - f_off[a])
        _REFERENCE[name, k] = run_tracker(frames, CASES[name], 0.08)
    return _REFERENCE[name, k]


@pytest.mark.parametrize("name", list(CASES))
def test_kernel_equals_reference(dataset, name):
    p = CASES[name]
    z = dataset.measurements()
    f_off, t_off = dataset.frame_offsets, dataset.trajectory_offsets
    # the immortal corner keeps ~20 tracks a frame: the slow reference runs one trajectory only
    sel = np.arange(1 if name == "cv-corner-immortal" else dataset.n_trajectories)
    est_xy, has, psi, conf_xy, n_conf, n_tr, est_x, est_P = track_frames(
        z, f_off, t_off, sel, p, 0.08
    )
    for k in sel:
        a, b = t_off[k], t_off[k + 1]
        ref = _reference(dataset, name, k)
        s = slice(a, b)
        np.testing.assert_array_equal(has[s], ref.has_estimate)
        np.testing.assert_array_equal(n_tr[s], ref.n_tracks)
        np.testing.assert_array_equal(n_conf[s], ref.n_confirmed)
        np.testing.assert_allclose(est_xy[s], ref.estimate_xy, rtol=0, atol=1e-10)
        np.testing.assert_allclose(psi[s], ref.estimate_psi, rtol=0, atol=1e-10)
        np.testing.assert_allclose(est_x[s], ref.estimate_state, rtol=1e-10, atol=1e-10)
        np.testing.assert_allclose(est_P[s], ref.estimate_covariance, rtol=1e-10, atol=1e-10)
        np.testing.assert_allclose(conf_xy[s], ref.confirmed_xy, rtol=0, atol=1e-10)
        assert ref.has_estimate.any()  # the comparison covers tracked frames
    if name == "cv-corner-immortal":
        assert n_tr.max() == p.max_tracks  # the cap is exercised


# ---- recording every live track (the GUI's compiled path) ----
def _trajectory(dataset, k):
    z, f_off, t_off = dataset.measurements(), dataset.frame_offsets, dataset.trajectory_offsets
    a, b = t_off[k], t_off[k + 1]
    return z[f_off[a] : f_off[b]], f_off[a : b + 1] - f_off[a]


@pytest.mark.parametrize("name", list(CASES))
def test_recorded_tracks_equal_the_reference(dataset, name):
    p = CASES[name]
    tol = dict(rtol=1e-10, atol=1e-10)
    n_checked = n_tentative = n_confirmed = n_updated = 0
    ids_seen: set[int] = set()
    for k in range(1 if name == "cv-corner-immortal" else dataset.n_trajectories):
        frames = _trajectory(dataset, k)
        ref = _reference(dataset, name, k)
        fast = run_tracker(frames, p, 0.08, engine="numba")
        np.testing.assert_array_equal(fast.has_estimate, ref.has_estimate)
        np.testing.assert_array_equal(fast.estimate_id, ref.estimate_id)
        np.testing.assert_array_equal(fast.n_tracks, ref.n_tracks)
        np.testing.assert_array_equal(fast.n_confirmed, ref.n_confirmed)
        np.testing.assert_allclose(fast.estimate_xy, ref.estimate_xy, **tol)
        np.testing.assert_allclose(fast.estimate_psi, ref.estimate_psi, **tol)
        np.testing.assert_allclose(fast.estimate_state, ref.estimate_state, **tol)
        np.testing.assert_allclose(fast.estimate_covariance, ref.estimate_covariance, **tol)
        np.testing.assert_allclose(fast.confirmed_xy, ref.confirmed_xy, **tol)
        assert len(fast.frames) == len(ref.frames) == len(frames[1]) - 1
        for f, (a, b) in enumerate(zip(fast.frames, ref.frames)):
            assert len(a) == len(b) == ref.n_tracks[f]
            np.testing.assert_array_equal(a.ids, b.ids)
            np.testing.assert_array_equal(a.confirmed, b.confirmed)
            np.testing.assert_array_equal(a.birth_frame, b.birth_frame)
            assert a.estimate == b.estimate
            np.testing.assert_allclose(a.psi, b.psi, **tol)
            np.testing.assert_allclose(a.state, b.state, **tol)
            np.testing.assert_allclose(a.covariance, b.covariance, **tol)
            np.testing.assert_allclose(a.gate_center_xy, b.gate_center_xy, **tol)
            # gates are γ-scaled m²: relative 1e-10 of the largest entry
            scale = max(1.0, float(np.abs(b.gate_shape_xy).max(initial=0.0)))
            np.testing.assert_allclose(
                a.gate_shape_xy, b.gate_shape_xy, rtol=1e-10, atol=1e-10 * scale
            )
            # gated measurements and NIS of the frame's update (NaN in the same places)
            np.testing.assert_array_equal(a.n_associated, b.n_associated)
            np.testing.assert_allclose(a.nis, b.nis, **tol)
            newborn = a.birth_frame == f
            assert np.all(a.n_associated[newborn] == 0) and np.all(np.isnan(a.nis[newborn]))
            assert np.all(np.isnan(a.nis) == (a.n_associated == 0))
            n_updated += int((a.n_associated > 0).sum())
            assert np.all(a.birth_frame <= f) and np.all(a.birth_frame >= 0)
            n_checked += len(a)
            n_tentative += int((~a.confirmed).sum())
            n_confirmed += int(a.confirmed.sum())
            ids_seen.update(a.ids.tolist())
    # the comparison is not vacuous: many tracks, both states, births and deaths
    assert n_checked >= 100 and n_tentative > 0 and n_confirmed > 0 and n_updated > 0
    if name != "ca-corner-upper":  # there the huge gates swallow all clutter: one track lives
        assert len(ids_seen) > 5  # clutter tracks are born, merged and deleted


def test_recording_does_not_change_the_hot_path_outputs(dataset):
    p = CASES["ca-nonparametric-p21"]
    z, f_off, t_off = dataset.measurements(), dataset.frame_offsets, dataset.trajectory_offsets
    sel = np.arange(dataset.n_trajectories)
    off = track_frames(z, f_off, t_off, sel, p, 0.08)
    on = track_frames(z, f_off, t_off, sel, p, 0.08, record=True)
    assert len(off) == 8 and len(on) == 9
    for a, b in zip(off, on[:8]):
        np.testing.assert_array_equal(a, b)
    rec = on[8]
    n_tr = on[5]
    np.testing.assert_array_equal(rec.n_tracks, n_tr)
    assert rec.ids.shape == (len(n_tr), p.max_tracks)
    # the estimate slot holds the estimate's state; ψ of live tracks lies in [0, 1]
    rows = np.flatnonzero(rec.estimate >= 0)
    assert rows.size > 0
    np.testing.assert_array_equal(rec.state[rows, rec.estimate[rows]], on[6][rows])
    live = np.arange(p.max_tracks)[None, :] < n_tr[:, None]
    assert np.all((rec.psi[live] >= 0) & (rec.psi[live] <= 1))
    assert np.all(rec.ids[~live] == -1)


def test_gate_of_a_newborn_track_follows_the_formula():
    # one measurement at r = 5 m, az = 0: G = γ J S_ra Jᵀ with S = H P0 Hᵀ + R, J = diag(1, r)
    p = TrackerParams.default("cv")
    res = run_tracker([np.array([[5.0, 0.0, 0.0]])], p, 0.08, engine="numba")
    ft = res.frames[0]
    assert len(ft) == 1 and ft.birth_frame[0] == 0 and not ft.confirmed[0]
    from core.tracking.gating import gate_threshold

    gamma = gate_threshold(p.p_g, 3)
    p0 = np.asarray(p.p0, dtype=float) ** 2  # P0 = diag(p0²)
    # at (0, 5) with zero velocity: ∂r/∂y = 1, ∂az/∂x = 1/r
    s_rr = p0[1] + p.r11**2
    s_aa = p0[0] / 25.0 + p.r22**2
    np.testing.assert_allclose(ft.gate_center_xy[0], [0.0, 5.0], atol=1e-12)
    np.testing.assert_allclose(
        ft.gate_shape_xy[0], gamma * np.diag([25.0 * s_aa, s_rr]), rtol=1e-12, atol=1e-12
    )


def test_unknown_engine_is_an_input_error():
    with pytest.raises(InputError, match="engine"):
        run_tracker([np.zeros((0, 3))], TrackerParams(), 0.08, engine="cuda")


def test_nan_measurement_is_an_input_error():
    with pytest.raises(InputError, match="NaN"):
        run_tracker([np.array([[np.nan, 0.0, 0.0]])], TrackerParams(), 0.08, engine="numba")


def test_compiled_run_accepts_both_input_forms_and_rejects_bad_offsets(dataset):
    p = CASES["cv-default"]
    z, offsets = _trajectory(dataset, 0)
    pair = run_tracker((z, offsets), p, 0.08, engine="numba")
    listed = run_tracker(
        [z[a:b] for a, b in zip(offsets[:-1], offsets[1:])], p, 0.08, engine="numba"
    )
    np.testing.assert_array_equal(pair.estimate_xy, listed.estimate_xy)
    np.testing.assert_array_equal(pair.estimate_id, listed.estimate_id)
    with pytest.raises(InputError, match="frame_offsets"):
        run_tracker((z, offsets[:-1]), p, 0.08, engine="numba")  # misses the last points
    with pytest.raises(InputError, match="frame_period_s"):
        run_tracker((z, offsets), p, 0.0, engine="numba")

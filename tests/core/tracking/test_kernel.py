"""The compiled kernel and the readable numpy tracker agree to 1e-10 on the same input."""

import numpy as np
import pytest

from core.tracking.kernel import track_frames
from core.tracking.params import TrackerParams
from core.tracking.stability import corner_params
from core.tracking.synthetic import SyntheticScene, synthetic_dataset
from core.tracking.tracker import run_tracker

CASES = {
    "cv-default": TrackerParams.default("cv"),
    "ca-default": TrackerParams.default("ca"),
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
        ref = run_tracker((z[f_off[a] : f_off[b]], f_off[a : b + 1] - f_off[a]), p, 0.08)
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

"""The readable tracker: per-frame output for the GUI, management rules."""

import numpy as np
import pytest
from scipy.stats import chi2

from core.tracking import TrackerParams, run_tracker
from core.tracking import management as mg


def test_every_track_is_reported_and_births_follow_the_rules():
    # frame 0: two far-apart points → two tentative tracks, none confirmed in its birth frame
    z0 = np.array([[3.0, 0.0, 0.5], [6.0, 0.5, -1.0]])
    p = TrackerParams(p_te=0.95)  # even P_te ≥ 0.9 does not confirm in the birth frame
    res = run_tracker([z0, z0 + [0.0, 0.0, 0.0]], p)
    f0, f1 = res.frames
    assert list(f0.ids) == [0, 1] and not f0.confirmed.any() and f0.estimate == -1
    np.testing.assert_allclose(f0.state[0], [0, 3.0, 0, 0.5])
    np.testing.assert_allclose(f0.psi, [0.95, 0.95])
    # frame 1: both re-detected inside their gates → updated, confirmed, no new tracks
    assert list(f1.ids) == [0, 1] and f1.confirmed.all()
    assert res.has_estimate.tolist() == [False, True]
    assert res.estimate_id[1] == f1.ids[np.argmax(f1.psi)]
    assert f1.state.shape == (2, 4) and f1.covariance.shape == (2, 4, 4)


def test_merge_keeps_the_higher_psi_and_older_on_ties():
    pos = np.array([[0.0, 5.0], [0.1, 5.0], [3.0, 5.0]])
    cov = np.repeat(np.eye(2)[None] * 0.01, 3, axis=0)
    g2 = chi2.ppf(0.99, 2)
    keep = mg.merge(pos, cov, np.array([0.5, 0.8, 0.9]), np.array([0, 1, 2]), g2)
    assert keep.tolist() == [False, True, True]
    keep = mg.merge(pos, cov, np.array([0.7, 0.7, 0.9]), np.array([0, 1, 2]), g2)
    assert keep.tolist() == [True, False, True]


def test_cap_and_best_confirmed():
    psi = np.array([0.3, 0.9, 0.3, 0.95])
    ids = np.array([4, 5, 6, 7])
    assert mg.cap(psi, ids, 3).tolist() == [True, True, False, True]  # tie: the youngest goes
    assert mg.best_confirmed(psi, ids, np.array([True, True, True, False])) == 1
    assert mg.best_confirmed(np.array([0.9, 0.9]), np.array([3, 2]), np.ones(2, bool)) == 1
    assert mg.best_confirmed(psi, ids, np.zeros(4, bool)) == -1


@pytest.mark.parametrize("bad", [[np.array([[1.0, np.nan, 0.0]])]])
def test_non_finite_measurements_are_an_input_error(bad):
    from core.errors import InputError

    with pytest.raises(InputError, match="frame 0"):
        run_tracker(bad, TrackerParams())


def test_merge_of_confirmed_tracks_needs_agreeing_velocities():
    """JIPDA's merge: two confirmed tracks at one position merge only when Δvᵀ(ΣP_v)⁻¹Δv ≤ 2 ln 10;
    a tentative track merges on position alone."""
    from core.tracking.management import VELOCITY_MERGE_D2, merge

    pos = np.zeros((2, 2))
    cov = np.tile(np.eye(4) * 0.05, (2, 1, 1))  # combined velocity variance 0.1 per axis
    psi, ids = np.array([0.99, 0.95]), np.array([0, 1])
    dv = np.sqrt(VELOCITY_MERGE_D2 * 0.1)  # on the threshold along x
    for dvx, confirmed, merged in [
        (0.0, [True, True], True),
        (0.99 * dv, [True, True], True),
        (1.01 * dv, [True, True], False),
        (5.0, [True, False], True),  # the tentative one goes
    ]:
        state = np.array([[0, 0, 1.0, 0], [0, 0, 1.0 + dvx, 0]])
        keep = merge(
            pos,
            cov[:, :2, :2],
            psi,
            ids,
            9.21,
            confirmed=np.array(confirmed),
            state=state,
            state_cov=cov,
        )
        assert keep.tolist() == ([True, False] if merged else [True, True])
    # without the JIPDA arguments: position alone, as the IPDA tracker always did
    assert merge(pos, cov[:, :2, :2], psi, ids, 9.21).tolist() == [True, False]

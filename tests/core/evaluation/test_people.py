"""Several persons: GOSPA and its decomposition, the track-to-person assignment with hysteresis
and identity switches, the multi-person loss (equal to eq. 14 with one person), the count error.
Every expected number is derived by hand in the comments."""

from __future__ import annotations

import itertools
import json
import math

import numpy as np
import pytest

from core.evaluation import (
    assign_identities,
    evaluate,
    gospa,
    people_trajectory_loss,
    person_estimates,
    trajectory_loss,
    trajectory_losses,
)
from core.evaluation.people import frame_metrics
from core.tracking import TrackerParams, track_dataset
from core.tracking.batch import ConfirmedTracks
from core.tracking.synthetic import SyntheticScene, synthetic_dataset

NAN2 = [np.nan, np.nan]

# ---- GOSPA ---------------------------------------------------------------------------------------


def _gospa_brute(x: np.ndarray, y: np.ndarray, c: float, p: float) -> float:
    """GOSPA α = 2 by enumerating every partial assignment γ of pairs closer than c."""
    best = math.inf
    m, n = len(x), len(y)
    for k in range(min(m, n) + 1):
        for xs in itertools.combinations(range(m), k):
            for ys in itertools.permutations(range(n), k):
                d = [np.linalg.norm(x[i] - y[j]) for i, j in zip(xs, ys)]
                if any(v >= c for v in d):
                    continue
                cost = sum(v**p for v in d) + c**p / 2 * (m + n - 2 * k)
                best = min(best, cost)
    return best ** (1 / p)


def test_gospa_by_hand() -> None:
    c = 1.0
    # one pair 0.3 m apart, one false track far away: 0.3² + c²/2
    g = gospa(np.array([[0.0, 0.3], [5.0, 5.0]]), np.array([[0.0, 0.0]]), c, 2)
    assert (g.localisation, g.missed, g.false) == (pytest.approx(0.09), 0.0, 0.5)
    assert g.distance_m == pytest.approx(math.sqrt(0.59))
    assert (g.n_missed, g.n_false) == (0, 1)
    # a pair beyond c counts as one missed person and one false track: c²/2 + c²/2
    g = gospa(np.array([[0.0, 2.0]]), np.array([[0.0, 0.0]]), c, 2)
    assert (g.n_missed, g.n_false, g.distance_m) == (1, 1, pytest.approx(1.0))
    assert g.track_of_truth.tolist() == [-1]
    # empty sets: 0; n points against none: (c^p/2 · n)^(1/p)
    assert gospa(np.zeros((0, 2)), np.array([NAN2])).distance_m == 0.0
    assert gospa(np.zeros((0, 2)), np.zeros((3, 2)), 2.0, 2).distance_m == pytest.approx(
        math.sqrt(4 / 2 * 3)
    )
    # absent rows (NaN) are not in the set and keep index −1
    g = gospa(np.array([[1.0, 1.0]]), np.array([NAN2, [1.0, 1.2]]))
    assert g.track_of_truth.tolist() == [-1, 0] and g.n_missed == 0


@pytest.mark.parametrize("seed", range(20))
def test_gospa_equals_enumeration(seed: int) -> None:
    rng = np.random.default_rng(seed)
    x = rng.uniform(0, 2, (rng.integers(0, 4), 2))
    y = rng.uniform(0, 2, (rng.integers(0, 4), 2))
    c, p = float(rng.uniform(0.3, 1.5)), float(rng.choice([1, 2, 3]))
    g = gospa(x, y, c, p)
    assert g.distance_m == pytest.approx(_gospa_brute(x, y, c, p), rel=1e-12, abs=1e-12)
    assert g.distance_m**p == pytest.approx(g.localisation + g.missed + g.false, rel=1e-12)


# ---- identities ----------------------------------------------------------------------------------


def test_hysteresis_keeps_the_track_while_within_cutoff() -> None:
    # two persons walk toward each other along x and cross at frame 2; two tracks follow them
    # but the tracks swap sides (track 0 ends on person 1's path): at frame 2 both tracks are
    # 0.1 m from both persons, the optimal assignment alone would swap, the kept pairing wins
    truth = np.array([[[-1.0, 0], [1.0, 0]], [[-0.5, 0], [0.5, 0]], [[0.0, 0], [0.0, 0.0]]])
    tracks = np.array([[[-1.0, 0], [1.0, 0]], [[-0.5, 0], [0.5, 0]], [[0.0, 0.1], [0.0, -0.1]]])
    ids = np.array([[0, 1], [0, 1], [1, 0]])  # frame 2 lists track 1 first
    a = assign_identities(ids, tracks, truth)
    assert a.track_id.tolist() == [[0, 1], [0, 1], [0, 1]]
    assert a.switches_per_person.tolist() == [0, 0]


def test_switch_when_the_track_is_lost_and_another_takes_over() -> None:
    truth = np.zeros((4, 1, 2))
    tracks = np.array([[[0.1, 0.0], NAN2]] * 4)
    ids = np.array([[3, -1], [3, -1], [-1, -1], [7, -1]])
    tracks[2] = np.nan
    tracks[3, 0] = [0.2, 0.0]
    a = assign_identities(ids, tracks, truth)
    # frames 0, 1 track 3; frame 2 nothing (no switch); frame 3 track 7: one switch
    assert a.track_id[:, 0].tolist() == [3, 3, -1, 7]
    assert a.switch[:, 0].tolist() == [False, False, False, True]
    # the same track coming back after a gap is no switch
    ids[3, 0] = 3
    assert assign_identities(ids, tracks, truth).switches_per_person.tolist() == [0]


def test_drift_beyond_cutoff_releases_the_track() -> None:
    truth = np.zeros((3, 1, 2))
    tracks = np.array([[[0.5, 0.0], [3.0, 0.0]], [[1.5, 0.0], [0.2, 0.0]], [[0.1, 0.0], NAN2]])
    ids = np.array([[0, 1], [0, 1], [0, -1]])
    a = assign_identities(ids, tracks, truth, cutoff_m=1.0)
    # frame 1: track 0 is 1.5 m away (> c): released, track 1 (0.2 m) taken: a switch;
    # frame 2: track 1 gone, track 0 back within c: a second switch
    assert a.track_id[:, 0].tolist() == [0, 1, 0]
    assert a.switches_per_person.tolist() == [2]
    np.testing.assert_allclose(a.distance_m[:, 0], [0.5, 0.2, 0.1])


def test_assignment_restarts_per_trajectory_and_handles_empty_frames() -> None:
    truth = np.zeros((4, 1, 2))
    tracks = np.full((4, 1, 2), 0.1)
    ids = np.array([[0], [0], [1], [1]])
    # one trajectory: 0 → 1 is a switch; two trajectories split between: ids restart, none
    assert assign_identities(ids, tracks, truth).switches_per_person.tolist() == [1]
    assert assign_identities(ids, tracks, truth, [0, 2, 4]).switches_per_person.tolist() == [0]
    # no person, no track, nothing at all: defined, empty pairing
    a = assign_identities(np.zeros((3, 0), np.int64), np.zeros((3, 0, 2)), np.zeros((3, 0, 2)))
    assert a.track_id.shape == (3, 0)
    a = assign_identities(np.full((2, 1), -1), np.full((2, 1, 2), np.nan), np.zeros((2, 2, 2)))
    assert (a.track_id == -1).all() and not a.switch.any()


# ---- the multi-person loss -----------------------------------------------------------------------


def test_person_estimates_take_the_most_probable_tracks() -> None:
    truth = np.array([[[0.0, 0.0], [2.0, 0.0]], [[0.0, 0.0], NAN2]])
    # ranked by ψ: a track at 2.1 first, one at 0.1 second, a weak one at 0.0 third
    ranked = np.array([[[2.1, 0.0], [0.1, 0.0], [0.0, 0.0]]] * 2)
    est = person_estimates(ranked, truth)
    # frame 0: the two most probable tracks, paired by least Σ d²
    np.testing.assert_array_equal(est[0], [[0.1, 0.0], [2.1, 0.0]])
    # frame 1: one person present: the single most probable track (the paper's estimate),
    # however far; the absent person has none
    np.testing.assert_array_equal(est[1, 0], [2.1, 0.0])
    assert np.isnan(est[1, 1]).all()


def test_people_loss_is_mean_over_persons_present() -> None:
    n = 10
    truth = np.zeros((n, 3, 2))
    truth[:, 1] = [1.0, 0.0]
    truth[:, 2] = np.nan  # person 2 never present: not counted
    est = truth + [0.1, 0.0]
    est[5:, 1] = np.nan  # person 1 has an estimate in 5 frames only
    r = people_trajectory_loss(est, truth)
    # L_0 = 0.01/10, L_1 = 0.01/5  → L = (0.001 + 0.002)/2
    assert r.person_n_c.tolist() == [10, 5, 0]
    assert r.loss == pytest.approx((0.001 + 0.002) / 2, rel=1e-12)
    assert r.counted.tolist() == [True, True, False]
    # a person present but never estimated scores 1 m²
    est[:, 1] = np.nan
    assert people_trajectory_loss(est, truth).loss == pytest.approx((0.001 + 1.0) / 2)
    # nobody present at all: 1 m², like a trajectory never confirmed
    assert people_trajectory_loss(est, np.full_like(truth, np.nan)).loss == 1.0


@pytest.fixture(scope="module")
def one_person():
    scene = SyntheticScene(clutter_per_frame=2.0)
    return synthetic_dataset(3, n_per_class=1, classes="abcde", scene=scene, n_frames=60)


@pytest.mark.parametrize("model", ["cv", "ca"])
def test_one_person_loss_bit_identical_to_eq_14(one_person, model) -> None:
    """With one person the multi-person loss is today's eqs. (12)–(14), bit for bit."""
    params = TrackerParams.default(model)
    est = track_dataset(one_person, params, with_tracks=True)
    truth = one_person.truth_xy_m[est.frame_index, 0]
    off = est.offsets
    old = [
        trajectory_loss(est.estimate_xy[off[i] : off[i + 1]], est.has_estimate[off[i] : off[i + 1]],
                        truth[off[i] : off[i + 1]])[0]
        for i in range(len(off) - 1)
    ]  # fmt: skip
    ev = evaluate(one_person, est)
    assert ev.loss.tolist() == old
    assert trajectory_losses(one_person, est).tolist() == old
    assert ev.loss_total == float(np.mean(old))
    # the general several-person path (ranked tracks, assignment) gives the same numbers too
    pe = person_estimates(est.tracks.xy, one_person.truth_xy_m[est.frame_index])
    general = [people_trajectory_loss(pe[off[i] : off[i + 1]],
                                      one_person.truth_xy_m[est.frame_index][off[i] : off[i + 1]]
                                      ).loss for i in range(len(off) - 1)]  # fmt: skip
    assert general == old
    # the ranked tracks' first column is the tracker's estimate
    has = est.has_estimate
    np.testing.assert_array_equal(est.tracks.xy[has, 0], est.estimate_xy[has])
    assert (est.tracks.n == est.n_confirmed).all()


def test_numpy_engine_gives_the_same_tracks(one_person) -> None:
    params = TrackerParams.default("cv")
    a = track_dataset(one_person, params, with_tracks=True)
    b = track_dataset(one_person, params, with_tracks=True, engine="numpy")
    np.testing.assert_array_equal(a.tracks.ids, b.tracks.ids)
    np.testing.assert_allclose(a.tracks.xy, b.tracks.xy, atol=1e-9)


# ---- whole runs: no NaN, no traceback ------------------------------------------------------------


def _two_person_set(seed: int = 4, clutter: float = 1.0):
    """Two persons per trajectory: person 1 follows person 0's path shifted by (2, 0) m, absent
    in the first 20 frames of the set (of trajectory 0)."""
    from dataclasses import replace

    scene = SyntheticScene(clutter_per_frame=clutter)
    ds = synthetic_dataset(seed, n_per_class=1, classes="ac", scene=scene, n_frames=50)
    second = ds.truth_xy_m[:, :1] + [2.0, 0.0]
    vel = ds.truth_v_mps[:, :1].copy()
    second[: 20] = np.nan  # fmt: skip
    vel[:20] = np.nan
    return replace(
        ds,
        truth_xy_m=np.concatenate((ds.truth_xy_m, second), axis=1),
        truth_v_mps=np.concatenate((ds.truth_v_mps, vel), axis=1),
    )


def test_frame_metrics_count_error_and_decomposition() -> None:
    truth = np.array([[[0.0, 0.0], NAN2], [[0.0, 0.0], [3.0, 0.0]], [NAN2, NAN2]])
    conf = np.array([[[0.0, 0.2], [5.0, 5.0]], [[0.0, 0.2], NAN2], [[1.0, 1.0], NAN2]])
    fm = frame_metrics(truth, conf, np.array([[0, 1], [0, -1], [0, -1]]))
    assert fm.count_error.tolist() == [1, -1, 1]
    assert fm.n_missed.tolist() == [0, 1, 0] and fm.n_false.tolist() == [1, 0, 1]
    np.testing.assert_allclose(fm.localisation, [0.04, 0.04, 0.0])
    np.testing.assert_allclose(fm.gospa_m**2, fm.localisation + fm.missed + fm.false)
    m = fm.mean()
    assert m["count_abs_error"] == 1.0 and m["count_exact_fraction"] == 0.0
    assert fm.identity.track_id.tolist() == [[0, -1], [0, -1], [-1, -1]]


@pytest.mark.parametrize(
    "case", ["two persons", "no track", "no person", "absent person", "empty selection"]
)
def test_every_metric_defined(case) -> None:
    from dataclasses import replace

    ds = _two_person_set()
    params = TrackerParams.default("cv")
    if case == "no person":
        f = ds.n_frames
        ds = replace(ds, truth_xy_m=np.zeros((f, 0, 2)), truth_v_mps=np.zeros((f, 0, 2)))
    est = track_dataset(ds, params, with_tracks=True, trajectories=[] if "empty" in case else None)
    if case == "no track":
        nan = np.full_like(est.tracks.xy, np.nan)
        est = replace(
            est,
            estimate_xy=np.full_like(est.estimate_xy, np.nan),
            has_estimate=np.zeros_like(est.has_estimate),
            confirmed_xy=np.full_like(est.confirmed_xy, np.nan),
            n_confirmed=np.zeros_like(est.n_confirmed),
            tracks=ConfirmedTracks(ids=np.full(nan.shape[:2], -1), xy=nan, psi=nan[..., 0]),
        )
    if case == "absent person":
        truth = ds.truth_xy_m.copy()
        truth[5:15, 0] = np.nan
        v = ds.truth_v_mps.copy()
        v[5:15, 0] = np.nan
        ds = replace(ds, truth_xy_m=truth, truth_v_mps=v)
    ev = evaluate(ds, est)
    text = ev.format_table()
    assert "nan" not in text.lower() and "inf" not in text.lower(), text
    doc = ev.to_dict()
    json.dumps(doc, allow_nan=False)
    if case == "empty selection":
        return
    assert np.isfinite(ev.frames.gospa_m).all()
    assert len(doc["persons"]) == ds.n_persons
    if case == "no track":
        assert ev.loss_total == 1.0 and ev.identity_switches_total == 0
        # every present person is missed: GOSPA² = c²/2 per person present
        np.testing.assert_allclose(ev.frames.gospa_m**2, 0.5 * ev.frames.n_present)
        assert (ev.frames.count_error == -ev.frames.n_present).all()
    if case == "no person":
        assert ev.loss_total == 1.0 and doc["persons"] == []
        assert (ev.frames.count_error == ev.frames.n_confirmed).all()
    if case == "two persons":
        assert np.isfinite(ev.loss_total) and ev.loss_total < 1.0
        assert [m.frames_present for m in ev.persons] == [ds.n_frames, ds.n_frames - 20]


def test_people_run_of_one_readable_tracker_run_matches_the_batch(one_person) -> None:
    """The GUI's result type (one run of the readable tracker) gives the batch's numbers."""
    from core.evaluation import people_run
    from core.tracking import run_tracker
    from core.tracking.batch import dataset_frame_period_s

    params = TrackerParams.default("cv")
    ds = one_person
    a, b = int(ds.trajectory_offsets[2]), int(ds.trajectory_offsets[3])
    f_off = ds.frame_offsets
    res = run_tracker(
        (ds.measurements()[f_off[a] : f_off[b]], f_off[a : b + 1] - f_off[a]),
        params,
        dataset_frame_period_s(ds),
    )
    run = people_run(ds.truth_xy_m[a:b], ConfirmedTracks.from_frames(res.frames))
    ev = evaluate(ds, track_dataset(ds, params, trajectories=[2], with_tracks=True))
    assert run.loss.loss == pytest.approx(ev.loss[0], rel=1e-9)
    np.testing.assert_allclose(run.frames.gospa_m, ev.frames.gospa_m, atol=1e-9)
    assert run.persons[0].identity_switches == ev.persons[0].identity_switches
    assert run.persons[0].n_c == ev.persons[0].n_c


@pytest.mark.parametrize("seed", range(5))
def test_person_estimates_equal_brute_force(seed: int) -> None:
    """The vectorised pairings (one pair; two tracks and two persons) and the general loop give
    the pairing of least Σ d² over the P_f most probable tracks, checked by enumeration."""
    rng = np.random.default_rng(seed)
    n, p, c = 200, 4, 5
    truth = rng.uniform(-3, 3, (n, p, 2))
    truth[rng.random((n, p)) < 0.4] = np.nan
    ranked = rng.uniform(-3, 3, (n, c, 2))
    n_tracks = rng.integers(0, c + 1, n)
    ranked[np.arange(c)[None, :] >= n_tracks[:, None]] = np.nan
    est = person_estimates(ranked, truth)
    for f in range(n):
        persons = np.flatnonzero(np.isfinite(truth[f, :, 0]))
        k = min(len(persons), int(n_tracks[f]))
        best, best_cost = {}, math.inf
        for chosen in itertools.permutations(persons, k):  # track i → person chosen[i]
            cost = sum(np.sum((ranked[f, i] - truth[f, j]) ** 2) for i, j in enumerate(chosen))
            if cost < best_cost:
                best, best_cost = dict(zip(chosen, range(k))), cost
        for j in range(p):
            if j in best:
                np.testing.assert_array_equal(est[f, j], ranked[f, best[j]])
            else:
                assert np.isnan(est[f, j]).all()

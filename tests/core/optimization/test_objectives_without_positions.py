"""Study objectives without positions (count, fragmentation, nis) and studies on recordings."""

from __future__ import annotations

import dataclasses
import json
import math
from types import SimpleNamespace

import numpy as np
import pytest

from core.cli import main
from core.evaluation.counting import recording_scores, trajectory_terms
from core.evaluation.robust import OBJECTIVE_NEEDS, OBJECTIVES, aggregate
from core.optimization.objective import evaluate, tracker_losses
from core.optimization.validation import check_same_radar
from core.tracking import TrackerParams, track_dataset
from core.tracking.results import TrackRecord
from core.tracking.synthetic import synthetic_dataset


def _no_truth(ds):
    empty = np.zeros((ds.n_frames, 0, 2))
    return dataclasses.replace(ds, truth_xy_m=empty, truth_v_mps=empty)


def _run():
    """Two runs: frames 0-3 (n̂ = 0, 1, 1, 2; ids 0, 0, 0+1) and 4-5 (one track, id 0)."""
    rec = TrackRecord.allocate(6, 3, 4)
    n_hat = np.array([0, 1, 1, 2, 1, 1])
    rec.n_tracks[:] = [1, 1, 1, 2, 1, 1]
    rec.ids[:, 0] = [0, 0, 0, 0, 0, 0]
    rec.ids[3, 1] = 1
    rec.confirmed[:] = False
    rec.confirmed[1:, 0] = True
    rec.confirmed[3, 1] = True
    rec.nis[1:4, 0] = [1.0, 20.0, 0.1]  # inside, above, below the χ²₃ band [0.216, 9.35]
    rec.nis[3, 1] = 2.0
    return SimpleNamespace(offsets=np.array([0, 4, 6]), n_confirmed=n_hat, record=rec)


def test_terms_are_the_derived_numbers() -> None:
    est = _run()
    counts = np.ones(6, np.int64)
    count = trajectory_terms("count", est, counts)
    assert count == [(0.5, 4.0), (0.0, 2.0)]  # |n̂ − 1| = 1, 0, 0, 1 and 0, 0
    v, w = zip(*count)
    assert aggregate(v, "weighted", w) == pytest.approx(2 / 6)
    # run 0: Σ|n̂ − n| = 2 and ids {0, 1}, one beyond the one person, over 4 person-frames
    frag = trajectory_terms("fragmentation", est, counts)
    assert frag == [(pytest.approx(3 / 4), 4.0), (0.0, 2.0)]
    nis = trajectory_terms("nis", est, None)
    assert nis == [(0.5, 4.0), (1.0, 1.0)]  # run 1 has no NIS sample: scores 1
    with pytest.raises(Exception, match="head count"):
        trajectory_terms("count", est, None)


def test_registry_and_needs() -> None:
    assert set(OBJECTIVE_NEEDS) == set(OBJECTIVES)
    assert {k for k, v in OBJECTIVE_NEEDS.items() if v != "truth"} == {
        "count", "fragmentation", "nis", "reference"
    }  # fmt: skip


def test_objectives_agree_with_the_scores_of_track() -> None:
    ds = _no_truth(synthetic_dataset(2, 1, n_frames=120))
    params = TrackerParams.default("cv").to_dict()
    est = track_dataset(ds, TrackerParams.from_dict(params), with_tracks=True)
    scores = recording_scores(ds, est, 0.08, people=1)
    count = evaluate(tracker_losses(ds, "count", people=1), params, loss="count")
    # frame-weighted mean over the trajectories = the mean over every frame
    assert count.value == pytest.approx(scores.count.error, rel=1e-12)
    assert all(math.isnan(v) for v in count.losses)  # no truth: no paper loss
    nis = evaluate(tracker_losses(ds, "nis"), params, loss="nis")
    assert nis.value == pytest.approx(1.0 - scores.nis.inside, rel=1e-12)
    frag = evaluate(tracker_losses(ds, "fragmentation", people=1), params, loss="fragmentation")
    assert frag.value >= count.value  # the count error plus identity switches
    with pytest.raises(Exception, match="--people"):
        tracker_losses(ds, "count")


def test_radar_check_tolerates_a_measured_frame_period(tmp_path) -> None:
    ds = synthetic_dataset(0, 1, classes="a", n_frames=40)

    def with_period(name, t):
        radar = json.loads(ds.radar_json)
        radar["frame_period_s"] = t
        return str(dataclasses.replace(ds, radar_json=json.dumps(radar)).save(tmp_path / name))

    a, b, c = with_period("a.npz", 0.1), with_period("b.npz", 0.0993), with_period("c.npz", 0.08)
    check_same_radar(a, b, "validation")
    with pytest.raises(Exception, match="frame_period_s"):
        check_same_radar(a, c, "validation")


def test_tune_on_a_recording_without_truth(tmp_path, capsys) -> None:
    train = _no_truth(synthetic_dataset(5, 1, n_frames=80)).save(tmp_path / "rec.npz")
    val = _no_truth(synthetic_dataset(6, 1, n_frames=80)).save(tmp_path / "val.npz")
    storage = f"sqlite:///{tmp_path / 's.db'}"
    base = ["tune", "--model", "cv", "--trials", "4", "--dataset", str(train),
            "--storage", storage, "--no-progress"]  # fmt: skip
    # an objective on positions is refused, one line, exit 2
    assert main([*base, "--loss", "trimmed"]) == 2
    assert "--loss nis" in capsys.readouterr().err
    assert main([*base, "--loss", "count"]) == 2
    assert "head count" in capsys.readouterr().err
    assert main([*base, "--loss", "reference"]) == 2
    assert "no reference layer" in capsys.readouterr().err
    code = main([*base, "--people", "1", "--validation", str(val), "--study", "rec"])
    assert code == 0
    captured = capsys.readouterr()
    assert "minimises --loss fragmentation" in captured.err
    out = json.loads(captured.out.strip().splitlines()[-1])
    assert out["loss"] == "fragmentation" and 0 <= out["validation_value"]
    assert out["studies"][0]["validation_paper_loss"] is None
    # the printed params are what track --params takes
    p = tmp_path / "best.json"
    p.write_text(json.dumps(out["params"]))
    assert main(["track", "--data", str(val), "--params", str(p), "--people", "1"]) == 0
    assert "head count from --people 1" in capsys.readouterr().out
    # the report (the paper's loss on simulated sets) refuses such a study before any work
    assert main(["report", "--storage", storage, "--out", str(tmp_path / "rep")]) == 2
    assert "--loss fragmentation" in capsys.readouterr().err
    assert not (tmp_path / "rep").exists()


def test_bench_cuts_a_recording_to_its_first_frames() -> None:
    from core.benchmarks.tune import first_frames

    ds = synthetic_dataset(1, 1, classes="abc", n_frames=50)
    n = int(ds.trajectory_offsets[1]) + 7  # into the second trajectory
    cut = first_frames(ds, n)
    assert cut.n_frames == n and cut.n_trajectories == 2
    assert len(cut.frame) == int(ds.frame_offsets[n]) and cut.frame.max() < n
    np.testing.assert_array_equal(cut.x_m, ds.x_m[: len(cut.x_m)])
    np.testing.assert_array_equal(cut.truth_xy_m, ds.truth_xy_m[:n])


def test_bench_recording_flags_are_for_tune_only(capsys) -> None:
    assert main(["bench", "track", "--people", "1"]) == 2
    assert "for tune only" in capsys.readouterr().err


def test_mixed_objective_is_one_at_the_defaults_and_weights_the_parts() -> None:
    from core.optimization.mix import MixedObjective, parse_mix

    sim = synthetic_dataset(7, 1, classes="abc", n_frames=60)
    rec = _no_truth(synthetic_dataset(8, 1, classes="ab", n_frames=80))
    mixed = MixedObjective(
        [(sim, 1.0), (rec, 3.0)], "cv", loss="trimmed", recording_loss="count", people=1
    )
    assert mixed.objectives == ["trimmed", "count"]
    default = TrackerParams.default("cv").to_dict()
    # every part divided by its own value at the defaults
    assert mixed.evaluate(default).value == pytest.approx(1.0, rel=1e-12)
    other = {**default, "r11": 0.3, "p_d": 0.85}
    v = mixed.part_values(other)
    b = mixed.baselines
    expected = (1.0 * v[0] / b[0] + 3.0 * v[1] / b[1]) / 4.0
    assert mixed.evaluate(other).value == pytest.approx(expected, rel=1e-12)
    assert parse_mix("a.npz=0.5").weight == 0.5 and parse_mix("paper:3").weight == 1.0
    for bad in ("a.npz=x", "a.npz=0", "a.npz=-1"):
        with pytest.raises(Exception, match="--mix"):
            parse_mix(bad)


def test_tune_mixed_with_a_recording(tmp_path, capsys) -> None:
    sim = synthetic_dataset(9, 1, classes="ab", n_frames=60).save(tmp_path / "sim.npz")
    rec = _no_truth(synthetic_dataset(10, 1, classes="ab", n_frames=60)).save(tmp_path / "r.npz")
    val = _no_truth(synthetic_dataset(11, 1, classes="a", n_frames=60)).save(tmp_path / "v.npz")
    storage = f"sqlite:///{tmp_path / 's.db'}"
    code = main(["tune", "--model", "cv", "--trials", "3", "--dataset", str(sim), "--mix",
                 f"{rec}=2", "--people", "1", "--validation", str(val), "--storage", storage,
                 "--no-progress"])  # fmt: skip
    assert code == 0
    captured = capsys.readouterr()
    assert "by validation: fragmentation" in captured.err
    out = json.loads(captured.out.strip().splitlines()[-1])
    assert out["loss"] == "trimmed" and set(out["params"]) >= {"model", "r11", "p0"}
    # the same study name with another mix is refused
    code = main(["tune", "--model", "cv", "--trials", "3", "--dataset", str(sim), "--mix",
                 f"{rec}=1", "--people", "1", "--validation", str(val), "--storage", storage,
                 "--no-progress"])  # fmt: skip
    assert code == 2 and "mix" in capsys.readouterr().err


def test_gtrack_objectives_without_positions_agree_with_its_scores() -> None:
    """A gtrack study on a recording without truth scores count, fragmentation and nis (its
    NIS against the χ² band of gtrack's 3-D measurement, 4 degrees of freedom), as `track
    --tracker gtrack --people N` reports them."""
    from core.optimization.objective import make_losses
    from core.tracking.gtrack import GtrackParams
    from core.tracking.gtrack.batch import gtrack_dataset
    from core.tracking.space import GTRACK

    ds = _no_truth(synthetic_dataset(2, 1, n_frames=120))
    # one point a frame: allocation from a single point, so that tracks are confirmed
    gp = dataclasses.replace(GtrackParams(), points_thre=1, snr_thre=0.0, max_distance_thre_m2=4.0)
    est, _ = gtrack_dataset(ds, gp, with_tracks=True)
    assert est.n_confirmed.mean() > 0.3
    scores = recording_scores(ds, est, 0.08, people=1, nis_dof=4)
    params = gp.to_dict()

    def value(kind: str, people: int | None) -> float:
        losses = make_losses(
            "tracker", GTRACK, ds, capped=False, without_positions=kind, people=people
        )
        result = evaluate(losses, params, loss=kind)
        assert math.isfinite(result.value), kind
        return result.value

    assert value("count", 1) == pytest.approx(scores.count.error, rel=1e-12)
    assert value("nis", None) == pytest.approx(1.0 - scores.nis.inside, rel=1e-12)
    assert value("fragmentation", 1) >= value("count", 1)


def test_tune_gtrack_on_a_recording_with_validation(tmp_path, capsys) -> None:
    """`tune --tracker gtrack` on a recording without truth, chosen on a validation recording
    (the validation tracked gtrack's trials with the paper tracker and stopped with "unknown
    tracker parameter keys"); the chosen parameters are what `track --tracker gtrack` takes."""
    train = _no_truth(synthetic_dataset(5, 1, n_frames=80)).save(tmp_path / "rec.npz")
    val = _no_truth(synthetic_dataset(6, 1, n_frames=80)).save(tmp_path / "val.npz")
    storage = f"sqlite:///{tmp_path / 'g.db'}"
    code = main(["tune", "--tracker", "gtrack", "--trials", "3", "--dataset", str(train),
                 "--people", "1", "--validation", str(val), "--storage", storage,
                 "--study", "g", "--no-progress"])  # fmt: skip
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert "chosen trial" in captured.err
    out = json.loads(captured.out.strip().splitlines()[-1])
    assert out["loss"] == "fragmentation" and 0 <= out["validation_value"]
    p = tmp_path / "best.json"
    p.write_text(json.dumps(out["params"]))
    assert main(["track", "--tracker", "gtrack", "--data", str(val), "--params", str(p)]) == 0

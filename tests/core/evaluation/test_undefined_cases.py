"""Every metric is defined (or reported as undefined with its reason, never NaN) in the cases the
paper's single-person scenes never reach: no track confirmed, no person, a person absent for some
frames, several persons. Each case is computed by hand."""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest

from core.cli import main
from core.evaluation import evaluate, ospa, trajectory_loss
from core.tracking.batch import ConfirmedTracks, DatasetEstimates
from core.tracking.synthetic import SyntheticScene, synthetic_dataset


@pytest.fixture(scope="module")
def ds():
    """Two trajectories (classes a, b) of 60 frames, one person each, no clutter."""
    scene = SyntheticScene(clutter_per_frame=0.0)
    return synthetic_dataset(5, n_per_class=1, classes="ab", scene=scene, n_frames=60)


def _estimates(ds, est_xy, has, conf_xy):
    """DatasetEstimates over every trajectory; est_xy (F, 2), has (F,), conf_xy (F, C, 2).

    Column c of conf_xy is the track with id c, ranked by ψ in column order."""
    ok = np.isfinite(conf_xy[..., 0])
    c = conf_xy.shape[1]
    tracks = ConfirmedTracks.from_slots(
        np.where(ok, np.arange(c), -1), conf_xy, np.where(ok, 1.0 - 0.1 * np.arange(c), 0.0), ok
    )
    return DatasetEstimates(
        trajectories=np.arange(ds.n_trajectories),
        frame_index=np.arange(ds.n_frames),
        offsets=ds.trajectory_offsets,
        estimate_xy=np.where(has[:, None], est_xy, np.nan),
        has_estimate=has,
        estimate_psi=np.where(has, 0.9, np.nan),
        confirmed_xy=conf_xy,
        n_confirmed=np.isfinite(conf_xy[..., 0]).sum(1),
        n_tracks=np.isfinite(conf_xy[..., 0]).sum(1),
        tracks=tracks,
    )


def _no_nan_anywhere(ev) -> None:
    text = ev.format_table()
    assert "nan" not in text.lower() and "inf" not in text.lower(), text
    json.dumps(ev.to_dict(), allow_nan=False)  # raises on NaN or Inf


def test_no_track_ever_confirmed(ds) -> None:
    f = ds.n_frames
    ev = evaluate(
        ds, _estimates(ds, np.zeros((f, 2)), np.zeros(f, bool), np.full((f, 4, 2), np.nan))
    )
    _no_nan_anywhere(ev)
    np.testing.assert_array_equal(ev.loss, [1.0, 1.0])  # SPEC §5: never confirmed → 1 m²
    assert ev.loss_total == 1.0 and ev.confirmed_fraction == 0.0 and ev.far_frames_total == 0
    assert ev.ospa_mean_m == 1.0  # one person, no track: every frame costs c
    d = ev.to_dict()
    assert d["rmse_m"] is None and d["mean_first_confirmation_s"] is None
    assert "position RMSE        – (no track confirmed)" in ev.format_table()


def _absent_too(v: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """The velocities with a person absent (NaN) wherever its position is: the data-set rule."""
    v = np.array(v, dtype=float, copy=True)
    v[np.isnan(xy)] = np.nan
    return v


def test_no_person(ds) -> None:
    f = ds.n_frames
    empty = replace(
        ds,
        truth_xy_m=np.zeros((f, 0, 2)),
        truth_v_mps=np.zeros((f, 0, 2)),
        source=np.full_like(ds.source, -1),
    )
    has = np.zeros(f, bool)
    has[10:20] = True  # a clutter track confirmed in 10 frames
    xy = np.tile([1.0, 3.0], (f, 1))
    conf = np.full((f, 4, 2), np.nan)
    conf[has, 0] = xy[has]
    ev = evaluate(empty, _estimates(empty, xy, has, conf))
    _no_nan_anywhere(ev)
    # no frame in which a person could be scored: the loss is the no-confirmation value
    np.testing.assert_array_equal(ev.loss, [1.0, 1.0])
    np.testing.assert_array_equal(ev.n_c, [0, 0])
    assert math.isnan(ev.rmse_m)
    assert "position RMSE        – (no person present in a confirmed frame)" in ev.format_table()
    # every confirmed track is far from every person (there is none); OSPA: c where a track is
    assert ev.far_frames_total == 10
    assert ev.ospa_mean_m == pytest.approx(10 / f)


def test_person_absent_for_some_frames(ds) -> None:
    f = ds.n_frames
    truth = ds.truth_xy_m.copy()
    truth[10:20, 0] = np.nan  # trajectory 0: the person leaves for frames 10–19
    gone = replace(ds, truth_xy_m=truth, truth_v_mps=_absent_too(ds.truth_v_mps, truth))
    has = np.ones(f, bool)
    xy = np.nan_to_num(truth[:, 0]) + [0.1, 0.0]  # 0.1 m off where present, anywhere when absent
    conf = np.full((f, 4, 2), np.nan)
    conf[:, 0] = xy
    ev = evaluate(gone, _estimates(gone, xy, has, conf))
    _no_nan_anywhere(ev)
    n0 = int(ds.trajectory_offsets[1])
    # trajectory 0 is scored on the frames in which the person is present: N_c = n0 − 10
    assert ev.n_c[0] == n0 - 10
    assert ev.mse[0] == pytest.approx(0.01, abs=1e-12)
    assert ev.loss[0] == pytest.approx(0.01 / (n0 - 10), abs=1e-12)
    assert ev.rmse_m == pytest.approx(0.1, abs=1e-12)
    # OSPA: 0.1 m where present, c = 1 m for the track while the person is absent
    assert ev.ospa_mean_m == pytest.approx((0.1 * (f - 10) + 1.0 * 10) / f, abs=1e-12)
    # the track is within 1 m of nobody while the person is absent
    assert ev.far_frames_total == 10
    L, mse, n_c = trajectory_loss(xy[:n0], has[:n0], truth[:n0, 0])
    assert (n_c, mse) == (n0 - 10, pytest.approx(0.01, abs=1e-12))


def test_several_persons_ospa_over_the_persons_present(ds) -> None:
    f = ds.n_frames
    second = ds.truth_xy_m[:, :1] + [2.0, 0.0]
    second[:30] = np.nan  # person 1 enters at frame 30
    two = replace(
        ds,
        truth_xy_m=np.concatenate((ds.truth_xy_m, second), axis=1),
        truth_v_mps=_absent_too(
            np.concatenate((ds.truth_v_mps, ds.truth_v_mps[:, :1]), axis=1),
            np.concatenate((ds.truth_xy_m, second), axis=1),
        ),
    )
    has = np.ones(f, bool)
    conf = np.full((f, 4, 2), np.nan)
    conf[:, 0] = two.truth_xy_m[:, 0]  # a perfect track on person 0 throughout
    conf[:, 1] = ds.truth_xy_m[:, 0] + [2.0, 0.0]  # a track where person 1 is (from frame 30)
    ev = evaluate(two, _estimates(two, two.truth_xy_m[:, 0], has, conf))
    _no_nan_anywhere(ev)
    # frames < 30: one person, two tracks → one false track: sqrt((0 + c²)/2); later: 0
    assert ev.ospa_mean_m == pytest.approx(30 * math.sqrt(0.5) / f, abs=1e-12)
    # each person has a perfect estimate whenever present: the multi-person loss is 0
    assert ev.loss_total == 0.0 and ev.rmse_m == 0.0
    assert [m.n_c for m in ev.persons] == [f, f - 30]
    assert ev.far_frames_total == 30  # the second track is 2 m from person 0 before frame 30


def test_ospa_leaves_out_absent_rows() -> None:
    nan = [np.nan, np.nan]
    assert ospa(np.array([[0.3, 0.4]]), np.array([[0.0, 0.0], nan])) == pytest.approx(0.5)
    assert ospa(np.array([nan]), np.array([nan, nan])) == 0.0
    assert ospa(np.array([[0.0, 0.0], [5.0, 5.0]]), np.array([nan])) == 1.0


def test_track_cli_two_persons_prints_no_nan(ds, tmp_path, capsys) -> None:
    """The shipped two-person case end to end: tracked, every number printed, exit 0."""
    second = ds.truth_xy_m[:, :1] + [1.5, 0.5]
    second[::7] = np.nan  # absent now and then
    truth = ds.truth_xy_m.copy()
    truth[:5, 0] = np.nan  # person 0 enters late
    two = replace(
        ds,
        truth_xy_m=np.concatenate((truth, second), axis=1),
        truth_v_mps=_absent_too(
            np.concatenate((ds.truth_v_mps, ds.truth_v_mps[:, :1]), axis=1),
            np.concatenate((truth, second), axis=1),
        ),
    )
    data = two.save(tmp_path / "two.npz")
    out = tmp_path / "r.json"
    assert main(["track", "--data", str(data), "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "nan" not in text.lower() and "OSPA" in text
    doc = json.loads(out.read_text())
    json.dumps(doc, allow_nan=False)
    assert doc["ospa_mean_m"] is not None and doc["loss_total"] is not None


@pytest.mark.slow
def test_shipped_two_person_scene_simulated_then_tracked(tmp_path, capsys) -> None:
    """resources/scenes/two_persons.json: person 0 is absent for some frames (the reported
    ``ValueError: matrix contains invalid numeric entries`` in ``ospa``)."""
    from pathlib import Path

    scene = Path(__file__).resolve().parents[3] / "resources" / "scenes" / "two_persons.json"
    data = tmp_path / "x.npz"
    assert main(["simulate", "--scene", str(scene), "--out", str(data), "--fidelity", "fast"]) == 0
    out = tmp_path / "r.json"
    assert main(["track", "--data", str(data), "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "nan" not in text.lower() and "OSPA (c=1 m, p=2)" in text
    doc = json.loads(out.read_text())
    assert 0.0 <= doc["ospa_mean_m"] <= 1.0  # OSPA is bounded by the cut-off c = 1 m

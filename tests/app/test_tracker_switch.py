"""The tracker switch: paper IPDA / room mode / gtrack. The sliders follow the chosen tracker's
search space (core.tracking.space), its parameters build the tracker's own parameter object, and
a change re-tracks with it: each tracker follows a walking person's blob of points."""

from __future__ import annotations

import json

import numpy as np
import pytest

from app.data import FrameData
from core.config import PAPER_RADAR
from core.pointcloud import PointCloud

T = PAPER_RADAR.frame_period_s
N = 50


def _walker_frames() -> list[FrameData]:
    """A person as a blob of 30 points (σ 0.15 m) walking along +y at 1 m/s from (0.5, 2)."""
    rng = np.random.default_rng(1)
    frames = []
    for k in range(N):
        cx, cy, n = 0.5, 2.0 + 1.0 * k * T, 30
        x = cx + 0.15 * rng.standard_normal(n)
        y = cy + 0.15 * rng.standard_normal(n)
        z = 0.3 * rng.standard_normal(n)
        r = np.sqrt(x * x + y * y + z * z)
        cloud = PointCloud(
            range_m=r, azimuth_rad=np.arctan2(x, y), elevation_rad=np.arcsin(z / r),
            radial_velocity_mps=y / r, snr_db=np.full(n, 20.0), x_m=x, y_m=y, z_m=z,
            source=np.zeros(n, dtype=np.int32),
        )  # fmt: skip
        frames.append(FrameData(index=k, t_s=k * T, cloud=cloud, truth_xy_m=np.array([[cx, cy]])))
    return frames


def test_sliders_follow_the_chosen_tracker(qtbot) -> None:
    from app.engine import Engine
    from app.models import TrackerParamsModel
    from app.panels.tracker_panel import TrackerPanel
    from core.tracking import TrackerParams
    from core.tracking.gtrack import GtrackParams
    from core.tracking.space import GTRACK_SPACE, search_space

    model = TrackerParamsModel(Engine())
    panel = TrackerPanel(model)
    qtbot.addWidget(panel)
    model.set_value("q_coeff", 2.5)
    panel.tracker_combo.setCurrentIndex(panel.tracker_combo.findData("room"))
    assert model.tracker == "room"
    assert list(panel.rows) == [p.name for p in search_space("cv", "room")]
    assert isinstance(model.params(), TrackerParams) and model.params().mode == "room"
    assert model.values["q_coeff"] == 2.5  # a shared row keeps its value
    assert panel.fixed_group.isVisibleTo(panel) and panel.model_combo.isEnabled()
    panel.tracker_combo.setCurrentIndex(panel.tracker_combo.findData("gtrack"))
    assert list(panel.rows) == [p.name for p in GTRACK_SPACE]
    params = model.params()
    assert isinstance(params, GtrackParams)
    assert params.gating_gain == pytest.approx(3.0) and params.det2act == 3  # TI's defaults
    assert not panel.fixed_group.isVisibleTo(panel) and not panel.model_combo.isEnabled()
    assert "gtrack" in panel.params_group.title()
    # a slider edits gtrack's parameter (counters rounded to integers)
    panel.rows["det2act"].spin.setValue(5.0)
    assert model.params().det2act == 5 and json.loads(model.key())[0] == "gtrack"
    panel.tracker_combo.setCurrentIndex(panel.tracker_combo.findData("paper"))
    assert list(panel.rows) == [p.name for p in search_space("cv")]
    assert model.params().mode == "paper"


@pytest.mark.parametrize(
    ("tracker", "model", "mode"),
    [("paper", "cv", "paper"), ("room", "cv", "room"), ("gtrack", "gtrack", "paper")],
)
def test_each_tracker_follows_the_walker(tracker, model, mode) -> None:
    from app import engine as eng

    frames = _walker_frames()
    params = eng.make_params(model, eng.default_values(model, mode), {}, mode)
    res = eng.track(frames, params, T, engine="numpy")
    assert res.n_frames == N
    last = res.frames[-1]
    assert last.confirmed.sum() == 1
    y_end = 2.0 + (N - 1) * T
    xy = last.xy_m[last.confirmed][0]
    assert abs(xy[0] - 0.5) < 0.15 and abs(xy[1] - y_end) < 0.3
    # the velocity is read from the tracker's own state layout (gtrack 3-D: [x y z vx vy vz …])
    v = last.velocity_xy_mps[last.confirmed][0]
    assert abs(v[0]) < 0.2 and abs(v[1] - 1.0) < 0.2
    assert np.isfinite(res.estimate_xy_m[-1]).all()


def test_switching_trackers_retracks(qtbot, window, long_scene_doc, fill_cache) -> None:
    w = window
    fill_cache(w, long_scene_doc, _walker_frames())
    qtbot.waitUntil(lambda: w.tracking_model.result is not None, timeout=120000)
    w.tracker_panel.tracker_combo.setCurrentIndex(w.tracker_panel.tracker_combo.findData("gtrack"))
    qtbot.waitUntil(
        lambda: (
            w.tracking_model.result is not None
            and json.loads(w.tracking_model.result.params_key)[0] == "gtrack"
        ),
        timeout=120000,
    )
    result = w.tracking_model.result
    assert np.isnan(result.frames[-1].psi).all()  # gtrack has no existence probability
    assert result.frames[-1].confirmed.sum() == 1


def test_parameter_files_and_workspaces_keep_the_tracker(window, tmp_path) -> None:
    """Save tracker parameters of room mode or gtrack, load them: the tracker switches with
    them and every value comes back; a workspace stores the tracker too."""
    from core.tracking.gtrack import GtrackParams

    w = window
    w.scene_control.load_paper_scene()
    pm = w.params_model
    pm.set_tracker("gtrack")
    pm.set_value("points_thre", 12.0)
    g = tmp_path / "g.json"
    pm.params().save(g)
    pm.set_tracker("room")
    pm.set_value("ghost_gap", 0.7)
    room_values = pm.values
    r = tmp_path / "r.json"
    pm.params().save(r)
    pm.set_tracker("paper")
    assert w.load_params(g)
    assert pm.tracker == "gtrack" and pm.params().points_thre == 12
    assert isinstance(pm.params(), GtrackParams)
    assert w.load_params(r)
    assert pm.tracker == "room" and pm.values == pytest.approx(room_values)
    # a workspace: the tracker and its values round-trip
    ws = tmp_path / "ws.json"
    assert w.record.save_workspace(ws)
    assert json.loads(ws.read_text())["tracker"]["tracker"] == "room"
    pm.set_tracker("paper")
    assert w.record.open_workspace(ws)
    assert pm.tracker == "room" and pm.values == pytest.approx(room_values)
    doc = json.loads(ws.read_text())
    doc["tracker"]["tracker"] = "kalman"
    ws.write_text(json.dumps(doc))
    assert not w.record.open_workspace(ws)
    assert "tracker.tracker" in w.errors[-1] and pm.tracker == "room"


def test_study_and_live_link_refuse_another_tracker(window) -> None:
    """The study panel tunes the tracker the tracker panel shows (it follows a switch); the
    sliders of another tracker are not enqueued into it: one line. The live link tracks with
    the paper tracker or gtrack: with the room mode chosen it says so in one line (the link is
    not started)."""
    w = window
    w.params_model.set_tracker("gtrack")
    assert w.study_model.form.tracker == "gtrack"
    assert w.study_model.form.effective_name == "radartune-gtrack"
    w.study_model.set_form(tracker="room")  # chosen in the study panel
    w.enqueue_current()
    assert "study tunes the room tracker; the tracker panel shows gtrack" in w.errors[-1]
    w.params_model.set_tracker("room")
    w.live.start(None)  # refused before the settings are looked at
    assert "not the room mode" in w.errors[-1] and "choose 'paper' or 'gtrack'" in w.errors[-1]
    assert not w.live.running

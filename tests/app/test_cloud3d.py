"""The 3-D point-cloud view: its colour scales, track colouring and box edges (anywhere), the
one-line reason offscreen, and the drawing itself under Xvfb with Mesa (``make test-xcb``): the
points' pixels on screen, the sensor at its mounting height, Reset view, and the View menu."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6 import QtWidgets

from app.data import FrameData, TrackFrame
from app.views import cloud3d_view as c3
from core.pointcloud import PointCloud
from core.scene.room import Room, SensorPose


def _cloud(xyz: np.ndarray, snr_db: float = 30.0, v_mps: float = 0.0) -> PointCloud:
    x, y, z = (np.asarray(xyz, dtype=float)[:, k] for k in range(3))
    r = np.sqrt(x**2 + y**2 + z**2)
    n = len(x)
    return PointCloud(
        range_m=r,
        azimuth_rad=np.arctan2(x, y),
        elevation_rad=np.arcsin(z / r),
        radial_velocity_mps=np.full(n, v_mps),
        snr_db=np.full(n, snr_db),
        x_m=x,
        y_m=y,
        z_m=z,
        source=np.zeros(n, dtype=np.int64),
    )


def _tracks(xy: list[tuple[float, float]], ids: list[int]) -> TrackFrame:
    n = len(ids)
    return TrackFrame(
        track_id=np.array(ids),
        xy_m=np.array(xy, dtype=float),
        gate_center_xy_m=np.array(xy, dtype=float),
        gate_shape_xy_m2=np.tile(np.eye(2), (n, 1, 1)),
        psi=np.ones(n),
        confirmed=np.ones(n, dtype=bool),
    )


def test_scaled_colours_clip_to_the_ends_of_the_scale() -> None:
    lut = np.linspace(0, 1, c3.N_LUT)[:, None] * np.ones((1, 4))
    out = c3.scaled_colours(np.array([-100.0, 10.0, 30.0, 50.0, 100.0]), 10.0, 50.0, lut)
    assert out[0, 0] == out[1, 0] == 0.0 and out[3, 0] == out[4, 0] == 1.0
    # the middle of the range: the middle of the table (index round(0.5 * 63) = 32)
    assert out[2, 0] == pytest.approx(32 / 63)


def test_points_take_the_colour_of_the_nearest_track_within_reach() -> None:
    xy = np.array([[0.0, 3.0], [2.1, 5.0], [2.0 + c3.TRACK_RADIUS_M + 0.1, 5.0]])
    out = c3.track_colours(xy, _tracks([(0.2, 3.0), (2.0, 5.0)], [3, 14]))
    palette = np.asarray(c3.IDENTITY_PALETTE, dtype=np.float32) / 255
    np.testing.assert_allclose(out[0, :3], palette[3])
    np.testing.assert_allclose(out[1, :3], palette[14 % len(palette)])
    np.testing.assert_allclose(out[2], c3.NO_TRACK_RGBA)
    assert c3.track_colours(xy, TrackFrame.empty()).shape == (3, 4)


def test_box_edges_are_twelve_axis_parallel_edges_of_the_box() -> None:
    e = c3.box_edges((0, 1, 2, 4, 0, 3)).reshape(12, 2, 3)
    lengths = sorted(np.abs(e[:, 1] - e[:, 0]).sum(axis=1))
    assert lengths == [1] * 4 + [2] * 4 + [3] * 4  # each edge changes one coordinate
    assert {tuple(p) for p in e.reshape(-1, 3)} == {
        (x, y, z) for x in (0, 1) for y in (2, 4) for z in (0, 3)
    }


def test_offscreen_the_view_says_why_in_one_line(qtbot) -> None:
    if QtWidgets.QApplication.platformName() != "offscreen":
        pytest.skip("the offscreen platform's behaviour")
    v = c3.Cloud3DView()
    qtbot.addWidget(v)
    assert v.gl is None and "no OpenGL" in v.reason and "\n" not in v.reason
    assert v.findChild(QtWidgets.QLabel, "cloud3dReason").text() == v.reason
    frame = FrameData(
        index=0, t_s=0.0, cloud=_cloud(np.array([[0, 2, 0.5]])), truth_xy_m=np.zeros((0, 2))
    )
    v.show_frame(0, [frame])  # nothing to draw on, nothing raised
    assert v.n_draws == 1


# ---- under Xvfb (make test-xcb) ----
@pytest.fixture
def gl_view(qtbot):
    if QtWidgets.QApplication.platformName() != "xcb":
        pytest.skip("needs the real xcb platform (make test-xcb runs it under Xvfb)")
    v = c3.Cloud3DView()
    qtbot.addWidget(v)
    v.resize(500, 400)
    v.show()
    qtbot.waitExposed(v)
    assert v.reason is None, v.reason
    return v


@pytest.mark.xcb
def test_points_are_drawn_in_their_colour(gl_view, qtbot) -> None:
    v = gl_view
    v.set_scene(None)
    image = v.gl.grabFramebuffer()

    def yellow(img) -> int:  # plasma's top (SNR ≥ 50 dB) is yellow: (240, 249, 33)
        return sum(
            (c := img.pixelColor(x, y)).red() > 180 and c.green() > 180 and c.blue() < 120
            for x in range(0, img.width(), 2)
            for y in range(0, img.height(), 2)
        )

    empty = yellow(image)
    rng = np.random.default_rng(1)
    xyz = np.column_stack(
        (rng.uniform(-2, 2, 2000), rng.uniform(2, 6, 2000), rng.uniform(0, 2, 2000))
    )
    frame = FrameData(index=0, t_s=0.0, cloud=_cloud(xyz, snr_db=60.0), truth_xy_m=np.zeros((0, 2)))
    v.show_frame(0, [frame])
    assert v.last_n_points == 2000
    assert yellow(v.gl.grabFramebuffer()) > empty + 100


@pytest.mark.xcb
def test_room_sensor_pose_and_reset_view(gl_view) -> None:
    v = gl_view
    room = Room(walls=(), furniture=(), sensor=SensorPose(height_m=2.0, tilt_deg=15.0))

    class Scene:
        pass

    scene = Scene()
    scene.room = room
    v.set_scene(scene)
    np.testing.assert_allclose(v.sensor.pos[0], (0.0, 0.0, 2.0))
    # the boresight drawn 1.5 m ahead, 15° down
    ahead = v.boresight.pos[1] - v.boresight.pos[0]
    np.testing.assert_allclose(
        ahead, 1.5 * np.array([0, np.cos(np.radians(15)), -np.sin(np.radians(15))]), atol=1e-9
    )
    before = dict(v.gl.opts)
    v.gl.orbit(40, 10)
    v.gl.opts["distance"] *= 2
    v.reset_button.click()
    assert v.gl.opts["azimuth"] == before["azimuth"]
    assert v.gl.opts["elevation"] == before["elevation"]
    assert v.gl.opts["distance"] == before["distance"]


@pytest.mark.xcb
def test_three_d_dock_in_the_view_menu_draws_the_window_frame(
    qtbot, settings, long_scene_frames
) -> None:
    if QtWidgets.QApplication.platformName() != "xcb":
        pytest.skip("needs the real xcb platform")
    from app.window import MainWindow
    from tests.app.conftest import LONG_SCENE, _fill_cache

    w = MainWindow(settings, load_scene=False)
    qtbot.addWidget(w)
    w.resize(1400, 900)
    w.show()
    try:
        _, frames = long_scene_frames
        _fill_cache(w, LONG_SCENE, frames)
        view_menu = next(a.menu() for a in w.menuBar().actions() if a.text() == "&View")
        action = next(a for a in view_menu.actions() if a.text() == "3-D view")
        assert not w.views_control.cloud3d_dock.isVisible()
        action.trigger()
        qtbot.waitUntil(lambda: w.views_control.cloud3d_dock.isVisible(), timeout=5000)
        w.playback.set_frame(100)
        n0 = w.views_control.cloud3d.n_draws
        qtbot.waitUntil(lambda: w.views_control.cloud3d.n_draws > n0, timeout=5000)
        c = w.views_control.cloud3d
        expected = sum(len(f.cloud) for f in frames[100 - c.persistence + 1 : 101])
        assert c.last_n_points == expected > 0
    finally:
        w.shutdown()

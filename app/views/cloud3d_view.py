"""3-D point cloud (pyqtgraph's OpenGL widget): the sensor's pose, the room's walls (the
boundary) and furniture or the tracker's zones (boxes), the points of the last frames coloured by
SNR, height, Doppler or track, and the tracks as markers on a stem from the floor with their trail
on the floor. Rotate with the left mouse button, zoom with the wheel, *Reset view* goes back to
the view over the sensor's shoulder.

Coordinates: a scene with a room is drawn in the room's frame (x across, y along the horizontal
boresight, z up from the floor; the sensor at ``(0, 0, height)`` tilted down), the clouds (which
are in the sensor's frame) turned into it with ``SensorPose.to_room``. Without a room the radar's
frame is drawn as it is (the radar at the origin).

The OpenGL widget is made when the view is first shown: with a ``QOpenGLWidget`` in it, Qt
composes the whole main window through OpenGL at every repaint, which under Mesa's software
renderer costs tens of ms of CPU (``radartune bench gui`` measures the 3-D view's redraws).

OpenGL needs a real display: on Qt's ``offscreen`` platform (the test suite) or without PyOpenGL
the view shows one line saying why instead of the plot.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pyqtgraph as pg
from PySide6 import QtGui, QtWidgets

from app.colours import IDENTITY_PALETTE, identity_index
from app.data import FrameData, TrackFrame, TrackingResult
from app.geometry import trails_polyline

SNR_RANGE_DB = (10.0, 50.0)
HEIGHT_RANGE_M = (0.0, 2.5)
DOPPLER_RANGE_MPS = (-3.0, 3.0)
#: points farther than this from every track (x-y) are "no track" when coloured by track
TRACK_RADIUS_M = 0.8
N_LUT = 64
#: how a wall is drawn: from the floor to this height (a scene's walls have no height)
WALL_HEIGHT_M = 2.5
COLOUR_MODES = (("SNR", "snr"), ("height", "height"), ("Doppler", "doppler"), ("track", "track"))
NO_TRACK_RGBA = (0.55, 0.55, 0.55, 0.6)


def gl_unavailable_reason() -> str | None:
    """Why the 3-D view cannot draw here, in one line; ``None`` when it can."""
    app = QtGui.QGuiApplication.instance()
    platform = app.platformName() if isinstance(app, QtGui.QGuiApplication) else ""
    if platform in ("offscreen", "minimal"):
        return f"3-D view: no OpenGL on Qt's '{platform}' platform (run on a display)"
    try:
        import OpenGL.GL  # noqa: F401
        import pyqtgraph.opengl  # noqa: F401
    except Exception as exc:  # PyOpenGL missing or no libGL
        return f"3-D view: OpenGL unavailable ({type(exc).__name__}: {exc})"
    return None


def _lut(name: str) -> np.ndarray:
    """``(N_LUT, 4)`` RGBA in [0, 1] of a pyqtgraph colour map."""
    rgb = pg.colormap.get(name).getLookupTable(0.0, 1.0, N_LUT, alpha=False)
    out = np.ones((N_LUT, 4), dtype=np.float32)
    out[:, :3] = np.asarray(rgb, dtype=np.float32) / 255.0
    return out


def scaled_colours(values: np.ndarray, lo: float, hi: float, lut: np.ndarray) -> np.ndarray:
    """Colour of each value on ``lut`` between ``lo`` and ``hi`` (clipped), ``(n, 4)``."""
    k = np.clip((np.asarray(values, dtype=float) - lo) / (hi - lo), 0.0, 1.0) * (len(lut) - 1)
    return lut[np.round(k).astype(np.int64)]


def track_colours(xy_m: np.ndarray, tracks: TrackFrame) -> np.ndarray:
    """Each point coloured as the nearest track within :data:`TRACK_RADIUS_M` (x-y), grey where
    none is that close, ``(n, 4)``."""
    out = np.tile(np.asarray(NO_TRACK_RGBA, dtype=np.float32), (len(xy_m), 1))
    if len(tracks) == 0 or len(xy_m) == 0:
        return out
    d2 = ((xy_m[:, None, :] - tracks.xy_m[None, :, :]) ** 2).sum(axis=2)
    nearest = np.argmin(d2, axis=1)
    near = d2[np.arange(len(xy_m)), nearest] <= TRACK_RADIUS_M**2
    palette = np.asarray(IDENTITY_PALETTE, dtype=np.float32) / 255.0
    colour = palette[identity_index(tracks.track_id)[nearest[near]]]
    out[near, :3] = colour
    out[near, 3] = 1.0
    return out


def box_edges(box: Sequence[float]) -> np.ndarray:
    """The 12 edges of a box ``(xmin, xmax, ymin, ymax, zmin, zmax)`` as 24 points (pairs)."""
    x0, x1, y0, y1, z0, z1 = (float(v) for v in box)
    c = np.array([[x, y, z] for z in (z0, z1) for y in (y0, y1) for x in (x0, x1)])
    pairs = [(0, 1), (2, 3), (4, 5), (6, 7), (0, 2), (1, 3), (4, 6), (5, 7),
             (0, 4), (1, 5), (2, 6), (3, 7)]  # fmt: skip
    return np.array([c[i] for pair in pairs for i in pair])


class Cloud3DView(QtWidgets.QWidget):
    """The 3-D view with its own colour-by selector and *Reset view* button; call
    :meth:`set_scene` when the scene changes and :meth:`show_frame` per redraw."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setObjectName("cloud3dView")
        self.persistence = 5
        self.trail_length = 25
        self.colour_by = "snr"
        self.n_draws = 0
        self.last_n_points = 0
        self._pose = None  # core.scene.room.SensorPose, or None: the radar's frame
        self._scene_args: tuple | None = None  # what set_scene was given (drawn once shown)
        layout = QtWidgets.QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        bar = QtWidgets.QHBoxLayout()
        bar.addWidget(QtWidgets.QLabel("colour by"))
        self.colour_combo = QtWidgets.QComboBox()
        self.colour_combo.setObjectName("cloud3dColour")
        for label, key in COLOUR_MODES:
            self.colour_combo.addItem(label, key)
        self.colour_combo.currentIndexChanged.connect(
            lambda _i: setattr(self, "colour_by", self.colour_combo.currentData())
        )
        bar.addWidget(self.colour_combo)
        self.scale_label = QtWidgets.QLabel()
        bar.addWidget(self.scale_label)
        bar.addStretch(1)
        self.reset_button = QtWidgets.QPushButton("Reset view")
        self.reset_button.setObjectName("cloud3dReset")
        bar.addWidget(self.reset_button)
        layout.addLayout(bar)
        self.reason = gl_unavailable_reason()
        self.gl = None
        if self.reason is not None:
            label = QtWidgets.QLabel(self.reason)
            label.setObjectName("cloud3dReason")
            label.setWordWrap(True)
            layout.addWidget(label, 1)
            self.colour_combo.setEnabled(False)
            self.reset_button.setEnabled(False)
            return
        self._layout = layout
        self.reset_button.clicked.connect(self.reset_view)
        self.colour_combo.currentIndexChanged.connect(lambda _i: self._show_scale())
        self._show_scale()

    def showEvent(self, event) -> None:
        if self.gl is None and self.reason is None:
            self._build_gl(self._layout)
            if self._scene_args is not None:
                self.set_scene(*self._scene_args)
        super().showEvent(event)

    # ---- construction ----
    def _build_gl(self, layout: QtWidgets.QVBoxLayout) -> None:
        import pyqtgraph.opengl as gl

        self._gl = gl
        self.gl = gl.GLViewWidget()
        self.gl.setObjectName("cloud3dGL")
        self.gl.setBackgroundColor((20, 20, 24))
        self.gl.setMinimumSize(80, 40)
        layout.addWidget(self.gl, 1)
        self._luts = {"snr": _lut("plasma"), "height": _lut("viridis"), "doppler": _lut("CET-D1")}
        grid = gl.GLGridItem()
        grid.setSize(20, 20)
        grid.setSpacing(1, 1)
        grid.setColor((90, 90, 90, 120))
        grid.translate(0, 10, 0)
        self.gl.addItem(grid)
        self.sensor = gl.GLScatterPlotItem(
            pos=np.zeros((1, 3)), size=14, color=(1.0, 0.2, 0.9, 1.0), pxMode=True
        )
        self.boresight = gl.GLLinePlotItem(
            pos=np.zeros((2, 3)), color=(1.0, 0.2, 0.9, 1.0), width=2, mode="lines"
        )
        self.walls = gl.GLLinePlotItem(
            pos=np.zeros((0, 3)), color=(0.67, 0.59, 0.47, 1.0), width=1.5, mode="lines"
        )
        self.boxes = gl.GLLinePlotItem(
            pos=np.zeros((0, 3)), color=(0.59, 0.3, 0.0, 1.0), width=1.5, mode="lines"
        )
        self.zones = gl.GLLinePlotItem(
            pos=np.zeros((0, 3)), color=(0.3, 0.8, 1.0, 0.8), width=1, mode="lines"
        )
        self.points = gl.GLScatterPlotItem(pos=np.zeros((0, 3)), size=5, pxMode=True)
        self.points.setGLOptions("translucent")
        self.track_marks = gl.GLScatterPlotItem(pos=np.zeros((0, 3)), size=12, pxMode=True)
        self.stems = gl.GLLinePlotItem(pos=np.zeros((0, 3)), width=2, mode="lines")
        self.trails = gl.GLLinePlotItem(pos=np.zeros((0, 3)), width=2, mode="lines")
        for item in (self.sensor, self.boresight, self.walls, self.boxes, self.zones,
                     self.trails, self.stems, self.points, self.track_marks):  # fmt: skip
            self.gl.addItem(item)
        self.reset_view()

    def reset_view(self) -> None:
        """Over the sensor's shoulder, looking along the boresight into the area."""
        if self.gl is None:
            return
        self.gl.setCameraPosition(
            pos=pg.Vector(0.0, 4.0, 0.8), distance=13.0, elevation=28.0, azimuth=-90.0
        )

    def _show_scale(self) -> None:
        text = {
            "snr": f"{SNR_RANGE_DB[0]:g}–{SNR_RANGE_DB[1]:g} dB",
            "height": f"{HEIGHT_RANGE_M[0]:g}–{HEIGHT_RANGE_M[1]:g} m",
            "doppler": f"{DOPPLER_RANGE_MPS[0]:g}…+{DOPPLER_RANGE_MPS[1]:g} m/s",
            "track": f"≤ {TRACK_RADIUS_M:g} m",
        }[self.colour_by]
        self.scale_label.setText(text)
        self.scale_label.setToolTip(
            {
                "snr": "SNR, plasma colour map (dark: weak, yellow: strong)",
                "height": "height above the floor (the radar's z without a room), viridis",
                "doppler": "radial velocity: blue negative, white zero, red positive",
                "track": f"the nearest track within {TRACK_RADIUS_M:g} m in x-y; grey: none",
            }[self.colour_by]
        )

    # ---- the scene ----
    def set_scene(self, scene, zones=None) -> None:
        """The sensor's pose, the room's walls and furniture of a ``core.scene.Scene`` (or
        ``None``); ``zones`` (``core.tracking.zones.Zones``, sensor frame): its boundary and
        static boxes as well."""
        self._scene_args = (scene, zones)
        room = getattr(scene, "room", None)
        self._pose = None if room is None else room.sensor
        if self.gl is None:
            return
        origin = self._to_view(np.zeros((1, 3)))[0]
        ahead = self._to_view(np.array([[0.0, 1.5, 0.0]]))[0]
        self.sensor.setData(pos=origin[None, :])
        self.boresight.setData(pos=np.array([origin, ahead]))
        walls: list[np.ndarray] = []
        boxes: list[np.ndarray] = []
        if room is not None:
            for w in room.walls:
                (x0, y0), (x1, y1) = w.from_m, w.to_m
                h = WALL_HEIGHT_M
                walls.append(np.array([[x0, y0, 0], [x1, y1, 0], [x0, y0, h], [x1, y1, h],
                                       [x0, y0, 0], [x0, y0, h], [x1, y1, 0], [x1, y1, h]],
                                      dtype=float))  # fmt: skip
            for f in room.furniture:
                hx, hy = f.width_m / 2, f.depth_m / 2
                boxes.append(box_edges((f.x_m - hx, f.x_m + hx, f.y_m - hy, f.y_m + hy,
                                        0.0, f.height_m)))  # fmt: skip
        self.walls.setData(pos=np.concatenate(walls) if walls else np.zeros((0, 3)))
        self.boxes.setData(pos=np.concatenate(boxes) if boxes else np.zeros((0, 3)))
        self.set_zones(zones)

    def set_zones(self, zones) -> None:
        """The tracker's boundary box and static boxes (sensor frame), infinite limits clipped
        to 10 m; ``None``: none drawn."""
        if self.gl is None:
            return
        parts = []
        if zones is not None:
            for box in ((zones.boundary,) if zones.boundary else ()) + tuple(zones.static):
                b = np.clip(np.asarray(box, dtype=float), -10.0, 10.0)
                parts.append(self._to_view(box_edges(b)))
        self.zones.setData(pos=np.concatenate(parts) if parts else np.zeros((0, 3)))

    def _to_view(self, xyz_sensor_m: np.ndarray) -> np.ndarray:
        """Sensor-frame points in the drawn frame (the room's when there is one)."""
        xyz = np.asarray(xyz_sensor_m, dtype=float).reshape(-1, 3)
        return xyz if self._pose is None else self._pose.to_room(xyz)

    # ---- per frame ----
    def show_frame(
        self, index: int, frames: Sequence[FrameData], tracking: TrackingResult | None = None
    ) -> None:
        """Draw frame ``index`` with the points of the last ``persistence`` frames."""
        self.n_draws += 1
        if self.gl is None:
            return
        tf = TrackFrame.empty()
        if tracking is not None and 0 <= index < tracking.n_frames:
            tf = tracking.frames[index]
        if not frames or index < 0:
            self.points.setData(pos=np.zeros((0, 3)))
            self.last_n_points = 0
            self._show_tracks(TrackFrame.empty(), None, index, np.zeros((0, 3)))
            return
        index = min(index, len(frames) - 1)
        window = frames[max(0, index - self.persistence + 1) : index + 1]
        clouds = [f.cloud for f in window]
        xyz_s = np.column_stack(
            [np.concatenate([getattr(c, a) for c in clouds]) for a in ("x_m", "y_m", "z_m")]
        )
        pos = self._to_view(xyz_s)
        if self.colour_by == "snr":
            colour = scaled_colours(
                np.concatenate([c.snr_db for c in clouds]), *SNR_RANGE_DB, self._luts["snr"]
            )
        elif self.colour_by == "height":
            colour = scaled_colours(pos[:, 2], *HEIGHT_RANGE_M, self._luts["height"])
        elif self.colour_by == "doppler":
            v = np.concatenate([c.radial_velocity_mps for c in clouds])
            colour = scaled_colours(v, *DOPPLER_RANGE_MPS, self._luts["doppler"])
        else:
            colour = track_colours(xyz_s[:, :2], tf)
        self.points.setData(pos=pos, color=colour)
        self.last_n_points = len(pos)
        cur = frames[index].cloud
        current = np.column_stack((cur.x_m, cur.y_m, cur.z_m)) if len(cur) else np.zeros((0, 3))
        self._show_tracks(tf, tracking, index, current)

    def _show_tracks(
        self, tf: TrackFrame, tracking: TrackingResult | None, index: int, current: np.ndarray
    ) -> None:
        """Tracks as markers at the median height of this frame's points near them (sensor
        frame), on a stem from the floor, with their trails on the floor."""
        n = len(tf)
        if n == 0:
            for item in (self.track_marks, self.stems, self.trails):
                item.setData(pos=np.zeros((0, 3)))
            return
        z_s = np.zeros(n)
        for k in range(n):
            d2 = ((current[:, :2] - tf.xy_m[k]) ** 2).sum(axis=1)
            near = d2 <= TRACK_RADIUS_M**2
            if near.any():
                z_s[k] = float(np.median(current[near, 2]))
        top = self._to_view(np.column_stack((tf.xy_m, z_s)))
        floor = top.copy()
        floor[:, 2] = 0.0 if self._pose is not None else min(0.0, float(top[:, 2].min()))
        palette = np.asarray(IDENTITY_PALETTE, dtype=np.float32) / 255.0
        rgba = np.ones((n, 4), dtype=np.float32)
        rgba[:, :3] = palette[identity_index(tf.track_id)]
        rgba[~tf.confirmed, 3] = 0.45
        self.track_marks.setData(pos=top, color=rgba)
        self.stems.setData(
            pos=np.stack((floor, top), axis=1).reshape(-1, 3), color=np.repeat(rgba, 2, axis=0)
        )
        segments, seg_colours = [], []
        if tracking is not None:
            live = tf.track_id[tf.confirmed]
            for tid in live:
                t = trails_polyline(
                    tracking.trail_id, tracking.trail_t_index, tracking.trail_xy_m,
                    index, self.trail_length, np.array([tid]),
                )  # fmt: skip
                if len(t) < 2:
                    continue
                p = self._to_view(np.column_stack((t, np.zeros(len(t)))))
                p[:, 2] = floor[0, 2]
                segments.append(np.stack((p[:-1], p[1:]), axis=1).reshape(-1, 3))
                c = palette[identity_index(np.array([tid]))[0]]
                seg_colours.append(np.tile(np.append(c, 0.9), (2 * (len(t) - 1), 1)))
        if segments:
            self.trails.setData(pos=np.concatenate(segments), color=np.concatenate(seg_colours))
        else:
            self.trails.setData(pos=np.zeros((0, 3)))

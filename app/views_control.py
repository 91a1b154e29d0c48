"""The radar views a radar engineer expects beside the top view: range-azimuth map, range
profile with its CFAR threshold, micro-Doppler spectrogram of the selected person, elevation
view, and the track table. Built into the main window as two docks; drawn from the window's
draw timer (only the visible ones), from the models' data, never computing."""

from __future__ import annotations

import numpy as np
from PySide6 import QtCore, QtWidgets

from app.views.cloud3d_view import Cloud3DView
from app.views.elevation_view import ElevationView
from app.views.people_table import PeopleTable
from app.views.ra_view import RangeAzimuthView
from app.views.range_profile_view import RangeProfileView
from app.views.spectrogram_view import MicroDopplerView
from app.views.track_table import TrackTable

#: below this available height (logical px) the two docks start closed
SMALL_SCREEN_HEIGHT_PX = 700


class ViewsController(QtCore.QObject):
    """Owns the radar views and the track table of a :class:`~app.window.MainWindow`."""

    def __init__(self, window) -> None:
        super().__init__(window)
        self._window = window
        self.ra_view = RangeAzimuthView()
        self.profile_view = RangeProfileView()
        self.spectrogram_view = MicroDopplerView()
        self.elevation_view = ElevationView()
        self.track_table = TrackTable()
        self.people_table = PeopleTable()
        tracks_and_people = QtWidgets.QSplitter(QtCore.Qt.Vertical)
        tracks_and_people.addWidget(self.track_table)
        tracks_and_people.addWidget(self.people_table)
        self.tabs = QtWidgets.QTabWidget()
        self.tabs.setObjectName("radarViewTabs")
        self.tabs.addTab(self.ra_view, "Range-azimuth")
        self.tabs.addTab(self.profile_view, "Range profile")
        self.tabs.addTab(self.spectrogram_view, "Micro-Doppler")
        self.tabs.addTab(self.elevation_view, "Elevation")
        # small minimum heights: the window must still fit 1366x768 at 150 % (512 logical px)
        for widget in (self.tabs, self.track_table, self.people_table, self.ra_view,
                       self.profile_view, self.spectrogram_view, self.elevation_view):  # fmt: skip
            widget.setMinimumSize(80, 40)
        self.views_dock = self._dock("Radar views", self.tabs)
        # the 3-D point cloud: starts closed (View → 3-D view), OpenGL only on a display
        self.cloud3d = Cloud3DView()
        self.cloud3d.setMinimumSize(80, 40)
        self.cloud3d_dock = self._dock("3-D view", self.cloud3d)
        self.cloud3d_dock.hide()
        self.cloud3d.reset_button.clicked.connect(window._mark_dirty)
        self.cloud3d.colour_combo.currentIndexChanged.connect(lambda _i: window._mark_dirty())
        self.cloud3d_dock.visibilityChanged.connect(lambda _v: window._mark_dirty())
        self.tracks_dock = self._dock("Tracks", tracks_and_people)
        # side by side under the central views: the track table beside the radar views
        window.splitDockWidget(self.views_dock, self.tracks_dock, QtCore.Qt.Horizontal)
        window.resizeDocks([self.views_dock], [250], QtCore.Qt.Vertical)
        window.resizeDocks([self.views_dock, self.tracks_dock], [3, 2], QtCore.Qt.Horizontal)
        # a small logical screen (1366x768 at 150 %: 512 px) has no height to spare for them:
        # they start closed there (View menu opens them)
        screen = window.screen() or QtWidgets.QApplication.primaryScreen()
        if screen is not None and screen.availableGeometry().height() < SMALL_SCREEN_HEIGHT_PX:
            self.views_dock.hide()
            self.tracks_dock.hide()
        view_menu = next(
            (a.menu() for a in window.menuBar().actions() if a.text() == "&View"), None
        )
        if view_menu is not None:
            view_menu.addAction(self.views_dock.toggleViewAction())
            view_menu.addAction(self.tracks_dock.toggleViewAction())
            view_menu.addAction(self.cloud3d_dock.toggleViewAction())
        window.scene_control.info_changed.connect(self._on_scene_info)
        window.scene_model.selection_changed.connect(self._on_person)
        window.cache.reset.connect(self.spectrogram_view.reset)
        self.tabs.currentChanged.connect(lambda _i: window._mark_dirty())
        self.views_dock.visibilityChanged.connect(lambda _v: window._mark_dirty())
        self.tracks_dock.visibilityChanged.connect(lambda _v: window._mark_dirty())

    def _dock(self, title: str, widget: QtWidgets.QWidget) -> QtWidgets.QDockWidget:
        dock = QtWidgets.QDockWidget(title, self._window)
        dock.setObjectName(f"dock{title.replace(' ', '')}")
        dock.setWidget(widget)
        # not in window.docks: those are the panels' docks (scroll areas) the window arranges;
        # the views stay in the bottom area, across the window's width
        self._window.addDockWidget(QtCore.Qt.BottomDockWidgetArea, dock)
        return dock

    def _on_scene_info(self, info) -> None:
        radar = info.radar
        max_r = float(info.aoi["max_range_m"])
        self.ra_view.set_radar(radar, max_r)
        self.profile_view.set_radar(radar, max_r)
        self.spectrogram_view.set_radar(radar, info.frame_period_s)
        self.track_table.frame_period_s = info.frame_period_s
        scene = self._window.scene_model.scene
        xyz = np.array(
            [[r.x_m, r.y_m, r.z_m] for r in getattr(scene, "static_reflectors", ())], dtype=float
        ).reshape(-1, 3)
        measures = bool(scene is not None and radar.has_elevation and not scene.is_planar)
        self.elevation_view.set_scene(max_r, xyz, measures_elevation=measures)
        self.cloud3d.set_scene(scene)

    def _on_person(self, index: int) -> None:
        self.spectrogram_view.set_person(index)
        self._window._mark_dirty()

    def redraw(self, index: int, frame, result) -> None:
        """Draw the frame shown in the views that are visible (called by the window's draw)."""
        frames = self._window.cache.frames
        if self.views_dock.isVisible() and not self.views_dock.visibleRegion().isEmpty():
            current = self.tabs.currentWidget()
            if current is self.ra_view:
                self.ra_view.show_frame(frame)
            elif current is self.profile_view:
                self.profile_view.show_frame(frame)
            elif current is self.spectrogram_view:
                self.spectrogram_view.show_frame(index, frames)
            elif current is self.elevation_view:
                self.elevation_view.persistence = self._window.top_view.persistence
                self.elevation_view.show_frame(index, frames)
        if self.cloud3d_dock.isVisible() and not self.cloud3d_dock.visibleRegion().isEmpty():
            self._draw_cloud3d(index, frames, result)
        if self.tracks_dock.isVisible() and not self.tracks_dock.visibleRegion().isEmpty():
            tf = result.frames[index] if result is not None and index < result.n_frames else None
            self.track_table.show_tracks(tf, index)
            self.people_table.show_people(None if result is None else result.people, index)

    def _draw_cloud3d(self, index: int, frames, result) -> None:
        top = self._window.top_view
        self.cloud3d.persistence, self.cloud3d.trail_length = top.persistence, top.trail_length
        self.cloud3d.show_frame(index, frames, result)

    def draw_all(self, index: int, frame, result) -> None:
        """Draw every view whether visible or not (exports, tests)."""
        frames = self._window.cache.frames
        self.ra_view.show_frame(frame)
        self.profile_view.show_frame(frame)
        self.spectrogram_view.show_frame(index, frames)
        self.elevation_view.persistence = self._window.top_view.persistence
        self.elevation_view.show_frame(index, frames)
        self._draw_cloud3d(index, frames, result)
        tf = result.frames[index] if result is not None and index < result.n_frames else None
        self.track_table.show_tracks(tf, index)
        self.people_table.show_people(None if result is None else result.people, index)

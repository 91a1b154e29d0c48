"""Playback: the play timer, play / pause / step, speed and the frame index.

:class:`PlaybackController` builds the playback bar (bottom tool bar of the window) and binds it
both ways to the :class:`~app.models.PlaybackModel`: the bar's actions edit the model, the model's
signals update the bar (signals blocked while syncing). The play timer steps the model at the
scene's frame period divided by the speed; the frame index is bounded by the frames cached so far.
"""

from __future__ import annotations

from PySide6 import QtCore, QtGui, QtWidgets

from app.models import FrameCache, PlaybackModel
from core.config import PAPER_RADAR

SPEEDS = (0.25, 0.5, 1.0, 2.0, 4.0, 8.0)


class PlaybackController(QtCore.QObject):
    """Owns the play timer and the playback bar of ``window`` (a ``QMainWindow``)."""

    def __init__(
        self, model: PlaybackModel, cache: FrameCache, window: QtWidgets.QMainWindow
    ) -> None:
        super().__init__(window)
        self.model = model
        self.cache = cache
        self.frame_period_s = PAPER_RADAR.frame_period_s
        self.timer = QtCore.QTimer(self)
        self.timer.timeout.connect(self._on_tick)
        self._build_bar(window)
        model.frame_changed.connect(self._on_frame_changed)
        model.playing_changed.connect(self._on_playing_changed)
        model.speed_changed.connect(self._on_speed_changed)
        cache.reset.connect(self._on_cache_reset)
        cache.frames_added.connect(self._on_frames_added)
        self._update_interval()

    def _build_bar(self, window: QtWidgets.QMainWindow) -> None:
        bar = QtWidgets.QToolBar("Playback", window)
        bar.setObjectName("playbackBar")
        self.bar = bar
        window.addToolBar(QtCore.Qt.BottomToolBarArea, bar)
        style = window.style()
        self.act_back = bar.addAction(
            style.standardIcon(QtWidgets.QStyle.SP_MediaSeekBackward), "Step back"
        )
        self.act_play = bar.addAction(style.standardIcon(QtWidgets.QStyle.SP_MediaPlay), "Play")
        self.act_play.setCheckable(True)
        self.act_fwd = bar.addAction(
            style.standardIcon(QtWidgets.QStyle.SP_MediaSeekForward), "Step forward"
        )
        self.act_back.setShortcut(QtGui.QKeySequence(QtCore.Qt.Key_Left))
        self.act_fwd.setShortcut(QtGui.QKeySequence(QtCore.Qt.Key_Right))
        self.act_play.setShortcut(QtGui.QKeySequence(QtCore.Qt.Key_Space))
        self.speed_combo = QtWidgets.QComboBox()
        self.speed_combo.setObjectName("speedCombo")
        for s in SPEEDS:
            self.speed_combo.addItem(f"{s:g}×", s)
        self.speed_combo.setCurrentIndex(SPEEDS.index(1.0))
        bar.addWidget(QtWidgets.QLabel(" speed "))
        bar.addWidget(self.speed_combo)
        self.timeline = QtWidgets.QSlider(QtCore.Qt.Horizontal)
        self.timeline.setObjectName("timeline")
        self.timeline.setRange(0, 0)
        self.timeline.setMinimumWidth(300)
        bar.addWidget(self.timeline)
        self.frame_label = QtWidgets.QLabel("frame – / –")
        self.frame_label.setObjectName("frameLabel")
        self.frame_label.setMinimumWidth(170)
        bar.addWidget(self.frame_label)
        self.fps_label = QtWidgets.QLabel()  # written by the window's draw timer
        self.fps_label.setObjectName("fpsLabel")
        self.fps_label.setMinimumWidth(230)
        bar.addWidget(self.fps_label)
        self.act_back.triggered.connect(lambda: self.step(-1))
        self.act_fwd.triggered.connect(lambda: self.step(1))
        self.act_play.toggled.connect(self.model.set_playing)
        self.speed_combo.currentIndexChanged.connect(
            lambda i: self.model.set_speed(self.speed_combo.itemData(i))
        )
        self.timeline.valueChanged.connect(self.model.set_frame)

    # ---- commands ----
    def step(self, delta: int) -> None:
        """Pause and move ``delta`` frames."""
        self.model.set_playing(False)
        self.model.step(delta)

    def set_frame_period(self, frame_period_s: float) -> None:
        """The scene's frame period (s): the play timer's interval at speed 1."""
        self.frame_period_s = frame_period_s
        self._update_interval()

    def stop(self) -> None:
        self.timer.stop()

    # ---- model -> bar ----
    def _on_frame_changed(self, index: int) -> None:
        self.timeline.blockSignals(True)
        self.timeline.setValue(index)
        self.timeline.blockSignals(False)
        self.update_frame_label()

    def _on_playing_changed(self, playing: bool) -> None:
        self.act_play.blockSignals(True)
        self.act_play.setChecked(playing)
        self.act_play.blockSignals(False)
        icon = QtWidgets.QStyle.SP_MediaPause if playing else QtWidgets.QStyle.SP_MediaPlay
        self.act_play.setIcon(self.bar.style().standardIcon(icon))
        self.act_play.setText("Pause" if playing else "Play")
        if playing:
            self.timer.start()
        else:
            self.timer.stop()

    def _on_speed_changed(self, speed: float) -> None:
        i = self.speed_combo.findData(speed)
        if i >= 0:
            self.speed_combo.blockSignals(True)
            self.speed_combo.setCurrentIndex(i)
            self.speed_combo.blockSignals(False)
        self._update_interval()

    def _update_interval(self) -> None:
        self.timer.setInterval(max(1, int(round(1000 * self.frame_period_s / self.model.speed))))

    # ---- cache -> frame range ----
    def _on_cache_reset(self) -> None:
        self.model.set_available(0)
        self.model.set_frame(0)
        self.timeline.setRange(0, 0)

    def _on_frames_added(self, n: int) -> None:
        self.model.set_available(n)
        self.timeline.blockSignals(True)
        self.timeline.setRange(0, max(n - 1, 0))
        self.timeline.blockSignals(False)
        self.update_frame_label()

    def _on_tick(self) -> None:
        n = self.model.n_available
        if n == 0:
            return
        if self.model.frame + 1 < n:
            self.model.step(1)
        elif self.cache.complete and self.model.loop:
            self.model.set_frame(0)

    def update_frame_label(self) -> None:
        total = self.cache.expected or len(self.cache)
        t = self.model.frame * self.frame_period_s
        n = len(self.cache)
        # out of the scene's frames; how many are simulated only while the cache fills
        filling = f" ({n} simulated so far)" if n < total else ""
        self.frame_label.setText(
            f" frame {self.model.frame + 1 if n else 0} / {total}{filling} · {t:5.2f} s"
        )

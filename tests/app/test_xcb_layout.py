"""The real window under Xvfb (Qt's xcb platform): ``make test-xcb`` runs this on a 1366x768
and a 1920x1080 screen, at 100 % and 150 % (``QT_SCALE_FACTOR``). Offscreen it is skipped.

What a user saw clipped or lost is checked on the laid-out window: every panel fits
its dock without a horizontal scroll bar, the "Load TI .cfg" button is inside the dock, the top
view shows the whole area of interest without wasting most of its height, the range-Doppler
colour bar's labels are inside the view, and the first track is drawn.
"""

from __future__ import annotations

import pytest
from PySide6 import QtCore, QtWidgets

pytestmark = pytest.mark.xcb


@pytest.fixture
def shown_window(qtbot, settings):
    if QtWidgets.QApplication.platformName() != "xcb":
        pytest.skip("needs the real xcb platform (make test-xcb runs it under Xvfb)")
    from app.window import MainWindow

    w = MainWindow(settings)  # empty settings: the first start's layout, paper scene
    qtbot.addWidget(w)
    w.setGeometry(w.screen().availableGeometry())
    w.show()
    qtbot.waitExposed(w)
    qtbot.waitUntil(lambda: w.cache.complete, timeout=300000)
    qtbot.waitUntil(
        lambda: (
            w.tracker.idle
            and w.tracking_model.result is not None
            and w.tracking_model.result.n_frames == len(w.cache)
        ),
        timeout=300000,
    )
    w.redraw()
    qtbot.wait(200)
    yield w
    w.shutdown()


def _inside(widget: QtWidgets.QWidget, window: QtWidgets.QWidget) -> bool:
    top_left = widget.mapTo(window, QtCore.QPoint(0, 0))
    rect = QtCore.QRect(top_left, widget.size())
    return window.rect().contains(rect)


def test_first_start_layout_fits_the_screen(shown_window) -> None:
    w = shown_window
    screen = w.screen().availableGeometry()
    assert w.frameGeometry().width() <= screen.width() + 1
    assert w.height() <= screen.height()
    for title, dock in w.docks.items():
        dock.raise_()
        QtWidgets.QApplication.processEvents()
        scroll = dock.widget()
        assert not scroll.horizontalScrollBar().isVisible(), f"{title} panel scrolls sideways"
    w.docks["Radar"].raise_()
    QtWidgets.QApplication.processEvents()
    button = w.radar_panel.load_button
    viewport = w.docks["Radar"].widget().viewport()
    pos = button.mapTo(viewport, QtCore.QPoint(0, 0))
    assert pos.x() >= 0 and pos.x() + button.width() <= viewport.width(), "Load TI .cfg cut off"
    # the top view: the whole area (0.5–10 m, ±60°) and no more than 2.5x its height
    (x0, x1), (y0, y1) = w.top_view.getPlotItem().vb.viewRange()
    assert y0 <= 0.0 and y1 >= 10.0 and x0 <= -8.6 and x1 >= 8.6
    assert (y1 - y0) <= 2.5 * 10.7, f"top view shows {y0:.1f}…{y1:.1f} m for a 10 m area"
    # the colour bar (its axis labels included) lies inside the range-Doppler view
    bar = w.rd_view.colorbar
    rect = bar.mapRectToScene(bar.boundingRect())
    assert w.rd_view.sceneRect().contains(rect) or rect.right() <= w.rd_view.width() + 1
    assert w.tracking_model.result.n_frames == len(w.cache) > 0

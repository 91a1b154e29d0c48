"""A view's "cannot show this" state: a message over the whole view instead of empty or
meaningless axes (a recording of points has no range-Doppler map to show)."""

from __future__ import annotations

from PySide6 import QtCore, QtWidgets


class _Cover(QtWidgets.QLabel):
    """A label covering its parent view, following its size."""

    def __init__(self, view: QtWidgets.QWidget) -> None:
        super().__init__(view)
        self.setObjectName("unavailableCover")
        self.setWordWrap(True)
        self.setAlignment(QtCore.Qt.AlignCenter)
        self.setMargin(16)
        self.setAutoFillBackground(True)
        self.setStyleSheet("background: #202020; color: #d8d8d8; font-size: 13px")
        view.installEventFilter(self)
        self.setGeometry(view.rect())

    def eventFilter(self, obj, event) -> bool:
        if event.type() == QtCore.QEvent.Resize:
            self.setGeometry(obj.rect())
        return False


def set_unavailable(view: QtWidgets.QWidget, reason: str | None) -> None:
    """Cover ``view`` with ``reason`` (why it cannot be drawn); ``None`` uncovers it."""
    cover = view.findChild(_Cover, "unavailableCover", QtCore.Qt.FindDirectChildrenOnly)
    if reason is None:
        if cover is not None:
            cover.hide()
        return
    if cover is None:
        cover = _Cover(view)
    cover.setText(reason)
    cover.setGeometry(view.rect())
    cover.raise_()
    cover.show()


def unavailable_reason(view: QtWidgets.QWidget) -> str | None:
    """The reason ``view`` shows, None when it draws."""
    cover = view.findChild(_Cover, "unavailableCover", QtCore.Qt.FindDirectChildrenOnly)
    return cover.text() if cover is not None and not cover.isHidden() else None

"""Axes painted from a cached pixmap: a redraw during playback changes the data, not the axes,
and repainting their tick labels was 40 % of a redraw (profiled under ``radartune bench gui``)."""

from __future__ import annotations

import pyqtgraph as pg
from PySide6 import QtWidgets


def cache_axes(*plots: pg.PlotItem) -> None:
    """Give every axis of ``plots`` a device-coordinate cache (redrawn only when it changes)."""
    for plot in plots:
        for name in ("left", "bottom", "right", "top"):
            axis = plot.getAxis(name)
            axis.setCacheMode(QtWidgets.QGraphicsItem.DeviceCoordinateCache)

"""Clicks on the 3D view: a click told from a drag, and the triangle under it.

:class:`ClickWatch` tells a click (left press and release within :data:`CLICK_SLOP`
pixels) from a drag, which rotates or pans the view; the view's tools and the picker
share it. :class:`ViewPicker` turns a click into the triangle under the mouse. A flat
mesh is picked from the core's arrays (its ``locate`` hook: the camera ray meets the
mesh's plane and a point-in-triangle search finds the triangle, at any mesh size,
whatever is drawn); a curved imported mesh with VTK's ``vtkCellPicker`` restricted to the
faces actor.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any, cast

import numpy as np
from PySide6.QtCore import QEvent, QObject, QPointF, Qt, Signal
from PySide6.QtGui import QMouseEvent
from vtkmodules.vtkRenderingCore import vtkCellPicker

log = logging.getLogger(__name__)

#: A press and release closer than this (px) is a click; farther is a drag (rotate/pan).
CLICK_SLOP = 4


class ClickWatch:
    """Follows the left button on a widget: :meth:`is_click` is True for the release of
    a press that moved at most :data:`CLICK_SLOP` pixels (a drag is not a click)."""

    def __init__(self) -> None:
        self._press: QPointF | None = None

    def press(self, event: QEvent) -> None:
        """Note a left press (the view's tools call this where they see presses)."""
        self._press = event.position()  # type: ignore[attr-defined]

    def is_click(self, event: QEvent) -> bool:
        """Feed every event of the widget; True on the release that ends a click."""
        kind = event.type()
        left = kind in (QEvent.Type.MouseButtonPress, QEvent.Type.MouseButtonRelease) and (
            event.button() == Qt.MouseButton.LeftButton  # type: ignore[attr-defined]
        )
        if not left:
            return False
        if kind == QEvent.Type.MouseButtonPress:
            self.press(event)
            return False
        if self._press is None:
            return False
        moved = (event.position() - self._press).manhattanLength()  # type: ignore[attr-defined]
        self._press = None
        return moved <= CLICK_SLOP


class ViewPicker(QObject):
    """Clicks on the 3D view → ``triangle_picked(triangle, world_point)``.

    Parameters
    ----------
    plotter : pyvistaqt.QtInteractor
    faces_actor : vtkActor
        The actor whose cells are the mesh's triangles, in order.

    Attributes
    ----------
    locate : callable or None
        ``locate(x, y, defer) -> (triangle or None, point) or None``: the triangle of the
        mesh's own arrays under display point (x, y) and the point on the mesh, or None
        when it cannot tell (no mesh, a curved mesh): then VTK picks what is drawn. With
        ``defer`` a click that comes before the mesh's search structure is ready is
        answered (``triangle_picked``) once it is.
    """

    triangle_picked = Signal(int, object)

    def __init__(self, plotter: Any, faces_actor: Any, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.plotter = plotter
        self.enabled = False
        self.suspended = False  # the measure tool takes the clicks
        self.faces_actor = faces_actor
        self.locate: (
            Callable[[float, float, bool], tuple[int | None, np.ndarray | None] | None] | None
        ) = None
        self.picker = vtkCellPicker()
        self.picker.SetTolerance(1e-4)
        self.picker.PickFromListOn()
        self.picker.AddPickList(faces_actor)
        self._clicks = ClickWatch()
        plotter.installEventFilter(self)

    def pick_display(self, x: float, y: float, emit: bool = True) -> tuple[int, np.ndarray] | None:
        """Pick at VTK display coordinates (pixels, origin bottom left).

        Returns the triangle and the picked world point, or None off the mesh. Emits
        ``triangle_picked`` on a hit (unless ``emit`` is false). A flat mesh is searched
        in its arrays (:attr:`locate`), so a dense mesh drawn reduced is picked as
        exactly as a small one. Otherwise the triangles are picked by VTK, even while
        the Triangles layer is hidden (VTK skips invisible actors, so the faces are made
        visible for the pick, which draws nothing); a flat mesh's click that neither
        finds (its locator still being built) is answered when the locator is ready.
        """
        locate = self.locate
        located = locate(float(x), float(y), False) if locate is not None else None
        if located is not None and located[0] is not None and located[1] is not None:
            triangle, point = int(located[0]), located[1]
            if emit:
                self.triangle_picked.emit(triangle, point)
            return triangle, point
        hit = self._vtk_pick(x, y, emit)
        if hit is None and located is not None and locate is not None and emit:
            locate(float(x), float(y), True)  # a big mesh's locator not ready: later
        return hit

    def _vtk_pick(self, x: float, y: float, emit: bool) -> tuple[int, np.ndarray] | None:
        """VTK's pick of what is drawn (a curved mesh; a flat one before its locator)."""
        renderer = self.plotter.renderer
        actor = self.faces_actor
        hidden = not actor.GetVisibility()
        if hidden:
            actor.SetVisibility(True)
        try:
            found = self.picker.Pick(float(x), float(y), 0.0, renderer)
        finally:
            if hidden:
                actor.SetVisibility(False)
        if not found:
            return None
        cell = int(self.picker.GetCellId())
        if cell < 0:
            return None
        # the faces of a dense mesh's detail are a part of it: the "triangle" cell array
        # holds each cell's triangle in the mesh (barymesh.app.view.scene_data.detail_data)
        data = self.picker.GetDataSet()
        ids = data.GetCellData().GetArray("triangle") if data is not None else None
        if ids is not None and cell < ids.GetNumberOfTuples():
            cell = int(ids.GetValue(cell))
        point = np.array(self.picker.GetPickPosition(), dtype=np.float64)
        if emit:
            self.triangle_picked.emit(cell, point)
        return cell, point

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:  # noqa: N802 - Qt's name
        if self._clicks.is_click(event):
            if self.enabled and not self.suspended:
                try:
                    ratio = self.plotter.devicePixelRatioF()
                    pos = cast(QMouseEvent, event).position()  # a click: a mouse release
                    height = self.plotter.height()
                    self.pick_display(pos.x() * ratio, (height - 1 - pos.y()) * ratio)
                except Exception:  # noqa: BLE001 - a failed pick must never crash the window
                    log.exception("picking failed")
        return False  # the view still gets every event (rotate, zoom)

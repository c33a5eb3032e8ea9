"""Cell ▸ Drag elements (G): press on an element in the 3D view, drag, release: the
element moves there, its position snapped to the grid of the Elements panel, or, when
one of its bounding box's sides comes within :data:`EDGE_SNAP_PX` screen pixels of a
side of another element's box, onto that side (so that elements line up and touch).

While the tool is on and a cell is on screen, a press on an element's metal belongs to
the tool (the view does not rotate); a press elsewhere still turns or pans the camera.
During the drag the element's own mesh is drawn where it would go (an outline colour
over the scene); the release is one :meth:`barymesh.app.model.AppModel.edit_cell` call, one undo
step, and the cell is meshed again as after a typed position.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from typing import Any, cast

import numpy as np
import pyvista as pv
from PySide6.QtCore import QEvent, QObject, QPointF, Qt
from PySide6.QtGui import QMouseEvent

from barymesh.app.model import AppModel, ClickTools
from barymesh.app.tool_host import ToolHost
from barymesh.app.view.framing import pixels_per_mm

log = logging.getLogger(__name__)
DRAG_COLOR = "#00a0b0"
#: A side of the dragged element's box this close (screen pixels) to another's snaps to it.
EDGE_SNAP_PX = 8.0


def snapped(value: float, grid: float | None) -> float:
    """``value`` on the nearest multiple of ``grid`` (unchanged without a grid).

    >>> snapped(1.26, 0.5), snapped(-0.74, 0.25), snapped(1.26, None)
    (1.5, -0.75, 1.26)
    """
    if not grid:
        return float(value)
    return round(round(value / grid) * grid, 12)


def edge_snap(
    moving: np.ndarray, others: np.ndarray, reach: float
) -> tuple[float | None, float | None]:
    """The shift (dx, dy) that puts a side of box ``moving`` onto the nearest side of one
    of ``others`` within ``reach`` mm, per axis; None where no side is that close.

    Boxes are ``(x0, y0, x1, y1)``: ``moving`` (4,), ``others`` (K, 4) float.

    >>> edge_snap(np.array([0, 0, 1, 1.]), np.array([[1.25, 5, 3, 6]]), 0.5)
    (0.25, None)
    """
    out: list[float | None] = []
    for lo, hi in ((0, 2), (1, 3)):
        if not len(others):
            out.append(None)
            continue
        sides = np.array([moving[lo], moving[hi]])
        targets = np.concatenate([others[:, lo], others[:, hi]])
        gaps = targets[None, :] - sides[:, None]  # (2, 2K)
        k = np.unravel_index(np.argmin(np.abs(gaps)), gaps.shape)
        gap = float(gaps[k])
        out.append(gap if abs(gap) <= reach else None)
    return out[0], out[1]


class ElementDragger(QObject):
    """The drag tool of one window (see the module docstring).

    Parameters
    ----------
    host : ToolHost
        The window: the tool's action, render requests.
    model : AppModel
        The cell it edits (one :meth:`AppModel.edit_cell` per drag).
    plotter : pyvistaqt.QtInteractor
        The 3D view whose presses it takes.
    clicks : ClickTools
        The view's click tools; this is ``"drag"``.
    world_at : callable
        ``world_at(pos) -> (point or None, triangle or None)``: the View tools' mesh point
        under a widget position.
    picker : barymesh.app.view.picker.ViewPicker
        The view's picker: which triangle (so which element) is under the pointer.
    snap_grid : callable
        ``snap_grid() -> float or None``: the Elements panel's grid (mm) positions snap to.
    """

    def __init__(
        self,
        host: ToolHost,
        model: AppModel,
        plotter: Any,
        clicks: ClickTools,
        world_at: Callable[[QPointF], tuple[Any, Any]],
        picker: Any,
        snap_grid: Callable[[], float | None],
    ) -> None:
        super().__init__(host.widget)
        self.host, self.model, self.plotter, self.clicks = host, model, plotter, clicks
        self.world_at, self.picker, self.snap_grid = world_at, picker, snap_grid
        self.dragging: int | None = None  # element index in the whole cell
        self._start: np.ndarray | None = None  # world point of the press
        self._origin = (0.0, 0.0)  # the element's position at the press
        self.target: tuple[float, float] | None = None  # where the release puts it
        self._box = np.zeros(4)  # the dragged element's box (x0, y0, x1, y1) at the press
        self._others = np.zeros((0, 4))  # the other shown elements' boxes
        self._actor: Any = None
        self.act = host.add_action(
            "&Drag elements",
            self.set_active,
            "G",
            "Move an element by dragging it in the view (snapped to the Elements panel's grid)",
            checkable=True,
        )
        plotter.installEventFilter(self)

    @property
    def active(self) -> bool:
        return self.clicks.is_on("drag")

    def set_active(self, on: bool) -> None:
        self.clicks.set_on("drag", on)
        if self.act.isChecked() != self.active:
            self.act.setChecked(self.active)
        if not self.active:
            self._cancel()

    # -- mouse ------------------------------------------------------------------------

    def _world(self, pos: QPointF) -> np.ndarray | None:
        point, _triangle = self.world_at(pos)
        return None if point is None else np.asarray(point, dtype=np.float64)[:2]

    def element_at(self, pos: QPointF) -> int | None:
        """The element (index in the whole cell) whose metal is under ``pos``, or None."""
        result, state = self.model.result, self.model.cell_state
        if (
            result is None
            or result.cell is None
            or result.mesh is None
            or state is None
            or state.visible != result.cell
        ):
            return None
        ratio = self.plotter.devicePixelRatioF()
        hit = self.picker.pick_display(
            pos.x() * ratio, (self.plotter.height() - 1 - pos.y()) * ratio, emit=False
        )
        if hit is None:
            return None
        part = int(result.mesh.regions[hit[0]]) - 1
        shown = [k for k, hidden in enumerate(state.hidden) if not hidden]
        return shown[part] if 0 <= part < len(shown) else None  # the pixels stay put

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:  # noqa: N802 - Qt's name
        if not self.active:
            return False
        kind = event.type()
        mouse = cast(QMouseEvent, event)  # read in the mouse events' branches only
        try:
            if kind == QEvent.Type.MouseButtonPress and mouse.button() == Qt.MouseButton.LeftButton:
                return self._press(mouse.position())
            if kind == QEvent.Type.MouseMove and self.dragging is not None:
                self._move(mouse.position())
                return True
            if (
                kind == QEvent.Type.MouseButtonRelease
                and self.dragging is not None
                and mouse.button() == Qt.MouseButton.LeftButton
            ):
                self._release(mouse.position())
                return True
        except Exception:  # noqa: BLE001 - a drag must never take the window down
            log.exception("dragging an element failed")
            self._cancel()
        return False

    def _press(self, pos: QPointF) -> bool:
        k = self.element_at(pos)
        start = self._world(pos)
        if k is None or start is None:
            return False  # not on an element: the camera's press
        model = self.model
        model.select_element(k)
        self.dragging, self._start = k, start
        assert model.cell_state is not None  # an element was found
        self._origin = model.cell_state.elements[k].position
        self.target = self._origin
        boxes = self._boxes()
        self._box = boxes.pop(k)
        self._others = np.array(list(boxes.values())).reshape(-1, 4)
        self._draw_part(k)
        return True

    def _boxes(self) -> dict[int, np.ndarray]:
        """Bounding box (x0, y0, x1, y1) of every shown element as placed, by its index."""
        result, state = self.model.result, self.model.cell_state
        assert result is not None and state is not None  # a cell's mesh is on screen
        shown = [k for k, hidden in enumerate(state.hidden) if not hidden]
        boxes = {}
        for k, mesh in zip(shown, result.cell_mesh.part_meshes, strict=False):
            if mesh.n_vertices:
                xy = mesh.points[:, :2]
                boxes[k] = np.concatenate([xy.min(axis=0), xy.max(axis=0)])
        return boxes

    def _move(self, pos: QPointF) -> None:
        point = self._world(pos)
        if point is None or self._start is None:
            return
        grid = self.snap_grid()
        delta = point - self._start
        x = snapped(self._origin[0] + delta[0], grid)
        y = snapped(self._origin[1] + delta[1], grid)
        # a side near another element's side wins over the grid
        raw = np.array([self._origin[0] + delta[0], self._origin[1] + delta[1]])
        shift = np.tile(raw - self._origin, 2)
        reach = EDGE_SNAP_PX / max(pixels_per_mm(self.plotter), 1e-12)
        dx, dy = edge_snap(self._box + shift, self._others, reach)
        if dx is not None:
            x = round(float(raw[0] + dx), 12)
        if dy is not None:
            y = round(float(raw[1] + dy), 12)
        self.target = (x, y)
        if self._actor is not None:
            self._actor.SetPosition(
                self.target[0] - self._origin[0], self.target[1] - self._origin[1], 0.0
            )
            self.host.request_render()

    def _release(self, pos: QPointF) -> None:
        self._move(pos)
        k, target = self.dragging, self.target
        moved = target is not None and not all(
            math.isclose(a, b, abs_tol=1e-12) for a, b in zip(target, self._origin, strict=True)
        )
        self._cancel()
        if moved and k is not None:  # k: a drag was under way
            self.model.edit_cell(lambda s: s.placed(k, position=target))

    def _cancel(self) -> None:
        self.dragging = None
        self._start = None
        if self._actor is not None:
            self.plotter.remove_actor(self._actor, render=False)
            self._actor = None
            self.host.request_render()

    def _draw_part(self, k: int) -> None:
        """The element's own mesh as a wireframe that follows the pointer."""
        result, state = self.model.result, self.model.cell_state
        assert result is not None and state is not None  # a cell's mesh is on screen
        part = [j for j, hidden in enumerate(state.hidden) if not hidden].index(k)
        mesh = result.cell_mesh.part_meshes[part]
        if not mesh.n_triangles:
            return
        faces = np.hstack([np.full((mesh.n_triangles, 1), 3), mesh.triangles]).ravel()
        lift = 1e-3 * state.cell.lattice.size
        points = np.column_stack([mesh.points[:, :2], np.full(mesh.n_vertices, lift)])
        poly = pv.PolyData(points, faces=faces.astype(np.int64))
        self._actor = self.plotter.add_mesh(
            poly,
            color=DRAG_COLOR,
            opacity=0.5,
            reset_camera=False,
            lighting=False,
            render=False,
            pickable=False,
            name="element_drag",
        )
        self.host.request_render()

"""The RWG inspector's panel and the click picking of the 3D view.

:class:`ViewPicker` turns a click (press and release within a few pixels, so a drag still
rotates the view) on the 3D view into the triangle under the mouse. A flat mesh is picked
from the core's arrays (its ``locate`` hook: the camera ray meets the mesh's plane and a
point-in-triangle search finds the triangle, at any mesh size, whatever is drawn); a
curved imported mesh with VTK's ``vtkCellPicker`` restricted to the faces actor.
:class:`InspectorPanel` keeps the selected edge, drives
:class:`barymesh.app.teach.inspector.InspectorOverlay` and shows the info box.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any

import numpy as np
from PySide6.QtCore import QEvent, QObject, QPointF, Qt, Signal
from PySide6.QtWidgets import (
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)
from vtkmodules.vtkRenderingCore import vtkCellPicker

from barymesh import TriMesh
from barymesh.app.teach.inspector import (
    DEFAULT_QUADRATURE,
    EdgeInfo,
    InspectorOverlay,
    edge_info,
    edge_midpoint,
    nearest_edge,
    nearest_edge_to_point,
    overlay_data,
    step_edge,
)

log = logging.getLogger(__name__)

#: A press and release closer than this (px) is a click; farther is a drag (rotate/pan).
CLICK_SLOP = 4


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
        self._press: QPointF | None = None
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
        located = self.locate(float(x), float(y), False) if self.locate is not None else None
        if located is not None and located[0] is not None:
            triangle, point = int(located[0]), located[1]
            if emit:
                self.triangle_picked.emit(triangle, point)
            return triangle, point
        hit = self._vtk_pick(x, y, emit)
        if hit is None and located is not None and emit:
            self.locate(float(x), float(y), True)  # a big mesh's locator not ready: later
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
        kind = event.type()
        if kind == QEvent.Type.MouseButtonPress and event.button() == Qt.MouseButton.LeftButton:
            self._press = event.position()
        elif (
            kind == QEvent.Type.MouseButtonRelease
            and event.button() == Qt.MouseButton.LeftButton
            and self._press is not None
        ):
            moved = (event.position() - self._press).manhattanLength()
            self._press = None
            if self.enabled and not self.suspended and moved <= CLICK_SLOP:
                try:
                    ratio = self.plotter.devicePixelRatioF()
                    pos = event.position()
                    height = self.plotter.height()
                    self.pick_display(pos.x() * ratio, (height - 1 - pos.y()) * ratio)
                except Exception:  # noqa: BLE001 - a failed pick must never crash the window
                    log.exception("picking failed")
        return False  # the view still gets every event (rotate, zoom)


class InspectorPanel(QWidget):
    """Edge selection, the info box and the overlay of the RWG inspector.

    ``edge_selected(edge)`` is emitted with every new selection (-1: none).
    """

    edge_selected = Signal(int)
    zoom_requested = Signal()

    def __init__(self, plotter: Any, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.plotter = plotter
        self.overlay = InspectorOverlay(plotter)
        self.mesh: TriMesh | None = None
        self.edge: int | None = None
        self.info: EdgeInfo | None = None
        self.active = False

        layout = QVBoxLayout(self)
        hint = QLabel(
            "Click an edge or a triangle in the 3D view. "
            "<b>N</b> / <b>P</b>: next / previous RWG unknown.",
            self,
        )
        hint.setWordWrap(True)
        layout.addWidget(hint)
        form = QFormLayout()
        self.edge_spin = QSpinBox(self)
        self.edge_spin.setRange(-1, 0)
        self.edge_spin.setSpecialValueText("none")
        self.edge_spin.setToolTip("Edge id (row of TriMesh.edges)")
        self.edge_spin.valueChanged.connect(self._spin_changed)
        self.quadrature = QSpinBox(self)
        self.quadrature.setRange(1, 8)
        self.quadrature.setValue(DEFAULT_QUADRATURE)
        self.quadrature.setToolTip(
            "f_n is drawn at the centroids of q² sub-triangles of T+ and T− (the quadrature points)"
        )
        self.quadrature.valueChanged.connect(lambda _q: self.refresh())
        form.addRow("&Edge", self.edge_spin)
        form.addRow("&Quadrature q (q² points)", self.quadrature)
        layout.addLayout(form)
        buttons = QHBoxLayout()
        self.prev_button = QPushButton("◀ Previous", self)
        self.next_button = QPushButton("Next ▶", self)
        self.prev_button.clicked.connect(self.previous_edge)
        self.next_button.clicked.connect(self.next_edge)
        self.zoom_button = QPushButton("Zoom to edge", self)
        self.zoom_button.setToolTip("Frame T+ and T− in the view (Z)")
        self.zoom_button.clicked.connect(self.zoom_requested.emit)
        buttons.addWidget(self.prev_button)
        buttons.addWidget(self.next_button)
        buttons.addWidget(self.zoom_button)
        layout.addLayout(buttons)
        self.info_label = QLabel(self)
        self.info_label.setWordWrap(True)
        self.info_label.setTextFormat(Qt.TextFormat.RichText)
        self.info_label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.info_label.setAlignment(Qt.AlignmentFlag.AlignTop | Qt.AlignmentFlag.AlignLeft)
        layout.addWidget(self.info_label)
        legend = QLabel(
            "<small><span style='color:#b40426'>■</span> T+ (∇·f = +l/A+) &nbsp; "
            "<span style='color:#3b4cc0'>■</span> T− (∇·f = −l/A−)<br>"
            "<span style='background:#000000;color:#ffe000'>━━</span> the edge &nbsp; "
            "<span style='color:#00a651'>➜</span> ρ± and free vertices r± &nbsp; "
            "<b>➜</b> f_n at the quadrature points</small>",
            self,
        )
        legend.setWordWrap(True)
        layout.addWidget(legend)
        layout.addStretch(1)
        self._show_info()

    # -- selection ----------------------------------------------------------------------

    def set_active(self, on: bool) -> None:
        """Show or hide the overlay (the panel itself is shown by its dock)."""
        self.active = bool(on)
        self.overlay.set_visible(self.active)
        if self.active and self.edge is None and self.mesh is not None:
            self.select_edge(step_edge(self.mesh, None, 1))
            return
        self.plotter.render()

    def set_mesh(self, mesh: TriMesh | None) -> None:
        """A new mesh: keep the selection at the same place (nearest edge midpoint)."""
        old, old_edge = self.mesh, self.edge
        self.mesh = mesh
        self.edge = None
        edges = len(mesh.edges) if mesh is not None else 0
        self.edge_spin.blockSignals(True)
        self.edge_spin.setRange(-1, max(edges - 1, -1))
        self.edge_spin.blockSignals(False)
        target = None
        if mesh is not None and old is not None and old_edge is not None:
            target = nearest_edge_to_point(mesh, edge_midpoint(old, old_edge))
        elif mesh is not None and self.active:
            target = step_edge(mesh, None, 1)
        self.select_edge(target, render=False)

    def select_edge(self, edge: int | None, render: bool = True) -> None:
        """Select ``edge`` (an id of ``mesh.edges``; ``None`` clears)."""
        mesh = self.mesh
        if mesh is None or edge is None or not 0 <= int(edge) < len(mesh.edges):
            edge = None
        self.edge = None if edge is None else int(edge)
        self.refresh(render)
        self.edge_selected.emit(-1 if self.edge is None else self.edge)

    def select_triangle(self, triangle: int, point: np.ndarray | None = None) -> None:
        """A click on ``triangle`` (at world ``point``): its nearest edge."""
        if self.mesh is None or not 0 <= int(triangle) < self.mesh.n_triangles:
            return
        self.select_edge(nearest_edge(self.mesh, int(triangle), point))

    def next_edge(self) -> None:
        if self.mesh is not None:
            self.select_edge(step_edge(self.mesh, self.edge, 1))

    def previous_edge(self) -> None:
        if self.mesh is not None:
            self.select_edge(step_edge(self.mesh, self.edge, -1))

    def refresh(self, render: bool = True) -> None:
        """Recompute the info and the overlay for the current edge."""
        self.info = None
        data = None
        if self.mesh is not None and self.edge is not None:
            try:
                self.info = edge_info(self.mesh, self.edge, self.quadrature.value())
                data = overlay_data(self.mesh, self.info)
            except Exception:  # noqa: BLE001 - the window keeps running whatever happens
                log.exception("inspecting edge %s failed", self.edge)
                self.info, data = None, None
        self.overlay.update(data)
        self.edge_spin.blockSignals(True)
        self.edge_spin.setValue(-1 if self.edge is None else self.edge)
        self.edge_spin.blockSignals(False)
        self._show_info()
        if render:
            self.plotter.render()

    def _spin_changed(self, value: int) -> None:
        self.select_edge(None if value < 0 else value)

    def _show_info(self) -> None:
        if self.info is None:
            self.info_label.setText("<i>No edge selected.</i>")
        else:
            self.info_label.setText(self.info.html())

    @property
    def status_text(self) -> str:
        """The sentence that says whether (and why not) the edge carries an RWG function."""
        return "" if self.info is None else self.info.status

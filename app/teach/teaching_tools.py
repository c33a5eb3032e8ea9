"""Teach menu tools of the window: RWG inspector, connectivity matrix, presentation mode.

:class:`TeachingTools` builds the two docks, the click picking of the 3D view, the
overlays and the actions, and links them: a click on the mesh selects an edge in the
inspector and the triangle's row in the matrix; hovering a matrix cell marks its two
triangles; clicking a one selects the edge they share. The window calls
:meth:`TeachingTools.mesh_changed` with every new mesh.

The tools make the view's click picker and triangle highlight, which the View tools use
too; their zoom buttons ask for a zoom through :attr:`TeachingTools.zoom_to_points_requested`
and :attr:`~TeachingTools.zoom_to_selection_requested`, which the window connects to the
View tools (made after these).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
from PySide6.QtCore import Qt, QTimer
from PySide6.QtWidgets import QDockWidget, QMenu, QWidget

from barymesh import TriMesh
from barymesh.app.model import ClickTools, Event
from barymesh.app.teach.inspector_panel import InspectorPanel
from barymesh.app.teach.presentation import EMPHASIS, PresentationMode
from barymesh.app.tool_host import ToolHost
from barymesh.app.view.framing import pixels_per_mm
from barymesh.app.view.highlight import TriangleHighlight
from barymesh.app.view.picker import ViewPicker

if TYPE_CHECKING:
    from barymesh.app.teach.matrix_view import MatrixView

log = logging.getLogger(__name__)

#: The 3D view is repainted this long after the last hover over the matrix.
HOVER_REPAINT_MS = 80


def shared_edge(mesh: TriMesh, a: int, b: int) -> int | None:
    """The edge triangles ``a`` and ``b`` share, or None."""
    common = np.intersect1d(mesh.triangle_edges[a], mesh.triangle_edges[b])
    return int(common[0]) if a != b and len(common) else None


class TeachingTools:
    """The inspector, matrix view and presentation mode of one window.

    Parameters
    ----------
    host : ToolHost
        The window: the actions, the two docks, render requests, presentation mode.
    plotter : pyvistaqt.QtInteractor
        The 3D view: its picker, highlight and overlays are made here.
    scene : barymesh.app.view.scene.MeshScene
        What the picker picks (the faces) and what presentation mode thickens.
    clicks : ClickTools
        The view's click tools: the inspector and the matrix are two of them.
    beside : QDockWidget, optional
        The docks are tabbed with this one (the Statistics dock).
    refit : callable, optional
        Frames the mesh again if it is framed (the window's ``refit_if_framed``): the
        inspector's header comes and goes with it, and the mesh is framed under it.

    Events: ``zoom_to_selection_requested()`` (the inspector's Zoom) and
    ``zoom_to_points_requested(points)`` ((k, 3) mm, the matrix cell's Zoom).
    """

    def __init__(
        self,
        host: ToolHost,
        plotter: Any,
        scene: Any,
        clicks: ClickTools,
        beside: QDockWidget | None = None,
        refit: Callable[[], None] | None = None,
    ) -> None:
        self.host = host
        self.refit = refit
        self._return_to: dict[QDockWidget, QDockWidget | None] = {}
        self.clicks = clicks
        self.plotter, self.scene = plotter, scene
        self.beside = beside
        self.mesh: TriMesh | None = None
        self.zoom_to_selection_requested = Event()
        self.zoom_to_points_requested = Event()
        self.inspector = InspectorPanel(plotter)
        self._matrix: MatrixView | None = None  # made when first needed (see matrix)
        self._matrix_scale = 1.0
        self.highlight = TriangleHighlight(plotter)
        self.picker = ViewPicker(plotter, scene.actors["faces"], host.widget)
        self.picker.triangle_picked.connect(self._triangle_picked)
        self.inspector.zoom_requested.connect(self.zoom_to_edge)
        self.presentation = PresentationMode(host.widget, self._emphasize)
        # a hover marks the triangles at once but repaints the 3D view only when the
        # pointer rests: a sweep across the spy plot costs one paint, not one per cell
        self._repaint = QTimer(host.widget)
        self._repaint.setSingleShot(True)
        self._repaint.setInterval(HOVER_REPAINT_MS)
        self._repaint.timeout.connect(host.request_render)

        self.inspector_dock = self._dock("RWG inspector", "dock_inspector", self.inspector)
        self.matrix_dock = self._dock("Connectivity matrix", "dock_matrix", QWidget())
        self.matrix_dock.visibilityChanged.connect(self._matrix_shown)

        a = host.add_action
        self.act_inspector = a(
            "RWG &basis inspector",
            self.set_inspector_active,
            "I",
            "Click an edge or triangle: T+, T−, ρ±, f_n and ∇·f_n",
            checkable=True,
        )
        self.act_next = a("&Next edge", self._next, ["N", "]"], "Next RWG unknown")
        self.act_previous = a("&Previous edge", self._previous, ["P", "["], "Previous RWG unknown")
        self.act_matrix = a(
            "Connectivity &matrix",
            self.set_matrix_active,
            "M",
            "The paper's Eq. 27: which triangles share an edge",
            checkable=True,
        )
        self.act_presentation = a(
            "Presentation &mode",
            self.presentation.set_active,
            "F5",
            "Panels hidden, thicker lines, larger fonts (F5 again: back)",
            checkable=True,
        )
        self._sync_step_actions()

    def _dock(self, title: str, name: str, widget: Any) -> QDockWidget:
        dock = self.host.add_dock(
            title, widget, Qt.DockWidgetArea.RightDockWidgetArea, name=name, tab_with=self.beside
        )
        dock.hide()
        dock.visibilityChanged.connect(lambda _v, d=dock: self._dock_visibility(d))
        dock.visibilityChanged.connect(lambda v, d=dock: self._tab_left(d, v))
        return dock

    @property
    def matrix(self) -> MatrixView:
        """The connectivity-matrix view, made the first time it is needed (its dock
        shown): it draws with matplotlib, whose import (about 0.6 s) the window's first
        frame does not wait for."""
        if self._matrix is None:
            from barymesh.app.teach import matrix_view

            view = matrix_view.MatrixView()
            view.cell_hovered.connect(self._cell_hovered)
            view.cell_clicked.connect(self._cell_clicked)
            view.zoom_requested.connect(self.zoom_to_cell)
            view.set_font_scale(self._matrix_scale)
            if self.mesh is not None:
                view.set_mesh(self.mesh)
            self._matrix = view
            placeholder = self.matrix_dock.widget()
            self.matrix_dock.setWidget(view)
            if placeholder is not None:
                placeholder.deleteLater()
        return self._matrix

    def _matrix_shown(self, visible: bool) -> None:
        if visible:
            self.matrix  # noqa: B018 - made now, in its dock

    def add_to_menu(self, menu: QMenu) -> None:
        """Add the actions to the window's Teach (or View) menu."""
        menu.addSeparator()
        menu.addActions([self.act_inspector, self.act_next, self.act_previous])
        menu.addSeparator()
        menu.addAction(self.act_matrix)
        menu.addSeparator()
        menu.addAction(self.act_presentation)

    # -- activation ------------------------------------------------------------------

    @property
    def inspector_active(self) -> bool:
        return self.clicks.is_on("inspector")

    @property
    def matrix_active(self) -> bool:
        return self.clicks.is_on("matrix")

    def set_inspector_active(self, on: bool) -> None:
        on = bool(on)
        self.clicks.set_on("inspector", on)
        if self.act_inspector.isChecked() != on:
            self.act_inspector.setChecked(on)
        if on:
            if self.inspector.mesh is not self.mesh:
                self.inspector.set_mesh(self.mesh)
            self._show_dock(self.inspector_dock)
        elif not self.presentation.active:
            self.inspector_dock.hide()
            self._dock_closed(self.inspector_dock)
        self.inspector.set_active(on)
        # over T+ and T- the matrix marks are outlines: the divergence colours stay true
        self.highlight.set_outline_only(on)
        self._sync_picking()
        if self.refit is not None:
            self.refit()  # the mesh under the inspector's header, or the whole view again

    def set_matrix_active(self, on: bool) -> None:
        on = bool(on)
        self.clicks.set_on("matrix", on)
        if self.act_matrix.isChecked() != on:
            self.act_matrix.setChecked(on)
        if on:
            self._show_dock(self.matrix_dock)
        else:
            if not self.presentation.active:
                self.matrix_dock.hide()
                self._dock_closed(self.matrix_dock)
            self.highlight.show(None, None)
            self.host.request_render()
        self._sync_picking()

    def _show_dock(self, dock: QDockWidget) -> None:
        if self.presentation.active:
            return
        before = self._current_tab(dock)
        dock.show()
        dock.raise_()
        self._return_to[dock] = before  # the tab the user had, raised again on close

    def _current_tab(self, dock: QDockWidget) -> QDockWidget | None:
        """The dock on top of the tab group ``dock`` joins (beside the Statistics)."""
        if self.beside is None:
            return None
        group = [self.beside, *self.host.widget.tabifiedDockWidgets(self.beside)]
        # a tab under another still says isVisible(); only the one on top is painted
        return next((d for d in group if d is not dock and not d.visibleRegion().isEmpty()), None)

    def _tab_left(self, dock: QDockWidget, visible: bool) -> None:
        """Another tab was raised over ``dock`` (it is not closed): closing it later
        leaves the tabs as they are."""
        if not visible and not dock.isHidden():
            self._return_to.pop(dock, None)

    def _dock_closed(self, dock: QDockWidget) -> None:
        """``dock`` was closed while on top: the tab the user had before it comes back
        (Qt raised its neighbour, the Quality tab, instead)."""
        before = self._return_to.pop(dock, None)
        if before is not None and not before.isHidden() and dock.isHidden():
            before.raise_()

    def _dock_visibility(self, dock: QDockWidget) -> None:
        """A dock closed with its own button turns its tool off, a dock shown (a restored
        session, View menu) turns it on: a dock is never shown for a tool that is off.
        Not while presenting or while the window arranges its docks."""
        if self.presentation.active or self.host.arranging_docks:
            return
        inspector = dock is self.inspector_dock
        active = self.inspector_active if inspector else self.matrix_active
        switch = self.set_inspector_active if inspector else self.set_matrix_active
        if dock.isHidden() == active:
            switch(not dock.isHidden())

    def _sync_picking(self) -> None:
        self.picker.enabled = self.clicks.picking
        self._sync_step_actions()

    def _sync_step_actions(self) -> None:
        for act in (self.act_next, self.act_previous):
            act.setEnabled(self.inspector_active)

    def sync_with_docks(self) -> None:
        """After a restored layout: a tool whose dock came back visible is on, so a dock
        is never shown for a tool that is off."""
        if not self.inspector_dock.isHidden() and not self.inspector_active:
            self.set_inspector_active(True)
        if not self.matrix_dock.isHidden() and not self.matrix_active:
            self.set_matrix_active(True)

    # -- events ----------------------------------------------------------------------

    def mesh_changed(self, mesh: TriMesh | None) -> None:
        """A new mesh is on screen (the window's result hook)."""
        self.mesh = mesh
        try:
            self.inspector.set_mesh(mesh)
            if self._matrix is not None:
                self._matrix.set_mesh(mesh)
            self.highlight.show(None, None)
        except Exception:  # noqa: BLE001 - a teaching view must never take the window down
            log.exception("updating the teaching tools failed")

    def _triangle_picked(self, triangle: int, point: np.ndarray) -> None:
        if self.inspector_active:
            self.inspector.select_triangle(triangle, point)
        if self.matrix_active:
            self.matrix.highlight_row(triangle)
            if not self.inspector_active:
                self._mark(triangle)
        self.host.request_render()

    def _mark(self, row: int | None, col: int | None = None) -> None:
        self.highlight.show(self.mesh, row, col)
        self.highlight.fit(pixels_per_mm(self.plotter))

    def _cell_hovered(self, row: int, col: int) -> None:
        """Cheap at any size: the spy plot blits one box, the 3D view is asked for one
        repaint (coalesced by Qt), the two triangles are looked up, not searched for."""
        self.matrix.highlight_cell(row, col)
        self._mark(row, col if col != row else None)
        self._repaint.start()

    def _cell_clicked(self, row: int, col: int) -> None:
        self._cell_hovered(row, col)
        self._repaint.stop()
        self.host.request_render()
        self.matrix.highlight_row(row)
        if self.inspector_active and self.mesh is not None:
            edge = shared_edge(self.mesh, row, col)
            if edge is not None:
                self.inspector.select_edge(edge)

    def _next(self) -> None:
        if self.inspector_active:
            self.inspector.next_edge()

    def _previous(self) -> None:
        if self.inspector_active:
            self.inspector.previous_edge()

    def zoom_to_edge(self) -> None:
        """Centre the view on the inspected edge, its triangles filling about a third."""
        if self.inspector_active and self.inspector.info is not None:
            self.zoom_to_selection_requested.emit()

    def selected_triangles(self) -> list[int] | None:
        """The triangles these tools select, for Zoom to selection: the inspected edge's
        two, else the marked matrix cell's (or row's); None when neither tool is on or
        holds a selection."""
        if self.inspector_active and self.inspector.info is not None:
            return list(self.inspector.info.triangles)
        if self.matrix_active and self.highlight.triangles:
            return list(self.highlight.triangles)
        return None

    def zoom_to_cell(self) -> None:
        """Frame the two triangles of the clicked matrix cell (the spy plot's Zoom button)."""
        cell = self.matrix.cell
        if cell is None or self.mesh is None:
            return
        self._mark(*cell)
        tris = sorted(set(cell))
        mesh = self.mesh
        self.zoom_to_points_requested.emit(mesh.points[mesh.triangles[tris]].reshape(-1, 3))

    def _emphasize(self, scale: float) -> None:
        self.scene.set_emphasis(scale)
        overlay = 1.0 if scale == 1.0 else 0.8 * EMPHASIS
        self.inspector.overlay.set_scale(overlay)
        self.highlight.set_scale(overlay)
        self._matrix_scale = scale
        if self._matrix is not None:
            self._matrix.set_font_scale(scale)
        if self.act_presentation.isChecked() != self.presentation.active:
            self.act_presentation.setChecked(self.presentation.active)
        self.plotter.render()

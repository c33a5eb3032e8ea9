"""The 3D view's own tools: the hover readout, the measure tool and zoom-to-selection.

:class:`ViewTools` adds an information strip under the 3D view (on the left a note, such
as a preset's description, kept until the parameters change; on the right the readout of
what is under the cursor: the vertex, edge or triangle with its numbers and coordinates
in mm), the View actions *Measure distance* (D) and *Zoom to selection* (Z), and a click
selection when no teaching tool takes the clicks.

Hovering is cheap at any mesh size: mouse moves are coalesced into one query per event-
loop pass, a query asks a :class:`barymesh.app.view.readout.MeshLocator` (a k-d tree
built once per mesh,
in a worker thread for big meshes) about a dozen candidate triangles, and it only sets a
label's text; the 3D view is not re-rendered for a hover.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Sequence
from functools import partial
from typing import Any, cast

import numpy as np
from PySide6.QtCore import QEvent, QObject, QPointF, Qt, QTimer
from PySide6.QtGui import QMouseEvent, QPainter
from PySide6.QtWidgets import QLabel, QSizePolicy, QVBoxLayout, QWidget

from barymesh import TriMesh
from barymesh.app.jobs import Jobs
from barymesh.app.model import ClickTools, ViewSelection
from barymesh.app.tool_host import ToolHost
from barymesh.app.view.framing import frame_points, pixels_per_mm
from barymesh.app.view.measure import MeasureTool
from barymesh.app.view.picker import ClickWatch
from barymesh.app.view.readout import SNAP_PIXELS, Hit, MeshLocator, decimals_for, ray_plane_point
from barymesh.app.worker import release_memory

log = logging.getLogger(__name__)

#: A mesh's locator is built when the pointer first comes over the view (or a click or a
#: tool asks where something is): at once for up to this many triangles, in a worker
#: thread above. A mesh only passed through (a slider drag) never builds one.
SYNC_LOCATOR = 50_000


class ElidedLabel(QLabel):
    """One line of text, cut with "…" when it does not fit (the whole text is ``text()``)."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Fixed)

    def paintEvent(self, _event: Any) -> None:  # noqa: N802 - Qt's name
        painter = QPainter(self)
        shown = self.fontMetrics().elidedText(
            self.text(), Qt.TextElideMode.ElideRight, self.contentsRect().width()
        )
        painter.setPen(self.palette().color(self.foregroundRole()))
        painter.drawText(self.contentsRect(), int(self.alignment()), shown)


class ViewTools(QObject):
    """Readout, measuring and zoom-to-selection of one window.

    The window puts :meth:`container` (its 3D view with :attr:`strip` under it) in the
    middle and calls :meth:`mesh_changed` with every new mesh.

    Parameters
    ----------
    host : ToolHost
        The window: the actions, status messages, render requests.
    plotter : pyvistaqt.QtInteractor
        The 3D view.
    scene : barymesh.app.view.scene.MeshScene
        Its bounds and marker sizes.
    clicks : ClickTools
        The view's click tools: measuring is one of them; a click with none on selects.
    picker : barymesh.app.view.picker.ViewPicker
        The Teach tools' click picker: clicks go to it while one of them is on, and it
        asks :meth:`locate_display` where a click is.
    highlight : barymesh.app.view.highlight.TriangleHighlight
        The triangles a click selects are marked with it.
    selected_triangles : callable
        ``selected_triangles() -> list of int or None``: what the Teach tools select
        (framed by Zoom to selection after a measurement, before a clicked triangle).
    refit : callable
        ``refit(render=False)``: the window's keep-a-framed-mesh-framed, on a resize.
    """

    def __init__(
        self,
        host: ToolHost,
        plotter: Any,
        scene: Any,
        clicks: ClickTools,
        *,
        picker: Any,
        highlight: Any,
        selected_triangles: Callable[[], Sequence[int] | None],
        refit: Callable[..., None],
    ) -> None:
        super().__init__(host.widget)
        self.host = host
        self.plotter = plotter
        self.scene = scene
        self.clicks = clicks
        self.picker, self.highlight = picker, highlight
        self.selected_triangles, self.refit = selected_triangles, refit
        self.mesh: TriMesh | None = None
        self.locator: MeshLocator | None = None
        self._locator_started: TriMesh | None = None  # the mesh whose locator is being built
        self.hit: Hit | None = None
        self.selection = ViewSelection()  # a click's, when no click tool takes it
        self.cursor: np.ndarray | None = None
        self._pos: QPointF | None = None
        self._clicks = ClickWatch()  # a click, not a drag
        self._pending_pick: np.ndarray | None = None  # a click waiting for the locator
        #: a selecting click made before the locator was ready: (point, triangle picked,
        #: snap tolerance in mm at the click's zoom), answered by _locator_ready
        self._pending_select: tuple[np.ndarray, int | None, float] | None = None

        # two lines of a fixed height (a new text never resizes, so never repaints, the
        # 3D view): the note, then the readout; text too long is elided, whole in the tip
        self.strip = QWidget(host.widget)
        self.strip.setObjectName("info_strip")
        col = QVBoxLayout(self.strip)
        col.setContentsMargins(8, 2, 8, 3)
        col.setSpacing(1)
        self.note = ElidedLabel(self.strip)
        self.note.setObjectName("view_note")
        self.note.setStyleSheet("color: #444;")
        self.readout = ElidedLabel(self.strip)
        self.readout.setObjectName("readout")
        col.addWidget(self.note)
        col.addWidget(self.readout)
        line = self.readout.fontMetrics().lineSpacing()
        self.strip.setFixedHeight(2 * line + 8)

        self.measure = MeasureTool(self.plotter)
        self.jobs = Jobs(self, name="barymesh-locator")
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setInterval(0)
        self._timer.timeout.connect(self._update_hover)

        a = host.add_action
        self.act_measure = a(
            "&Measure distance",
            self.set_measuring,
            "D",
            "Click two points in the view: the distance between them in mm",
            checkable=True,
        )
        self.act_zoom = a(
            "&Zoom to selection",
            self.zoom_to_selection,
            "Z",
            "Frame the selected edge, triangles or measured segment",
        )
        self.plotter.setMouseTracking(True)
        self.plotter.installEventFilter(self)
        # the inspector's and the matrix's clicks are searched in the mesh's arrays too
        picker.locate = self.locate_display

    def container(self) -> QWidget:
        """The 3D view with the strip under it (the window's central widget)."""
        box = QWidget(self.host.widget)
        col = QVBoxLayout(box)
        col.setContentsMargins(0, 0, 0, 0)
        col.setSpacing(0)
        col.addWidget(self.plotter, 1)
        col.addWidget(self.strip)
        return box

    # -- mesh ------------------------------------------------------------------------

    def mesh_changed(self, mesh: TriMesh | None) -> None:
        """A new mesh on screen: a new locator (the old selection and measurement go)."""
        self.mesh = mesh
        self.locator = None
        self._pending_pick = None
        self._pending_select = None
        self.hit = None
        self.selection.clear()
        self.measure.set_active(self.measure.active)  # forget the points
        if mesh is not None and mesh.n_triangles:
            # the scene's bounds (computed in the worker): a pass over millions of points
            # here would block the GUI thread
            b = getattr(self.scene, "bounds", None)
            if b is not None:
                span = float(max(b[1] - b[0], b[3] - b[2]))
            else:
                pts = np.asarray(mesh.points)
                span = float(np.ptp(pts[:, :2], axis=0).max()) if len(pts) else 1.0
            self.measure.set_lift(8e-4 * max(span, 1e-9))
            # the locator is built when the pointer first comes over the view
            # (_ensure_locator): a mesh only passed through (a slider drag, a return to
            # the last one) never builds one (30-70 ms of the GUI thread at 23k triangles),
            # nor keeps its memory alive while it does
        self._locator_started = None
        self._show_readout()

    def _ensure_locator(self) -> None:
        """Build the locator of the mesh on screen, once, if it has none: at once for a
        small mesh, in a worker thread for a big one."""
        mesh = self.mesh
        if (
            mesh is None
            or not mesh.n_triangles
            or self.locator is not None
            or self._locator_started is mesh
        ):
            return
        if mesh.n_triangles <= SYNC_LOCATOR:
            self.locator = MeshLocator(mesh)
            return
        self._locator_started = mesh
        self.jobs.submit(partial(_build_locator, mesh), self._locator_ready)

    def _locator_ready(self, locator: MeshLocator | None) -> None:
        if locator is not None and locator.mesh is self.mesh:
            self.locator = locator
            self._update_hover()  # the pointer may be resting there already
            pending, self._pending_pick = self._pending_pick, None
            if pending is not None and locator.planar:
                triangle = locator.triangle_at(pending)
                if triangle is not None:
                    self.picker.triangle_picked.emit(triangle, pending)
            clicked, self._pending_select = self._pending_select, None
            if clicked is not None:
                point, triangle, tol = clicked
                self._select(locator.hit(point, tol, triangle))
            return
        if locator is not None and locator.mesh.n_triangles > 200_000:
            # the locator of a mesh no longer on screen (built while the user moved on)
            # held it alive until now: once dropped, hand the pages back, off this thread
            QTimer.singleShot(
                0, lambda: threading.Thread(target=release_memory, daemon=True).start()
            )

    def set_note(self, text: str) -> None:
        """Show ``text`` on the left of the strip (until the next parameter change)."""
        self.note.setText(text)
        self.note.setToolTip(text)

    # -- hover -----------------------------------------------------------------------

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:  # noqa: N802 - Qt's name
        kind = event.type()
        mouse = cast(QMouseEvent, event)  # read in the mouse events' branches only
        if kind == QEvent.Type.Resize:
            # at once, before the paint this resize brings: the refit then costs no paint
            self.refit(render=False)
        elif kind == QEvent.Type.MouseMove:
            self._ensure_locator()
            if not mouse.buttons():
                self._pos = mouse.position()
                self._timer.start()
        elif kind == QEvent.Type.Leave:
            self._pos = None
            self.hit = None
            self.cursor = None
            self._show_readout()
        elif kind == QEvent.Type.MouseButtonPress and mouse.button() == Qt.MouseButton.LeftButton:
            self._ensure_locator()
            self._clicks.press(event)
        elif kind == QEvent.Type.MouseButtonRelease and self._clicks.is_click(event):
            try:
                self._clicked(mouse.position())
            except Exception:  # noqa: BLE001 - a click must never take the window down
                log.exception("click in the view failed")
        return False

    def world_at(self, pos: QPointF) -> tuple[np.ndarray | None, int | None]:
        """The mesh point under widget position ``pos`` and, if VTK picked it, its triangle."""
        ratio = self.plotter.devicePixelRatioF()
        x = pos.x() * ratio
        y = (self.plotter.height() - 1 - pos.y()) * ratio
        locator = self.locator
        if locator is not None and not locator.planar:
            return self._picked(x, y)
        z0 = locator.z0 if locator is not None else 0.0
        return self._plane_point(x, y, z0), None

    def _plane_point(self, x: float, y: float, z0: float) -> np.ndarray | None:
        """Where the camera ray through display pixel (x, y) meets the plane ``z = z0``."""
        renderer = self.plotter.renderer
        renderer.SetDisplayPoint(float(x), float(y), 0.0)
        renderer.DisplayToWorld()
        wx, wy, wz, w = renderer.GetWorldPoint()
        if abs(w) < 1e-300:
            return None
        origin = np.array([wx, wy, wz]) / w
        direction = np.asarray(self.plotter.camera.GetDirectionOfProjection())
        return ray_plane_point(origin, direction, z0)

    def locate_display(
        self, x: float, y: float, defer: bool = True
    ) -> tuple[int | None, np.ndarray | None] | None:
        """The triangle of the mesh's arrays under display pixel (x, y), and the point.

        The :class:`barymesh.app.view.picker.ViewPicker`'s ``locate`` hook: for a flat
        mesh the camera ray meets its plane and the locator's point-in-triangle search
        finds the triangle, at any size and whatever the scene draws (a dense mesh is
        drawn reduced). None for a curved mesh (VTK picks it). While a big mesh's locator
        is still being built, ``(None, point)``; with ``defer`` the click is answered
        (``triangle_picked``) when the locator is ready.
        """
        mesh = self.mesh
        if mesh is None or not mesh.n_triangles:
            return None
        if mesh.n_triangles <= SYNC_LOCATOR:
            self._ensure_locator()
        locator = self.locator
        if locator is not None:
            if not locator.planar:
                return None
            z0 = locator.z0
        else:
            z = np.asarray(mesh.points)[:, 2]
            lo, hi = float(z.min()), float(z.max())
            b = getattr(self.scene, "bounds", None)
            size = float(max(b[1] - b[0], b[3] - b[2])) if b is not None else 1.0
            if hi - lo > 1e-9 * max(size, 1e-12):
                return None
            z0 = lo
        point = self._plane_point(x, y, z0)
        if point is None:
            return None, None
        if locator is None:
            if defer:
                self._pending_pick = point
                self._ensure_locator()
            return None, point
        return locator.triangle_at(point), point

    def _picked(self, x: float, y: float) -> tuple[np.ndarray | None, int | None]:
        hit = self.picker.pick_display(x, y, emit=False)
        return (None, None) if hit is None else (hit[1], hit[0])

    def _update_hover(self) -> None:
        if self._pos is None:
            return
        try:
            point, triangle = self.world_at(self._pos)
            self.cursor = point
            self.hit = None
            if point is not None and self.locator is not None:
                tol = SNAP_PIXELS / pixels_per_mm(self.plotter)
                self.hit = self.locator.hit(point, tol, triangle)
        except Exception:  # noqa: BLE001 - a hover must never take the window down
            log.exception("hover readout failed")
            self.hit = None
        self._show_readout()

    def _show_readout(self) -> None:
        decimals = decimals_for(pixels_per_mm(self.plotter))
        parts = []
        if self.measure.active:
            parts.append(self.measure.text(decimals))
        if self.cursor is not None:
            x, y = self.cursor[:2]
            parts.append(f"x = {x:.{decimals}f}, y = {y:.{decimals}f} mm")
        if self.hit is not None and self.locator is not None:
            parts.append(self.locator.describe(self.hit, decimals))
        elif self.cursor is not None and self.mesh is not None and self.locator is None:
            parts.append("(finding elements…)")
        if self._pending_select is not None and not self.measure.active:
            parts.append("selecting the element clicked (finding elements…)")
        elif self.selected is not None and self.locator is not None and not self.measure.active:
            parts.append(
                f"selected: {self.locator.summary(self.selected, decimals)} (Z: zoom to it)"
            )
        text = "  ·  ".join(parts)
        self.readout.setText(text)
        self.readout.setToolTip(text)

    # -- clicks, measuring, selection ------------------------------------------------

    @property
    def selected(self) -> Hit | None:
        """The element a click selected (:attr:`selection`), or None."""
        return self.selection.clicked

    def set_measuring(self, on: bool) -> None:
        on = bool(on)
        if self.act_measure.isChecked() != on:
            self.act_measure.setChecked(on)
        self.clicks.set_on("measure", on)
        self.measure.set_active(on)
        self.picker.suspended = self.clicks.measuring
        self._show_readout()
        self.host.request_render()

    def _clicked(self, pos: QPointF) -> None:
        point, triangle = self.world_at(pos)
        if point is None:
            return
        hit = None
        if self.locator is not None:
            tol = SNAP_PIXELS / pixels_per_mm(self.plotter)
            hit = self.locator.hit(point, tol, triangle)
        goes_to = self.clicks.click_goes_to()
        if goes_to == "measure":
            if hit is not None and hit.kind == "vertex":
                assert self.locator is not None  # it found the vertex
                point = self.locator.points[hit.index]  # snap to the vertex
            self.measure.add_point(point)
            self.host.request_render()
        elif goes_to == "select":
            if self.locator is None and self.mesh is not None and self.mesh.n_triangles:
                # a big mesh's elements are still being found (the pointer has only just
                # come over the view): the click is kept and answered when they are
                tol = SNAP_PIXELS / pixels_per_mm(self.plotter)
                self._pending_select = (np.asarray(point, dtype=np.float64), triangle, tol)
                self._ensure_locator()
            else:
                self._pending_select = None
                self._select(hit)
                return
        self._show_readout()

    def _select(self, hit: Hit | None) -> None:
        """A click selected ``hit`` (None: nothing): mark it and say so."""
        self.selection.click(hit)
        self.highlight.show(self.mesh, None if hit is None else hit.triangle)
        self.host.request_render()
        self._show_readout()

    def selection_points(self) -> np.ndarray | None:
        """The corners of what is selected, (k, 3) mm, or None.

        In order: a finished measurement, the inspector's edge (its triangles), the matrix
        cell's triangles, a clicked element (:meth:`ViewSelection.points`).
        """
        measured = self.measure.points if self.measure.active and self.measure.complete else None
        taught = self.selected_triangles() if self.mesh is not None else None
        return self.selection.points(self.mesh, measured, taught)

    def zoom_to_selection(self) -> bool:
        """Centre the view on the selection, filling about a third of it."""
        pts = self.selection_points()
        if pts is None:
            self.host.show_status(
                "Nothing selected: click a triangle, an edge or a vertex first", 5000
            )
            return False
        self.zoom_to_points(pts)
        return True

    def zoom_to_points(self, pts: np.ndarray) -> None:
        """Centre the view on the points (k, 3) mm, filling about a third of it."""
        frame_points(self.plotter, pts, fill=0.35)
        self.scene.fit_marker_sizes()
        self.highlight.fit(pixels_per_mm(self.plotter))
        self.host.request_render()
        self._show_readout()


def _build_locator(mesh: TriMesh) -> MeshLocator | None:
    try:
        return MeshLocator(mesh)
    except Exception:  # noqa: BLE001 - no readout is better than a dead worker
        log.exception("building the mesh locator failed")
        return None

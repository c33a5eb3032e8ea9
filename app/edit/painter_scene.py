"""GUI thread only: the pixel painter's VTK scene (its view, datasets and actors).

:class:`PainterScene` makes the painter's ``QtInteractor`` (top view, parallel
projection) and one pyvista dataset and actor per layer: the pixel grid, the mesh's faces
and triangle edges, the pixels painted or erased since that mesh, the cell outline, the
corner contacts and the pixel under the mouse with its images. It reads the grid and the
lattice from the painter's document (:class:`barymesh.app.model.painter_document.PainterDocument`)
and wraps the worker's plain arrays (:mod:`barymesh.app.edit.painter_preview`) for VTK here,
on the GUI thread. Every change asks for one render, from a zero timer.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pyvista as pv
from PySide6.QtCore import QObject, QPointF, QTimer
from PySide6.QtWidgets import QWidget

from barymesh.app.edit.painter_preview import Built, lines_layer, segments_layer, squares_layer
from barymesh.app.model.painter_document import PainterDocument
from barymesh.app.view.framing import frame_from_above
from barymesh.app.view.gl_info import tune_multi_samples
from barymesh.app.view.polydata import Layer

COLORS = {
    "background": "#ffffff",
    "metal": "#e2b65c",
    "triangle_edges": "#8a6320",
    "grid": "#c9ced6",
    "outline": "#3a4250",
    "contacts": "#e0001b",
    "erased": "#ffffff",
    "hover": "#1f6fd1",
}
#: Triangle edges are drawn while a pixel covers at least this many screen pixels.
EDGES_MIN_PIXELS = 20.0
#: Meshes with more edges draw only the edges in view (again after a zoom or a pan).
EDGES_ALL = 150_000


class PainterScene(QObject):
    """The painter's view and what it draws (see the module docstring).

    Parameters
    ----------
    parent : QWidget
        The painter's window: the parent of the view widget, :attr:`plotter`.
    document : PainterDocument
        The edited cell, read for the grid and the lattice.
    """

    def __init__(self, parent: QWidget, document: PainterDocument) -> None:
        super().__init__(parent)
        from pyvistaqt import QtInteractor

        self.document = document
        self._closed = False
        self._last_good: Built | None = None  # the mesh on screen
        self._built_mask: np.ndarray | None = None  # the mask it was built for
        self._edges_view: tuple[object, ...] | None = None

        self.plotter = QtInteractor(parent, auto_update=False)
        tune_multi_samples(self.plotter)  # before its first frame (app/view/gl_info.py)
        self.plotter.theme.allow_empty_mesh = True  # datasets start empty, filled later
        self.plotter.set_background(COLORS["background"])
        self.plotter.enable_parallel_projection()
        self.plotter.view_xy(render=False)
        self.plotter.setMinimumSize(480, 420)
        self._make_actors()
        self._render_timer = QTimer(self)
        self._render_timer.setSingleShot(True)
        self._render_timer.setInterval(0)
        self._render_timer.timeout.connect(self._render)

    @property
    def dz(self) -> float:
        """The height (mm) between the layers drawn over one another."""
        return 1e-3 * self.document.state.lattice.size

    def _make_actors(self) -> None:
        p = self.plotter
        self.datasets = {
            name: pv.PolyData()
            for name in (
                "grid",
                "faces",
                "edges",
                "painted",
                "erased",
                "outline",
                "contacts",
                "hover",
            )
        }
        # dataset -> colour key and how it is drawn, in drawing order (bottom to top); every
        # actor flat (no lighting), not pickable, added without a render or a camera reset
        looks: dict[str, tuple[str, dict[str, Any]]] = {
            "grid": ("grid", {"line_width": 1.0}),
            "faces": ("metal", {}),
            "edges": ("triangle_edges", {"line_width": 1.0}),
            "painted": ("metal", {}),
            "erased": ("erased", {}),
            "outline": ("outline", {"line_width": 2.0}),
            "contacts": ("contacts", {"point_size": 11.0, "render_points_as_spheres": True}),
            "hover": ("hover", {"line_width": 2.5, "style": "wireframe"}),
        }
        self.actors = {
            name: p.add_mesh(
                self.datasets[name],
                color=COLORS[colour],
                lighting=False,
                reset_camera=False,
                render=False,
                pickable=False,
                **style,
            )
            for name, (colour, style) in looks.items()
        }
        # after the style has moved the camera (observers run in no promised order)
        self._camera_timer = QTimer(self)
        self._camera_timer.setSingleShot(True)
        self._camera_timer.setInterval(0)
        self._camera_timer.timeout.connect(self._zoomed)
        for event in ("EndInteractionEvent", "MouseWheelForwardEvent", "MouseWheelBackwardEvent"):
            p.iren.add_observer(event, lambda *_: self._camera_timer.start())

    def _set(self, name: str, data: Layer | pv.PolyData, deep: bool = True) -> None:
        if isinstance(data, Layer):  # wrapped here, on the GUI thread
            data = data.polydata()
        self.datasets[name].copy_from(data, deep=deep)

    # -- what is drawn -----------------------------------------------------------------------

    def draw_grid(self) -> None:
        """The pixel grid's lines (under the metal) and the cell outline."""
        g = self.document.grid
        rows, cols = g.shape
        x0, y0 = g.origin
        p = g.pixel_size
        xs = x0 + p * np.arange(cols + 1)
        ys = y0 + p * np.arange(rows + 1)
        a = np.vstack(
            [
                np.column_stack([xs, np.full(cols + 1, ys[0])]),
                np.column_stack([np.full(rows + 1, xs[0]), ys]),
            ]
        )
        b = np.vstack(
            [
                np.column_stack([xs, np.full(cols + 1, ys[-1])]),
                np.column_stack([np.full(rows + 1, xs[-1]), ys]),
            ]
        )
        self._set("grid", segments_layer(a, b, -self.dz))
        corners = self.document.state.lattice.corners()
        self._set("outline", segments_layer(corners, np.roll(corners, -1, axis=0), 3 * self.dz))
        self._schedule_render()

    def draw_pending(self, mask: np.ndarray) -> None:
        """Pixels of ``mask`` that differ from the mesh on screen, as flat squares over it;
        and the corner contacts of ``mask``."""
        built = self._built_mask
        if built is None or built.shape != mask.shape:
            built = np.zeros_like(mask)
        grid = self.document.grid
        origin = np.asarray(grid.origin)
        p = grid.pixel_size
        self._set("painted", squares_layer(origin, p, np.argwhere(mask & ~built), 2 * self.dz))
        self._set("erased", squares_layer(origin, p, np.argwhere(built & ~mask), 2 * self.dz))
        contacts = grid.replaced(mask=mask).corner_contacts()
        if len(contacts):
            corner = contacts.max(axis=1)[:, ::-1]  # (row, col) of the upper right → (x, y)
            xy = origin + p * corner
            self._set("contacts", pv.PolyData(np.column_stack([xy, np.full(len(xy), 4 * self.dz)])))
        else:
            self._set("contacts", pv.PolyData())
        self._schedule_render()

    def draw_hover(self, cells: np.ndarray) -> None:
        """Outline the pixels ``cells`` (K, 2) (row, column): the one under the mouse and
        its images."""
        grid = self.document.grid
        self._set(
            "hover", squares_layer(np.asarray(grid.origin), grid.pixel_size, cells, 5 * self.dz)
        )
        self._schedule_render()

    def show_mesh(self, built: Built) -> None:
        """Draw the mesh of ``built`` (a good one: no error), its faces and triangle edges."""
        self._last_good = built
        self._built_mask = built.mask
        self._set("faces", built.faces, deep=False)  # the worker's arrays, kept in `built`
        self._edges_view = None
        self._zoomed()

    def _zoomed(self, *_args: Any) -> None:
        """Hide the triangle edges when a pixel is too small on screen to read them."""
        if self._closed:
            return
        from barymesh.app.view.framing import pixels_per_mm

        on_screen = self.document.grid.pixel_size * pixels_per_mm(self.plotter)
        shown = on_screen >= EDGES_MIN_PIXELS
        self.actors["edges"].SetVisibility(shown)
        if shown:
            self._edges_in_view()
        # a contact dot of at most half a pixel, so that many of them still read as dots
        self.actors["contacts"].GetProperty().SetPointSize(
            float(np.clip(0.45 * on_screen, 4.0, 12.0))
        )
        self._schedule_render()

    def _edges_in_view(self) -> None:
        """The triangle edges to draw: all of them, or on a large mesh those whose midpoint
        is in view (with a margin of a pixel)."""
        built = self._last_good
        if built is None:
            return
        if built.edge_pairs is None:  # no mesh (no metal)
            self._set("edges", pv.PolyData())
            self._edges_view = None
            return
        if len(built.edge_pairs) <= EDGES_ALL:
            if self._edges_view != ("all", id(built)):
                self._set("edges", built.edges, deep=False)
                self._edges_view = ("all", id(built))
            return
        x0, x1, y0, y1 = self.view_rect(margin=self.document.grid.pixel_size)
        key = (id(built), x0, x1, y0, y1)
        if self._edges_view == key:
            return
        m = built.midpoints
        assert m is not None and built.lifted is not None and built.edge_pairs is not None
        keep = (m[:, 0] >= x0) & (m[:, 0] <= x1) & (m[:, 1] >= y0) & (m[:, 1] <= y1)
        self._set("edges", lines_layer(built.lifted, built.edge_pairs[keep]), deep=False)
        self._edges_view = key

    # -- the camera --------------------------------------------------------------------------

    def view_rect(self, margin: float = 0.0) -> tuple[float, float, float, float]:
        """(x0, x1, y0, y1) mm the view shows from above, widened by ``margin``."""
        from barymesh.app.view.framing import view_size

        camera = self.plotter.camera
        w, h = view_size(self.plotter)
        half_h = float(camera.parallel_scale)
        half_w = half_h * w / h
        cx, cy, _ = camera.focal_point
        return (
            cx - half_w - margin,
            cx + half_w + margin,
            cy - half_h - margin,
            cy + half_h + margin,
        )

    def reset_view(self) -> None:
        """Frame the cell and the grid from above."""
        g = self.document.grid
        c = self.document.state.lattice.corners()
        x = [g.origin[0], g.origin[0] + g.shape[1] * g.pixel_size, *c[:, 0]]
        y = [g.origin[1], g.origin[1] + g.shape[0] * g.pixel_size, *c[:, 1]]
        frame_from_above(self.plotter, (min(x), max(x), min(y), max(y)), rulers=False, margin=0.03)
        self._zoomed()

    def ground_point(self, pos: QPointF) -> tuple[float, float] | None:
        """(x, y) mm where the ray of the view through the widget position ``pos`` meets
        z = 0 (None if it runs parallel to the plane)."""
        ratio = self.plotter.devicePixelRatioF()
        x = pos.x() * ratio
        y = (self.plotter.height() - 1 - pos.y()) * ratio
        renderer = self.plotter.renderer
        ends = []
        for depth in (0.0, 1.0):
            renderer.SetDisplayPoint(x, y, depth)
            renderer.DisplayToWorld()
            w = np.array(renderer.GetWorldPoint(), dtype=np.float64)
            ends.append(w[:3] / w[3])
        a, b = ends
        if abs(b[2] - a[2]) < 1e-300:
            return None
        t = a[2] / (a[2] - b[2])
        point = a + t * (b - a)
        return float(point[0]), float(point[1])

    # -- rendering ---------------------------------------------------------------------------

    def _schedule_render(self) -> None:
        if not self._closed:
            self._render_timer.start()

    def _render(self) -> None:
        if not self._closed:
            self.plotter.render()

    def image(self) -> np.ndarray:
        """The view as an (h, w, 3) uint8 array."""
        image = self.plotter.screenshot(None, return_img=True)
        self.plotter.render()
        return np.ascontiguousarray(image)

    def close(self) -> None:
        """Stop the timers and release the GL context (idempotent)."""
        if self._closed:
            return
        self._closed = True
        self._render_timer.stop()
        self._camera_timer.stop()
        from barymesh.app.view.interactor import close_view

        close_view(self.plotter)  # pyvistaqt's surface wrapper dropped too

"""The 3D scene: pyvista datasets and actors for one :class:`barymesh.TriMesh`.

The view is built in rooms, so that the expensive part can run in a worker thread:

* :mod:`barymesh.app.view.scene_data` turns a mesh into plain numpy arrays
  (:func:`~barymesh.app.view.scene_data.scene_data`), one layer each; it imports no VTK,
  so a worker thread cannot make a VTK object by accident.
* :mod:`barymesh.app.view.rulers` draws the rulers in mm and chooses their ticks.
* :class:`MeshScene` (here) owns the actors of one plotter (a ``pyvistaqt.QtInteractor`` or an
  off-screen ``pyvista.Plotter``). They are created once; :meth:`MeshScene.update` wraps
  the layers' arrays as pyvista datasets (:meth:`Layer.polydata`, on the thread that
  renders), copies them into the existing datasets (``copy_from``) and the caller renders
  once.

:func:`barymesh.app.view.scaled_shot.render_screenshot` is the headless entry point the
command line uses (it draws a :class:`MeshScene` off screen).
"""

from __future__ import annotations

import logging
import os
from typing import Any

import numpy as np
import pyvista as pv
from vtkmodules.vtkCommonCore import vtkDoubleArray
from vtkmodules.vtkRenderingAnnotation import vtkScalarBarActor
from vtkmodules.vtkRenderingCore import vtkActor2D, vtkTextActor
from vtkmodules.vtkRenderingLabel import vtkLabeledDataMapper

from barymesh.app.model.layers import COLOR_BY, DEFAULT_VISIBLE, DETAIL_MODES, LABEL_LIMIT, LAYERS
from barymesh.app.view.overview import (
    DETAIL_TRIANGLES,
    count_in_rect,
)
from barymesh.app.view.rulers import Rulers, nice_inside, nice_span
from barymesh.app.view.scene_data import (
    BACKGROUND,
    CATEGORIES,
    COLORS,
    COVERED_HIDES,
    DETAIL_LAYERS,
    LABEL_PX,
    LIGHT_PX,
    OVERLAP_LOOK,
    WIDE_FROM,
    WIDTHS,
    ZOOM_TEXEL_PX,
    Overview,
    SceneData,
    full_detail_warning,
    line_set,
    lut_settings,
    outline_stride,
    overview_rgba,
    rect_outlines,
    shown_color,
)

log = logging.getLogger(__name__)


def overview_image(rgba: np.ndarray) -> pv.ImageData:
    """The texture input of an overview's (rows, cols, 4) colours (GUI thread only)."""
    rows, cols = rgba.shape[:2]
    image = pv.ImageData(dimensions=(cols, rows, 1))
    image.point_data["rgba"] = rgba.reshape(-1, 4)
    return image


def add_text_labels(
    plotter: pv.Plotter,
    points: pv.PolyData,
    color: str,
    font_size: int = 12,
    background_opacity: float = 0.8,
) -> tuple[vtkLabeledDataMapper, vtkActor2D]:
    """One 2D actor drawing the string array ``"label"`` of ``points``, bold, centred on
    each point over a light box so it reads on top of a mesh. Returns (mapper, actor)."""
    mapper = vtkLabeledDataMapper()
    mapper.SetInputData(points)
    mapper.SetLabelModeToLabelFieldData()
    mapper.SetFieldDataName("label")
    text = mapper.GetLabelTextProperty()
    text.SetColor(pv.Color(color).float_rgb)
    text.SetFontSize(font_size)
    text.SetBold(True)
    text.SetItalic(False)
    text.SetShadow(False)
    text.SetJustificationToCentered()
    text.SetVerticalJustificationToCentered()
    text.SetBackgroundColor(1.0, 1.0, 1.0)
    text.SetBackgroundOpacity(background_opacity)
    actor = vtkActor2D()
    actor.SetMapper(mapper)
    plotter.add_actor(actor, reset_camera=False, pickable=False, render=False)
    return mapper, actor


class MeshScene:
    """The actors of every layer on one plotter, created once and updated in place.

    Parameters
    ----------
    plotter : pyvista.Plotter
        A ``pyvistaqt.QtInteractor`` (the window) or an off-screen ``pyvista.Plotter``.
    visible : dict of str to bool, optional
        Initial layer visibility (defaults: :data:`DEFAULT_VISIBLE`).
    color_by : str
        A key of :data:`COLOR_BY`.
    """

    def __init__(
        self,
        plotter: pv.Plotter,
        visible: dict[str, bool] | None = None,
        color_by: str = "none",
        detail: str = "auto",
    ) -> None:
        if detail not in DETAIL_MODES:
            raise ValueError(
                f"detail={detail!r} is unknown; expected one of {', '.join(DETAIL_MODES)}"
            )
        self.detail = detail
        self.plotter = plotter
        self.visible = dict(DEFAULT_VISIBLE)
        self.visible.update(visible or {})
        self.color_by = color_by if color_by in COLOR_BY else "none"
        self.datasets: dict[str, pv.PolyData] = {name: pv.PolyData() for name in LAYERS}
        self.actors: dict[str, Any] = {}  # pyvista actors and VTK 2D props
        self.bounds: tuple[float, float, float, float] | None = None
        self.ranges: dict[str, tuple[float, float]] = {}
        self.n_triangles = 0
        self.typical_edge = 0.0
        self.overview: Overview | None = None
        self.zoom: Overview | None = None  # a sharper image of the part in view
        self.paper = False
        self.overlap_ratio: float | None = None
        self.patch_rects: np.ndarray | None = None
        self._lut_key: tuple | None = None  # the face colours' table as last set
        self.outline_stride = 0  # overlap look: every k-th patch outlined (0: look off)
        self._outlines = pv.PolyData()  # the mesh's own patch outlines
        #: id(texture) -> (the rgba array shown, its vtkImageData), made on this thread
        self._texture_inputs: dict[int, tuple[np.ndarray, pv.ImageData]] = {}
        self.detail_rect: tuple[float, float, float, float] | None = None
        self.detail_triangles = 0
        self.light = False  # triangles under LIGHT_PX: edges and centroids not drawn
        self.crowded = False  # triangles under LABEL_PX: their numbers not drawn
        self.covered = False  # a layer over the faces (surface current): see set_covered
        self.edge_px = np.inf
        self.emphasis = 1.0  # presentation mode: thicker lines, larger fonts
        plotter.set_background(BACKGROUND)
        plotter.theme.allow_empty_mesh = True  # datasets start empty and are filled later
        self._create_actors()

    # -- construction --------------------------------------------------------

    def _create_actors(self) -> None:
        p = self.plotter
        common = {"reset_camera": False, "lighting": False, "render": False, "pickable": True}
        faces = p.add_mesh(self.datasets["faces"], color=COLORS["faces"], **common)
        faces.mapper.lookup_table = pv.LookupTable(cmap="viridis")
        faces.mapper.SetScalarModeToUseCellFieldData()
        self.actors["faces"] = faces
        for name in (
            "triangle_edges",
            "patch_outlines",
            "shared_edges",
            "boundary_edges",
            "junction_edges",
        ):
            self.actors[name] = p.add_mesh(
                self.datasets[name],
                color=COLORS[name],
                line_width=WIDTHS[name],
                style="wireframe",
                **common,
            )
        self.actors["centroids"] = p.add_mesh(
            self.datasets["centroids"],
            color=COLORS["centroids"],
            point_size=WIDTHS["centroids"],
            render_points_as_spheres=True,
            style="points",
            **common,
        )
        mapper = vtkLabeledDataMapper()
        mapper.SetInputData(self.datasets["labels"])
        mapper.SetLabelModeToLabelIds()
        text = mapper.GetLabelTextProperty()
        text.SetColor(pv.Color(COLORS["labels"]).float_rgb)
        text.SetFontSize(12)
        text.SetBold(False)
        text.SetItalic(False)
        text.SetShadow(False)
        # the number sits up and right of its centroid dot rather than on top of it
        text.SetJustificationToLeft()
        text.SetVerticalJustificationToBottom()
        labels = vtkActor2D()
        labels.SetMapper(mapper)
        p.add_actor(labels, reset_camera=False, pickable=False, render=False)
        self.actors["labels"] = labels

        bar = vtkScalarBarActor()
        bar.SetLookupTable(faces.mapper.lookup_table)
        bar.SetNumberOfLabels(5)
        bar.SetOrientationToVertical()
        bar.SetPosition(0.88, 0.1)
        bar.SetWidth(0.08)
        bar.SetHeight(0.8)
        bar.UnconstrainedFontSizeOn()
        for prop in (bar.GetTitleTextProperty(), bar.GetLabelTextProperty()):
            prop.SetColor(0.1, 0.1, 0.1)
            prop.SetShadow(False)
            prop.SetItalic(False)
            prop.SetFontSize(14)
        bar.GetTitleTextProperty().SetBold(True)
        bar.SetLabelFormat("%-#6.3g")
        bar.SetPosition(0.9, 0.08)
        bar.SetWidth(0.07)
        bar.SetHeight(0.78)
        bar.SetTitle("")  # drawn by legend_title: a bar's own title is cut at the edge
        p.add_actor(bar, reset_camera=False, pickable=False, render=False)
        self.scalar_bar = bar
        self.legend_title = self._text_actor((0.985, 0.9), 14, bold=True, right=True)
        self.note = self._text_actor((0.01, 0.012), 12)
        self.note.GetTextProperty().SetColor(0.2, 0.2, 0.2)
        self.note.GetTextProperty().SetBackgroundColor(1.0, 1.0, 1.0)
        self.note.GetTextProperty().SetBackgroundOpacity(0.85)  # readable over the mesh

        # the faces of a dense mesh as one textured rectangle (barymesh.app.view.overview)
        self.overview_texture = pv.Texture(np.zeros((2, 2, 4), dtype=np.uint8))
        # the texture's colours are the overview's own (a 4-component uint8 image)
        self.overview_texture.SetColorModeToDirectScalars()
        self.overview_quad = pv.PolyData()
        self.actors_overview = p.add_mesh(
            self.overview_quad,
            color="white",
            reset_camera=False,
            lighting=False,
            render=False,
            pickable=False,
        )
        self.actors_overview.SetTexture(self.overview_texture)
        # a sharper image of the part in view, over the overview (detail_data)
        self.zoom_texture = pv.Texture(np.zeros((2, 2, 4), dtype=np.uint8))
        self.zoom_texture.SetColorModeToDirectScalars()
        self.zoom_quad = pv.PolyData()
        self.actors_zoom = p.add_mesh(
            self.zoom_quad,
            color="white",
            reset_camera=False,
            lighting=False,
            render=False,
            pickable=False,
        )
        self.actors_zoom.SetTexture(self.zoom_texture)
        for texture in (self.overview_texture, self.zoom_texture):
            # about one texel a pixel: no mipmaps to make on the GUI thread (llvmpipe
            # builds them on the CPU with every new image)
            texture.mipmap = False
            texture.interpolate = True
        self._set_overview_quad()

        # Axes in mm with "nice" tick values along the bottom and left of the mesh.
        self.axes = Rulers(p.renderer, color="#303030", font_size=12)
        self.axes.SetPickable(False)
        self._apply_visibility()
        self._apply_color_by()

    # -- state ----------------------------------------------------------------

    def _text_actor(
        self, position: tuple[float, float], size: int, bold: bool = False, right: bool = False
    ) -> vtkTextActor:
        actor = vtkTextActor()
        actor.GetPositionCoordinate().SetCoordinateSystemToNormalizedViewport()
        actor.GetPositionCoordinate().SetValue(*position)
        prop = actor.GetTextProperty()
        prop.SetFontSize(size)
        prop.SetColor(0.1, 0.1, 0.1)
        prop.SetBold(bold)
        prop.SetShadow(False)
        prop.SetItalic(False)
        if right:
            prop.SetJustificationToRight()
        actor.SetPickable(False)
        self.plotter.add_actor(actor, reset_camera=False, pickable=False, render=False)
        return actor

    def update(self, data: SceneData) -> None:
        """Copy new datasets into the existing ones (no new actors); the caller renders."""
        for name in LAYERS:
            self.datasets[name].copy_from(data.layers[name].polydata(), deep=False)
        self.bounds = data.bounds
        self.ranges = data.ranges
        self.n_triangles = data.n_triangles
        self.typical_edge = data.typical_edge
        self.overview = data.overview
        self.zoom = None
        self.paper = data.paper
        self.overlap_ratio = data.overlap_ratio
        self.patch_rects = data.patch_rects
        self.outline_stride = 0
        self._outlines = data.layers["patch_outlines"].polydata()
        self.detail_rect = None
        self.detail_triangles = 0 if data.overview is not None else data.n_triangles
        self._set_overview_quad()
        self._place_rulers()
        self.fit_marker_sizes()
        self._apply_color_by()
        self._apply_visibility()

    @property
    def overlap_look(self) -> bool:
        """Whether the overlap look is on: colouring "overlap" (Patches over each point)
        chosen on a paper mesh whose patches overlap at least :data:`OVERLAP_LOOK`."""
        return (
            self.color_by == "overlap"
            and self.overlap_ratio is not None
            and self.overlap_ratio >= OVERLAP_LOOK
        )

    @property
    def shown_color_by(self) -> str:
        """The colouring drawn: the chosen one, or "overlap" for the overlap look."""
        return shown_color(self.color_by, self.overlap_ratio)

    @property
    def reduced(self) -> bool:
        """Whether the mesh is drawn as an overview (not every triangle is a polygon)."""
        return self.overview is not None

    def show_detail(self, data: SceneData) -> None:
        """Draw the full detail of a part of an overview mesh (see :func:`detail_data`)."""
        if self.overview is None:
            return
        if data.overview is not None:  # too many triangles there: a sharper image of it
            self.zoom = data.overview
            self._set_quad(self.zoom_quad, data.overview.bounds, -0.5)
            self._recolor_overview()
            self._apply_visibility()
            return
        for name in DETAIL_LAYERS:
            self.datasets[name].copy_from(data.layers[name].polydata(), deep=False)
        self.detail_rect = data.rect
        self.detail_triangles = data.n_triangles
        self._apply_color_by()
        self._apply_visibility()

    def clear_detail(self) -> None:
        """Drop the detailed part (the camera left it, or shows too much of the mesh)."""
        if self.detail_rect is None:
            return
        for name in DETAIL_LAYERS:
            self.datasets[name].copy_from(pv.PolyData(), deep=False)
        self.detail_rect = None
        self.detail_triangles = 0
        self._apply_visibility()

    def view_rect(self) -> tuple[float, float, float, float] | None:
        """The part of the z = 0 plane the camera sees, (x0, x1, y0, y1) in mm."""
        renderer = self.plotter.renderer
        width, height = renderer.GetSize()
        if width <= 0 or height <= 0:
            return None
        xs, ys = [], []
        for px, py in ((0, 0), (width, 0), (0, height), (width, height)):
            ends = []
            for depth in (0.0, 1.0):
                renderer.SetDisplayPoint(float(px), float(py), depth)
                renderer.DisplayToWorld()
                wx, wy, wz, ww = renderer.GetWorldPoint()
                ends.append(np.array([wx, wy, wz]) / (ww or 1.0))
            a, b = ends
            dz = b[2] - a[2]
            t = 0.0 if abs(dz) < 1e-15 else -a[2] / dz
            hit = a + min(max(t, 0.0), 1.0) * (b - a)
            xs.append(hit[0])
            ys.append(hit[1])
        return float(min(xs)), float(max(xs)), float(min(ys)), float(max(ys))

    def wanted_detail(
        self, limit: int = DETAIL_TRIANGLES
    ) -> tuple[float, float, float, float] | None:
        """The view's rectangle if the camera rests on a part of an overview mesh small
        enough to draw in full and not yet drawn so; None otherwise."""
        if self.overview is None:
            return None
        rect = self.view_rect()
        if rect is None:
            return None
        if _inside(rect, self.detail_rect):
            return None
        ov = self.overview
        assert ov.centroid_counts is not None  # scene_data gives every overview its counts
        inside = count_in_rect(ov.centroid_counts, ov.bounds, rect)
        if inside <= limit // 4:  # the detail grows the rectangle 2 x 2 times
            return rect
        # too many for full detail: a sharper image when the texels show as blocks
        image = self.zoom if self.zoom is not None and _inside(rect, self.zoom.bounds) else ov
        if self.texel_px(image, rect) > ZOOM_TEXEL_PX:
            return rect
        return None

    def texel_px(self, image: Overview, rect: tuple[float, float, float, float]) -> float:
        """Pixels a texel of ``image`` covers on screen when the view shows ``rect``."""
        width, _ = self.plotter.renderer.GetSize()
        texel = (image.bounds[1] - image.bounds[0]) / image.covered.shape[1]
        return float(texel * width / max(rect[1] - rect[0], 1e-12))

    def _set_quad(
        self, quad: pv.PolyData, bounds: tuple[float, float, float, float], level: float
    ) -> None:
        """``quad`` spans ``bounds`` at ``level`` * 1e-4 of the mesh's size above z = 0."""
        size = (
            max(self.bounds[1] - self.bounds[0], self.bounds[3] - self.bounds[2], 1e-9)
            if self.bounds is not None
            else 1.0
        )
        x0, x1, y0, y1 = bounds
        dz = level * 1e-4 * size
        new = pv.PolyData(
            np.array([[x0, y0, dz], [x1, y0, dz], [x1, y1, dz], [x0, y1, dz]]),
            faces=np.array([4, 0, 1, 2, 3]),
        )
        new.active_texture_coordinates = np.array(
            [[0, 0], [1, 0], [1, 1], [0, 1]], dtype=np.float32
        )
        quad.copy_from(new, deep=True)

    def _set_overview_quad(self) -> None:
        self._set_quad(self.zoom_quad, (0.0, 0.0, 0.0, 0.0), 0.0)  # no sharper part yet
        ov = self.overview
        if ov is None:
            # a zero-area textured quad: drawn with every frame, so the textured shader is
            # compiled with the first one, not when the first dense mesh arrives
            blank = pv.ImageData(dimensions=(2, 2, 1))
            blank.point_data["rgba"] = np.zeros((4, 4), dtype=np.uint8)
            self.overview_texture.SetInputDataObject(blank)
            self._texture_inputs.clear()
            bounds, dz = (0.0, 0.0, 0.0, 0.0), 0.0
        else:
            bounds = ov.bounds
            dz = -1e-4 * max(bounds[1] - bounds[0], bounds[3] - bounds[2], 1e-9)
        x0, x1, y0, y1 = bounds
        quad = pv.PolyData(
            np.array([[x0, y0, dz], [x1, y0, dz], [x1, y1, dz], [x0, y1, dz]]),
            faces=np.array([4, 0, 1, 2, 3]),
        )
        quad.active_texture_coordinates = np.array(
            [[0, 0], [1, 0], [1, 1], [0, 1]], dtype=np.float32
        )
        self.overview_quad.copy_from(quad, deep=True)

    def _recolor_overview(self) -> None:
        ov = self.overview
        if ov is None:
            return
        key = self.shown_color_by
        for image, texture in ((ov, self.overview_texture), (self.zoom, self.zoom_texture)):
            if image is None:
                continue
            if image.rgba is None or image.image_key != key:  # colouring changed since
                image.rgba = overview_rgba(image, key, self.ranges)
                image.image_key = key
            # the VTK image is made here, on the GUI thread, and kept by the scene (not by
            # the Overview, which a worker made and may be the last to let go of)
            cached = self._texture_inputs.get(id(texture))
            if cached is None or cached[0] is not image.rgba:
                cached = (image.rgba, overview_image(image.rgba))
                self._texture_inputs[id(texture)] = cached
            texture.SetInputDataObject(cached[1])

    def set_visible(self, layer: str, on: bool) -> None:
        if layer not in self.visible:
            raise ValueError(f"layer={layer!r} is unknown; expected one of {', '.join(LAYERS)}")
        self.visible[layer] = bool(on)
        self._apply_visibility()

    def set_detail(self, detail: str) -> None:
        """Detail "auto" (light look below :data:`LIGHT_PX`) or "full" (always drawn)."""
        if detail not in DETAIL_MODES:
            raise ValueError(
                f"detail={detail!r} is unknown; expected one of {', '.join(DETAIL_MODES)}"
            )
        self.detail = detail
        self.fit_marker_sizes()
        self._apply_visibility()

    def set_covered(self, covered: bool) -> None:
        """A layer drawn over the faces (the surface current's colours and arrows) is on:
        shared edges, centroids, labels and the faces' legend step aside so that its
        arrows read; triangle, boundary and junction edges stay."""
        self.covered = bool(covered)
        self._apply_visibility()

    def set_color_by(self, key: str) -> None:
        if key not in COLOR_BY:
            raise ValueError(f"color_by={key!r} is unknown; expected one of {', '.join(COLOR_BY)}")
        self.color_by = key
        self._apply_color_by()
        self.fit_marker_sizes()  # the overlap look's outlines come and go with it
        self._apply_visibility()

    @property
    def labels_shown(self) -> bool:
        """Whether index labels are drawn (asked for, the mesh small enough, and its
        triangles large enough on screen to hold their numbers)."""
        return self.visible["labels"] and 0 < self.n_triangles <= LABEL_LIMIT and not self.crowded

    def drawn(self, name: str) -> bool:
        """Whether layer ``name`` is drawn now (asked for, and not left out for density)."""
        on = self.visible[name]
        if self.covered and name in COVERED_HIDES:
            return False
        if name == "labels":
            return on and self.labels_shown
        if name in ("triangle_edges", "shared_edges", "centroids") and self.light:
            return False
        if name == "boundary_edges" and self.light and self.paper:
            return False  # in paper mode every patch's border: a texture at this size
        if name in DETAIL_LAYERS and self.overview is not None and self.detail_rect is None:
            return False
        if self.overlap_look:
            if name == "patch_outlines":
                return True  # part of the look (every k-th patch, see fit_marker_sizes)
            if name in ("triangle_edges", "shared_edges", "centroids", "boundary_edges"):
                return False  # overlapping patches' own edges tangle into a moire

        return bool(on)

    def edges_covered(self) -> bool:
        """Whether the shared, boundary and junction edges drawn cover every triangle
        edge: each edge is one of the three, and they are drawn over the triangle edges
        at least as wide. The triangle edges' own lines are then left out (unseen, they
        were a fifth of a software-rendered frame)."""
        return self.drawn("triangle_edges") and all(
            self.drawn(name) or self.datasets[name].n_cells == 0
            for name in ("shared_edges", "boundary_edges", "junction_edges")
        )

    def shows(self, name: str) -> bool:
        """Whether layer ``name`` can be seen: its actor is drawn, or (the triangle edges)
        the lines drawn over them cover every one (:meth:`edges_covered`)."""
        if name == "triangle_edges" and self.edges_covered():
            return True
        return bool(self.actors[name].GetVisibility())

    def _apply_visibility(self) -> None:
        covered = self.edges_covered()
        for name in LAYERS:
            drawn = self.drawn(name) and not (name == "triangle_edges" and covered)
            self.actors[name].SetVisibility(drawn)
        self.actors_overview.SetVisibility(bool(self.visible["faces"]))
        self.actors_zoom.SetVisibility(bool(self.visible["faces"] and self.zoom is not None))
        legend = bool(
            self.visible["faces"]
            and self.shown_color_by != "none"
            and self.n_triangles
            and not self.covered
        )
        self.scalar_bar.SetVisibility(legend)
        self.legend_title.SetVisibility(legend)
        self.axes.SetVisibility(self.bounds is not None and self.n_triangles > 0)
        self._show_note()

    def _show_note(self) -> None:
        """The note, wrapped when it is wider than the view (a long one ran off its edge)."""
        import textwrap

        text = self.note_text()
        if text != self.note.GetInput():
            self.note.SetInput(text)
        size = self.plotter.window_size
        width = 0.97 * float(size[0]) if size else 0.0
        if not text or width <= 0:
            return
        box = [0.0] * 4
        try:
            self.note.GetBoundingBox(self.plotter.renderer, box)
        except (TypeError, AttributeError):
            return
        drawn = box[1] - box[0]
        if drawn <= width:
            return
        longest = max(len(line) for line in text.split("\n"))
        chars = max(30, int(longest * width / drawn))
        self.note.SetInput("\n".join(textwrap.fill(line, chars) for line in text.split("\n")))

    def note_text(self) -> str:
        """What the view leaves out and why (empty when it draws everything asked for)."""
        if not self.n_triangles:
            return ""
        parts = []
        if self.overlap_look and self.patch_rects is not None:
            patches = len(self.patch_rects)
            which = (
                "all outlined"
                if self.outline_stride == 1
                else f"1 in {self.outline_stride} of {patches:,} outlined"
            )
            parts.append(
                f"Overlapping patches (ratio {self.overlap_ratio:.2f}): colour = "
                f"patches over each point, {which}"
            )
            parts.append(
                "Triangle edges hidden: they cross between overlapping patches "
                "(colour faces by Solid to see them)"
            )
        if self.overview is not None:
            if self.detail_rect is None:
                rest = (
                    ""
                    if self.overlap_look
                    else ("; zoom in and rest for triangles, edges and centroids")
                )
                parts.append(
                    f"Detail reduced: {self.n_triangles:,} triangles drawn as an image{rest}"
                )
            else:
                parts.append(
                    f"Full detail of {self.detail_triangles:,} of "
                    f"{self.n_triangles:,} triangles around the view"
                )
        wanted = [n for n in ("triangle_edges", "shared_edges", "centroids") if self.visible[n]]
        if (
            self.light
            and wanted
            and not self.overlap_look
            and (self.overview is None or self.detail_rect is not None)
        ):
            borders = " and patch borders" if self.paper and self.visible["boundary_edges"] else ""
            parts.append(
                f"Triangle edges, centroids{borders} hidden: triangles are "
                f"{self.edge_px:.1f} px on screen (shown from {LIGHT_PX:g} px; "
                "zoom in or set Detail: always full)"
            )
        if self.crowded and self.visible["labels"] and 0 < self.n_triangles <= LABEL_LIMIT:
            parts.append(
                f"Triangle numbers hidden: triangles are {self.edge_px:.0f} px on screen "
                f"(numbered from {LABEL_PX * self.emphasis:g} px; zoom in)"
            )
        shown = [n for n in COVERED_HIDES if self.visible[n] and n != "labels"]
        if self.covered and shown:
            parts.append(
                "Surface current shown: shared edges and centroids hidden "
                "(untick Surface current in the Solve panel to see them)"
            )
        warning = full_detail_warning(self.n_triangles, self.detail)
        if warning:
            parts.append(warning)
        return "\n".join(parts)

    def _apply_color_by(self) -> None:
        array, title = COLOR_BY[self.shown_color_by]
        mapper = self.actors["faces"].mapper
        if (
            array is None
            or array not in self.datasets["faces"].cell_data
            and (self.overview is None or array not in self.overview.values)
        ):
            mapper.SetScalarVisibility(False)
            self._recolor_overview()
            return
        lut = mapper.lookup_table
        cmap, n_values, lo, hi = lut_settings(array, self.ranges)
        key = (array, cmap if isinstance(cmap, str) else tuple(cmap), n_values, lo, hi)
        if key != self._lut_key:  # (a new mesh of the same colouring and range: as is;
            # a changed table would also make the legend lay out its labels again)
            lut.cmap, lut.n_values = cmap, n_values
            mapper.SetScalarRange(lo, hi)
            lut.scalar_range = (lo, hi)
            self.scalar_bar.SetLookupTable(lut)
            self._set_legend(array, title, lo, hi)
            self._lut_key = key
        mapper.SelectColorArray(array)
        mapper.SetScalarVisibility(True)
        self._recolor_overview()

    def _set_legend(self, array: str, title: str, lo: float, hi: float) -> None:
        """A categorical legend for patch and region colours, readable ticks otherwise."""
        bar = self.scalar_bar
        self.legend_title.SetInput(title)
        labels = vtkDoubleArray()
        if array in ("patch", "region"):
            # one swatch per category, named at its middle
            if array == "patch":
                values = range(CATEGORIES)
                self.legend_title.SetInput("patch number, last digit\n(colours repeat)")
            else:
                values = range(1, 4)
            bar.SetNumberOfLabels(len(values))
            bar.SetMaximumNumberOfColors(len(values))
            for v in values:
                labels.InsertNextValue(float(v))
            bar.SetLabelFormat("%.0f")
            bar.SetDrawTickLabels(True)
            bar.SetUseCustomLabels(True)
            bar.SetCustomLabels(labels)
            if array == "region":
                self.legend_title.SetInput("region\n1 inner ring / patch\n2 outer ring")
            return
        ticks, fmt = readable_ticks(lo, hi)
        for v in ticks:
            labels.InsertNextValue(float(v))
        bar.SetMaximumNumberOfColors(256)
        bar.SetLabelFormat(fmt)
        bar.SetUseCustomLabels(True)
        bar.SetCustomLabels(labels)

    #: Left edge of the colour bar's column (normalised viewport x), and of its numbers.
    LEGEND_LEFT = 0.885

    def legend_px(self) -> float:
        """Pixels at the right of the view the colour legend takes (0 when none is shown):
        the bar's column, or its title if that is wider. The mesh is framed left of it."""
        if not self.scalar_bar.GetVisibility():
            return 0.0
        width = float(self.plotter.window_size[0]) if self.plotter.window_size else 0.0
        px = (1.0 - self.LEGEND_LEFT) * width
        box = [0.0] * 4
        try:
            self.legend_title.GetBoundingBox(self.plotter.renderer, box)
        except (TypeError, AttributeError):  # no renderer size yet
            return px
        return float(max(px, 0.015 * width + (box[1] - box[0]) + 6.0))

    def show_rulers(self, bounds: tuple[float, float, float, float]) -> None:
        """Rulers in mm around ``bounds`` = (x0, x1, y0, y1) without a mesh (teaching views)."""
        x0, x1, y0, y1 = bounds
        self.bounds = (float(x0), float(x1), float(y0), float(y1))
        self._place_rulers()
        self.axes.SetVisibility(True)

    #: Room (px) the rulers keep inside the view's edges when zoomed in: left of the y
    #: axis for its labels, right, under the x axis for its labels and title, top.
    RULER_INSET_PX = (64.0, 10.0, 52.0, 10.0)

    def note_px(self) -> float:
        """Pixels the note at the bottom of the view takes (0 without one)."""
        if not self.note.GetInput():
            return 0.0
        box = [0.0] * 4
        try:
            self.note.GetBoundingBox(self.plotter.renderer, box)
        except (TypeError, AttributeError):
            return 0.0
        size = self.plotter.window_size
        height = float(size[1]) if size else 0.0
        return float(box[3] - box[2]) + 0.012 * height + 6.0

    def _place_rulers(self) -> None:
        """Rulers on the mesh's extent rounded out to nice ticks; zoomed in so far that
        they would leave the view, along the part in view instead (inside its edges,
        above the note), so their tick labels stay on screen."""
        if self.bounds is None:
            return
        x0, x1, y0, y1 = self.bounds
        (x0, x1, nx), (y0, y1, ny) = nice_span(x0, x1), nice_span(y0, y1)
        inner = self._rulers_in_view((x0, x1, y0, y1))
        if inner is not None:
            (x0, x1, nx), (y0, y1, ny) = inner
        if self.axes.x_label_format != "{:.4g}":  # 7.5 on a zoomed-in ruler, not "8"
            self.axes.x_label_format = self.axes.y_label_format = "{:.4g}"
        if (self.axes.n_xlabels, self.axes.n_ylabels) != (nx, ny):
            self.axes.n_xlabels, self.axes.n_ylabels = nx, ny
        bounds = (x0, x1, y0, y1, 0.0, 0.0)
        if tuple(self.axes.bounds) != bounds:
            self.axes.bounds = bounds

    def _rulers_in_view(
        self, box: tuple[float, float, float, float]
    ) -> tuple[tuple[float, float, int], tuple[float, float, int]] | None:
        """The rulers' spans inside the view when ``box`` (the rounded-out extent) is not
        all in view; None when it is (or the view is not known)."""
        if not self.plotter.camera.parallel_projection:
            return None
        width, height = self.plotter.renderer.GetSize()
        rect = self.view_rect()
        if rect is None or width <= 0 or height <= 0:
            return None
        tol = 1e-9 * max(box[1] - box[0], box[3] - box[2], 1e-12)
        if (
            rect[0] <= box[0] + tol
            and box[1] <= rect[1] + tol
            and rect[2] <= box[2] + tol
            and box[3] <= rect[3] + tol
        ):
            return None
        per_px = (rect[1] - rect[0]) / width
        left, right, bottom, top = self.RULER_INSET_PX
        right += self.legend_px()
        bottom += self.note_px()
        lo_x, hi_x = max(box[0], rect[0] + left * per_px), min(box[1], rect[1] - right * per_px)
        lo_y, hi_y = max(box[2], rect[2] + bottom * per_px), min(box[3], rect[3] - top * per_px)
        if hi_x <= lo_x or hi_y <= lo_y:
            return None
        return nice_inside(lo_x, hi_x), nice_inside(lo_y, hi_y)

    # -- camera and output ---------------------------------------------------------------

    def top_view(self) -> None:
        """Look down the z axis with a parallel projection, the whole mesh and rulers framed."""
        p = self.plotter
        p.enable_parallel_projection()
        p.view_xy(render=False)
        self.reset_camera()

    def reset_camera(self) -> None:
        p = self.plotter
        if self.bounds is None:
            p.reset_camera(render=False)
            return
        # frame the rulers (rounded out to nice ticks), not only the mesh, so no label is cut
        (x0, x1, _), (y0, y1, _) = nice_span(*self.bounds[:2]), nice_span(*self.bounds[2:])
        pad = 0.12 * max(x1 - x0, y1 - y0, 1e-9)
        x0, x1, y0, y1 = x0 - pad, x1 + pad / 3, y0 - pad, y1 + pad / 3
        width = float(p.window_size[0]) if p.window_size else 0.0
        share = min(self.legend_px() / width, 0.5) if width > 0 else 0.0
        x1 += (x1 - x0) * share / (1.0 - share)  # the legend's column right of the mesh
        p.reset_camera(render=False, bounds=(x0, x1, y0, y1, 0.0, 0.0))
        self.fit_marker_sizes()

    def fit_marker_sizes(self, settled: bool = True) -> None:
        """Thin the lines and shrink the dots when triangles are a few pixels wide on screen.

        Fixed sizes would bury a dense mesh (the paper's Fig. 12(a) zoomed out): lines
        keep their full width from 12 px per typical edge up and thin to 1 px below, and a
        dot is at most a quarter of a typical edge. Below :data:`LIGHT_PX` (Detail "auto")
        triangle edges, shared edges and centroids are left out (the light look).

        ``settled=False`` (a wheel step, the camera still moving) leaves the rulers and
        the note as they are until :meth:`settle`: rebuilding the rulers' labels took
        about 100 ms of the GUI thread per wheel step under load, and rulers in mm zoom
        along with the mesh meanwhile, still true.
        """
        camera = self.plotter.camera
        height = self.plotter.window_size[1] if self.plotter.window_size else 0
        edge_px = np.inf
        if self.typical_edge > 0 and camera.parallel_projection and height > 0:
            edge_px = self.typical_edge * height / max(2.0 * camera.parallel_scale, 1e-12)
        self.edge_px = float(edge_px)
        if settled:
            self._place_rulers()  # zoomed in: along the part in view
        light = bool(self.detail == "auto" and edge_px < LIGHT_PX)
        crowded = bool(self.detail == "auto" and edge_px < LABEL_PX * self.emphasis)
        stride_changed = self._fit_outlines(height, camera)
        if light != self.light or crowded != self.crowded or stride_changed:
            self.light, self.crowded = light, crowded
            self._apply_visibility()
        elif settled:
            self._show_note()
        for name, width in WIDTHS.items():
            prop = self.actors[name].prop
            if name == "centroids":
                prop.point_size = float(np.clip(0.25 * edge_px, 1.5, width)) * self.emphasis
            else:
                thin = float(np.clip(width * edge_px / 12.0, 1.0, width))
                if thin < WIDE_FROM:
                    thin = 1.0  # a wider line costs a software renderer twice as much
                prop.line_width = thin * self.emphasis

    def settle(self) -> bool:
        """The camera rests: the rulers along the part in view and the note for the zoom
        (what :meth:`fit_marker_sizes` left while it moved). Whether either changed."""
        before = (tuple(self.axes.bounds), self.axes.n_xlabels, self.axes.n_ylabels)
        note = self.note.GetInput()
        self._place_rulers()
        self._show_note()
        after = (tuple(self.axes.bounds), self.axes.n_xlabels, self.axes.n_ylabels)
        return before != after or note != self.note.GetInput()

    def _fit_outlines(self, height: int, camera: Any) -> bool:
        """In the overlap look, outline every k-th patch for the zoom (see
        :func:`outline_stride`); else the layer's own outlines. True if that changed."""
        stride = 0
        if self.overlap_look and self.patch_rects is not None and self.overlap_ratio is not None:
            px_per_mm = (
                height / max(2.0 * camera.parallel_scale, 1e-12)
                if camera.parallel_projection and height > 0
                else np.inf
            )
            stride = outline_stride(self.patch_rects, self.overlap_ratio, px_per_mm)
        if stride == self.outline_stride:
            return False
        self.outline_stride = stride
        if stride == 0:
            self.datasets["patch_outlines"].copy_from(self._outlines, deep=False)
        else:
            assert self.bounds is not None and self.patch_rects is not None  # see the stride
            x0, x1, y0, y1 = self.bounds
            z = 2e-4 * max(x1 - x0, y1 - y0, 1e-9)
            pts, pairs = rect_outlines(self.patch_rects[::stride], z)
            self.datasets["patch_outlines"].copy_from(line_set(pts, pairs).polydata(), deep=False)
        return True

    def set_emphasis(self, scale: float) -> None:
        """Lines, dots and fonts ``scale`` times their normal size (presentation mode)."""
        self.emphasis = float(scale)
        self.fit_marker_sizes()
        size = int(round(12 * self.emphasis))
        self.actors["labels"].GetMapper().GetLabelTextProperty().SetFontSize(size)
        for prop in (
            self.scalar_bar.GetTitleTextProperty(),
            self.scalar_bar.GetLabelTextProperty(),
        ):
            prop.SetFontSize(int(round(14 * self.emphasis)))
        for axis in range(3):
            self.axes.GetTitleTextProperty(axis).SetFontSize(size)
            self.axes.GetLabelTextProperty(axis).SetFontSize(size)


def _inside(
    rect: tuple[float, float, float, float], outer: tuple[float, float, float, float] | None
) -> bool:
    """Whether ``rect`` (x0, x1, y0, y1) lies within ``outer`` (False if None)."""
    if outer is None:
        return False
    return (
        outer[0] <= rect[0] and rect[1] <= outer[1] and outer[2] <= rect[2] and rect[3] <= outer[3]
    )


def readable_ticks(lo: float, hi: float, count: int = 5) -> tuple[np.ndarray, str]:
    """Tick values on a 1-2-5 step inside [lo, hi] and a printf format that tells them apart.

    >>> readable_ticks(0.0081, 0.0093)
    (array([0.0082, 0.0084, 0.0086, 0.0088, 0.009 , 0.0092]), '%.4f')
    """
    span = max(hi - lo, 1e-300)
    power = 10.0 ** np.floor(np.log10(span))
    steps = [m * power * f for f in (1.0, 0.1, 0.01) for m in (5, 2, 1)]
    for step in steps:  # the widest step that still gives ``count - 1`` ticks
        first = np.ceil(lo / step - 1e-9) * step
        n = int(np.floor((hi - first) / step + 1e-9)) + 1
        if n >= count - 1:
            break
    ticks = np.round((first + step * np.arange(n)) / step) * step
    if len(ticks) < 2:
        ticks = np.array([lo, hi])
    decimals = max(0, int(-np.floor(np.log10(step) + 1e-9)))
    big = max(abs(lo), abs(hi))
    if big >= 1e5 or (big < 1e-4 and big > 0):
        return ticks, "%.3g"
    return ticks, f"%.{decimals}f"


def prepare_headless() -> None:
    """Without an X display, have VTK render through EGL instead of trying X first."""
    if not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")


def resized_image(image: np.ndarray, width: int, height: int) -> np.ndarray:
    """Nearest-neighbour resize (rarely needed; keeps the promised size exact)."""
    rows = (np.arange(height) * image.shape[0] / height).astype(int)
    cols = (np.arange(width) * image.shape[1] / width).astype(int)
    return image[rows][:, cols]

"""The 3D scene: pyvista datasets and actors for one :class:`core.TriMesh`.

Two halves, so that the expensive part can run in a worker thread:

* :func:`scene_data` turns a mesh into plain pyvista datasets (faces with per-cell
  quality arrays, line sets for edges, points for centroids). No rendering, no plotter:
  safe to call from any thread.
* :class:`MeshScene` owns the actors of one plotter (a ``pyvistaqt.QtInteractor`` or an
  off-screen ``pyvista.Plotter``). They are created once; :meth:`MeshScene.update` copies
  new data into the existing datasets (``copy_from``) and the caller renders once.

:func:`render_screenshot` is the headless entry point the command line uses.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pyvista as pv
from vtkmodules.vtkRenderingAnnotation import vtkScalarBarActor
from vtkmodules.vtkRenderingCore import vtkActor2D
from vtkmodules.vtkRenderingLabel import vtkLabeledDataMapper

from core import TriMesh

from .layers import COLOR_BY, DEFAULT_VISIBLE, LABEL_LIMIT, LAYERS

log = logging.getLogger(__name__)

BACKGROUND = "white"
COLORS = {
    "faces": "#dbe8f6",
    "triangle_edges": "#5b6b7d",
    "patch_outlines": "#111111",
    "shared_edges": "#f28e2b",
    "boundary_edges": "#1f4e9c",
    "junction_edges": "#e0001b",
    "centroids": "#b0147a",
    "labels": "#202020",
}
#: Line width (px) or point size (px) at screenshot scale 1.
WIDTHS = {
    "triangle_edges": 1.0,
    "patch_outlines": 1.5,
    "shared_edges": 1.5,
    "boundary_edges": 2.5,
    "junction_edges": 4.0,
    "centroids": 5.0,
}
_CATEGORIES = 10  # patches are coloured cyclically with a 10-colour qualitative map


@dataclass
class SceneData:
    """Pyvista datasets of one mesh, ready to be copied into a :class:`MeshScene`."""

    datasets: dict[str, pv.PolyData]
    bounds: tuple[float, float, float, float]  # x0, x1, y0, y1 (mm)
    ranges: dict[str, tuple[float, float]] = field(default_factory=dict)
    n_triangles: int = 0
    typical_edge: float = 0.0  # mean edge length (mm), to size the centroid dots


def _line_set(points: np.ndarray, pairs: np.ndarray) -> pv.PolyData:
    """(V, 3) points and (k, 2) vertex pairs as a PolyData of k line cells."""
    pairs = np.asarray(pairs).reshape(-1, 2)
    if len(pairs) == 0:
        return pv.PolyData()
    cells = np.empty((len(pairs), 3), dtype=np.int64)
    cells[:, 0] = 2
    cells[:, 1:] = pairs
    # all points are kept (unused ones cost a few bytes, a np.unique to drop them cost
    # a third of the dataset update on every slider move)
    return pv.PolyData(np.ascontiguousarray(points), lines=cells.ravel())


def _lifted(points: np.ndarray, dz: float) -> np.ndarray:
    """Points moved up by ``dz``, so lines are drawn over the faces they lie on."""
    out = np.array(points, dtype=np.float64)
    out[:, 2] += dz
    return out


def patch_outline_pairs(mesh: TriMesh) -> tuple[np.ndarray, np.ndarray]:
    """Line segments of the patch outlines.

    Paper mode: the four sides of every (possibly overlapping) square patch. Otherwise: the
    edges whose triangles belong to different patches, plus the boundary and junction edges.

    Returns
    -------
    points : (m, 3) float64
    pairs : (k, 2) int
    """
    if mesh.patch_rects is not None and len(mesh.patch_rects):
        r = np.asarray(mesh.patch_rects, dtype=np.float64)
        x0, y0, x1, y1 = r.T
        corners = np.stack(
            [np.column_stack(c) for c in ((x0, y0), (x1, y0), (x1, y1), (x0, y1))], axis=1
        )  # (P, 4, 2)
        points = np.column_stack([corners.reshape(-1, 2), np.zeros(4 * len(r))])
        sides = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])
        pairs = (4 * np.arange(len(r))[:, None, None] + sides[None]).reshape(-1, 2)
        return points, pairs
    et = mesh.edge_triangles
    pid = mesh.patch_ids
    two = (et[:, 1] >= 0)
    differs = np.zeros(len(et), dtype=bool)
    differs[two] = pid[et[two, 0]] != pid[et[two, 1]]
    outline = differs | ~two
    outline[mesh.junction_edges] = True
    return mesh.points, mesh.edges[outline]


def scene_data(mesh: TriMesh) -> SceneData:
    """Build the datasets of every layer for ``mesh`` (thread-safe, no rendering).

    Parameters
    ----------
    mesh : TriMesh

    Returns
    -------
    SceneData
        ``datasets`` has one PolyData per layer name of :data:`LAYERS`; the faces carry
        the cell arrays ``patch``, ``region``, ``area``, ``min_angle``, ``aspect_ratio``.
    """
    pts = np.asarray(mesh.points, dtype=np.float64)
    tri = np.asarray(mesh.triangles)
    if len(pts):
        lo, hi = pts.min(axis=0), pts.max(axis=0)
    else:
        lo = hi = np.zeros(3)
    size = float(max(hi[0] - lo[0], hi[1] - lo[1], 1e-9))
    dz = 1e-4 * size

    faces = pv.PolyData.from_regular_faces(pts, tri) if len(tri) else pv.PolyData()
    ranges: dict[str, tuple[float, float]] = {}
    if len(tri):
        arrays = {
            "patch": (np.asarray(mesh.patch_ids) % _CATEGORIES).astype(np.float64),
            "region": np.asarray(mesh.regions, dtype=np.float64),
            "area": np.asarray(mesh.areas),
            "min_angle": np.asarray(mesh.min_angles),
            "aspect_ratio": np.asarray(mesh.aspect_ratios),
        }
        for name, values in arrays.items():
            faces.cell_data[name] = values
            finite = values[np.isfinite(values)]
            a, b = (float(finite.min()), float(finite.max())) if len(finite) else (0.0, 1.0)
            if b - a < 1e-12 * max(1.0, abs(a)):
                a, b = a - 0.5, b + 0.5
            ranges[name] = (a, b)
        ranges["patch"] = (-0.5, _CATEGORIES - 0.5)

    edges = np.asarray(mesh.edges) if len(tri) else np.empty((0, 2), dtype=np.int64)
    sets = {"faces": faces}
    sets["triangle_edges"] = _line_set(_lifted(pts, dz), edges)
    out_pts, out_pairs = patch_outline_pairs(mesh) if len(tri) else (pts, edges)
    sets["patch_outlines"] = _line_set(_lifted(out_pts, 2 * dz), out_pairs)
    for level, name, ids in (
        (3, "shared_edges", mesh.interior_edges if len(tri) else ()),
        (4, "boundary_edges", mesh.boundary_edges if len(tri) else ()),
        (5, "junction_edges", mesh.junction_edges if len(tri) else ()),
    ):
        sets[name] = _line_set(_lifted(pts, level * dz), edges[np.asarray(ids, dtype=np.int64)])
    centroids = _lifted(np.asarray(mesh.centroids), 6 * dz) if len(tri) else np.empty((0, 3))
    sets["centroids"] = pv.PolyData(centroids) if len(centroids) else pv.PolyData()
    small = 0 < len(tri) <= LABEL_LIMIT
    sets["labels"] = pv.PolyData(centroids) if small else pv.PolyData()
    bounds = (float(lo[0]), float(hi[0]), float(lo[1]), float(hi[1]))
    typical = float(np.mean(mesh.edge_lengths)) if len(tri) else 0.0
    return SceneData(sets, bounds, ranges, len(tri), typical)


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
    ) -> None:
        self.plotter = plotter
        self.visible = dict(DEFAULT_VISIBLE)
        self.visible.update(visible or {})
        self.color_by = color_by if color_by in COLOR_BY else "none"
        self.datasets: dict[str, pv.PolyData] = {name: pv.PolyData() for name in LAYERS}
        self.actors: dict[str, object] = {}
        self.bounds: tuple[float, float, float, float] | None = None
        self.ranges: dict[str, tuple[float, float]] = {}
        self.n_triangles = 0
        self.typical_edge = 0.0
        self._line_scale = 1.0
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
        for name in ("triangle_edges", "patch_outlines", "shared_edges", "boundary_edges",
                     "junction_edges"):
            self.actors[name] = p.add_mesh(
                self.datasets[name], color=COLORS[name], line_width=WIDTHS[name],
                style="wireframe", **common,
            )
        self.actors["centroids"] = p.add_mesh(
            self.datasets["centroids"], color=COLORS["centroids"],
            point_size=WIDTHS["centroids"], render_points_as_spheres=True,
            style="points", **common,
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
        p.add_actor(bar, reset_camera=False, pickable=False, render=False)
        self.scalar_bar = bar

        # Axes in mm with "nice" tick values along the bottom and left of the mesh.
        self.axes = p.show_bounds(
            bounds=(0.0, 1.0, 0.0, 1.0, 0.0, 0.0), show_zaxis=False, xtitle="x (mm)",
            ytitle="y (mm)", location="outer", ticks="outside", color="#303030",
            bold=False, font_size=12, n_xlabels=5, n_ylabels=5, use_2d=True, render=False,
            fmt="%.4g",
        )
        self.axes.SetPickable(False)
        self._apply_visibility()
        self._apply_color_by()

    # -- state ----------------------------------------------------------------

    def update(self, data: SceneData) -> None:
        """Copy new datasets into the existing ones (no new actors); the caller renders."""
        for name in LAYERS:
            self.datasets[name].copy_from(data.datasets[name], deep=False)
        self.bounds = data.bounds
        self.ranges = data.ranges
        self.n_triangles = data.n_triangles
        self.typical_edge = data.typical_edge
        self._place_rulers()
        self.fit_marker_sizes()
        self._apply_color_by()
        self._apply_visibility()

    def set_visible(self, layer: str, on: bool) -> None:
        if layer not in self.visible:
            raise ValueError(f"layer={layer!r} is unknown; expected one of {', '.join(LAYERS)}")
        self.visible[layer] = bool(on)
        self._apply_visibility()

    def set_color_by(self, key: str) -> None:
        if key not in COLOR_BY:
            raise ValueError(f"color_by={key!r} is unknown; expected one of {', '.join(COLOR_BY)}")
        self.color_by = key
        self._apply_color_by()
        self._apply_visibility()

    @property
    def labels_shown(self) -> bool:
        """Whether index labels are drawn (asked for, and the mesh is small enough)."""
        return self.visible["labels"] and 0 < self.n_triangles <= LABEL_LIMIT

    def _apply_visibility(self) -> None:
        for name in LAYERS:
            on = self.visible[name]
            if name == "labels":
                on = self.labels_shown
            self.actors[name].SetVisibility(bool(on))
        self.scalar_bar.SetVisibility(
            bool(self.visible["faces"] and self.color_by not in ("none", "patch")
                 and self.n_triangles)
        )
        self.axes.SetVisibility(self.bounds is not None and self.n_triangles > 0)

    def _apply_color_by(self) -> None:
        array, title = COLOR_BY[self.color_by]
        mapper = self.actors["faces"].mapper
        if array is None or array not in self.datasets["faces"].cell_data:
            mapper.SetScalarVisibility(False)
            return
        lut = mapper.lookup_table
        if array == "patch":
            lut.cmap = "tab10"
            lut.n_values = _CATEGORIES
        elif array == "region":
            lut.cmap = ["#9ecae1", "#fdae6b", "#a1d99b"]
            lut.n_values = 3
        else:
            lut.cmap = "viridis"
            lut.n_values = 256
        lo, hi = self.ranges.get(array, (0.0, 1.0))
        if array == "region":
            lo, hi = 0.5, 3.5
        mapper.SelectColorArray(array)
        mapper.SetScalarRange(lo, hi)
        lut.scalar_range = (lo, hi)
        mapper.SetScalarVisibility(True)
        self.scalar_bar.SetLookupTable(lut)
        self.scalar_bar.SetTitle(title)

    def show_rulers(self, bounds: tuple[float, float, float, float]) -> None:
        """Rulers in mm around ``bounds`` = (x0, x1, y0, y1) without a mesh (teaching views)."""
        self.bounds = tuple(float(v) for v in bounds)
        self._place_rulers()
        self.axes.SetVisibility(True)

    def _place_rulers(self) -> None:
        if self.bounds is None:
            return
        x0, x1, y0, y1 = self.bounds
        (x0, x1, nx), (y0, y1, ny) = nice_span(x0, x1), nice_span(y0, y1)
        self.axes.n_xlabels, self.axes.n_ylabels = nx, ny
        self.axes.bounds = (x0, x1, y0, y1, 0.0, 0.0)

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
        p.reset_camera(render=False, bounds=(x0 - pad, x1 + pad / 3, y0 - pad, y1 + pad / 3,
                                             0.0, 0.0))
        self.fit_marker_sizes()

    @contextmanager
    def scaled_lines(self, scale: float) -> Iterator[None]:
        """Temporarily multiply line widths, point sizes and fonts (for scaled screenshots)."""
        previous = self._line_scale
        self._set_line_scale(scale)
        try:
            yield
        finally:
            self._set_line_scale(previous)

    def _set_line_scale(self, scale: float) -> None:
        self._line_scale = scale
        self.fit_marker_sizes()

    def fit_marker_sizes(self) -> None:
        """Thin the lines and shrink the dots when triangles are a few pixels wide on screen.

        Fixed sizes would bury a dense mesh (the paper's Fig. 12(a) zoomed out): lines
        keep their full width from 12 px per typical edge up and thin to 1 px below, and a
        dot is at most a quarter of a typical edge.
        """
        camera = self.plotter.camera
        height = self.plotter.window_size[1] if self.plotter.window_size else 0
        edge_px = np.inf
        if self.typical_edge > 0 and camera.parallel_projection and height > 0:
            edge_px = self.typical_edge * height / max(2.0 * camera.parallel_scale, 1e-12)
        for name, width in WIDTHS.items():
            prop = self.actors[name].prop
            if name == "centroids":
                prop.point_size = (float(np.clip(0.25 * edge_px, 1.5, width))
                                   * self._line_scale * self.emphasis)
            else:
                thin = float(np.clip(width * edge_px / 12.0, 1.0, width))
                prop.line_width = thin * self._line_scale * self.emphasis

    def set_emphasis(self, scale: float) -> None:
        """Lines, dots and fonts ``scale`` times their normal size (presentation mode)."""
        self.emphasis = float(scale)
        self.fit_marker_sizes()
        size = int(round(12 * self.emphasis))
        self.actors["labels"].GetMapper().GetLabelTextProperty().SetFontSize(size)
        for prop in (self.scalar_bar.GetTitleTextProperty(),
                     self.scalar_bar.GetLabelTextProperty()):
            prop.SetFontSize(int(round(14 * self.emphasis)))
        for axis in range(3):
            self.axes.GetTitleTextProperty(axis).SetFontSize(size)
            self.axes.GetLabelTextProperty(axis).SetFontSize(size)


def nice_span(lo: float, hi: float, ticks: int = 5) -> tuple[float, float, int]:
    """Widen [lo, hi] to multiples of a 1-2-5 step; return the span and its label count.

    >>> nice_span(-9.7, 9.7)
    (-10.0, 10.0, 5)
    """
    width = max(hi - lo, 1e-12)
    raw = width / max(ticks - 1, 1)
    power = 10.0 ** np.floor(np.log10(raw))
    step = next(m * power for m in (1, 2, 2.5, 5, 10) if m * power >= raw * (1 - 1e-9))
    a = np.floor(lo / step + 1e-9) * step
    b = np.ceil(hi / step - 1e-9) * step
    return float(a), float(b), int(round((b - a) / step)) + 1


def _prepare_headless() -> None:
    """Without an X display, have VTK render through EGL instead of trying X first."""
    if not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")


def render_screenshot(
    mesh: TriMesh,
    path: str | os.PathLike[str],
    window_size: tuple[int, int] = (1024, 768),
    transparent: bool = False,
    *,
    visible: dict[str, bool] | None = None,
    color_by: str = "none",
) -> None:
    """Render ``mesh`` off-screen from above and save a PNG of exactly ``window_size``.

    Parallel projection, rulers in mm, triangles with their edges, centroids, shared
    and boundary edges (and junction edges, if any) in distinct colours. Works without
    an X display (VTK's EGL render window, Mesa's llvmpipe as the software driver).

    Parameters
    ----------
    mesh : TriMesh
    path : path-like
        Output PNG file.
    window_size : (int, int)
        Width and height in pixels.
    transparent : bool
        Transparent background instead of white.
    visible : dict of str to bool, optional
        Layer visibility overrides (see :data:`LAYERS`).
    color_by : str
        Face colouring, a key of :data:`COLOR_BY`.
    """
    width, height = (int(v) for v in window_size)
    if width < 1 or height < 1:
        raise ValueError(f"window_size={window_size!r} is invalid; expected two positive ints")
    path = Path(path)
    _prepare_headless()
    plotter = pv.Plotter(off_screen=True, window_size=(width, height))
    try:
        scene = MeshScene(plotter, visible=visible, color_by=color_by)
        scene.update(scene_data(mesh))
        scene.top_view()
        image = plotter.screenshot(None, transparent_background=transparent, return_img=True)
    finally:
        plotter.close()
    image = np.asarray(image)
    if image.shape[:2] != (height, width):  # high-DPI or a window manager resized it
        image = _resized(image, width, height)
    import imageio.v3 as iio

    iio.imwrite(path, image, extension=".png")


def _resized(image: np.ndarray, width: int, height: int) -> np.ndarray:
    """Nearest-neighbour resize (rarely needed; keeps the promised size exact)."""
    rows = (np.arange(height) * image.shape[0] / height).astype(int)
    cols = (np.arange(width) * image.shape[1] / width).astype(int)
    return image[rows][:, cols]

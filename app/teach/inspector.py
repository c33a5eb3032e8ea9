"""The RWG basis inspector: which edge a click means, and the overlay that draws it.

Two halves, as in :mod:`barymesh.app.view.scene`:

* Plain functions on a :class:`barymesh.TriMesh` (no Qt, no rendering): the edge a click on a
  triangle means (:func:`nearest_edge`), next/previous RWG unknown (:func:`step_edge`),
  the same spot in a new mesh (:func:`nearest_edge_to_point`), the info text
  (:func:`edge_info`), flat arrows as polygons (:func:`arrow_polygons`).
* :class:`InspectorOverlay` owns the overlay actors on one plotter: the edge, T+ and T−
  coloured by the divergence ±l/A±, the free vertices r±, the vectors ρ± and arrows of
  f_n at the quadrature points. They are created once and updated in place
  (``copy_from``), like :class:`barymesh.app.view.scene.MeshScene`; the caller renders.
"""

from __future__ import annotations

import html
from dataclasses import dataclass
from typing import Any

import numpy as np
import pyvista as pv
from vtkmodules.vtkCommonCore import vtkDoubleArray
from vtkmodules.vtkRenderingAnnotation import vtkScalarBarActor
from vtkmodules.vtkRenderingCore import vtkTextActor

from barymesh import TriMesh
from barymesh.app.view.scene import add_text_labels
from barymesh.teach.rwg_basis import BasisSample, edge_status, sample_rwg

#: Overlay colours: the selected edge, the quadrature arrows of f_n, the vectors ρ±, the
#: free vertices; T± take the divergence colour map (red +, blue −).
COLORS = {
    "edge": "#ffe000",  # yellow on a black rim: apart from the orange shared edges
    "edge_rim": "#000000",
    "arrows": "#111111",
    "rho": "#00a651",
    "free": "#00a651",
    "other": "#ffe08a",  # the triangle(s) of a boundary or junction edge
    "labels": "#000000",
}
DIVERGENCE_CMAP = "coolwarm"
EDGE_WIDTH = 6.0
FREE_SIZE = 14.0
FONT_SIZE = 15
DEFAULT_QUADRATURE = 4


# -- selection logic (pure) -----------------------------------------------------------


def edge_triangles(mesh: TriMesh, edge: int) -> np.ndarray:
    """Every triangle that has ``edge`` (one, two, or more at a junction), ascending.

    Returns
    -------
    (k,) int64
    """
    return np.flatnonzero((np.asarray(mesh.triangle_edges) == int(edge)).any(axis=1))


def _point_segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance from point ``p`` (3,) to segments ``a``–``b`` ((k, 3) each)."""
    ab = b - a
    denom = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)
    t = np.clip(np.einsum("ij,ij->i", p - a, ab) / denom, 0.0, 1.0)
    return np.linalg.norm(a + t[:, None] * ab - p, axis=1)


def nearest_edge(mesh: TriMesh, triangle: int, point: np.ndarray | None = None) -> int:
    """The edge of ``triangle`` a click at ``point`` means.

    The nearest of its three edges to ``point``; without a point, its first interior edge
    (or its first edge when it has none).

    >>> from barymesh import MeshParams, build_mesh
    >>> mesh = build_mesh(MeshParams(structure="patch", subdivisions=1))
    >>> int(nearest_edge(mesh, 0)) in set(mesh.interior_edges.tolist())
    True
    """
    if not 0 <= int(triangle) < mesh.n_triangles:
        raise ValueError(f"triangle={triangle!r} is out of range 0..{mesh.n_triangles - 1}")
    edges = np.asarray(mesh.triangle_edges[int(triangle)])
    if point is None:
        interior = mesh.topology.valence[edges] == 2
        return int(edges[np.argmax(interior)]) if interior.any() else int(edges[0])
    ends = np.asarray(mesh.points)[np.asarray(mesh.edges)[edges]]  # (3, 2, 3)
    p = np.asarray(point, dtype=np.float64)
    return int(edges[np.argmin(_point_segment_distance(p, ends[:, 0], ends[:, 1]))])


def nearest_edge_to_point(mesh: TriMesh, point: np.ndarray) -> int | None:
    """The edge whose midpoint is nearest ``point`` (to keep a selection across meshes)."""
    if len(mesh.edges) == 0:
        return None
    pts = np.asarray(mesh.points)
    mid = 0.5 * (pts[mesh.edges[:, 0]] + pts[mesh.edges[:, 1]])
    return int(np.argmin(np.linalg.norm(mid - np.asarray(point, dtype=np.float64), axis=1)))


def edge_midpoint(mesh: TriMesh, edge: int) -> np.ndarray:
    a, b = mesh.edges[int(edge)]
    return 0.5 * (mesh.points[a] + mesh.points[b])


def step_edge(mesh: TriMesh, edge: int | None, step: int) -> int | None:
    """The interior edge ``step`` RWG rows after (or before, ``step < 0``) ``edge``.

    Wraps around. From a boundary or junction edge, +1 goes to the first interior edge
    after it and −1 to the last one before it. ``None`` if the mesh has no interior edge.

    >>> from barymesh import MeshParams, build_mesh
    >>> mesh = build_mesh(MeshParams(structure="patch", subdivisions=1))
    >>> e = int(mesh.rwg.edge[0])
    >>> step_edge(mesh, e, 1) == int(mesh.rwg.edge[0]), step_edge(mesh, e, -1) == e
    (True, True)
    """
    rows = np.asarray(mesh.rwg.edge)
    if len(rows) == 0:
        return None
    if edge is None:
        return int(rows[0] if step >= 0 else rows[-1])
    pos = int(np.searchsorted(rows, int(edge)))
    exact = pos < len(rows) and rows[pos] == edge
    if exact:
        target = pos + step
    elif step > 0:
        target = pos + step - 1
    else:
        target = pos + step
    return int(rows[target % len(rows)])


@dataclass(frozen=True)
class EdgeInfo:
    """What the info box says about one edge."""

    edge: int
    vertices: tuple[int, int]
    length: float
    triangles: tuple[int, ...]
    status: str
    sample: BasisSample | None  # None for boundary and junction edges

    @property
    def is_rwg(self) -> bool:
        return self.sample is not None

    def rows(self) -> list[tuple[str, str]]:
        """(label, value) pairs for the info box, in the literature's names."""
        out = [
            ("Edge", f"{self.edge}"),
            ("Vertices", f"{self.vertices[0]}, {self.vertices[1]}"),
            ("Length l", f"{self.length:.4g} mm"),
        ]
        s = self.sample
        if s is None:
            out.append(("Triangles", ", ".join(str(t) for t in self.triangles)))
            return out
        out[1:1] = [("RWG row n", f"{s.row}")]
        out += [
            ("T+ / T−", f"{s.t_plus} / {s.t_minus}"),
            ("A+ / A−", f"{s.area_plus:.4g} / {s.area_minus:.4g} mm²"),
            ("Free vertices r+ / r−", f"{s.free_plus} / {s.free_minus}"),
            ("∇·f on T+ = l/A+", f"{s.divergence_plus:+.4g} 1/mm"),
            ("∇·f on T− = −l/A−", f"{s.divergence_minus:+.4g} 1/mm"),
        ]
        return out

    def html(self) -> str:
        cells = "".join(
            f"<tr><td>{html.escape(k)}</td><td><b>{html.escape(v)}</b></td></tr>"
            for k, v in self.rows()
        )
        return (
            f"<table cellspacing='3'>{cells}</table>"
            f"<p style='margin-top:6px'>{html.escape(self.status)}</p>"
        )

    def summary(self) -> str:
        """One or two lines for the in-view caption."""
        s = self.sample
        if s is None:
            kind = self.status.split(":", 1)[0]
            return f"edge {self.edge}: {kind}, no RWG function"
        return (
            f"edge {self.edge}: RWG unknown n = {s.row}, l = {s.length:.3g} mm\n"
            f"T+ = {s.t_plus}, A+ = {s.area_plus:.3g} mm²\n"
            f"T− = {s.t_minus}, A− = {s.area_minus:.3g} mm²"
        )


def edge_info(mesh: TriMesh, edge: int, quadrature: int = DEFAULT_QUADRATURE) -> EdgeInfo:
    """Everything the inspector shows about ``edge`` (sampled if it carries an RWG function)."""
    if not 0 <= int(edge) < len(mesh.edges):
        raise ValueError(f"edge={edge!r} is out of range; the mesh has {len(mesh.edges)} edges")
    edge = int(edge)
    a, b = (int(v) for v in mesh.edges[edge])
    length = float(np.linalg.norm(mesh.points[a] - mesh.points[b]))
    sample = sample_rwg(mesh, edge, quadrature) if mesh.topology.valence[edge] == 2 else None
    return EdgeInfo(
        edge,
        (a, b),
        length,
        tuple(int(t) for t in edge_triangles(mesh, edge)),
        edge_status(mesh, edge),
        sample,
    )


# -- geometry for the overlay -----------------------------------------------------------


def arrow_polygons(
    starts: np.ndarray, vectors: np.ndarray, width: float, head: float | None = None
) -> pv.PolyData:
    """Flat arrows in the xy plane as 7-gons: shaft of ``width``, head 3× wider.

    Parameters
    ----------
    starts, vectors : (k, 3) float64
        Tail positions and arrow vectors (their z is kept from ``starts``).
    width : float
        Shaft width; the head is ``3 * width`` wide and ``head`` long (default
        ``3 * width``, at most 60 % of the arrow).
    """
    starts = np.asarray(starts, dtype=np.float64).reshape(-1, 3)
    vectors = np.asarray(vectors, dtype=np.float64).reshape(-1, 3)
    length = np.linalg.norm(vectors[:, :2], axis=1)
    keep = length > 1e-12
    if not keep.any():
        return pv.PolyData()
    starts, vectors, length = starts[keep], vectors[keep], length[keep]
    d = np.zeros_like(vectors)
    d[:, :2] = vectors[:, :2] / length[:, None]
    n = np.column_stack([-d[:, 1], d[:, 0], np.zeros(len(d))])
    h = np.minimum(3.0 * width if head is None else head, 0.6 * length)[:, None]
    w = 0.5 * width
    tip = starts + d * length[:, None]
    neck = tip - d * h
    corners = np.stack(
        [
            starts + n * w,
            neck + n * w,
            neck + n * 3 * w,
            tip,
            neck - n * 3 * w,
            neck - n * w,
            starts - n * w,
        ],
        axis=1,
    )  # (k, 7, 3)
    k = len(corners)
    faces = np.empty((k, 8), dtype=np.int64)
    faces[:, 0] = 7
    faces[:, 1:] = 7 * np.arange(k)[:, None] + np.arange(7)
    return pv.PolyData(corners.reshape(-1, 3), faces=faces.ravel())


def _points(points: np.ndarray, labels: list[str] | None = None) -> pv.PolyData:
    poly = pv.PolyData(np.asarray(points, dtype=np.float64).reshape(-1, 3))
    if labels is not None:
        poly.point_data["label"] = np.array(labels)
    return poly


def _lift(points: np.ndarray, dz: float) -> np.ndarray:
    out = np.array(points, dtype=np.float64).reshape(-1, 3)
    out[:, 2] += dz
    return out


@dataclass
class OverlayData:
    """The overlay's datasets for one edge (see :func:`overlay_data`)."""

    datasets: dict[str, pv.PolyData]
    divergence: float  # colour range ±divergence
    caption: str
    divergence_plus: float = 0.0
    divergence_minus: float = 0.0


OVERLAY_PARTS = ("triangles", "others", "edge", "rho", "arrows", "free", "labels")


def overlay_data(mesh: TriMesh, info: EdgeInfo) -> OverlayData:
    """Datasets of the overlay for ``info`` (no rendering).

    ``triangles``: T+ and T− with the cell array ``divergence``; ``others``: the
    triangles of a boundary or junction edge; ``edge``: the edge; ``rho``: ρ± as flat
    arrows; ``arrows``: f_n at the quadrature points; ``free``: r+ and r−; ``labels``:
    points with a ``label`` string array (T+, T−, r+, r−).
    """
    pts = np.asarray(mesh.points, dtype=np.float64)
    span = np.ptp(pts[:, :2], axis=0).max() if len(pts) else 1.0
    dz = 1e-4 * max(float(span), 1e-9)
    a, b = info.vertices
    sets = {name: pv.PolyData() for name in OVERLAY_PARTS}
    sets["edge"] = pv.PolyData(_lift(pts[[a, b]], 8 * dz), lines=np.array([2, 0, 1]))
    s = info.sample
    if s is None:
        tri = np.asarray(mesh.triangles)[list(info.triangles)]
        if len(tri):
            sets["others"] = pv.PolyData.from_regular_faces(_lift(pts, 5.5 * dz), tri)
        return OverlayData(sets, 1.0, info.summary())

    corners = pts[np.asarray(mesh.triangles)[[s.t_plus, s.t_minus]]]  # (2, 3, 3)
    # above the scene's edge lines (up to 5 dz), so overlapping patches do not hatch T±
    faces = pv.PolyData.from_regular_faces(
        _lift(corners.reshape(-1, 3), 5.5 * dz), np.arange(6).reshape(2, 3)
    )
    faces.cell_data["divergence"] = np.array([s.divergence_plus, s.divergence_minus])
    sets["triangles"] = faces

    # arrows: the largest |f_n| sample is drawn 85 % of a quadrature cell long, centred on
    # its point; sizes are a fraction of the cell so they read at any zoom
    side = float(np.mean(np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2)))
    q = max(1, int(round(np.sqrt(len(s.points_plus)))))
    cell = side / q
    values = np.vstack([s.values_plus, s.values_minus])
    where = np.vstack([s.points_plus, s.points_minus])
    peak = float(np.linalg.norm(values[:, :2], axis=1).max()) or 1.0
    vec = values * (0.85 * cell / peak)
    sets["arrows"] = arrow_polygons(
        _lift(where - 0.5 * vec, 6.5 * dz), vec, 0.07 * cell, head=0.3 * cell
    )
    free = pts[[s.free_plus, s.free_minus]]
    rho_start = np.vstack([free[0], s.centroid_minus])
    rho_vec = np.vstack([s.rho_plus, s.rho_minus])
    sets["rho"] = arrow_polygons(_lift(rho_start, 7 * dz), rho_vec, 0.03 * side, head=0.1 * side)
    sets["free"] = _points(_lift(free, 9 * dz))
    # labels just outside the free vertices, away from the edge's midpoint
    mid = 0.5 * (pts[a] + pts[b])
    away = free - mid
    away /= np.maximum(np.linalg.norm(away, axis=1, keepdims=True), 1e-300)
    # VTK string arrays are ASCII only: r- with a hyphen
    sets["labels"] = _points(_lift(free + 0.14 * side * away, 10 * dz), ["r+", "r-"])
    return OverlayData(
        sets,
        max(abs(s.divergence_plus), abs(s.divergence_minus)),
        info.summary(),
        s.divergence_plus,
        s.divergence_minus,
    )


class InspectorOverlay:
    """Overlay actors of the inspector on one plotter, created once, updated in place.

    Parameters
    ----------
    plotter : pyvista.Plotter
    """

    def __init__(self, plotter: pv.Plotter) -> None:
        self.plotter = plotter
        self.datasets = {name: pv.PolyData() for name in OVERLAY_PARTS}
        self.actors: dict[str, Any] = {}  # pyvista actors and VTK 2D props
        self.visible = False
        self.scale = 1.0
        self._create_actors()
        self.set_visible(False)

    def _create_actors(self) -> None:
        p = self.plotter
        common = {"reset_camera": False, "lighting": False, "render": False, "pickable": False}
        tri = p.add_mesh(
            self.datasets["triangles"], scalars=None, opacity=0.75, show_scalar_bar=False, **common
        )
        tri.mapper.lookup_table = pv.LookupTable(cmap=DIVERGENCE_CMAP)
        tri.mapper.SetScalarModeToUseCellFieldData()
        tri.mapper.SelectColorArray("divergence")
        tri.mapper.SetScalarVisibility(True)
        self.actors["triangles"] = tri
        self.actors["others"] = p.add_mesh(
            self.datasets["others"], color=COLORS["other"], opacity=0.85, **common
        )
        self.actors["rho"] = p.add_mesh(self.datasets["rho"], color=COLORS["rho"], **common)
        self.actors["arrows"] = p.add_mesh(
            self.datasets["arrows"], color=COLORS["arrows"], **common
        )
        self.actors["edge_rim"] = p.add_mesh(
            self.datasets["edge"],
            color=COLORS["edge_rim"],
            line_width=EDGE_WIDTH + 4,
            style="wireframe",
            **common,
        )
        self.actors["edge"] = p.add_mesh(
            self.datasets["edge"],
            color=COLORS["edge"],
            line_width=EDGE_WIDTH,
            style="wireframe",
            **common,
        )
        self.actors["free"] = p.add_mesh(
            self.datasets["free"],
            color=COLORS["free"],
            point_size=FREE_SIZE,
            render_points_as_spheres=True,
            style="points",
            **common,
        )
        self.label_mapper, self.actors["labels"] = add_text_labels(
            p, self.datasets["labels"], COLORS["labels"], background_opacity=0.75
        )

        caption = vtkTextActor()
        caption.SetInput("")
        caption.GetPositionCoordinate().SetCoordinateSystemToNormalizedViewport()
        caption.SetPosition(0.015, 0.975)
        prop = caption.GetTextProperty()
        prop.SetColor(0.05, 0.05, 0.05)
        prop.SetVerticalJustificationToTop()
        prop.SetBackgroundColor(1.0, 1.0, 1.0)
        prop.SetBackgroundOpacity(0.8)
        prop.SetShadow(False)
        p.add_actor(caption, reset_camera=False, pickable=False, render=False)
        self.caption = caption

        bar = vtkScalarBarActor()
        bar.SetLookupTable(tri.mapper.lookup_table)
        bar.SetTitle("")  # VTK crowds a horizontal bar's title into its labels: own text
        bar.SetNumberOfLabels(3)
        bar.SetOrientationToHorizontal()
        bar.SetTextPositionToPrecedeScalarBar()  # labels under the bar, title above
        bar.SetPosition(0.64, 0.82)
        bar.SetWidth(0.33)
        bar.SetHeight(0.12)
        bar.SetUseCustomLabels(True)
        self._bar_labels = vtkDoubleArray()
        bar.SetCustomLabels(self._bar_labels)
        bar.UnconstrainedFontSizeOn()
        bar.SetLabelFormat("%-#6.3g")
        for prop in (bar.GetTitleTextProperty(), bar.GetLabelTextProperty()):
            prop.SetColor(0.1, 0.1, 0.1)
            prop.SetShadow(False)
            prop.SetItalic(False)
            prop.SetBackgroundColor(1.0, 1.0, 1.0)  # readable over a dense mesh
            prop.SetBackgroundOpacity(0.85)
        p.add_actor(bar, reset_camera=False, pickable=False, render=False)
        self.scalar_bar = bar
        title = vtkTextActor()
        title.SetInput("div f_n (1/mm)")
        title.GetPositionCoordinate().SetCoordinateSystemToNormalizedViewport()
        title.SetPosition(0.805, 0.975)
        prop = title.GetTextProperty()
        prop.SetColor(0.1, 0.1, 0.1)
        prop.SetBold(True)
        prop.SetShadow(False)
        prop.SetJustificationToCentered()
        prop.SetVerticalJustificationToTop()
        prop.SetBackgroundColor(1.0, 1.0, 1.0)
        prop.SetBackgroundOpacity(0.85)
        p.add_actor(title, reset_camera=False, pickable=False, render=False)
        self.bar_title = title
        self.set_scale(1.0)

    def top_px(self) -> float:
        """Pixels at the top of the view the overlay's header takes while it is shown:
        its caption (three lines) at the left, the colour bar with its title and numbers
        at the right. The window frames the mesh under it (it covered the mesh's top)."""
        if not self.visible:
            return 0.0
        h = float(self.plotter.window_size[1])
        caption = 3 * 1.3 * self.caption.GetTextProperty().GetFontSize() + 0.025 * h
        bar = (1.0 - self.scalar_bar.GetPosition()[1]) * h
        return max(caption, bar) + 8.0

    def set_scale(self, scale: float) -> None:
        """Line widths, dot sizes and fonts times ``scale`` (presentation mode)."""
        self.scale = float(scale)
        self.actors["edge"].prop.line_width = EDGE_WIDTH * self.scale
        self.actors["edge_rim"].prop.line_width = (EDGE_WIDTH + 4) * self.scale
        self.actors["free"].prop.point_size = FREE_SIZE * self.scale
        self.label_mapper.GetLabelTextProperty().SetFontSize(int(FONT_SIZE * 1.2 * self.scale))
        self.caption.GetTextProperty().SetFontSize(int(FONT_SIZE * self.scale))
        for prop in (
            self.scalar_bar.GetTitleTextProperty(),
            self.scalar_bar.GetLabelTextProperty(),
        ):
            prop.SetFontSize(int(13 * self.scale))
        self.bar_title.GetTextProperty().SetFontSize(int(13 * self.scale))

    def update(self, data: OverlayData | None) -> None:
        """Show ``data`` (``None``: nothing selected); the caller renders."""
        if data is None:
            for name in OVERLAY_PARTS:
                self.datasets[name].copy_from(pv.PolyData(), deep=False)
            self.caption.SetInput("")
            self._has_rwg = False
        else:
            for name in OVERLAY_PARTS:
                self.datasets[name].copy_from(data.datasets[name], deep=False)
            self.caption.SetInput(data.caption)
            lo, hi = -1.15 * data.divergence, 1.15 * data.divergence
            mapper = self.actors["triangles"].mapper
            mapper.SetScalarRange(lo, hi)
            mapper.lookup_table.scalar_range = (lo, hi)
            ticks = [data.divergence_minus, 0.0, data.divergence_plus]
            self._bar_labels.SetNumberOfValues(3)
            for i, v in enumerate(ticks):
                self._bar_labels.SetValue(i, v)
            self._bar_labels.Modified()
            self.scalar_bar.SetCustomLabels(self._bar_labels)
            self._has_rwg = data.datasets["triangles"].n_cells > 0
        self.set_visible(self.visible)

    def set_visible(self, on: bool) -> None:
        self.visible = bool(on)
        for actor in self.actors.values():
            actor.SetVisibility(self.visible)
        self.caption.SetVisibility(self.visible)
        self.scalar_bar.SetVisibility(self.visible and getattr(self, "_has_rwg", False))
        self.bar_title.SetVisibility(self.scalar_bar.GetVisibility())

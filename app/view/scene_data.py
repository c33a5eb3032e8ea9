"""What the view draws, as plain numpy arrays: made in worker threads, shown by
:class:`barymesh.app.view.scene.MeshScene` on the GUI thread.

:func:`scene_data` turns a mesh into one :class:`~barymesh.app.view.polydata.Layer` per
layer (faces with per-cell quality arrays, line sets for edges, points for centroids) and,
for a dense mesh, an :class:`Overview` image; :func:`detail_data` makes the full detail of
the part in view. This module imports neither VTK nor pyvista (a test holds it to that):
VTK objects are not thread-safe, and one made or freed in a worker while the GUI thread
renders corrupts the heap, so what a worker can import cannot make one by accident.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from barymesh import BuildCancelled, TriMesh
from barymesh.app.model.layers import COLOR_BY, LABEL_LIMIT, LAYERS
from barymesh.app.view.overview import (
    DETAIL_TRIANGLES,
    count_grid,
    decimated_lines,
    overlap_count_raster,
    overlap_counts_at,
    overview_raster,
    raster_shape,
    raster_side,
    triangles_in_rect,
)
from barymesh.app.view.polydata import Layer

log = logging.getLogger(__name__)


def _rgb255(colour: str) -> tuple[int, int, int]:
    """``"#rrggbb"`` as three 0-255 integers."""
    h = colour.lstrip("#")
    return int(h[0:2], 16), int(h[2:4], 16), int(h[4:6], 16)


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
CATEGORIES = 10  # patches are coloured cyclically with a 10-colour qualitative map
REGION_COLORS = ["#9ecae1", "#fdae6b", "#a1d99b"]
REGION_NAMES = {1: "inner ring / patch", 2: "outer ring", 3: "region 3"}
#: Lines thinned to less than this many pixels are drawn 1 px wide: a line wider than
#: 1 px is drawn as two triangles, and doubled a software-rendered frame's line cost.
WIDE_FROM = 1.5
#: Below this many pixels per typical triangle edge, triangle edges, shared edges and
#: centroids are not drawn (they would only paint a texture over the faces); from it up
#: the mesh is drawn the way the paper draws it. Detail "always full" (:data:`DETAIL_MODES`)
#: draws them at any size.
LIGHT_PX = 4.0
#: Triangle numbers (up to :data:`~barymesh.app.model.layers.LABEL_LIMIT` triangles) are
#: drawn from this many pixels per typical edge (times the presentation emphasis), in
#: Detail "auto": below it a label of three digits is wider than the gap between two
#: centroids, and a few hundred of them were a black smudge (the array preview, a ring
#: dragged small).
LABEL_PX = 40.0
#: Detail "always full" of more triangles than this gets a warning: every frame draws them
#: all (seconds per frame on a software renderer).
FULL_DETAIL_WARN = 1_000_000
#: Layers left out while a layer covers the faces (the surface current's arrows sit at
#: the centroids, dark on dark red: orange lines and magenta dots would hide them).
COVERED_HIDES = ("shared_edges", "centroids", "labels")
#: Layers that exist per triangle or per edge: drawn in full detail only.
DETAIL_LAYERS = ("faces", "triangle_edges", "shared_edges", "centroids", "labels")
_ARRAYS = ("patch", "region", "area", "min_angle", "aspect_ratio", "overlap")
#: Paper-mode meshes whose patches overlap at least this much (``TriMesh.overlap_ratio``)
#: get the *overlap look* when the user colours faces by "Patches over each point"
#: (colouring "overlap"; never by default): faces coloured by how many patches cover each
#: point, 1 in k patch outlines drawn for the zoom, every patch's triangle edges,
#: centroids and borders hidden (overlapping, they tangle into a moire).
OVERLAP_LOOK = 0.2
#: In the overlap look, outlines are drawn at least this far apart on screen (px) on
#: average: every k-th patch is outlined, k chosen from the zoom.
OUTLINE_SPACING_PX = 9.0
#: A resting view whose overview texels cover more than this many pixels gets a sharper
#: image of the part in view (when it holds too many triangles for full detail).
ZOOM_TEXEL_PX = 1.6


@dataclass
class Overview:
    """The faces of a dense mesh (or of a part of it) as an image.

    See :mod:`barymesh.app.view.overview`.

    ``values`` holds, per colouring array, the value of the triangle under each texel
    (float32, NaN where no triangle is); ``centroid_counts`` (a 256 x 256 grid over
    ``bounds``, :func:`barymesh.app.view.overview.count_grid`) lets the view count the
    triangles in a
    rectangle without touching the mesh.
    """

    bounds: tuple[float, float, float, float]
    covered: np.ndarray  # (rows, cols) bool
    values: dict[str, np.ndarray]
    centroid_counts: np.ndarray | None = None
    #: (rows, cols, 4) uint8 colours, made in the worker for the colouring ``image_key``
    #: (plain numpy there; the GUI thread wraps them for the texture, see
    #: :meth:`MeshScene._recolor_overview`)
    rgba: np.ndarray | None = None
    image_key: str | None = None


@dataclass
class SceneData:
    """The layers of one mesh as plain arrays, ready to be shown by a :class:`MeshScene`
    (made in any thread: it holds no VTK object)."""

    layers: dict[str, Layer]
    bounds: tuple[float, float, float, float]  # x0, x1, y0, y1 (mm)
    ranges: dict[str, tuple[float, float]] = field(default_factory=dict)
    n_triangles: int = 0
    typical_edge: float = 0.0  # mean edge length (mm), to size the centroid dots
    overview: Overview | None = None  # dense meshes: the faces as an image
    rect: tuple[float, float, float, float] | None = None  # a detail's extent (mm)
    paper: bool = False  # paper mode: the boundary edges outline every patch
    overlap_ratio: float | None = None  # paper mode: TriMesh.overlap_ratio
    patch_rects: np.ndarray | None = None  # paper mode: (P, 4) x0, y0, x1, y1 (mm)


def line_set(points: np.ndarray, pairs: np.ndarray) -> Layer:
    """(V, 3) points and (k, 2) vertex pairs as a layer of k line cells."""
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    if len(pairs) == 0:
        return Layer()
    # all points are kept (unused ones cost a few bytes, a np.unique to drop them cost
    # a third of the dataset update on every slider move)
    return Layer(np.ascontiguousarray(points, dtype=np.float64), lines=pairs)


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
        return rect_outlines(mesh.patch_rects)
    et = mesh.edge_triangles
    pid = mesh.patch_ids
    two = et[:, 1] >= 0
    differs = np.zeros(len(et), dtype=bool)
    differs[two] = pid[et[two, 0]] != pid[et[two, 1]]
    outline = differs | ~two
    outline[mesh.junction_edges] = True
    return mesh.points, mesh.edges[outline]


def rect_outlines(rects: np.ndarray, z: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """The four sides of each rectangle (x0, y0, x1, y1) of ``rects`` (P, 4) at height
    ``z``: points (4P, 3) float64 and vertex pairs (4P, 2) int."""
    r = np.asarray(rects, dtype=np.float64).reshape(-1, 4)
    x0, y0, x1, y1 = r.T
    corners = np.stack(
        [np.column_stack(c) for c in ((x0, y0), (x1, y0), (x1, y1), (x0, y1))], axis=1
    )  # (P, 4, 2)
    points = np.column_stack([corners.reshape(-1, 2), np.full(4 * len(r), float(z))])
    sides = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])
    pairs = (4 * np.arange(len(r))[:, None, None] + sides[None]).reshape(-1, 2)
    return points, pairs


def outline_stride(
    rects: np.ndarray,
    overlap_ratio: float,
    px_per_mm: float,
    spacing_px: float = OUTLINE_SPACING_PX,
) -> int:
    """Outline every k-th of the overlapping patches ``rects`` so that their sides lie
    about ``spacing_px`` apart on screen: the union's area over the sides' total length
    is their mean spacing (mm). Returns k >= 1."""
    r = np.asarray(rects, dtype=np.float64).reshape(-1, 4)
    w, h = r[:, 2] - r[:, 0], r[:, 3] - r[:, 1]
    length = float(2.0 * (w + h).sum())
    union = float((w * h).sum()) * max(1.0 - overlap_ratio, 1e-9)
    if length <= 0 or px_per_mm <= 0 or not np.isfinite(px_per_mm):
        return 1
    spacing = union / length * px_per_mm
    return max(1, min(len(r), int(np.ceil(spacing_px / max(spacing, 1e-12)))))


def _face_arrays(
    mesh: TriMesh, sel: np.ndarray | None, overlap: bool = True
) -> dict[str, np.ndarray]:
    """The colouring arrays of the triangles ``sel`` (all if None); ``overlap`` (paper
    mode, if asked for): how many patches cover each triangle's centroid."""
    arrays = {
        "patch": np.asarray(mesh.patch_ids) % CATEGORIES,
        "region": np.asarray(mesh.regions),
        "area": np.asarray(mesh.areas),
        "min_angle": np.asarray(mesh.min_angles),
        "aspect_ratio": np.asarray(mesh.aspect_ratios),
    }
    if sel is not None:
        arrays = {k: v[sel] for k, v in arrays.items()}
    rects = _paper_rects(mesh)
    if overlap and rects is not None:
        cents = np.asarray(mesh.centroids)
        arrays["overlap"] = overlap_counts_at(rects, cents if sel is None else cents[sel])
    return {k: v.astype(np.float64) for k, v in arrays.items()}


def _paper_rects(mesh: TriMesh) -> np.ndarray | None:
    """(P, 4) patch rectangles of a paper-mode mesh, else None."""
    rects = mesh.patch_rects
    if mesh.mode != "paper" or rects is None or len(rects) == 0:
        return None
    return np.asarray(rects, dtype=np.float64)


def lut_settings(
    array: str, ranges: dict[str, tuple[float, float]]
) -> tuple[str | list[str], int, float, float]:
    """(colour map, number of colours, low, high) of the face colouring ``array``."""
    lo, hi = ranges.get(array, (0.0, 1.0))
    if array == "patch":
        return "tab10", CATEGORIES, lo, hi
    if array == "region":
        return REGION_COLORS, 3, 0.5, 3.5
    if array == "overlap":  # whole counts: one colour each
        return "viridis", int(np.clip(round(hi - lo), 1, 256)), lo, hi
    return "viridis", 256, lo, hi


def overview_rgba(ov: Overview, key: str, ranges: dict[str, tuple[float, float]]) -> np.ndarray:
    """(rows, cols, 4) uint8 colours of the overview ``ov`` for the colouring ``key`` (a
    key of :data:`COLOR_BY`): the faces' lookup table (:func:`lut_settings`) applied as
    VTK's ``vtkLookupTable`` does, in plain numpy (no VTK object in a worker thread)."""
    rows, cols = ov.covered.shape
    array, _ = COLOR_BY[key]
    rgba = np.zeros((rows, cols, 4), dtype=np.uint8)
    if array is None or array not in ov.values:
        rgba[ov.covered] = (*_rgb255(COLORS["faces"]), 255)
        return rgba
    cmap, n_values, lo, hi = lut_settings(array, ranges)
    table = colour_table(cmap, n_values)
    v = ov.values[array][ov.covered].astype(np.float64)
    index = np.floor((v - lo) * (n_values / max(hi - lo, 1e-300)))
    index = np.clip(np.nan_to_num(index, nan=0.0), 0, n_values - 1).astype(np.intp)
    colours = table[index]
    colours[np.isnan(v)] = (128, 0, 0, 255)  # VTK's colour for NaN
    rgba[ov.covered] = colours
    return rgba


def colour_table(cmap: object, n_values: int) -> np.ndarray:
    """(n_values, 4) uint8: the table pyvista's ``LookupTable(cmap, n_values)`` holds."""
    from pyvista.plotting.colors import get_cmap_safe

    if isinstance(cmap, list):
        n_values = len(cmap)
    values = get_cmap_safe(cmap)(np.linspace(0, 1, n_values)) * 255
    return values.astype(np.uint8)


def shown_color(color_by: str, overlap_ratio: float | None) -> str:
    """The colouring drawn for the chosen one ``color_by``: itself. (The overlap count
    replaced "none" on overlapping paper meshes once; it is now a colouring to pick.)"""
    del overlap_ratio  # kept in the signature: callers pass the mesh's ratio
    return color_by


def needs_triangles(overview: Overview | None, color_by: str) -> bool:
    """Whether the overview ``overview`` lacks the per-triangle values of the colouring
    ``color_by`` (made by :func:`scene_data` only when shown: a new scene is needed)."""
    if overview is None or color_by not in COLOR_BY:
        return False
    array = COLOR_BY[color_by][0]
    return array is not None and array not in overview.values


def full_detail_warning(n_triangles: int, detail: str) -> str:
    """The cost warning of Detail ``detail`` for a mesh of ``n_triangles`` ("" if none).

    >>> full_detail_warning(999_999, "full")
    ''
    >>> full_detail_warning(2_000_000, "auto")
    ''
    """
    if detail != "full" or n_triangles <= FULL_DETAIL_WARN:
        return ""
    return (
        f"Full detail of {n_triangles:,} triangles: every frame draws each triangle, "
        "edge and centroid (slow above about 1M; Detail: automatic draws an image)"
    )


def _ranges(mesh: TriMesh, arrays: dict[str, np.ndarray]) -> dict[str, tuple[float, float]]:
    ranges = {}
    for name, values in arrays.items():
        finite = values[np.isfinite(values)]
        a, b = (float(finite.min()), float(finite.max())) if len(finite) else (0.0, 1.0)
        if b - a < 1e-12 * max(1.0, abs(a)):
            # one value (equal triangles): a scale of +-10 % around it, so its ticks are
            # near it and of its sign and digits (not -0.5..0.5 around 0.0005 mm²)
            half = 0.1 * abs(a) if a != 0 else 0.5
            a, b = a - half, b + half
        ranges[name] = (a, b)
    if "overlap" in ranges:
        ranges["overlap"] = (0.5, max(ranges["overlap"][1], 1.0) + 0.5)
    ranges["patch"] = (-0.5, CATEGORIES - 0.5)
    ranges["region"] = (0.5, 3.5)
    return ranges


def scene_data(
    mesh: TriMesh,
    detail_limit: int = DETAIL_TRIANGLES,
    *,
    color_by: str = "none",
    pixels: tuple[int, int] | None = None,
    cancel: Callable[[], bool] | None = None,
) -> SceneData:
    """Build the datasets of every layer for ``mesh`` (thread-safe, no rendering).

    A mesh of more than ``detail_limit`` triangles gets an :class:`Overview` (its faces
    as an image) and only the layers whose size follows the outline, not the triangle
    count (boundary and junction edges, patch outlines when few); :func:`detail_data`
    gives the full detail of a part of it.

    Parameters
    ----------
    mesh : TriMesh
    detail_limit : int
    color_by : str
        The colouring the window shows (a key of :data:`COLOR_BY`): a dense mesh's
        overview image is coloured for it here, not on the GUI thread.
    pixels : (int, int), optional
        The view's size: the overview has about one texel per pixel of its longer side
        (:func:`barymesh.app.view.overview.raster_side`), and its line layers are cut down to what
        those texels can show (:func:`barymesh.app.view.overview.decimated_lines`).
    cancel : callable, optional
        Polled between the stages of a dense mesh's overview; when it returns True,
        :class:`barymesh.BuildCancelled` is raised (an abandoned build stops here too).

    Returns
    -------
    SceneData
        ``datasets`` has one PolyData per layer name of :data:`LAYERS`; full-detail faces
        carry the cell arrays ``patch``, ``region``, ``area``, ``min_angle``,
        ``aspect_ratio`` and ``triangle`` (the mesh's triangle index).
    """
    pts = np.asarray(mesh.points, dtype=np.float64)
    n = mesh.n_triangles
    if len(pts):
        lo, hi = pts.min(axis=0), pts.max(axis=0)
    else:
        lo = hi = np.zeros(3)
    bounds = (float(lo[0]), float(hi[0]), float(lo[1]), float(hi[1]))
    typical = float(np.mean(mesh.edge_lengths)) if n else 0.0
    rects = _paper_rects(mesh)
    ratio = mesh.overlap_ratio if rects is not None else None
    paper: dict[str, Any] = {
        "paper": mesh.mode == "paper",
        "overlap_ratio": ratio,
        "patch_rects": rects,
    }
    dense = n > detail_limit
    arrays = _face_arrays(mesh, None, overlap=not dense) if n else {}
    ranges = _ranges(mesh, arrays) if n else {}
    if not dense:
        data = _detail_sets(mesh, None, bounds, arrays)
        return SceneData(data, bounds, ranges, n, typical, **paper)
    size = float(max(hi[0] - lo[0], hi[1] - lo[1], 1e-9))
    dz = 1e-4 * size
    side = raster_side(pixels)
    shape = raster_shape(bounds, side)

    def check() -> None:
        if cancel is not None and cancel():
            raise BuildCancelled("the build was cancelled")

    key = shown_color(color_by if color_by in COLOR_BY else "none", ratio)
    # paper patches shown solid or by their count: the image is the patches' coverage,
    # exact from their rectangles, and no triangle need be found under each texel (the
    # raster's point-in-triangle tests were most of a heavy overlap's scene time); a
    # colouring per triangle chosen later has the worker make it (needs_triangles)
    by_triangle = rects is None or COLOR_BY[key][0] not in (None, "overlap")
    check()
    raster = overview_raster(pts, mesh.triangles, bounds, side) if by_triangle else None
    check()
    sets = {name: Layer() for name in LAYERS}
    edges = np.asarray(mesh.edges)
    for level, name, ids in (
        (4, "boundary_edges", mesh.boundary_edges),
        (5, "junction_edges", mesh.junction_edges),
    ):
        pairs = edges[np.asarray(ids, dtype=np.int64)]
        sets[name] = _screen_lines(pts, pairs, bounds, shape, level * dz)
    if rects is None:  # (paper mode: the window outlines a part of the patches)
        out_pts, out_pairs = patch_outline_pairs(mesh)
        sets["patch_outlines"] = _screen_lines(out_pts, out_pairs, bounds, shape, 2 * dz)
    check()
    covered, values = _image_values(raster, shape, arrays if by_triangle else {}, rects, bounds)
    del raster, arrays
    check()
    if rects is not None:
        top = float(np.nanmax(values["overlap"])) if covered.any() else 1.0
        ranges["overlap"] = (0.5, max(top, 1.0) + 0.5)
    overview = Overview(bounds, covered, values, count_grid(mesh.centroids, bounds))
    overview.rgba = overview_rgba(overview, key, ranges)
    overview.image_key = key
    return SceneData(sets, bounds, ranges, n, typical, overview, **paper)


def _image_values(
    raster: np.ndarray | None,
    shape: tuple[int, int],
    arrays: dict[str, np.ndarray],
    rects: np.ndarray | None,
    bounds: tuple[float, float, float, float],
) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Texel coverage and colouring values of an image of ``shape`` texels.

    ``raster`` (triangle per texel,
    :func:`barymesh.app.view.overview.overview_raster`) may be coarser
    than ``shape`` (heavy overlaps cost more tests): it is stretched to it. Paper mode
    (``rects`` given): the count of patches over each texel centre is exact at the full
    ``shape`` (:func:`barymesh.app.view.overview.overlap_count_raster`), and so is the coverage.

    Returns
    -------
    covered : (rows, cols) bool
    values : dict of str to (rows, cols) float32
        NaN where no triangle is.
    """
    rows, cols = shape
    if raster is None:  # paper patches by their count only (see scene_data)
        assert rects is not None  # a paper mesh's
        count = overlap_count_raster(rects, bounds, shape)
        covered = count > 0
        return covered, {"overlap": np.where(covered, count, np.nan).astype(np.float32)}
    if raster.shape != (rows, cols):  # nearest texel of the coarser raster
        jj = np.minimum(np.arange(rows) * raster.shape[0] // rows, raster.shape[0] - 1)
        ii = np.minimum(np.arange(cols) * raster.shape[1] // cols, raster.shape[1] - 1)
        raster = raster[np.ix_(jj, ii)]
    hit = raster >= 0
    where = np.where(hit, raster, 0)
    values = {}
    for name, v in arrays.items():
        img = v.astype(np.float32)[where]
        img[~hit] = np.nan
        values[name] = img
    covered = hit
    if rects is not None:
        count = overlap_count_raster(rects, bounds, shape)
        covered = count > 0
        values["overlap"] = np.where(covered, count, np.nan).astype(np.float32)
    return covered, values


def _screen_lines(
    points: np.ndarray,
    pairs: np.ndarray,
    bounds: tuple[float, float, float, float],
    shape: tuple[int, int],
    dz: float,
) -> Layer:
    """Line cells of ``pairs`` snapped to a raster's texels (as many as it can show)."""
    xy, snapped = decimated_lines(points, pairs, bounds, shape)
    if len(snapped) == 0:
        return Layer()
    return line_set(np.column_stack([xy, np.full(len(xy), dz)]), snapped)


def detail_data(
    mesh: TriMesh,
    rect: tuple[float, float, float, float],
    limit: int = DETAIL_TRIANGLES,
    *,
    color_by: str = "none",
    pixels: tuple[int, int] | None = None,
    ranges: dict[str, tuple[float, float]] | None = None,
    bounds: tuple[float, float, float, float] | None = None,
) -> SceneData | None:
    """Full-detail datasets of the triangles of ``mesh`` around ``rect`` (thread-safe).

    ``rect`` (x0, x1, y0, y1, mm) is grown by half its size on every side, so a little
    panning stays detailed. Only the per-triangle layers (:data:`DETAIL_LAYERS`) are
    filled. When that part holds more than ``limit`` triangles: given the view's
    ``pixels``, the overview's ``ranges`` (colour scales) and the mesh's ``bounds``, an
    :class:`Overview` of just that part at about one texel a pixel (a sharper image of
    the part in view, coloured for ``color_by``, in ``SceneData.overview``); else None.
    """
    x0, x1, y0, y1 = rect
    grow = 0.5 * max(x1 - x0, y1 - y0)
    big = (x0 - grow, x1 + grow, y0 - grow, y1 + grow)
    sel = triangles_in_rect(mesh.centroids, big)
    if len(sel) > limit:
        if pixels is None or ranges is None or bounds is None:
            return None
        return _zoom_data(mesh, big, bounds, color_by, pixels, ranges)
    if bounds is None:
        pts = np.asarray(mesh.points)
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        bounds = (float(lo[0]), float(hi[0]), float(lo[1]), float(hi[1]))
    sets = _detail_sets(mesh, sel, bounds, _face_arrays(mesh, sel))
    for name in LAYERS:
        if name not in DETAIL_LAYERS:
            sets[name] = Layer()
    return SceneData(sets, bounds, {}, len(sel), 0.0, rect=big)


def _zoom_data(
    mesh: TriMesh,
    big: tuple[float, float, float, float],
    bounds: tuple[float, float, float, float],
    color_by: str,
    pixels: tuple[int, int],
    ranges: dict[str, tuple[float, float]],
) -> SceneData:
    """An overview of the part ``big`` of ``mesh`` (the view grown 2 x 2 times) at about
    one texel a pixel: ``2 * max(pixels)`` texels on its longer side, within the bounds of
    :mod:`barymesh.app.view.overview`."""
    zone = (
        max(big[0], bounds[0]),
        min(big[1], bounds[1]),
        max(big[2], bounds[2]),
        min(big[3], bounds[3]),
    )
    if zone[1] <= zone[0] or zone[3] <= zone[2]:
        zone = big
    reach = float(np.max(mesh.edge_lengths)) if mesh.n_triangles else 0.0
    sel = triangles_in_rect(mesh.centroids, zone, margin=reach)
    pts = np.asarray(mesh.points)
    tri = np.asarray(mesh.triangles)[sel]
    side = raster_side((2 * max(pixels), 1))
    raster = overview_raster(pts, tri, zone, side)
    rects = _paper_rects(mesh)
    covered, values = _image_values(
        raster, raster_shape(zone, side), _face_arrays(mesh, sel, overlap=False), rects, zone
    )
    zoom = Overview(zone, covered, values)
    key = shown_color(
        color_by if color_by in COLOR_BY else "none",
        mesh.overlap_ratio if rects is not None else None,
    )
    zoom.rgba = overview_rgba(zoom, key, ranges)
    zoom.image_key = key
    sets = {name: Layer() for name in LAYERS}
    return SceneData(sets, bounds, ranges, len(sel), 0.0, zoom, rect=zone)


def _detail_sets(
    mesh: TriMesh,
    sel: np.ndarray | None,
    bounds: tuple[float, float, float, float],
    arrays: dict[str, np.ndarray],
) -> dict[str, Layer]:
    """Every layer's dataset for the triangles ``sel`` of ``mesh`` (all if None), the
    faces carrying the colouring ``arrays`` of those triangles."""
    pts = np.asarray(mesh.points, dtype=np.float64)
    tri = np.asarray(mesh.triangles)
    x0, x1, y0, y1 = bounds
    dz = 1e-4 * float(max(x1 - x0, y1 - y0, 1e-9))
    if len(tri) == 0 or (sel is not None and len(sel) == 0):
        return {name: Layer() for name in LAYERS}
    edges = np.asarray(mesh.edges)
    kind = np.zeros(len(edges), dtype=np.int8)  # 3 shared, 4 boundary, 5 junction
    kind[np.asarray(mesh.interior_edges, dtype=np.int64)] = 3
    kind[np.asarray(mesh.boundary_edges, dtype=np.int64)] = 4
    kind[np.asarray(mesh.junction_edges, dtype=np.int64)] = 5
    if sel is None:
        ids = np.arange(len(tri))
        local_pts, local_tri, local_edges = pts, tri, edges
        centroids = np.asarray(mesh.centroids)
    else:
        ids = np.asarray(sel, dtype=np.int64)
        inside = np.zeros(len(tri), dtype=bool)
        inside[ids] = True
        et = np.asarray(mesh.edge_triangles)
        keep = inside[et[:, 0]] | ((et[:, 1] >= 0) & inside[np.maximum(et[:, 1], 0)])
        used = np.unique(tri[ids])
        remap = np.full(len(pts), -1, dtype=np.int64)
        remap[used] = np.arange(len(used))
        local_pts = pts[used]
        local_tri = remap[tri[ids]]
        edges_kept = edges[keep]
        ok = (remap[edges_kept] >= 0).all(axis=1)
        local_edges = remap[edges_kept[ok]]
        kind = kind[keep][ok]
        centroids = np.asarray(mesh.centroids)[ids]
    cell_data = dict(arrays)
    cell_data["triangle"] = ids.astype(np.int64)
    sets = {
        "faces": Layer(
            np.ascontiguousarray(local_pts, dtype=np.float64),
            faces=np.asarray(local_tri, dtype=np.int64),
            cell_data=cell_data,
        )
    }
    lifted = _lifted(local_pts, dz)
    sets["triangle_edges"] = line_set(lifted, local_edges)
    if sel is None:
        out_pts, out_pairs = patch_outline_pairs(mesh)
        sets["patch_outlines"] = line_set(_lifted(out_pts, 2 * dz), out_pairs)
    else:
        sets["patch_outlines"] = Layer()
    for level, name in ((3, "shared_edges"), (4, "boundary_edges"), (5, "junction_edges")):
        sets[name] = line_set(_lifted(local_pts, level * dz), local_edges[kind == level])
    cents = _lifted(centroids, 6 * dz)
    sets["centroids"] = Layer(cents)
    small = len(ids) <= LABEL_LIMIT and sel is None
    sets["labels"] = Layer(cents) if small else Layer()
    return sets

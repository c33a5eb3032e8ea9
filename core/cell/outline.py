"""The metal outline of a cell for fabrication: polygons with holes, to DXF and GDSII.

The outline is the designed metal, whatever the cell's mesh mode: every
element is meshed once more in conforming mode with one segment per patch
side and sectors narrow enough that each circle's chords stay within the
chosen chord error, parts are welded (touching parts merge), and the
boundary of that mesh is walked into closed loops. Counter-clockwise loops
are outer boundaries, clockwise loops are holes; straight runs are reduced
to their corners. Where two pieces of metal meet at a single point they
stay two polygons.

ezdxf and gdstk are imported only inside the writers, so the rest of the
core works without them (``pip install barymesh[cell]``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..mesh import TriMesh
from ..params import DOUBLE_STRUCTURES
from ..topology import EdgeTopology
from .build import build_cell, tile
from .model import Element, UnitCell

#: Default largest distance (mm) between an arc and its chords.
DEFAULT_CHORD_ERROR = 0.01


@dataclass(frozen=True)
class OutlinePolygon:
    """One piece of metal: an outer boundary and its holes.

    Attributes
    ----------
    outer : (N, 2) float64
        Counter-clockwise vertices (mm), not repeating the first.
    holes : tuple of (M, 2) float64
        Clockwise vertices of every hole.
    """

    outer: np.ndarray
    holes: tuple[np.ndarray, ...] = ()

    @property
    def area(self) -> float:
        """Metal area (mm²): the outer area minus the holes'."""
        return signed_area(self.outer) + sum(signed_area(h) for h in self.holes)


def signed_area(loop: np.ndarray) -> float:
    """Shoelace area of a closed loop (N, 2), positive when counter-clockwise."""
    x, y = loop[:, 0], loop[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def arc_angle_step(radius: float, chord_error: float) -> float:
    """Widest sector (degrees) whose chord is within ``chord_error`` of a circle of ``radius``."""
    if chord_error >= radius:
        return 120.0
    return min(120.0, math.degrees(2 * math.acos(1 - chord_error / radius)))


def _outline_element(el: Element, chord_error: float) -> Element:
    p = el.params
    changes = {"mode": "conforming", "subdivisions": 1, "scheme": "uniform"}
    if p.structure not in ("patch", "cross", "triangle", "square_split_double_ring"):
        outer = p.outer_radius if p.structure in DOUBLE_STRUCTURES else p.inner_radius
        changes["angle_step"] = arc_angle_step(outer + p.patch_size, chord_error)
    try:
        params = p.replace(**changes)
    except ValueError as exc:
        raise ValueError(f"element {el.name!r} has no conforming outline: {exc}") from None
    return Element(params, el.position, el.rotation, el.name)


def outline_polygons(
    cell: UnitCell, chord_error: float = DEFAULT_CHORD_ERROR, copies: tuple[int, int] = (1, 1)
) -> list[OutlinePolygon]:
    """The metal of ``cell`` (or of an n1 x n2 array of it) as polygons with holes.

    Parameters
    ----------
    cell : UnitCell
    chord_error : float
        Largest distance (mm) between a circular arc and the polyline replacing it.
    copies : (n1, n2)
        Outline of the array of n1 x n2 cells (metal crossing cell sides merges).

    Returns
    -------
    list of OutlinePolygon, largest first.

    Raises
    ------
    ValueError
        When elements overlap (the outline needs their union; move them apart
        or merge them) or an element has no conforming form.

    Examples
    --------
    >>> from barymesh.cell import PixelGrid
    >>> ring = np.ones((3, 3), bool); ring[1, 1] = False
    >>> [poly] = outline_polygons(UnitCell(pixels=PixelGrid(ring)))
    >>> len(poly.outer), [len(h) for h in poly.holes], poly.area
    (4, [4], 8.0)
    """
    try:
        err = float(chord_error)
    except (TypeError, ValueError):
        err = float("nan")
    if not math.isfinite(err) or err <= 0:
        raise ValueError(f"chord_error={chord_error!r} is invalid; expected a length > 0 mm")
    elements = tuple(_outline_element(el, err) for el in cell.elements)
    pixels = cell.pixels
    if pixels is not None:
        pixels = pixels.replaced(subdivisions=1, scheme="uniform")
    rendition = cell.replace(mode="conforming", elements=elements, pixels=pixels)
    try:
        built = build_cell(rendition)
    except ValueError as exc:
        raise ValueError(f"the outline needs parts that do not overlap: {exc}") from None
    if tuple(copies) != (1, 1):
        built = tile(built, *copies)
    return mesh_outline(built.mesh, cell.lattice.size)


def mesh_outline(mesh: TriMesh, size: float) -> list[OutlinePolygon]:
    """Boundary loops of a conforming, counter-clockwise triangle mesh as polygons with holes.

    A piece of metal is a set of triangles joined through shared edges; its
    one counter-clockwise loop is the outer boundary and its clockwise loops
    are its holes.

    Parameters
    ----------
    mesh : TriMesh
    size : float
        A length of the structure (mm), the scale of the straightness test.
    """
    xy = mesh.points[:, :2]
    start, end, tri = _boundary_half_edges(mesh.triangles, mesh.topology)
    if len(start) == 0:
        return []
    nxt = _next_half_edge(xy, start, end)
    loops = _loops(nxt)
    from scipy.sparse.csgraph import connected_components  # here: ``barymesh --help`` stays quick

    piece = connected_components(mesh.connectivity, directed=False)[1]
    loop_piece = piece[tri[[loop[0] for loop in loops]]]
    eps = 1e-9 * size
    rings = [_simplified(xy[start[loop]], eps) for loop in loops]
    areas = np.array([signed_area(r) for r in rings])
    outers: dict[int, list[int]] = {}
    for k in np.flatnonzero(areas > 0).tolist():
        outers.setdefault(int(loop_piece[k]), []).append(k)
    holes: dict[int, list[np.ndarray]] = {k: [] for ks in outers.values() for k in ks}
    for k in np.flatnonzero(areas <= 0).tolist():
        candidates = outers.get(int(loop_piece[k]), [])
        if len(candidates) > 1:  # not expected of a planar mesh: test containment
            probe = _metal_side_point(rings[k], eps * 1e3)
            candidates = [o for o in candidates if _contains(rings[o], probe)] or candidates
        if candidates:
            holes[min(candidates, key=lambda o: areas[o])].append(rings[k])
    polys = [OutlinePolygon(rings[k], tuple(h)) for k, h in holes.items()]
    return sorted(polys, key=lambda p: -p.area)


def _boundary_half_edges(
    triangles: np.ndarray, topology: EdgeTopology
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(B,) start vertex, end vertex and triangle of every boundary edge, metal on the left."""
    side_edge = topology.triangle_edges  # (T, 3): side k joins vertex k to k + 1
    on_boundary = topology.valence[side_edge] == 1
    t, k = np.nonzero(on_boundary)
    return (
        triangles[t, k].astype(np.int64),
        triangles[t, (k + 1) % 3].astype(np.int64),
        t.astype(np.int64),
    )


def _next_half_edge(xy: np.ndarray, start: np.ndarray, end: np.ndarray) -> np.ndarray:
    """(B,) the boundary half-edge that follows each one.

    At a vertex where several pieces of metal meet (more than one half-edge
    leaves it) the walk takes the outgoing half-edge first met turning
    clockwise from the way back, so each piece keeps its own loop.
    """
    order = np.argsort(start, kind="stable")
    first = np.searchsorted(start[order], end)  # outgoing half-edges of each end vertex
    count = np.searchsorted(start[order], end, side="right") - first
    if (count == 0).any():
        raise ValueError("the mesh boundary is not closed; cannot outline it")
    nxt = order[first]
    several = np.flatnonzero(count > 1)
    if len(several):
        rep = count[several]
        h = np.repeat(several, rep)  # incoming half-edge, once per candidate
        offset = np.arange(rep.sum()) - np.repeat(np.cumsum(rep) - rep, rep)
        cand = order[first[h] + offset]
        back = xy[start[h]] - xy[end[h]]
        out = xy[end[cand]] - xy[start[cand]]
        turn = (np.arctan2(back[:, 1], back[:, 0]) - np.arctan2(out[:, 1], out[:, 0])) % (2 * np.pi)
        turn[turn == 0] = 2 * np.pi
        group_start = np.cumsum(rep) - rep
        best = np.minimum.reduceat(turn, group_start)
        chosen = turn == np.repeat(best, rep)
        # one choice per incoming half-edge: the first minimal candidate
        pick = np.flatnonzero(chosen)
        pick = pick[np.r_[True, h[pick][1:] != h[pick][:-1]]]
        nxt[h[pick]] = cand[pick]
    return nxt


def _loops(nxt: np.ndarray) -> list[np.ndarray]:
    """Cycles of the permutation ``nxt`` (B,), each in walking order from its smallest member."""
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components

    n = len(nxt)
    graph = sp.coo_matrix((np.ones(n, dtype=np.int8), (np.arange(n), nxt)), shape=(n, n))
    n_loops, label = connected_components(graph, directed=True, connection="strong")
    head = np.full(n_loops, n, dtype=np.int64)
    np.minimum.at(head, label, np.arange(n))
    # list ranking by pointer jumping: distance of every half-edge to the end of its loop
    succ = np.where(nxt == head[label], np.arange(n), nxt)
    rank = (succ != np.arange(n)).astype(np.int64)
    while True:
        moved = succ[succ]
        if np.array_equal(moved, succ):
            break
        rank = rank + rank[succ] * (succ != np.arange(n))
        rank[succ == np.arange(n)] = 0
        succ = moved
    length = np.bincount(label, minlength=n_loops)
    position = length[label] - 1 - rank
    order = np.lexsort((position, label))
    return np.split(order, np.cumsum(length)[:-1])


def _simplified(ring: np.ndarray, eps: float) -> np.ndarray:
    """Drop vertices lying on the straight line through their neighbours (within ``eps``)."""
    prev, nxt = np.roll(ring, 1, axis=0), np.roll(ring, -1, axis=0)
    d = nxt - prev
    length = np.linalg.norm(d, axis=1)
    cross = d[:, 0] * (ring[:, 1] - prev[:, 1]) - d[:, 1] * (ring[:, 0] - prev[:, 0])
    forward = ((ring - prev) * (nxt - ring)).sum(axis=1) > 0
    straight = (np.abs(cross) <= eps * np.maximum(length, eps)) & forward
    return ring[~straight] if (~straight).sum() >= 3 else ring


def _metal_side_point(ring: np.ndarray, offset: float) -> np.ndarray:
    """A point just left of the middle of the ring's first side (in the metal)."""
    a, b = ring[0], ring[1]
    d = (b - a) / np.linalg.norm(b - a)
    return (a + b) / 2 + offset * np.array([-d[1], d[0]])


def _contains(loop: np.ndarray, point: np.ndarray) -> bool:
    """Even-odd test of one point against a closed loop (N, 2)."""
    x0, y0 = loop[:, 0], loop[:, 1]
    x1, y1 = np.roll(x0, -1), np.roll(y0, -1)
    crosses = (y0 > point[1]) != (y1 > point[1])
    with np.errstate(divide="ignore", invalid="ignore"):
        x_at = x0 + (point[1] - y0) * (x1 - x0) / (y1 - y0)
    return bool((crosses & (x_at > point[0])).sum() % 2)


# -- writers --------------------------------------------------------------------


def write_outline_dxf(
    polygons: list[OutlinePolygon], path: str | Path, layer: str = "METAL"
) -> None:
    """Write polygons to a DXF file in mm (ezdxf).

    Every loop is a closed LWPOLYLINE on ``layer`` (outer boundaries
    counter-clockwise, holes clockwise), and each polygon also gets a solid
    HATCH with its outer boundary and holes, so a viewer shows the metal filled.
    """
    import ezdxf
    from ezdxf import const

    from ..io.atomic import atomic_path

    doc = ezdxf.new("R2010", setup=False)
    doc.units = ezdxf.units.MM
    doc.layers.add(layer)
    msp = doc.modelspace()
    for poly in polygons:
        for loop in (poly.outer, *poly.holes):
            msp.add_lwpolyline(loop.tolist(), close=True, dxfattribs={"layer": layer})
        hatch = msp.add_hatch(dxfattribs={"layer": layer})
        hatch.paths.add_polyline_path(
            poly.outer.tolist(), is_closed=True, flags=const.BOUNDARY_PATH_EXTERNAL
        )
        for hole in poly.holes:
            hatch.paths.add_polyline_path(
                hole.tolist(), is_closed=True, flags=const.BOUNDARY_PATH_OUTERMOST
            )
    with atomic_path(path, suffix=".dxf") as tmp:
        doc.saveas(tmp)


def write_outline_gds(
    polygons: list[OutlinePolygon],
    path: str | Path,
    cell_name: str = "CELL",
    layer: int = 1,
    datatype: int = 0,
) -> None:
    """Write polygons to a GDSII file (gdstk), user unit 1 mm, database unit 1 nm.

    GDSII polygons have no holes: a polygon with holes is written as the
    outer boundary minus the holes (gdstk's boolean "not"), which cuts it
    into hole-free pieces of the same area.
    """
    import gdstk

    from ..io.atomic import atomic_path

    lib = gdstk.Library("BARYMESH", unit=1e-3, precision=1e-9)
    top = lib.new_cell(cell_name)
    for poly in polygons:
        # gdstk takes (N, 2) arrays; its stubs name sequences of points only
        outer = gdstk.Polygon(poly.outer, layer=layer, datatype=datatype)  # type: ignore[arg-type]
        if poly.holes:
            holes = [gdstk.Polygon(h) for h in poly.holes]  # type: ignore[arg-type]
            pieces = gdstk.boolean(
                outer, holes, "not", precision=1e-6, layer=layer, datatype=datatype
            )
            top.add(*pieces)
        else:
            top.add(outer)
    with atomic_path(path, suffix=".gds") as tmp:
        lib.write_gds(tmp)


def export_outline(
    cell: UnitCell,
    path: str | Path,
    chord_error: float = DEFAULT_CHORD_ERROR,
    copies: tuple[int, int] = (1, 1),
) -> list[OutlinePolygon]:
    """Write the outline of ``cell`` to ``path`` (``.dxf`` or ``.gds``); return the polygons."""
    suffix = Path(path).suffix.lower()
    if suffix not in (".dxf", ".gds"):
        raise ValueError(f"{path}: unknown outline format {suffix!r}; expected .dxf or .gds")
    polygons = outline_polygons(cell, chord_error, copies)
    if suffix == ".dxf":
        write_outline_dxf(polygons, path)
    else:
        write_outline_gds(polygons, path, cell_name=_gds_name(cell.name))
    return polygons


def _gds_name(name: str) -> str:
    cleaned = "".join(c if c.isalnum() or c in "_-$" else "_" for c in name)[:32]
    return cleaned or "CELL"

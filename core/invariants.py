"""What every mesh the core returns must satisfy, checked before it is returned.

A violation is a bug in the core or a geometry it cannot mesh; either way the
mesh is refused with :class:`MeshInvariantError` (a ``ValueError``) naming the
parameters, instead of reaching a solver. The checks are vectorised and
blocked (no (T, 3, 2) temporary), so they cost a fraction of the build:

- every coordinate is finite;
- every triangle is counter-clockwise seen from +z (our structures are planar)
  and not flat: its area is at least ``FLAT`` times its longest edge squared;
- in conforming mode: no two vertices at the same point and no edge on three
  or more triangles (a watertight, manifold mesh).
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from .mesh import _short_chain_topology
from .quality import lattice_diagonal
from .topology import BLOCK, edge_keys

#: A triangle whose area is below this fraction of its longest edge squared is flat.
FLAT = 1e-12


class MeshInvariantError(ValueError):
    """A built mesh breaks an invariant; the message names the parameters."""


def inverted_or_flat(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Triangles that are clockwise seen from +z or flatter than ``FLAT``.

    Parameters
    ----------
    points : (V, 2 or 3) float64
    triangles : (T, 3) int

    Returns
    -------
    (K,) int
        Indices of the offending triangles, ascending.

    Examples
    --------
    >>> pts = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [2.0, 0.0]])
    >>> inverted_or_flat(pts, np.array([[0, 1, 2], [0, 2, 1], [0, 1, 3]])).tolist()
    [1, 2]
    """
    x = np.ascontiguousarray(points[:, 0])
    y = np.ascontiguousarray(points[:, 1])
    bad = []
    for lo in range(0, len(triangles), BLOCK):
        tri = triangles[lo : lo + BLOCK]
        hit = np.flatnonzero(_flagged(x, y, *(tri[:, c] for c in range(3))))
        if len(hit):
            bad.append(hit + lo)
    return np.concatenate(bad) if bad else np.empty(0, dtype=np.intp)


def _flagged(x: np.ndarray, y: np.ndarray, i, j, k) -> np.ndarray:
    """Mask of the triangles (corners at i, j, k of x, y) that are clockwise or flat."""
    x0, y0 = x.take(i), y.take(i)
    ux = x.take(j)
    ux -= x0
    uy = y.take(j)
    uy -= y0
    vx = x.take(k)
    vx -= x0
    vy = y.take(k)
    vy -= y0
    twice_area = ux * vy
    twice_area -= uy * vx
    # first against 2 (|u|² + |v|²) >= the longest edge squared (a stricter test, fewer
    # operations); the few triangles it flags are measured exactly
    bound = ux * ux
    bound += uy * uy
    bound += vx * vx
    bound += vy * vy
    bound *= 4 * FLAT
    flagged = ~(twice_area >= bound)  # NaN counts as bad
    if flagged.any():
        f = np.flatnonzero(flagged)
        longest = np.maximum.reduce(
            [
                ux[f] ** 2 + uy[f] ** 2,
                vx[f] ** 2 + vy[f] ** 2,
                (ux[f] - vx[f]) ** 2 + (uy[f] - vy[f]) ** 2,
            ]
        )
        flagged[f] = ~(twice_area[f] >= 2 * FLAT * longest)
    return flagged


def inverted_or_flat_patches(
    points: np.ndarray,
    vertex_map: np.ndarray,
    template_triangles: np.ndarray,
    columns: list[np.ndarray] | None = None,
) -> np.ndarray:
    """:func:`inverted_or_flat` of the triangles ``vertex_map[:, template_triangles]``.

    The same answer on the same triangles, faster: each patch's vertex
    coordinates are gathered once and its triangles' corners read from them.

    Parameters
    ----------
    points : (V, 2 or 3) float64
    vertex_map : (P, Nv) int
        Global vertex of every patch-local vertex.
    template_triangles : (Nt, 3) int
        Local triangles of the template; triangle p Nt + l is patch p's triangle l.
    columns : list of (V,) float64, optional
        Contiguous copies of the x and y columns of ``points`` (then not made again).

    Returns
    -------
    (K,) int
    """
    if columns is None:
        columns = [np.ascontiguousarray(points[:, k]) for k in (0, 1)]
    x, y = columns[0], columns[1]
    n_tri = len(template_triangles)
    per_block = max(1, BLOCK // n_tri)
    diagonal = lattice_diagonal(template_triangles, vertex_map.shape[1])
    if diagonal is not None:  # grid cells: edges by slicing, no per-corner gathers
        n = round(np.sqrt(vertex_map.shape[1])) - 1
        for lo in range(0, len(vertex_map), per_block):
            vmap = vertex_map[lo : lo + per_block]
            if _lattice_flagged(x.take(vmap), y.take(vmap), n, diagonal):
                break
        else:
            return np.empty(0, dtype=np.intp)
    a, b, c = (np.ascontiguousarray(template_triangles[:, k]) for k in range(3))
    nv = vertex_map.shape[1]
    corners = [_rows(t, nv, min(per_block, len(vertex_map))) for t in (a, b, c)]
    bad = []
    for lo in range(0, len(vertex_map), per_block):
        vmap = vertex_map[lo : lo + per_block]
        px, py = x.take(vmap), y.take(vmap)  # (p, Nv): one read per patch vertex
        size = len(vmap) * n_tri
        hit = np.flatnonzero(_flagged(px, py, *(k[:size] for k in corners)))
        if len(hit):
            bad.append(hit + lo * n_tri)
    return np.concatenate(bad) if bad else np.empty(0, dtype=np.intp)


def _lattice_flagged(px: np.ndarray, py: np.ndarray, n: int, diagonal: str) -> bool:
    """Whether a triangle of these grid patches is clockwise or flat (stricter, see below).

    Each cell's two triangles have two grid edges as legs (h along a, v along
    b); the longest edge squared is at most 2 (|h|² + |v|²), which is tested
    against (a stricter test: exact indices are found by the caller).

    Parameters
    ----------
    px, py : (p, (n + 1)²) float64
        Vertex coordinates of p patches in grid order.
    """
    x = px.reshape(-1, n + 1, n + 1)  # [patch, b, a]
    y = py.reshape(-1, n + 1, n + 1)
    hx, hy = x[:, :, 1:] - x[:, :, :-1], y[:, :, 1:] - y[:, :, :-1]  # (p, n + 1, n)
    vx, vy = x[:, 1:, :] - x[:, :-1, :], y[:, 1:, :] - y[:, :-1, :]  # (p, n, n + 1)
    h2 = hx * hx
    h2 += hy * hy
    v2 = vx * vx
    v2 += vy * vy
    if diagonal == "BC":  # (a, b, c): h(j, i) x v(j, i); (d, c, b): h(j + 1, i) x v(j, i + 1)
        legs = ((slice(None, -1), slice(None, -1)), (slice(1, None), slice(1, None)))
    else:  # (a, b, d): h(j, i) x v(j, i + 1); (a, d, c): h(j + 1, i) x v(j, i)
        legs = ((slice(None, -1), slice(1, None)), (slice(1, None), slice(None, -1)))
    for h_rows, v_cols in legs:
        cross = hx[:, h_rows] * vy[:, :, v_cols]
        cross -= hy[:, h_rows] * vx[:, :, v_cols]
        bound = h2[:, h_rows] + v2[:, :, v_cols]
        bound *= 4 * FLAT
        if not (cross >= bound).all():  # NaN counts as bad
            return True
    return False


def _rows(corner: np.ndarray, nv: int, n_patches: int) -> np.ndarray:
    """Flat indices of template corner ``corner`` in each of ``n_patches`` rows of width nv."""
    return (np.arange(n_patches, dtype=np.intp)[:, None] * nv + corner[None, :]).ravel()


def glued_edge_valence(template: Any, vertex_map: np.ndarray, n_vertices: int) -> int:
    """Most triangles on one edge, counting only edges that patches may share.

    An edge can be on triangles of two patches only if both its vertices are
    shared with another patch; every other edge keeps its template valence (1
    or 2). Those candidate edges are grouped by vertex pair and their
    template valences added.

    Parameters
    ----------
    template : PatchTemplate
    vertex_map : (P, Nv) int
    n_vertices : int

    Returns
    -------
    int
        The largest valence among the candidate edges (0 if there are none).
    """
    shared = (np.bincount(vertex_map.ravel(), minlength=n_vertices) > 1).take(vertex_map)
    edges = template.edges
    on_sides = np.zeros(vertex_map.shape[1], dtype=bool)
    on_sides[template.side_vertices] = True
    if not shared[:, ~on_sides].any():  # as built: only side vertices are shared
        edges = edges[on_sides[edges[:, 0]] & on_sides[edges[:, 1]]]
    e0, e1 = edges[:, 0], edges[:, 1]
    p, e = np.nonzero(shared.take(e0, axis=1) & shared.take(e1, axis=1))
    if len(p) == 0:
        return 0
    index = np.searchsorted(
        template.edges[:, 0] * len(on_sides) + template.edges[:, 1], e0[e] * len(on_sides) + e1[e]
    )
    # one sort of (edge key, template valence - 1) packed together; valences summed per key
    keys = edge_keys(vertex_map[p, e0[e]], vertex_map[p, e1[e]], n_vertices)
    packed = np.sort(keys * 2 + (template.valence[index] - 1))
    starts = np.flatnonzero(np.r_[True, (packed[1:] >> 1) != (packed[:-1] >> 1)])
    return int(np.add.reduceat((packed & 1) + 1, starts).max())


def duplicate_vertices(points: np.ndarray, vertices: np.ndarray | None = None) -> int:
    """Number of vertices at exactly the same (x, y) as another one.

    Parameters
    ----------
    points : (V, 2 or 3) float64
    vertices : (K,) int, optional
        Only look among these vertices (for example those on the patches' sides).

    Examples
    --------
    >>> pts = np.array([[0.0, 1.0], [-0.0, 1.0], [1.0, 0.0], [-1.0, -1.0], [1.0, 1.0]])
    >>> duplicate_vertices(pts), duplicate_vertices(pts, np.array([2, 3, 4]))
    (1, 0)
    """
    points = np.asarray(points)
    if vertices is None:
        index = None
        n = len(points)
    else:
        seen = np.zeros(len(points), dtype=bool)
        seen[vertices.ravel()] = True
        index = np.flatnonzero(seen)
        n = len(index)
    if n < 2:
        return 0
    # equal points have equal bits (+ 0.0 turns -0.0 into 0.0): one integer key per point,
    # sorted fast; only when two keys agree are the points compared exactly
    x, y = (_column(points, axis, index) for axis in (0, 1))
    key = _point_keys(x, y)
    key.sort()
    if not (key[1:] == key[:-1]).any():
        return 0
    order = np.lexsort((y, x))
    sx, sy = x[order], y[order]
    return int(((sx[1:] == sx[:-1]) & (sy[1:] == sy[:-1])).sum())


def _column(points: np.ndarray, axis: int, index: np.ndarray | None) -> np.ndarray:
    """(K,) float64 coordinate ``axis`` of the points ``index`` (all if None), + 0.0."""
    if index is None:
        column = np.ascontiguousarray(points[:, axis])
    else:  # gathered straight from the rows: no copy of the whole column
        flat = points.reshape(-1) if points.flags.c_contiguous else points.ravel()
        column = flat.take(index * points.shape[1] + axis)
    column += 0.0  # -0.0 becomes 0.0 (in place: a fresh array either way)
    return column


#: An odd 64-bit multiplier (the golden ratio's bits) spreading x over the key.
_MIX = np.uint64(0x9E3779B97F4A7C15)


def _point_keys(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """(K,) uint64 keys, equal for equal points (and rarely otherwise).

    x's bits times an odd constant plus y's bits with their halves swapped: a
    sum of x's and y's bits would give (x, y) and (−x, −y) (sign bits 2⁶³ apart
    in both) the same key, so every point-symmetric ring would fall through to
    the exact comparison.
    """
    xb = x.view(np.uint64)
    yb = y.view(np.uint64)
    key = xb * _MIX
    key += (yb << np.uint64(32)) | (yb >> np.uint64(32))
    return key


def check_mesh(mesh: Any, params: Any, vertex_map: np.ndarray | None = None) -> None:
    """Raise :class:`MeshInvariantError` if ``mesh`` breaks an invariant.

    Parameters
    ----------
    mesh : TriMesh
        A freshly built mesh.
    params : MeshParams
        Named in the message.
    vertex_map : (P, Nv) int, optional
        With the mesh's patch template: the patch-local to global vertex map its
        triangles were made from (``vertex_map[:, template.triangles]``); the
        checks then read each patch once instead of every triangle corner.
    """
    points, triangles = mesh.points, mesh.triangles
    template = mesh._template
    if not np.isfinite(points).all():
        _fail(params, "has coordinates that are not finite")
    if vertex_map is not None and template is not None:
        # the mesh's own x and y columns, which centroids, lengths and quality reuse
        bad = inverted_or_flat_patches(points, vertex_map, template.triangles, mesh._columns)
    else:
        bad = inverted_or_flat(points, triangles)
    if len(bad):
        c = points[triangles[bad[0]]].mean(axis=0)
        _fail(
            params,
            f"has {len(bad):,} of {len(triangles):,} triangles clockwise or flat (area below "
            f"{FLAT:g} of the longest edge squared), the first near ({c[0]:.6g}, {c[1]:.6g})",
        )
    if mesh.mode != "conforming":
        return
    if vertex_map is not None and template is not None:
        # vertices on the patches' sides, where patches are glued; an interior vertex
        # of a patch is its own (a second vertex there would need overlapping triangles)
        dup = duplicate_vertices(points, vertex_map[:, template.side_vertices])
        valence = _chain_valence(mesh)
        if valence is None:
            valence = glued_edge_valence(template, vertex_map, len(points))
    else:
        dup = duplicate_vertices(points)
        valence = int(mesh.topology.valence.max(initial=0))
    if dup:
        _fail(params, f"has {dup:,} vertices at the same point as another vertex")
    if valence >= 3:
        _fail(params, f"has edges on {valence} triangles (a junction)")


def _chain_valence(mesh: Any) -> int | None:
    """Most triangles on one edge of rings of sectors numbered by formula, else None.

    When the vertex map is, entry for entry, that of chains of m sectors
    (``TriMesh._sector_chains``), every edge of a chain is a shifted copy of an
    edge of the short chain its topology repeats, on as many triangles
    (:func:`barymesh.topology.chain_topology`): the short chains' largest valence
    is the mesh's. Anything else (a sector glued twice, renumbered vertices)
    is counted by :func:`glued_edge_valence`.
    """
    chains = mesh._sector_chains
    if chains is None:
        return None
    return max(int(_short_chain_topology(mesh._template, c).valence.max()) for c in chains[1])


def _fail(params: Any, what: str) -> None:
    changed = _changed(params)
    raise MeshInvariantError(
        f"the {params.mode} mesh of {params.structure} with {changed} {what}; "
        "barymesh refuses it (a geometry it cannot mesh, or a bug to report)"
    )


def _changed(params: Any) -> str:
    """The parameters that differ from the defaults, as ``name=value`` pairs."""
    defaults = type(params)()
    pairs = [
        f"{f.name}={getattr(params, f.name)!r}"
        for f in dataclasses.fields(params)
        if f.name not in ("structure", "mode")
        and getattr(params, f.name) != getattr(defaults, f.name)
    ]
    return ", ".join(pairs) if pairs else "default parameters"

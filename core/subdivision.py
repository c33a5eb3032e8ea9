"""Subdivision of primary triangles and the patch template built from them.

A patch is meshed once, in its parameter square [0, 1]², and the result (the
*template*) is copied onto every patch of a structure. Corners follow the
paper::

    C (0,1) ------- D (1,1)
      |  \\            |
      |     \\  BC     |        diagonal "BC": primaries ABC and BCD
      |        \\      |        diagonal "AD": primaries ABD and ACD
      |           \\   |
    A (0,0) ------- B (1,0)

With the uniform scheme and n segments per edge the template is the
(n + 1) x (n + 1) grid of points (a/n, b/n), stored at index b (n + 1) + a,
and every grid cell is cut parallel to the chosen diagonal.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .grading import ALL_ENDS, coons_uv, graded_barycentric
from .topology import INDEX, edge_topology

#: Sides of the parameter square, each as (fixed axis, fixed value, running axis).
#: 0: A→B (v = 0), 1: B→D (u = 1), 2: C→D (v = 1), 3: A→C (u = 0).
SIDES = ((1, 0.0, 0), (0, 1.0, 1), (1, 1.0, 0), (0, 0.0, 1))


def uniform_subdivision(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Uniform subdivision of the reference triangle into n² sub-triangles.

    Every edge is cut into ``n`` equal segments; row k (from the apex) holds
    2k − 1 sub-triangles. ``n = 4`` gives the paper's 16 sub-triangles,
    ``n = 3`` the nine of classic RWG codes.

    Parameters
    ----------
    n : int
        Segments per edge, >= 1.

    Returns
    -------
    bary : (N, 2) float64
        Coordinates (s, t) of the N = (n + 1)(n + 2)/2 points: the point is
        P0 + s (P1 − P0) + t (P2 − P0).
    triangles : (n², 3) int
        Sub-triangles, counter-clockwise when (P0, P1, P2) is.

    Examples
    --------
    >>> bary, tri = uniform_subdivision(4)
    >>> bary.shape, tri.shape
    ((15, 2), (16, 3))
    """
    if n < 1:
        raise ValueError(f"n={n!r} must be >= 1")
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="xy")
    keep = i + j <= n
    i, j = i[keep], j[keep]
    index = np.full((n + 2, n + 2), -1, dtype=INDEX)
    index[i, j] = np.arange(len(i), dtype=INDEX)
    up_i, up_j = np.nonzero(np.add.outer(np.arange(n), np.arange(n)) <= n - 1)
    up = np.stack([index[up_i, up_j], index[up_i + 1, up_j], index[up_i, up_j + 1]], axis=1)
    dn_i, dn_j = np.nonzero(np.add.outer(np.arange(n), np.arange(n)) <= n - 2)
    down = np.stack(
        [index[dn_i + 1, dn_j], index[dn_i + 1, dn_j + 1], index[dn_i, dn_j + 1]], axis=1
    )
    bary = np.stack([i, j], axis=1) / n
    # number the sub-triangles row by row from the base P0 P1, left to right, so that
    # index labels read like the paper's Fig. 10 (up and down triangles alternate)
    key = np.concatenate([up_j * 2 * n + 2 * up_i, dn_j * 2 * n + 2 * dn_i + 1])
    return bary, np.concatenate([up, down])[np.argsort(key, kind="stable")].astype(INDEX)


def barycentric_subdivision(levels: int) -> tuple[np.ndarray, np.ndarray]:
    """Classical barycentric subdivision of the reference triangle.

    Each level joins every triangle's centroid to its vertices and edge
    midpoints, giving 6 sub-triangles; ``levels`` repetitions give 6**levels.
    Every edge of the primary triangle ends up cut into 2**levels equal
    segments, so neighbouring primaries still share their edge points.

    Returns the same ``(bary, triangles)`` pair as :func:`uniform_subdivision`.

    Examples
    --------
    >>> bary, tri = barycentric_subdivision(1)
    >>> len(bary), len(tri)
    (7, 6)
    """
    if levels < 1:
        raise ValueError(f"levels={levels!r} must be >= 1")
    corners = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    tri = corners[None]  # (m, 3, 2) triangle corner coordinates
    for _ in range(levels):
        a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
        g = (a + b + c) / 3
        mab, mbc, mca = (a + b) / 2, (b + c) / 2, (c + a) / 2
        tri = np.stack(
            [
                np.stack([a, mab, g], 1),
                np.stack([mab, b, g], 1),
                np.stack([b, mbc, g], 1),
                np.stack([mbc, c, g], 1),
                np.stack([c, mca, g], 1),
                np.stack([mca, a, g], 1),
            ],
            axis=1,
        ).reshape(-1, 3, 2)
    return _merge_exact(tri.reshape(-1, 2), np.arange(tri.shape[0] * 3).reshape(-1, 3))


def _merge_exact(points: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Merge points of a template that agree to 1e-12 (rational coordinates)."""
    key = np.round(points * 2**40).astype(np.int64)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first)  # keep first-appearance order
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return points[first[order]], rank[inverse.ravel()][triangles].astype(INDEX)


def subdivide(scheme: str, segments_or_levels: int) -> tuple[np.ndarray, np.ndarray]:
    """Dispatch to :func:`uniform_subdivision` or :func:`barycentric_subdivision`."""
    if scheme == "uniform":
        return uniform_subdivision(segments_or_levels)
    if scheme == "barycentric":
        return barycentric_subdivision(segments_or_levels)
    raise ValueError(f"scheme={scheme!r} is unknown; expected 'uniform' or 'barycentric'")


@dataclass(frozen=True)
class PatchTemplate:
    """One meshed patch in parameter space, copied onto every patch.

    Attributes
    ----------
    uv : (Nv, 2) float64
        Parameter coordinates of the vertices in [0, 1]².
    triangles : (Nt, 3) int
        Sub-triangles, counter-clockwise in (u, v); the first Nt/2 come from
        the first primary triangle (ABC or ABD).
    edges : (Ne, 2) int
        Local edges, ``edges[:, 0] < edges[:, 1]``.
    triangle_edges : (Nt, 3) int
        Local edge of each triangle side (k: vertex k to vertex k + 1).
    edge_triangles : (Ne, 2) int
        The one or two local triangles on each edge, ascending, -1 padded.
    valence : (Ne,) int
        Triangles on each edge: 1 on the patch border, 2 inside.
    sides : (4, segments + 1) int, or a tuple of four (k,) int arrays
        Vertices along each side of the square, in increasing running
        coordinate (see ``SIDES``); sides 0 and 2 of a tensor template (see
        :func:`tensor_template`) hold n_u + 1 vertices, sides 1 and 3 n_v + 1.
    segments : int
        Segments along side 0 (n, 2**levels, or n_u).
    lattice : bool
        True when ``uv`` is the regular grid (a/n, b/n) at index b (n + 1) + a.
    """

    uv: np.ndarray
    triangles: np.ndarray
    edges: np.ndarray
    triangle_edges: np.ndarray
    edge_triangles: np.ndarray
    valence: np.ndarray
    sides: np.ndarray | tuple[np.ndarray, ...]
    segments: int
    lattice: bool

    @property
    def side_vertices(self) -> np.ndarray:
        """(K,) int the vertices of the four sides, side after side (corners repeated)."""
        return np.concatenate(list(self.sides))


@lru_cache(maxsize=64)
def patch_template(scheme: str, subdivisions: int, diagonal: str) -> PatchTemplate:
    """Mesh the unit square ABCD once (cached).

    Examples
    --------
    >>> t = patch_template("uniform", 4, "BC")
    >>> len(t.uv), len(t.triangles), len(t.edges), int((t.valence == 2).sum())
    (25, 32, 56, 40)
    """
    bary, tri = subdivide(scheme, subdivisions)
    a, b, c, d = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    if diagonal == "BC":
        primaries = ((a, b, c), (d, c, b))
    elif diagonal == "AD":
        primaries = ((a, b, d), (a, d, c))
    else:
        raise ValueError(f"diagonal={diagonal!r} is unknown; expected 'BC' or 'AD'")
    pts: list[np.ndarray] = []
    tris: list[np.ndarray] = []
    for p0, p1, p2 in primaries:
        pts.append(p0 + bary[:, :1] * (p1 - p0) + bary[:, 1:] * (p2 - p0))
        tris.append(tri + len(bary) * len(tris))
    uv, triangles = _merge_exact(np.concatenate(pts), np.concatenate(tris))
    segments = subdivisions if scheme == "uniform" else 2**subdivisions
    if scheme == "uniform":
        uv = np.round(uv * segments) / segments  # exact grid values, whichever primary made them
    # Canonical vertex order: by v, then u (the grid index b (n + 1) + a when uniform),
    # compared on integer keys so that rounding noise cannot reorder a row.
    key = np.round(uv * 2**40).astype(np.int64)
    order = np.lexsort((key[:, 0], key[:, 1]))
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    uv, triangles = uv[order], rank[triangles].astype(INDEX)
    triangles = _counter_clockwise(uv, triangles)
    sides = np.stack([_side(uv, s) for s in range(4)])
    if sides.shape[1] != segments + 1:
        raise AssertionError("template sides do not hold segments + 1 vertices")
    return _template(uv, triangles, sides, segments, lattice=scheme == "uniform")


def graded_cell_count(cells: int, fine: float, ratio: float) -> int:
    """The number of cells :func:`graded_nodes` makes, computed in O(1) without making them.

    From each end ``ceil(log(1 / (cells fine)) / log(ratio))`` cells grow geometrically
    (their sum a geometric series), then uniform cells fill the middle. Rounding in the
    repeated products of :func:`graded_nodes` can move a boundary case by one cell at
    each end, so this is exact but for that: what a budget check needs before the nodes
    (which can be millions for a ratio next to 1) are made.

    >>> graded_cell_count(4, 0.125, 2.0), len(graded_nodes(4, 0.125, 2.0)) - 1
    (5, 5)
    >>> graded_cell_count(9, 0.00396, 1.0000001)  # the nodes would take gigabytes
    66685738
    """
    coarse = 1.0 / cells
    target = coarse * (1 - 1e-12)
    side = 0 if not fine < target else math.ceil(math.log(target / fine) / math.log1p(ratio - 1))
    graded = 2 * fine * math.expm1(side * math.log1p(ratio - 1)) / (ratio - 1)
    middle = max(0, math.ceil((1.0 - graded) / coarse - 1e-9))
    return 2 * side + middle


@lru_cache(maxsize=256)
def graded_patch_template(
    subdivisions: int, diagonal: str, sides: tuple[tuple[bool, bool], ...] = ALL_ENDS
) -> PatchTemplate:
    """The uniform patch template with its points graded toward the sides' ends (cached).

    The same vertices, triangles, edges and sides as
    ``patch_template("uniform", subdivisions, diagonal)``, in the same order: only the
    points move, to :func:`barymesh.grading.coons_uv` (``sides``: which ends of the
    bottom, right, top and left side to crowd toward; all of them by default, the
    tensor grid of :func:`barymesh.grading.edge_nodes` both ways). Each primary
    triangle is still cut into n² sub-triangles.

    Examples
    --------
    >>> g, t = graded_patch_template(4, "BC"), patch_template("uniform", 4, "BC")
    >>> np.array_equal(g.triangles, t.triangles), g.lattice, g.uv[:5, 0].round(4).tolist()
    (True, False, [0.0, 0.125, 0.5, 0.875, 1.0])
    """
    base = patch_template("uniform", subdivisions, diagonal)
    u, v = coons_uv(subdivisions, tuple(tuple(map(bool, s)) for s in sides))
    uv = np.stack([u, v], axis=1)
    uv.flags.writeable = False
    return PatchTemplate(
        uv=uv,
        triangles=base.triangles,
        edges=base.edges,
        triangle_edges=base.triangle_edges,
        edge_triangles=base.edge_triangles,
        valence=base.valence,
        sides=base.sides,
        segments=base.segments,
        lattice=False,
    )


def graded_nodes(cells: int, fine: float, ratio: float) -> tuple[float, ...]:
    """Nodes in [0, 1] fine at both ends, growing geometrically to the uniform 1 / cells.

    From each end the cells are ``fine``, ``fine * ratio``, ``fine * ratio**2``, …
    up to the last below 1 / cells; cells of 1 / cells fill the middle (enough to
    reach 1), and every cell is then scaled by one factor (at most 1) so that
    they add up to 1. Neighbouring cells therefore differ by at most ``ratio``,
    and no cell is wider than 1 / cells or than ``fine`` at the ends.

    Parameters
    ----------
    cells : int
        The uniform division the grading refines (>= 1).
    fine : float
        The end cells before the final scaling, as a fraction of 1, in (0, 1 / cells].
    ratio : float
        Growth between neighbouring cells, > 1.

    Returns
    -------
    tuple of float
        Increasing nodes from 0.0 to 1.0 exactly.

    Examples
    --------
    >>> [round(x, 4) for x in graded_nodes(4, 0.125, 2.0)]
    [0.0, 0.125, 0.375, 0.625, 0.875, 1.0]
    """
    if not 0.0 < fine < math.inf or not ratio > 1.0:
        raise ValueError(f"fine={fine!r} and ratio={ratio!r}: expected fine > 0 and ratio > 1")
    coarse = 1.0 / cells
    side = []
    size = fine
    while size < coarse * (1 - 1e-12):
        side.append(size)
        size *= ratio
    graded = 2 * sum(side)
    middle = max(0, math.ceil((1.0 - graded) / coarse - 1e-9))  # cells end no wider than 1/cells
    sizes = np.array(side + [coarse] * middle + side[::-1])
    nodes = np.concatenate([[0.0], np.cumsum(sizes / sizes.sum())])
    nodes[-1] = 1.0
    return tuple(float(x) for x in nodes)


@lru_cache(maxsize=256)
def tensor_template(
    u_nodes: tuple[float, ...], v_nodes: tuple[float, ...], diagonal: str
) -> PatchTemplate:
    """Mesh the unit square on the grid of ``u_nodes`` x ``v_nodes`` (cached).

    Every grid cell is cut by one diagonal, as the uniform scheme cuts its
    cells: ``"BC"`` from (u1, v0) to (u0, v1), ``"AD"`` from (u0, v0) to
    (u1, v1). The nodes need not be evenly spaced (graded meshes), and the
    two directions need not have as many (a conforming sector is n_u cells
    across its track and n_v along its arc)::

        v = 1  C --+-----+-- D       vertex of node (a, b): b (n_u + 1) + a
               |  /|    /|           cell (a, b): triangles (00, 10, 01) and
               | / |   / |           (11, 01, 10) with diagonal "BC"
        v = 0  A --+-----+-- B
             u = 0            u = 1

    Parameters
    ----------
    u_nodes, v_nodes : tuple of float
        Increasing node coordinates from 0 to 1 (n_u + 1 and n_v + 1 of them).
    diagonal : str
        ``"BC"`` or ``"AD"``.

    Returns
    -------
    PatchTemplate
        With ``sides`` a tuple of four arrays (side 0 is the first n_u + 1
        vertices, side 2 the last n_u + 1), ``segments`` = n_u and
        ``lattice`` False.

    Examples
    --------
    >>> t = tensor_template((0.0, 0.5, 1.0), (0.0, 1.0), "BC")
    >>> len(t.uv), len(t.triangles), len(t.edges), [len(s) for s in t.sides]
    (6, 4, 9, [3, 2, 3, 2])
    """
    u = np.asarray(u_nodes, dtype=np.float64)
    v = np.asarray(v_nodes, dtype=np.float64)
    for name, x in (("u_nodes", u), ("v_nodes", v)):
        if x.ndim != 1 or len(x) < 2 or x[0] != 0.0 or x[-1] != 1.0 or (np.diff(x) <= 0).any():
            raise ValueError(f"{name}={x.tolist()!r} must increase from 0 to 1")
    if diagonal not in ("BC", "AD"):
        raise ValueError(f"diagonal={diagonal!r} is unknown; expected 'BC' or 'AD'")
    nu, nv = len(u) - 1, len(v) - 1
    uu, vv = np.meshgrid(u, v, indexing="xy")
    uv = np.stack([uu.ravel(), vv.ravel()], axis=1)
    a, b = np.meshgrid(np.arange(nu), np.arange(nv), indexing="xy")
    p00 = (b * (nu + 1) + a).ravel()
    p10, p01 = p00 + 1, p00 + nu + 1
    p11 = p01 + 1
    if diagonal == "BC":
        pairs = [np.stack([p00, p10, p01], 1), np.stack([p11, p01, p10], 1)]
    else:
        pairs = [np.stack([p00, p10, p11], 1), np.stack([p00, p11, p01], 1)]
    triangles = np.stack(pairs, axis=1).reshape(-1, 3).astype(INDEX)  # cell by cell
    first = np.arange(nu + 1, dtype=INDEX)
    rows = np.arange(nv + 1, dtype=INDEX) * INDEX(nu + 1)
    sides = (first, rows + INDEX(nu), first + INDEX(nv * (nu + 1)), rows)
    return _template(uv, triangles, sides, nu, lattice=False)


def _template(
    uv: np.ndarray,
    triangles: np.ndarray,
    sides: np.ndarray | tuple[np.ndarray, ...],
    segments: int,
    lattice: bool,
) -> PatchTemplate:
    """A :class:`PatchTemplate` of local points and triangles, with their edge topology."""
    topo = edge_topology(triangles, len(uv))
    return PatchTemplate(
        uv=uv,
        triangles=triangles,
        edges=topo.edges,
        triangle_edges=topo.triangle_edges,
        edge_triangles=topo.edge_triangles,
        valence=topo.valence,
        sides=sides,
        segments=segments,
        lattice=lattice,
    )


def _side(uv: np.ndarray, side: int) -> np.ndarray:
    fixed, value, running = SIDES[side]
    on = np.flatnonzero(np.abs(uv[:, fixed] - value) < 1e-12)
    return on[np.argsort(uv[on, running])].astype(INDEX)


def _counter_clockwise(xy: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    p = xy[triangles]
    cross = (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1]) - (p[:, 1, 1] - p[:, 0, 1]) * (
        p[:, 2, 0] - p[:, 0, 0]
    )
    out = triangles.copy()
    flip = cross < 0
    out[flip] = out[flip][:, [0, 2, 1]]
    return out


@lru_cache(maxsize=64)
def edge_vectors(
    scheme: str, subdivisions: int, diagonal: str | None = None, graded: bool = False
) -> np.ndarray:
    """Distinct edge vectors of the sub-triangles, up to sign (cached).

    Parameters
    ----------
    scheme, subdivisions : as for :func:`subdivide`
    diagonal : str or None
        ``"BC"`` or ``"AD"``: edges of the patch template, in (u, v) of the unit
        square; ``None``: edges of one subdivided primary triangle, in its
        barycentric coordinates (s, t).
    graded : bool
        The edge-graded template (:func:`graded_patch_template`, every side graded at
        both ends) or primary triangle (:func:`barymesh.grading.graded_barycentric`);
        uniform scheme only.

    Returns
    -------
    (K, 2) float64
        A patch of sides (h, w) has its shortest edge at ``min |(h du, w dv)|``
        over the rows; a triangle P0 P1 P2 at ``min |ds (P1 - P0) + dt (P2 - P0)|``.
    """
    if diagonal is None:
        xy, tri = subdivide(scheme, subdivisions)
        if graded:
            xy = graded_barycentric(xy, subdivisions)
    else:
        template = (
            graded_patch_template(subdivisions, diagonal)
            if graded
            else patch_template(scheme, subdivisions, diagonal)
        )
        xy, tri = template.uv, template.triangles
    d = (xy[tri[:, [1, 2, 0]]] - xy[tri]).reshape(-1, 2)
    flip = (d[:, 0] < 0) | ((d[:, 0] == 0) & (d[:, 1] < 0))
    d[flip] *= -1
    key = np.round(d * 2**40).astype(np.int64)
    _, first = np.unique(key, axis=0, return_index=True)
    out = d[np.sort(first)]
    out.flags.writeable = False
    return out


@lru_cache(maxsize=64)
def closest_vertices(
    scheme: str, subdivisions: int, graded: bool, corners: tuple[tuple[float, float], ...]
) -> float:
    """Smallest distance (mm) between two vertices of one subdivided primary triangle.

    Shorter than its shortest edge where the triangle is obtuse: two sub-triangles that
    share an edge form a parallelogram whose other diagonal is no edge (corners (0, 0),
    (0, 3), (1, −3) at n = 5: edges of 0.6 mm and more, two vertices 0.2 mm apart). The
    welding tolerance must stay below half of it, or the weld joins vertices of one
    triangle (cached: at most 23,425 points, the barycentric scheme's sixth level).
    """
    from scipy.spatial import cKDTree

    st, _ = subdivide(scheme, subdivisions)
    if graded:
        st = graded_barycentric(st, subdivisions)
    p0, p1, p2 = (np.asarray(c, dtype=np.float64) for c in corners)
    xy = p0 + st[:, :1] * (p1 - p0) + st[:, 1:2] * (p2 - p0)
    distance = np.asarray(cKDTree(xy).query(xy, k=2)[0])  # (N, 2): itself, the nearest other
    return float(distance[:, 1].min())

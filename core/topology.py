"""Edges, shared edges, the RWG table and the connectivity matrix.

Edge k of a triangle joins its vertices k and k + 1 (mod 3). An edge on one
triangle is a boundary edge, on two an interior edge (one RWG unknown), on
three or more a junction, which is reported and never dropped.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import scipy.sparse as sp

#: The one integer dtype for vertex, triangle and edge indices.
INDEX = np.int32

#: Rows per block in gathers done block by block so that temporaries stay in cache.
BLOCK = 1 << 16


@dataclass(frozen=True)
class EdgeTopology:
    """Edges of a triangle mesh and their incidence.

    Attributes
    ----------
    edges : (E, 2) int
        Vertex pairs, ``edges[:, 0] < edges[:, 1]``.
    triangle_edges : (T, 3) int
        Edge id of side k (vertex k to k + 1) of each triangle.
    edge_triangles : (E, 2) int
        The first two triangles on each edge, ascending; -1 where missing.
    valence : (E,) int
        Number of triangles on each edge.
    junction_incidence : (J, 2) int
        (edge id, triangle id) for every triangle on a junction edge
        (valence >= 3), sorted by edge then triangle.
    free_vertices : (E, 2) int or None
        The vertex of ``edge_triangles[e, j]`` opposite edge e, -1 where that
        triangle is missing (the RWG free vertices); None when not computed.
    """

    edges: np.ndarray
    triangle_edges: np.ndarray
    edge_triangles: np.ndarray
    valence: np.ndarray
    junction_incidence: np.ndarray
    free_vertices: np.ndarray | None = None

    @property
    def interior_edges(self) -> np.ndarray:
        """(N,) int: ids of edges on exactly two triangles (the RWG edges)."""
        return np.flatnonzero(self.valence == 2).astype(INDEX)

    @property
    def boundary_edges(self) -> np.ndarray:
        """(B,) int: ids of edges on one triangle."""
        return np.flatnonzero(self.valence == 1).astype(INDEX)

    @property
    def junction_edges(self) -> np.ndarray:
        """(J,) int: ids of edges on three or more triangles."""
        return np.flatnonzero(self.valence >= 3).astype(INDEX)


def edge_keys(a: np.ndarray, b: np.ndarray, n_vertices: int) -> np.ndarray:
    """Pack unordered vertex pairs into one int64 key each (smaller id first)."""
    lo = np.minimum(a, b).astype(np.int64)
    hi = np.maximum(a, b).astype(np.int64)
    return lo * np.int64(n_vertices) + hi


def edge_topology(triangles: np.ndarray, n_vertices: int) -> EdgeTopology:
    """Find the unique edges of any triangle mesh by sorting its half-edges.

    This is the general path (imported meshes, single triangles, templates);
    structures built from patches use the faster repeated paths in
    :mod:`barymesh.repeat`, which give the same result.

    Parameters
    ----------
    triangles : (T, 3) int
    n_vertices : int

    Returns
    -------
    EdgeTopology

    Examples
    --------
    >>> topo = edge_topology(np.array([[0, 1, 2], [1, 3, 2]]), 4)
    >>> topo.edges.tolist(), topo.valence.tolist()
    ([[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]], [1, 1, 2, 1, 1])
    """
    triangles = np.asarray(triangles)
    n_tri = len(triangles)
    a = triangles.reshape(-1)
    b = triangles[:, [1, 2, 0]].reshape(-1)
    keys = edge_keys(a, b, n_vertices)
    order = np.argsort(keys, kind="stable")
    sorted_keys = keys[order]
    start = np.ones(len(keys), dtype=bool)
    start[1:] = sorted_keys[1:] != sorted_keys[:-1]
    group = np.cumsum(start) - 1
    first = np.flatnonzero(start)
    n_edges = len(first)
    edge_of_half = np.empty(len(keys), dtype=INDEX)
    edge_of_half[order] = group
    uniq = sorted_keys[first]
    edges = np.stack([uniq // n_vertices, uniq % n_vertices], axis=1).astype(INDEX)
    valence = np.diff(np.append(first, len(keys))).astype(INDEX)
    tri_of_sorted = (order // 3).astype(INDEX)
    edge_triangles = np.full((n_edges, 2), -1, dtype=INDEX)
    edge_triangles[:, 0] = tri_of_sorted[first]
    has_two = valence >= 2
    edge_triangles[has_two, 1] = tri_of_sorted[first[has_two] + 1]
    # half-edge k of a triangle joins its vertices k and k + 1; vertex k + 2 is opposite
    opposite = triangles[:, [2, 0, 1]].reshape(-1).astype(INDEX)
    free = np.full((n_edges, 2), -1, dtype=INDEX)
    free[:, 0] = opposite[order[first]]
    free[has_two, 1] = opposite[order[first[has_two] + 1]]
    junction = np.repeat(valence >= 3, valence)
    junction_incidence = np.stack([group[junction], tri_of_sorted[junction]], axis=1)
    return EdgeTopology(
        edges=edges,
        triangle_edges=edge_of_half.reshape(n_tri, 3),
        edge_triangles=edge_triangles,
        valence=valence,
        junction_incidence=junction_incidence.astype(INDEX).reshape(-1, 2),
        free_vertices=free,
    )


@dataclass(frozen=True)
class RWGTable:
    """The RWG basis functions of a mesh, in the convention of Makarov's codes.

    One row per interior edge (an edge on exactly two triangles).

    Attributes
    ----------
    edge : (N,) int
        Edge id in the mesh's ``edges``.
    vertices : (N, 2) int
        The edge's two vertices.
    t_plus, t_minus : (N,) int
        The lower and the higher triangle index on the edge.
    free_vertex_plus, free_vertex_minus : (N,) int
        The vertex of T+ (T−) that is not on the edge.
    length : (N,) float64
        Edge length l_n.
    """

    edge: np.ndarray
    vertices: np.ndarray
    t_plus: np.ndarray
    t_minus: np.ndarray
    free_vertex_plus: np.ndarray
    free_vertex_minus: np.ndarray
    length: np.ndarray

    def __len__(self) -> int:
        return len(self.edge)


def free_vertices(
    triangles: np.ndarray, triangle_edges: np.ndarray, tri: np.ndarray, edge: np.ndarray
) -> np.ndarray:
    """The vertex of each triangle ``tri[i]`` opposite its edge ``edge[i]``."""
    side = np.argmax(triangle_edges[tri] == edge[:, None], axis=1)
    return triangles[tri, (side + 2) % 3]


def rwg_table(
    points: np.ndarray,
    triangles: np.ndarray,
    topo: EdgeTopology,
    columns: list[np.ndarray] | None = None,
) -> RWGTable:
    """Build the RWG table (see :class:`RWGTable`) from a mesh and its edges.

    ``columns``, if given, are contiguous copies of the coordinate columns of
    ``points`` (see :func:`segment_lengths`).
    """
    edge = topo.interior_edges
    index = edge.astype(np.intp)
    verts = take_pairs(topo.edges, index)
    tri = take_pairs(topo.edge_triangles, index)
    t_plus, t_minus = tri[:, 0].copy(), tri[:, 1].copy()
    if topo.free_vertices is not None:
        free = take_pairs(topo.free_vertices, index)
        free_plus, free_minus = free[:, 0].copy(), free[:, 1].copy()
    else:
        free_plus = free_vertices(triangles, topo.triangle_edges, t_plus, edge)
        free_minus = free_vertices(triangles, topo.triangle_edges, t_minus, edge)
    return RWGTable(
        edge=edge,
        vertices=verts,
        t_plus=t_plus,
        t_minus=t_minus,
        free_vertex_plus=free_plus,
        free_vertex_minus=free_minus,
        length=segment_lengths(points, verts, columns),
    )


def take_pairs(pairs: np.ndarray, index: np.ndarray) -> np.ndarray:
    """``pairs[index]`` for (K, 2) int32 rows, gathered as single 8-byte items.

    Much faster than fancy indexing (or ``take(axis=0)``) of 2-D rows.
    """
    packed = np.ascontiguousarray(pairs, dtype=INDEX).view(np.int64).reshape(-1)
    return packed.take(index).view(INDEX).reshape(-1, 2)


def compress_pairs(pairs: np.ndarray, keep: np.ndarray) -> np.ndarray:
    """``pairs[keep]`` for (K, 2) int32 rows and a (K,) boolean mask, as 8-byte items."""
    packed = np.ascontiguousarray(pairs, dtype=INDEX).view(np.int64).reshape(-1)
    return packed[keep].view(INDEX).reshape(-1, 2)


def segment_lengths(
    points: np.ndarray, pairs: np.ndarray, columns: list[np.ndarray] | None = None
) -> np.ndarray:
    """(K,) float64 lengths of the segments between ``points[pairs[:, 0]]`` and ``pairs[:, 1]``.

    Coordinate by coordinate, in cache-sized blocks of segments, without
    (K, 3) temporaries; a coordinate that is zero everywhere (z of a planar
    mesh) adds nothing and is skipped. ``columns``: contiguous copies of the
    coordinate columns of ``points`` (any all-zero ones may be left out), to
    save making them again.
    """
    total = np.zeros(len(pairs))
    if columns is None:
        columns = [np.ascontiguousarray(points[:, axis]) for axis in range(points.shape[1])]
    axes = [x for x in columns if x.any()]
    for lo in range(0, len(pairs), BLOCK):
        block = pairs[lo : lo + BLOCK]
        start, end = block[:, 0].astype(np.intp), block[:, 1].astype(np.intp)
        acc = total[lo : lo + BLOCK]
        for x in axes:
            d = x.take(end)
            d -= x.take(start)
            d *= d
            acc += d
    return np.sqrt(total, out=total)


def triangle_adjacency(n_triangles: int, topo: EdgeTopology) -> sp.csr_matrix:
    """The paper's connectivity matrix (Eq. 27): T x T, 1 where two triangles share an edge.

    Triangles meeting at a junction edge are all connected to each other.
    """
    import scipy.sparse as sp  # here, not at the top: ``import barymesh`` stays light

    if len(topo.junction_incidence) == 0:
        direct = adjacency_without_junctions(n_triangles, topo)
        if direct is not None:
            return direct
    interior = topo.valence == 2
    rows = [topo.edge_triangles[interior, 0], topo.edge_triangles[interior, 1]]
    cols = [rows[1], rows[0]]
    inc = topo.junction_incidence
    if len(inc):
        # every ordered pair of distinct triangles on the same junction edge
        pa = _pairs_within_groups(inc[:, 0], inc[:, 1])
        rows.append(pa[:, 0])
        cols.append(pa[:, 1])
    r = np.concatenate(rows)
    c = np.concatenate(cols)
    m = sp.coo_matrix((np.ones(len(r), dtype=np.int8), (r, c)), shape=(n_triangles,) * 2).tocsr()
    m.sum_duplicates()
    m.data[:] = 1
    return m


def adjacency_without_junctions(n_triangles: int, topo: EdgeTopology) -> sp.csr_matrix | None:
    """The connectivity matrix built row by row: each triangle has at most 3 neighbours.

    Returns None when two triangles share more than one edge (a degenerate
    mesh), which the general path handles by summing duplicates.
    """
    import scipy.sparse as sp

    et = topo.edge_triangles
    # across an interior edge, the other triangle is (sum of both) - this one
    across = np.where(topo.valence == 2, et[:, 0] + et[:, 1], -1).astype(INDEX)
    rows = np.empty((n_triangles, 3), dtype=np.uint32)
    for start in range(0, n_triangles, BLOCK):
        block = topo.triangle_edges[start : start + BLOCK]
        this = np.arange(start, start + len(block), dtype=INDEX)
        side = []
        for k in range(3):
            other = across.take(block[:, k])
            other -= this  # negative where there is no neighbour ...
            side.append(other.view(np.uint32))  # ... which unsigned sorts after every triangle
        a, b, c = side  # sort each row with three exchanges
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        mid, top = np.minimum(hi, c), np.maximum(hi, c)
        out = rows[start : start + BLOCK]
        np.minimum(lo, mid, out=out[:, 0])
        np.maximum(lo, mid, out=out[:, 1])
        out[:, 2] = top
    has = rows < n_triangles
    twice = ((rows[:, 0] == rows[:, 1]) & has[:, 1]) | ((rows[:, 1] == rows[:, 2]) & has[:, 2])
    if twice.any():
        return None
    count = has[:, 0].astype(INDEX)
    count += has[:, 1]
    count += has[:, 2]
    indptr = np.zeros(n_triangles + 1, dtype=INDEX)
    np.cumsum(count, out=indptr[1:])
    indices = rows[has].view(INDEX)
    data = np.ones(len(indices), dtype=np.int8)
    return sp.csr_matrix((data, indices, indptr), shape=(n_triangles,) * 2)


def _pairs_within_groups(group: np.ndarray, value: np.ndarray) -> np.ndarray:
    """All ordered pairs (value[i], value[j]), i != j, of elements with the same group.

    ``group`` must be sorted.
    """
    start = np.flatnonzero(np.r_[True, group[1:] != group[:-1]])
    count = np.diff(np.append(start, len(group)))
    per_element = np.repeat(count, count)  # size of each element's group
    first = np.repeat(start, count)  # first element of each element's group
    i = np.repeat(np.arange(len(group)), per_element)
    block = np.repeat(np.cumsum(per_element) - per_element, per_element)
    j = np.repeat(first, per_element) + (np.arange(len(i)) - block)
    keep = i != j
    return np.stack([value[i[keep]], value[j[keep]]], axis=1)


def vertex_adjacency(n_vertices: int, edges: np.ndarray) -> sp.csr_matrix:
    """V x V symmetric matrix with 1 where two vertices are joined by an edge."""
    import scipy.sparse as sp

    r = np.concatenate([edges[:, 0], edges[:, 1]])
    c = np.concatenate([edges[:, 1], edges[:, 0]])
    return sp.coo_matrix((np.ones(len(r), dtype=np.int8), (r, c)), shape=(n_vertices,) * 2).tocsr()

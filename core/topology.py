"""Edges, shared edges, the RWG table and the connectivity matrix.

Edge k of a triangle joins its vertices k and k + 1 (mod 3). An edge on one
triangle is a boundary edge, on two an interior edge (one RWG unknown), on
three or more a junction, which is reported and never dropped.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
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
    structures built from patches use the faster template path in
    :mod:`barymesh.assembly`, which gives the same result.

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


def patch_edge_counts(
    local_edges: np.ndarray, local_valence: np.ndarray, vertex_map: np.ndarray, n_vertices: int
) -> np.ndarray:
    """How many edges lie on 1, 2, 3, ... triangles in a structure of patch copies.

    The counts of :func:`edge_topology` (and of the template path in
    :mod:`barymesh.assembly`) without making any per-edge array: an edge with an end
    that belongs to one patch only is that patch's template edge; only edges with
    both ends shared can be listed by several patches, and those are matched by
    one sort of their packed vertex pairs (the template valence in the two low
    bits, so the sort also groups what each copy contributes).

    Parameters
    ----------
    local_edges : (Ne, 2) int
        The template's edges (local vertex pairs).
    local_valence : (Ne,) int
        Triangles on each template edge (1 or 2).
    vertex_map : (P, Nv) int
        Global vertex of each local vertex of each patch.
    n_vertices : int

    Returns
    -------
    (K,) int64
        ``counts[k]``: number of edges on exactly k triangles (``counts[0] == 0``);
        its sum is the number of edges.
    """
    vmap = np.asarray(vertex_map)
    local_valence = np.asarray(local_valence, dtype=np.int64)
    n_patch = len(vmap)
    counts = np.bincount(local_valence, minlength=3) * np.int64(n_patch)
    if n_patch == 0 or len(local_edges) == 0:
        return counts
    shared = np.bincount(vmap.ravel(), minlength=n_vertices) > 1
    e0, e1 = local_edges[:, 0], local_edges[:, 1]
    keys = []
    for lo in range(0, n_patch, max(1, BLOCK // len(local_edges))):
        block = vmap[lo : lo + max(1, BLOCK // len(local_edges))]
        a, b = block.take(e0, axis=1), block.take(e1, axis=1)
        pooled = shared.take(a) & shared.take(b)  # (p, Ne)
        slot = np.nonzero(pooled)
        key = edge_keys(a[slot], b[slot], n_vertices)
        key <<= 2
        key |= local_valence.take(slot[1])
        keys.append(key)
    key = np.sort(np.concatenate(keys))
    if len(key) == 0:
        return counts
    # take the pooled copies out, then put each group back once with its summed valence
    counts -= np.bincount(key & 3, minlength=len(counts))[: len(counts)]
    pair = key >> 2
    start = np.flatnonzero(np.r_[True, pair[1:] != pair[:-1]])
    valence = np.add.reduceat(key & 3, start)
    grouped = np.bincount(valence)
    out = np.zeros(max(len(counts), len(grouped)), dtype=np.int64)
    out[: len(counts)] += counts
    out[: len(grouped)] += grouped
    return out


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
    if len(topo.junction_incidence) == 0:
        direct = _adjacency_without_junctions(n_triangles, topo)
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


def _adjacency_without_junctions(n_triangles: int, topo: EdgeTopology) -> sp.csr_matrix | None:
    """The connectivity matrix built row by row: each triangle has at most 3 neighbours.

    Returns None when two triangles share more than one edge (a degenerate
    mesh), which the general path handles by summing duplicates.
    """
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
    r = np.concatenate([edges[:, 0], edges[:, 1]])
    c = np.concatenate([edges[:, 1], edges[:, 0]])
    return sp.coo_matrix((np.ones(len(r), dtype=np.int8), (r, c)), shape=(n_vertices,) * 2).tocsr()


#: Sectors in the short chain whose topology a long chain repeats: two first, the middle
#: one (``MIDDLE``), two last. A sector's edges reach the vertices of the sector after
#: next (the free vertex across a glued side), so the middle one needs two on each side.
CHAIN = 5
MIDDLE = 2


def chain_topology(
    shorts: list[EdgeTopology],
    ms: list[int],
    n_tri: int,
    stride: int,
    chain_vertices: list[int],
) -> EdgeTopology:
    """Topology of chains of m_i sectors, each repeated from a chain of :data:`CHAIN` sectors.

    In a chain of sectors glued side 2 to side 0 and numbered by formula
    (:func:`barymesh.structures._sector_chain_vertices`: sector k's vertices start
    at k ``stride``), every sector between the first and the last lists the
    same edges, in the same order, with the same incidence, shifted by one
    sector's worth of vertices, triangles and edges. The short chain's first
    two sectors are the long chain's first two, its middle one is repeated for
    sectors 2 … m − 3 and its last two are the last two; a value of the first
    two that refers to the last sector (across a closed chain's seam) and one
    of the last two that refers to the middle sector or later move to the end
    of the long chain, a reference of the last two back to sector 0 (a closed
    chain) stays. Chains follow one another (vertices, triangles and edges
    numbered on). The same arrays as :func:`barymesh.assembly.patch_topology` on
    the whole structure, bit for bit (the tests compare them on many chains),
    without sorting or gathering anything of the size of the mesh.

    Parameters
    ----------
    shorts : list of EdgeTopology
        Per chain, ``patch_topology`` of the chain with :data:`CHAIN` sectors
        (vertices numbered by the formula from 0); free vertices filled in, no
        junctions.
    ms : list of int
        Sectors of each long chain (m_i), each at least :data:`CHAIN`.
    n_tri : int
        Triangles per sector.
    stride : int
        Vertices each sector adds (its own, side 0 included, side 2 not).
    chain_vertices : list of int
        Vertices of each long chain (m_i ``stride``, plus side 2's of an open chain).

    Returns
    -------
    EdgeTopology
    """
    if len(ms) != len(shorts) or min(ms, default=CHAIN) < CHAIN:
        raise ValueError(f"chain_topology: sectors per chain {list(ms)!r}, each >= {CHAIN}")
    if any(len(s.junction_incidence) or s.free_vertices is None for s in shorts):
        raise ValueError("chain_topology: a short chain with junctions or without free vertices")
    tri_cut = np.arange(CHAIN + 1) * n_tri
    vertex_starts = np.arange(CHAIN + 1) * stride
    edge_cuts, n_edges = [], []
    for short, m in zip(shorts, ms, strict=True):  # edges are listed sector by sector
        cut = np.searchsorted(short.edge_triangles[:, 0] // n_tri, np.arange(CHAIN + 1))
        edge_cuts.append(cut)
        n_edges.append(int(cut[-1] + (m - CHAIN) * (cut[MIDDLE + 1] - cut[MIDDLE])))
    total = sum(n_edges)
    edges = np.empty((total, 2), dtype=INDEX)
    edge_triangles = np.empty((total, 2), dtype=INDEX)
    free_vertices = np.empty((total, 2), dtype=INDEX)
    valence = np.empty(total, dtype=INDEX)
    triangle_edges = np.empty((sum(ms) * n_tri, 3), dtype=INDEX)
    e0 = t0 = v0 = 0
    for short, m, cut, n_e, n_v in zip(shorts, ms, edge_cuts, n_edges, chain_vertices, strict=True):
        assert short.free_vertices is not None  # refused above
        extra = m - CHAIN  # sectors 2 … m − 3: extra + 1 copies of the short chain's sector 2
        per_sector = int(cut[MIDDLE + 1] - cut[MIDDLE])  # edges listed by a middle sector
        rows = slice(e0, e0 + n_e)
        _extend(short.edges, edges[rows], cut, extra, per_sector, stride, vertex_starts, v0)
        _extend(
            short.edge_triangles, edge_triangles[rows], cut, extra, per_sector, n_tri, tri_cut, t0
        )
        _extend(
            short.free_vertices,
            free_vertices[rows],
            cut,
            extra,
            per_sector,
            stride,
            vertex_starts,
            v0,
        )
        _extend(short.valence, valence[rows], cut, extra, per_sector, 0, cut, 0)
        _extend(
            short.triangle_edges,
            triangle_edges[t0 : t0 + m * n_tri],
            tri_cut,
            extra,
            n_tri,
            per_sector,
            cut,
            e0,
        )
        e0, t0, v0 = e0 + n_e, t0 + m * n_tri, v0 + n_v
    return EdgeTopology(
        edges=edges,
        triangle_edges=triangle_edges,
        edge_triangles=edge_triangles,
        valence=valence,
        junction_incidence=np.empty((0, 2), dtype=INDEX),
        free_vertices=free_vertices,
    )


def _extend(
    short: np.ndarray,
    out: np.ndarray,
    cuts: np.ndarray,
    extra: int,
    unit: int,
    step: int,
    starts: np.ndarray,
    base: int,
) -> None:
    """Fill ``out`` with a long chain's rows from a short chain's (see :func:`chain_topology`).

    Rows ``cuts[q]:cuts[q + 1]`` of ``short`` belong to sector q; the middle
    sector's ``unit`` rows are written ``extra + 1`` times. Values are ids of
    things of which a middle sector has ``step`` (0: not ids), sector q's from
    ``starts[q]`` on, or -1 for none; ``base`` is added to every id.
    """
    n_head = int(cuts[MIDDLE])
    head = out[:n_head]
    head[...] = short[:n_head]
    middle = short[cuts[MIDDLE] : cuts[MIDDLE + 1]]
    block = out[n_head : n_head + (extra + 1) * unit].reshape((extra + 1,) + middle.shape)
    tail = out[n_head + (extra + 1) * unit :]
    tail[...] = short[cuts[MIDDLE + 1] :]
    if step == 0:
        block[...] = middle
        return
    # the first sectors reach at most two sectors on, or the last one across the seam
    head[head >= starts[MIDDLE + 2]] += INDEX(extra * step)
    # the last ones reach back to the middle one, or to sector 0 across the seam
    tail[tail >= starts[MIDDLE]] += INDEX(extra * step)
    _fill_tiled(block.reshape(-1), middle, extra + 1, step, base)
    if base:
        for part in (head, tail):
            part[part >= 0] += INDEX(base)


def copies_topology(
    local: EdgeTopology, n_patches: int, n_vertices: int, n_tri: int
) -> EdgeTopology:
    """Topology of ``n_patches`` unwelded copies of one patch, patch p's vertices from p Nv.

    Every edge is a template edge of one copy: the template's arrays shifted by
    p times the vertices, triangles and edges of a patch, written once each
    (no gathers). The same arrays as :func:`barymesh.assembly.patch_topology` on an
    identity vertex map, bit for bit.

    Parameters
    ----------
    local : EdgeTopology
        The template's topology, edges ascending within each pair, free vertices
        filled in, no junctions.
    n_patches : int
    n_vertices : int
        Vertices of one patch (Nv).
    n_tri : int
        Triangles of one patch.
    """
    assert local.free_vertices is not None  # a template's topology has them
    n_loc = len(local.edges)
    valence = np.empty((n_patches, n_loc), dtype=INDEX)
    valence[...] = local.valence
    return EdgeTopology(
        edges=_tiled(local.edges, n_patches, n_vertices),
        triangle_edges=_tiled(local.triangle_edges, n_patches, n_loc),
        edge_triangles=_tiled(local.edge_triangles, n_patches, n_tri),
        valence=valence.reshape(-1),
        junction_incidence=np.empty((0, 2), dtype=INDEX),
        free_vertices=_tiled(local.free_vertices, n_patches, n_vertices),
    )


def _tiled(a: np.ndarray, n_patches: int, step: int) -> np.ndarray:
    """``a`` once per patch, patch p's ids (not the -1 entries) shifted by p ``step``."""
    out = np.empty((n_patches,) + a.shape, dtype=INDEX)
    _fill_tiled(out.reshape(-1), a, n_patches, step, 0)
    return out.reshape((-1,) + a.shape[1:])


def _fill_tiled(out: np.ndarray, a: np.ndarray, copies: int, step: int, base: int) -> None:
    """Write ``copies`` copies of ``a`` into the flat ``out``, copy k's ids plus k ``step`` + base.

    Entries of -1 (none) stay -1. Block by block over a pattern of whole copies:
    long, contiguous adds even when ``a`` is a handful of values (a broadcast add
    over (copies, len(a)) would run one short inner loop per copy).
    """
    flat = np.ascontiguousarray(a, dtype=INDEX).reshape(-1)
    k = len(flat)
    if copies == 0 or k == 0:
        return
    per = max(1, min(copies, BLOCK // k))  # copies per block
    ramp = np.repeat(np.arange(per, dtype=INDEX) * INDEX(step), k)
    missing = flat < 0
    if missing.any():
        keep = np.tile(~missing, per).astype(INDEX)  # 0 where -1 must stay
        pattern = np.tile(flat, per) + ramp * keep + INDEX(base) * keep
    else:
        keep = None
        pattern = np.tile(flat, per) + ramp + INDEX(base)
    for lo in range(0, copies, per):
        n = min(per, copies - lo) * k
        block = out[lo * k : lo * k + n]
        if keep is None:
            np.add(pattern[:n], INDEX(lo * step), out=block)
        else:
            np.multiply(keep[:n], INDEX(lo * step), out=block)
            block += pattern[:n]


def copies_rwg(
    local: EdgeTopology,
    n_patches: int,
    n_vertices: int,
    n_tri: int,
    points: np.ndarray,
    columns: list[np.ndarray] | None = None,
) -> RWGTable:
    """:func:`rwg_table` of the topology :func:`copies_topology` makes, without gathers.

    The template's interior edges, copy after copy; only the lengths are
    measured. Parameters as for :func:`copies_topology`, plus the mesh's
    ``points`` (and ``columns``, see :func:`segment_lengths`).
    """
    assert local.free_vertices is not None  # a template's topology has them
    rows = np.flatnonzero(local.valence == 2)
    vertices = _tiled(local.edges[rows], n_patches, n_vertices)
    return RWGTable(
        edge=_tiled(rows.astype(INDEX), n_patches, len(local.edges)),
        vertices=vertices,
        t_plus=_tiled(local.edge_triangles[rows, 0], n_patches, n_tri),
        t_minus=_tiled(local.edge_triangles[rows, 1], n_patches, n_tri),
        free_vertex_plus=_tiled(local.free_vertices[rows, 0], n_patches, n_vertices),
        free_vertex_minus=_tiled(local.free_vertices[rows, 1], n_patches, n_vertices),
        length=segment_lengths(points, vertices, columns),
    )


def chain_rwg(
    shorts: list[EdgeTopology],
    ms: list[int],
    n_tri: int,
    stride: int,
    chain_vertices: list[int],
    points: np.ndarray,
    columns: list[np.ndarray] | None = None,
) -> RWGTable:
    """:func:`rwg_table` of the topology :func:`chain_topology` makes, without gathers.

    The short chains' interior edges are repeated as their edges are; only the
    lengths are measured. Parameters as for :func:`chain_topology`, plus the
    mesh's ``points`` (and ``columns``, see :func:`segment_lengths`).
    """
    tri_cut = np.arange(CHAIN + 1) * n_tri
    vertex_starts = np.arange(CHAIN + 1) * stride
    parts = []
    for short in shorts:
        cut = np.searchsorted(short.edge_triangles[:, 0] // n_tri, np.arange(CHAIN + 1))
        rows = np.flatnonzero(short.valence == 2)
        row_cut = np.searchsorted(rows, cut)  # the interior edges of each sector
        parts.append((short, cut, rows, row_cut))
    total = sum(
        int(rc[-1] + (m - CHAIN) * (rc[MIDDLE + 1] - rc[MIDDLE]))
        for (_, _, _, rc), m in zip(parts, ms, strict=True)
    )
    edge = np.empty(total, dtype=INDEX)
    vertices = np.empty((total, 2), dtype=INDEX)
    columns_out = [np.empty(total, dtype=INDEX) for _ in range(4)]
    r0 = e0 = t0 = v0 = 0
    for (short, cut, rows, row_cut), m, n_v in zip(parts, ms, chain_vertices, strict=True):
        assert short.free_vertices is not None  # as chain_topology's
        extra = m - CHAIN
        per_sector = int(cut[MIDDLE + 1] - cut[MIDDLE])
        unit = int(row_cut[MIDDLE + 1] - row_cut[MIDDLE])
        n_rows = int(row_cut[-1]) + extra * unit
        out = slice(r0, r0 + n_rows)
        _extend(rows.astype(INDEX), edge[out], row_cut, extra, unit, per_sector, cut, e0)
        _extend(short.edges[rows], vertices[out], row_cut, extra, unit, stride, vertex_starts, v0)
        for k, (source, step, starts, base) in enumerate(
            [
                (short.edge_triangles[rows, 0], n_tri, tri_cut, t0),
                (short.edge_triangles[rows, 1], n_tri, tri_cut, t0),
                (short.free_vertices[rows, 0], stride, vertex_starts, v0),
                (short.free_vertices[rows, 1], stride, vertex_starts, v0),
            ]
        ):
            _extend(source, columns_out[k][out], row_cut, extra, unit, step, starts, base)
        n_e = int(cut[-1]) + extra * per_sector
        r0, e0, t0, v0 = r0 + n_rows, e0 + n_e, t0 + m * n_tri, v0 + n_v
    t_plus, t_minus, free_plus, free_minus = columns_out
    return RWGTable(
        edge=edge,
        vertices=vertices,
        t_plus=t_plus,
        t_minus=t_minus,
        free_vertex_plus=free_plus,
        free_vertex_minus=free_minus,
        length=segment_lengths(points, vertices, columns),
    )


def copies_adjacency(local: sp.csr_matrix, n_patches: int) -> sp.csr_matrix:
    """The connectivity matrix of ``n_patches`` unwelded copies of one patch.

    Block diagonal: the patch's matrix ``local`` (sorted rows, as
    :func:`triangle_adjacency` makes them) once per copy, its column ids
    shifted by the patch's triangles; the same matrix as
    :func:`triangle_adjacency` on the whole mesh, array for array.
    """
    n_tri = local.shape[0]
    counts = np.diff(local.indptr).astype(INDEX)
    indptr = np.zeros(n_patches * n_tri + 1, dtype=INDEX)
    per_row = np.empty((n_patches, n_tri), dtype=INDEX)
    per_row[...] = counts
    np.cumsum(per_row.reshape(-1), out=indptr[1:])
    indices = _tiled(local.indices.astype(INDEX), n_patches, n_tri)
    data = np.ones(len(indices), dtype=np.int8)
    return sp.csr_matrix((data, indices, indptr), shape=(n_patches * n_tri,) * 2)


def chain_adjacency(shorts: list[sp.csr_matrix], ms: list[int], n_tri: int) -> sp.csr_matrix:
    """The connectivity matrix of chains of m_i sectors, repeated from short chains.

    ``shorts``: per chain, the matrix of its chain of :data:`CHAIN` sectors (as
    :func:`triangle_adjacency` makes it). Rows are repeated as the edges are in
    :func:`chain_topology`: a shift keeps each row's neighbours in ascending
    order, so the result is the matrix of the whole mesh, array for array.
    """
    tri_cut = np.arange(CHAIN + 1) * n_tri
    n_rows = sum(ms) * n_tri
    counts = np.empty(n_rows, dtype=INDEX)
    nnz = [
        int(s.indptr[-1])
        + (m - CHAIN) * int(s.indptr[tri_cut[MIDDLE + 1]] - s.indptr[tri_cut[MIDDLE]])
        for s, m in zip(shorts, ms, strict=True)
    ]
    indices = np.empty(sum(nnz), dtype=INDEX)
    i0 = t0 = 0
    for short, m, n in zip(shorts, ms, nnz, strict=True):
        extra = m - CHAIN
        rows = slice(t0, t0 + m * n_tri)
        _extend(
            np.diff(short.indptr).astype(INDEX), counts[rows], tri_cut, extra, n_tri, 0, tri_cut, 0
        )
        cuts = short.indptr[tri_cut]
        _extend(
            short.indices.astype(INDEX),
            indices[i0 : i0 + n],
            cuts,
            extra,
            int(cuts[MIDDLE + 1] - cuts[MIDDLE]),
            n_tri,
            tri_cut,
            t0,
        )
        i0, t0 = i0 + n, t0 + m * n_tri
    indptr = np.zeros(n_rows + 1, dtype=INDEX)
    np.cumsum(counts, out=indptr[1:])
    data = np.ones(len(indices), dtype=np.int8)
    return sp.csr_matrix((data, indices, indptr), shape=(n_rows, n_rows))

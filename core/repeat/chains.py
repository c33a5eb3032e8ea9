"""Chains of sectors: a conforming ring's arcs, numbered by formula.

A conforming ring (or each arc of a slotted one) is a chain of m sectors, each
a copy of one tensor template whose side 0 is its first ``s`` local vertices
and side 2 its last ``s``; sector k's side 2 is sector k + 1's side 0, and a
closed chain's last side 2 is its first side 0. With S = Nv − s (the vertices
a sector adds), the build numbers them by formula
(:func:`sector_chain_vertices`)::

    local vertex l of sector k    ->  vertex  v0 + k S + l      (a closed chain's
    local triangle t of sector k  ->  triangle t0 + k Nt + t      last side 2 is
                                                                   v0 + 0 … s − 1)
     side 2   kS+Nv-s .. kS+Nv-1  ==  (k+1)S+0 .. (k+1)S+s-1   side 0 of sector k + 1
              kS+s    .. kS+Nv-s-1                              the sector's own rows
     side 0   kS+0    .. kS+s-1   ==  side 2 of sector k - 1

so every sector's edges (listed sector by sector, as
:func:`barymesh.repeat.patches.patch_topology` lists them) are the same as its
predecessor's, shifted by S vertices, Nt triangles and the E_mid edges a middle
sector lists. A long chain's topology is that of a short chain of
:data:`CHAIN` sectors with its middle sector repeated::

    short chain (CHAIN = 5):  [ 0 ][ 1 ][ 2 ][ 3 ][ 4 ]
    long chain (m sectors):   [ 0 ][ 1 ][ 2 ][ 2 ] ... [ 2 ][ 3 ][ 4 ]
    sector of the long chain:   0    1    2    3   ...  m-3  m-2  m-1
                                          copy j = 0 … m − 5 of the short chain's
                                          sector 2: its ids plus j S, j Nt or j E_mid

(a sector's edges reach the vertices of the sector after next, the free vertex
across a glued side, so the middle sector needs two on each side). Chains follow
one another, their vertices, triangles and edges numbered on. The results equal
:func:`barymesh.repeat.patches.patch_topology` and the general paths of
:mod:`barymesh.topology` bit for bit (``tests/test_core_chain_paths.py``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from ..subdivision import PatchTemplate
from ..topology import INDEX, EdgeTopology, RWGTable, segment_lengths
from .copies import fill_tiled
from .patches import patch_edge_counts, patch_topology

if TYPE_CHECKING:
    import scipy.sparse as sp

#: Sectors in the short chain whose topology a long chain repeats: two first, the middle
#: one (``MIDDLE``), two last. A sector's edges reach the vertices of the sector after
#: next (the free vertex across a glued side), so the middle one needs two on each side.
CHAIN = 5
MIDDLE = 2

#: Chains of sectors the chain paths take at most (a conforming ring has one or two
#: rings of one or two arcs); more and the mesh takes the general paths.
MAX_CHAINS = 16


def sector_chain_vertices(
    template: PatchTemplate, m: int | list[int], closed: list[bool]
) -> tuple[np.ndarray, np.ndarray]:
    """Vertex ids of chains of sectors glued side 2 to side 0, by formula.

    The same ``(vertex_of_point, representative)`` as :func:`barymesh.weld.merge_pairs`
    on the glue pairs (vertices numbered by first appearance), without sorting:
    with the template's side 0 first and side 2 last, local vertex l of
    sector k is vertex k S + l, S = Nv − (side length), and a closed chain's
    last side 2 is its first side 0.

    Parameters
    ----------
    template : PatchTemplate
    m : int or list of int
        Sectors of every chain, or of each chain.
    closed : list of bool
        Whether each chain closes on itself.

    Returns
    -------
    vertex_of_point : (sum m_i Nv,) int
        Global vertex of each local vertex of each sector (the flat vertex map).
    representative : (V,) int
        The first point of each vertex.

    Examples
    --------
    >>> from barymesh.subdivision import tensor_template
    >>> t = tensor_template((0.0, 1.0), (0.0, 1.0), "BC")  # 4 vertices, sides of 2
    >>> sector_chain_vertices(t, 3, [True])[0].reshape(3, -1).tolist()
    [[0, 1, 2, 3], [2, 3, 4, 5], [4, 5, 0, 1]]
    """
    nv = len(template.uv)
    s = len(template.sides[0])
    stride = nv - s
    counts = [m] * len(closed) if isinstance(m, (int, np.integer)) else list(m)
    local = np.arange(nv, dtype=INDEX)
    ids, reps = [], []
    n_vertices = 0
    n_points = 0
    for k, is_closed in zip(counts, closed, strict=True):
        sector = np.arange(k, dtype=INDEX)[:, None]
        block = sector * INDEX(stride) + local + INDEX(n_vertices)  # (k, Nv)
        first = np.ones((k, nv), dtype=bool)  # first appearance of its vertex
        first[1:, :s] = False
        if is_closed:
            block[-1, nv - s :] = n_vertices + np.arange(s, dtype=INDEX)
            first[-1, nv - s :] = False
        ids.append(block.ravel())
        reps.append(np.flatnonzero(first.ravel()).astype(INDEX) + INDEX(n_points))
        n_vertices += k * stride + (0 if is_closed else s)
        n_points += k * nv
    return np.concatenate(ids), np.concatenate(reps)


def find_chains(
    template: PatchTemplate, vertex_map: np.ndarray, n_vertices: int
) -> tuple[tuple[int, ...], tuple[bool, ...]] | None:
    """(m_i, closed_i) per chain when the vertex map is chains of sectors numbered by formula.

    The chains are read off the vertex map (where a sector's side 2 is not the
    next one's side 0, a chain ends; it is closed when its last side 2 is its
    first side 0), then the whole map is checked, every entry, against
    :func:`sector_chain_vertices` for those chains: only then does the
    topology repeat that of short chains (:func:`chain_topology`). None for
    anything else: touching rings, a chain shorter than :data:`CHAIN`, more
    than :data:`MAX_CHAINS` chains, renumbered vertices, patches that are not
    sectors.

    Parameters
    ----------
    template : PatchTemplate
    vertex_map : (P, Nv) int
    n_vertices : int
    """
    n_p = len(vertex_map)
    if n_p < CHAIN:
        return None
    nv = len(template.uv)
    side0, side2 = np.asarray(template.sides[0]), np.asarray(template.sides[2])
    s = len(side0)
    if len(side2) != s:
        return None
    vmap = vertex_map
    glued = (vmap[:-1].take(side2, axis=1) == vmap[1:].take(side0, axis=1)).all(axis=1)
    starts = np.flatnonzero(np.r_[True, ~glued])
    if len(starts) > MAX_CHAINS:
        return None
    ends = np.r_[starts[1:], n_p]
    ms = ends - starts
    if ms.min() < CHAIN:
        return None
    closed = (vmap[ends - 1].take(side2, axis=1) == vmap[starts].take(side0, axis=1)).all(1)
    sectors, is_closed = tuple(int(m) for m in ms), tuple(bool(c) for c in closed)
    sizes = [m * (nv - s) + (0 if c else s) for m, c in zip(sectors, is_closed, strict=True)]
    if n_vertices != sum(sizes):
        return None
    ids, _ = sector_chain_vertices(template, list(sectors), list(is_closed))
    if not np.array_equal(vmap.ravel(), ids):
        return None
    return sectors, is_closed


#: (id of the template, closed) -> (template, topology of its short chain); a few entries.
_SHORT_CHAINS: dict[tuple[int, bool], tuple[PatchTemplate, EdgeTopology]] = {}


def short_chain_topology(template: PatchTemplate, closed: bool) -> EdgeTopology:
    """``patch_topology`` of a chain of :data:`CHAIN` sectors numbered by formula (cached)."""
    key = (id(template), closed)
    hit = _SHORT_CHAINS.get(key)
    if hit is not None and hit[0] is template:  # the template itself is kept: ids stay unique
        return hit[1]
    ids, _ = sector_chain_vertices(template, CHAIN, [closed])
    s = len(template.sides[0])
    n_vertices = CHAIN * (len(template.uv) - s) + (0 if closed else s)
    topo = patch_topology(template, ids.reshape(CHAIN, -1), n_vertices)
    if len(_SHORT_CHAINS) >= 16:
        _SHORT_CHAINS.clear()
    _SHORT_CHAINS[key] = (template, topo)
    return topo


class ChainParts(NamedTuple):
    """What :func:`chain_topology` repeats: short chains and the sizes of the long ones.

    Attributes
    ----------
    shorts : list of EdgeTopology
        Per chain, ``patch_topology`` of the chain with :data:`CHAIN` sectors
        (vertices numbered by the formula from 0); free vertices filled in, no
        junctions.
    sectors : list of int
        Sectors of each long chain (m_i), each at least :data:`CHAIN`.
    n_tri : int
        Triangles per sector (Nt).
    stride : int
        Vertices each sector adds (S: its own, side 0 included, side 2 not).
    chain_vertices : list of int
        Vertices of each long chain (m_i S, plus side 2's of an open chain).
    """

    shorts: list[EdgeTopology]
    sectors: list[int]
    n_tri: int
    stride: int
    chain_vertices: list[int]


def chain_parts(
    template: PatchTemplate, sectors: tuple[int, ...], closed: tuple[bool, ...]
) -> ChainParts:
    """The :class:`ChainParts` of chains of ``sectors`` copies of ``template``."""
    s = len(template.sides[0])
    stride = len(template.uv) - s
    shorts = [short_chain_topology(template, c) for c in closed]
    counts = [m * stride + (0 if c else s) for m, c in zip(sectors, closed, strict=True)]
    return ChainParts(shorts, list(sectors), len(template.triangles), stride, counts)


class Ids(NamedTuple):
    """What the values in a short chain's rows number, for :func:`extend`.

    Attributes
    ----------
    step : int
        Of these ids, how many one middle sector has (S vertices, Nt triangles
        or the edges it lists).
    starts : (CHAIN + 1,) int
        The first id of each sector of the short chain (and the end).
    base : int
        Added to every id: the long chain's first id in the mesh.
    """

    step: int
    starts: np.ndarray
    base: int


def extend(
    short: np.ndarray, out: np.ndarray, cuts: np.ndarray, extra: int, ids: Ids | None
) -> None:
    """Fill ``out`` with a long chain's rows from a short chain's (see :func:`chain_topology`).

    Rows ``cuts[q]:cuts[q + 1]`` of ``short`` belong to sector q; the middle
    sector's rows are written ``extra + 1`` times (``extra`` = m − :data:`CHAIN`).
    Values are ids as ``ids`` describes, or -1 for none; with ``ids`` None they
    are not ids (a valence, a count) and are copied as they are.
    """
    n_head = int(cuts[MIDDLE])
    unit = int(cuts[MIDDLE + 1] - cuts[MIDDLE])
    head = out[:n_head]
    head[...] = short[:n_head]
    middle = short[cuts[MIDDLE] : cuts[MIDDLE + 1]]
    block = out[n_head : n_head + (extra + 1) * unit].reshape((extra + 1,) + middle.shape)
    tail = out[n_head + (extra + 1) * unit :]
    tail[...] = short[cuts[MIDDLE + 1] :]
    if ids is None:
        block[...] = middle
        return
    step, starts, base = ids
    # the first sectors reach at most two sectors on, or the last one across the seam
    head[head >= starts[MIDDLE + 2]] += INDEX(extra * step)
    # the last ones reach back to the middle one, or to sector 0 across the seam
    tail[tail >= starts[MIDDLE]] += INDEX(extra * step)
    fill_tiled(block.reshape(-1), middle, extra + 1, step, base)
    if base:
        for part in (head, tail):
            part[part >= 0] += INDEX(base)


def chain_topology(parts: ChainParts) -> EdgeTopology:
    """Topology of chains of m_i sectors, each repeated from a chain of :data:`CHAIN` sectors.

    In a chain of sectors glued side 2 to side 0 and numbered by formula
    (:func:`sector_chain_vertices`: sector k's vertices start at k ``stride``),
    every sector between the first and the last lists the same edges, in the
    same order, with the same incidence, shifted by one sector's worth of
    vertices, triangles and edges. The short chain's first
    two sectors are the long chain's first two, its middle one is repeated for
    sectors 2 … m − 3 and its last two are the last two; a value of the first
    two that refers to the last sector (across a closed chain's seam) and one
    of the last two that refers to the middle sector or later move to the end
    of the long chain, a reference of the last two back to sector 0 (a closed
    chain) stays. Chains follow one another (vertices, triangles and edges
    numbered on). The same arrays as :func:`barymesh.repeat.patches.patch_topology` on
    the whole structure, bit for bit (the tests compare them on many chains),
    without sorting or gathering anything of the size of the mesh.

    Parameters
    ----------
    parts : ChainParts
        The short chains and the sizes of the long ones (:func:`chain_parts`).

    Returns
    -------
    EdgeTopology
    """
    shorts, ms, n_tri, stride, chain_vertices = parts
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
        vertex_ids = Ids(stride, vertex_starts, v0)
        extend(short.edges, edges[rows], cut, extra, vertex_ids)
        extend(short.edge_triangles, edge_triangles[rows], cut, extra, Ids(n_tri, tri_cut, t0))
        extend(short.free_vertices, free_vertices[rows], cut, extra, vertex_ids)
        extend(short.valence, valence[rows], cut, extra, None)
        edge_ids = Ids(per_sector, cut, e0)
        extend(short.triangle_edges, triangle_edges[t0 : t0 + m * n_tri], tri_cut, extra, edge_ids)
        e0, t0, v0 = e0 + n_e, t0 + m * n_tri, v0 + n_v
    return EdgeTopology(
        edges=edges,
        triangle_edges=triangle_edges,
        edge_triangles=edge_triangles,
        valence=valence,
        junction_incidence=np.empty((0, 2), dtype=INDEX),
        free_vertices=free_vertices,
    )


def chain_rwg(
    parts: ChainParts, points: np.ndarray, columns: list[np.ndarray] | None = None
) -> RWGTable:
    """The RWG table of the topology :func:`chain_topology` makes, without gathers.

    :func:`barymesh.topology.rwg_table` of that topology, bit for bit.

    The short chains' interior edges are repeated as their edges are; only the
    lengths are measured. ``parts`` as for :func:`chain_topology`, plus the
    mesh's ``points`` (and ``columns``, see :func:`barymesh.topology.segment_lengths`).
    """
    shorts, ms, n_tri, stride, chain_vertices = parts
    tri_cut = np.arange(CHAIN + 1) * n_tri
    vertex_starts = np.arange(CHAIN + 1) * stride
    pieces: list[tuple[EdgeTopology, np.ndarray, np.ndarray, np.ndarray]] = []
    for short in shorts:
        cut = np.searchsorted(short.edge_triangles[:, 0] // n_tri, np.arange(CHAIN + 1))
        rows = np.flatnonzero(short.valence == 2)
        row_cut = np.searchsorted(rows, cut)  # the interior edges of each sector
        pieces.append((short, cut, rows, row_cut))
    total = sum(
        int(rc[-1] + (m - CHAIN) * (rc[MIDDLE + 1] - rc[MIDDLE]))
        for (_, _, _, rc), m in zip(pieces, ms, strict=True)
    )
    edge = np.empty(total, dtype=INDEX)
    vertices = np.empty((total, 2), dtype=INDEX)
    columns_out = [np.empty(total, dtype=INDEX) for _ in range(4)]
    r0 = e0 = t0 = v0 = 0
    for (short, cut, rows, row_cut), m, n_v in zip(pieces, ms, chain_vertices, strict=True):
        assert short.free_vertices is not None  # as chain_topology's
        extra = m - CHAIN
        per_sector = int(cut[MIDDLE + 1] - cut[MIDDLE])
        unit = int(row_cut[MIDDLE + 1] - row_cut[MIDDLE])  # interior edges of a middle sector
        n_rows = int(row_cut[-1]) + extra * unit
        out = slice(r0, r0 + n_rows)
        vertex_ids = Ids(stride, vertex_starts, v0)
        extend(rows.astype(INDEX), edge[out], row_cut, extra, Ids(per_sector, cut, e0))
        extend(short.edges[rows], vertices[out], row_cut, extra, vertex_ids)
        triangle_ids = Ids(n_tri, tri_cut, t0)
        for k, (source, ids) in enumerate(
            [
                (short.edge_triangles[rows, 0], triangle_ids),
                (short.edge_triangles[rows, 1], triangle_ids),
                (short.free_vertices[rows, 0], vertex_ids),
                (short.free_vertices[rows, 1], vertex_ids),
            ]
        ):
            extend(source, columns_out[k][out], row_cut, extra, ids)
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


def chain_adjacency(shorts: list[sp.csr_matrix], ms: list[int], n_tri: int) -> sp.csr_matrix:
    """The connectivity matrix of chains of m_i sectors, repeated from short chains.

    ``shorts``: per chain, the matrix of its chain of :data:`CHAIN` sectors (as
    :func:`barymesh.topology.triangle_adjacency` makes it). Rows are repeated as the edges are in
    :func:`chain_topology`: a shift keeps each row's neighbours in ascending
    order, so the result is the matrix of the whole mesh, array for array.
    """
    import scipy.sparse as sp

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
        extend(np.diff(short.indptr).astype(INDEX), counts[rows], tri_cut, extra, None)
        cuts = short.indptr[tri_cut]
        triangle_ids = Ids(n_tri, tri_cut, t0)
        extend(short.indices.astype(INDEX), indices[i0 : i0 + n], cuts, extra, triangle_ids)
        i0, t0 = i0 + n, t0 + m * n_tri
    indptr = np.zeros(n_rows + 1, dtype=INDEX)
    np.cumsum(counts, out=indptr[1:])
    data = np.ones(len(indices), dtype=np.int8)
    return sp.csr_matrix((data, indices, indptr), shape=(n_rows, n_rows))


def sector_edge_counts(
    template: PatchTemplate,
    vertex_map: np.ndarray,
    n_vertices: int,
    chains: tuple[tuple[int, ...], tuple[bool, ...]] | None,
    patch_regions: np.ndarray,
) -> np.ndarray | None:
    """Edge counts by valence of chains of sectors, without sorting the glued edges.

    Chains of at least :data:`CHAIN` sectors (``chains`` from :func:`find_chains`)
    add up the counts of their short chains' sectors, as :func:`chain_topology`
    repeats them. Otherwise, closed rings of m_i ≥ 3 sectors (ring i the i-th
    run of equal ``patch_regions``) whose vertex map is exactly those chains',
    ring after ring, add the same edges per sector: Σ m_i / 3 times those of a
    closed chain of three sectors. The counts of
    :func:`barymesh.repeat.patches.patch_edge_counts`, as a bincount; None for
    anything else (touching, paper or renumbered rings).

    Parameters
    ----------
    template : PatchTemplate
    vertex_map : (P, Nv) int
    n_vertices : int
    chains : (sectors, closed) or None
    patch_regions : (P,) int
        The region of each patch.
    """
    if chains is not None:
        parts = chain_parts(template, *chains)
        counts = np.zeros(4, dtype=np.int64)
        for short, m in zip(parts.shorts, parts.sectors, strict=True):
            cut = np.searchsorted(short.edge_triangles[:, 0] // parts.n_tri, np.arange(CHAIN + 1))
            for lo, hi, times in (
                (0, MIDDLE, 1),
                (MIDDLE, MIDDLE + 1, m - CHAIN + 1),
                (MIDDLE + 1, CHAIN, 1),
            ):
                part = np.bincount(short.valence[cut[lo] : cut[hi]], minlength=4)
                counts[: len(part)] += times * part[:4]
        return counts[: max(3, len(np.trim_zeros(counts, "b")))]  # as a bincount
    n_p = len(vertex_map)
    if n_p == 0:
        return None
    nv = len(template.uv)
    starts = np.flatnonzero(np.r_[True, patch_regions[1:] != patch_regions[:-1]])
    sectors = np.diff(np.r_[starts, n_p]).tolist()  # sectors of each ring
    if min(sectors) < 3:
        return None
    s = len(template.sides[0])
    if n_vertices != n_p * (nv - s):
        return None
    ids, _ = sector_chain_vertices(template, sectors, [True] * len(starts))
    if not np.array_equal(vertex_map.ravel(), ids):
        return None
    chain3, _ = sector_chain_vertices(template, 3, [True])
    counts3 = patch_edge_counts(
        template.edges, template.valence, chain3.reshape(3, nv), 3 * (nv - s)
    )
    if (counts3 % 3).any():  # not one sector's worth three times: count them all
        return None
    return counts3 // 3 * np.int64(n_p)


def chain_valence(template: PatchTemplate, closed: tuple[bool, ...]) -> int:
    """Most triangles on one edge of chains of sectors numbered by formula.

    Every edge of a chain (:func:`find_chains`) is a shifted copy of an edge of
    the short chain its topology repeats, on as many triangles
    (:func:`chain_topology`): the short chains' largest valence is the mesh's.
    """
    return max(int(short_chain_topology(template, c).valence.max()) for c in closed)

"""Copies of a patch template glued by any vertex map: the general repeated path.

Patch p of a structure is the template with local vertex l at global vertex
``vertex_map[p, l]``; its triangles and template edges are the template's,
numbered on patch after patch::

    template (Nv vertices, Nt triangles, Ne edges)      patch p of P
    local vertex  l                           ->  global vertex  vertex_map[p, l]
    local triangle t                          ->  triangle       p Nt + t
    template edge  e                          ->  slot           p Ne + e

An edge can lie on triangles of two patches only when both its vertices are
shared with another patch (vertex multiplicity > 1); only those slots, a few
per patch on its glued sides, are matched globally by sorting, all others keep
their template incidence. The results equal the general paths over the
triangles (:func:`barymesh.topology.edge_topology`,
:func:`barymesh.invariants.inverted_or_flat`), array for array
(``tests/test_core_assembly.py``, ``tests/test_core_hostile.py``).
"""

from __future__ import annotations

import numpy as np

from ..invariants import flagged
from ..subdivision import PatchTemplate
from ..topology import BLOCK, INDEX, EdgeTopology, compress_pairs, edge_keys
from .compiled import axes_of, kernels
from .lattice import lattice_diagonal, lattice_flagged


def patch_triangles(template: PatchTemplate, vertex_map: np.ndarray) -> np.ndarray:
    """(P Nt, 3) global triangles from the (P, Nv) map of patch-local to global vertices."""
    return vertex_map.take(template.triangles.ravel(), axis=1).reshape(-1, 3)


def template_free_vertices(template: PatchTemplate) -> np.ndarray:
    """(Ne, 2) local vertex of ``template.edge_triangles[e, j]`` opposite edge e, -1 if none."""
    tri = template.triangles
    free = np.full((len(template.edges), 2), -1, dtype=INDEX)
    for j in (0, 1):
        t = template.edge_triangles[:, j]
        has = t >= 0
        # side k of a triangle joins its vertices k and k + 1; vertex k + 2 is opposite
        side = np.argmax(template.triangle_edges[t[has]] == np.flatnonzero(has)[:, None], axis=1)
        free[has, j] = tri[t[has], (side + 2) % 3]
    return free


def patch_topology(
    template: PatchTemplate, vertex_map: np.ndarray, n_vertices: int
) -> EdgeTopology:
    """Edges of the structure whose patch p has global vertices ``vertex_map[p]``.

    Parameters
    ----------
    template : PatchTemplate
    vertex_map : (P, Nv) int
    n_vertices : int

    Returns
    -------
    EdgeTopology
        Edges come patch by patch in template order; an edge shared by several
        patches appears once, where the first of them lists it. Free vertices
        are filled in.
    """
    vmap = np.ascontiguousarray(vertex_map, dtype=INDEX)
    n_patch = len(vmap)
    n_tri = len(template.triangles)
    n_loc = len(template.edges)
    n_slots = n_patch * n_loc  # (patch, template edge) pairs
    e0, e1 = template.edges[:, 0], template.edges[:, 1]
    local_tri = template.edge_triangles  # (Ne, 2)
    local_free = template_free_vertices(template)  # (Ne, 2)

    # Only edges with both ends shared with another patch can coincide across patches.
    shared = (np.bincount(vmap.ravel(), minlength=n_vertices) > 1)[vmap]  # (P, Nv)
    pool = np.flatnonzero(shared.take(e0, axis=1) & shared.take(e1, axis=1))  # slots p Ne + e

    # (take along an axis is much faster than fancy indexing on these 2-D arrays)
    ev0 = vmap.take(e0, axis=1)
    ev1 = vmap.take(e1, axis=1)
    edges: np.ndarray = np.empty((n_patch, n_loc, 2), dtype=INDEX)  # (P Ne, 2) once reshaped
    np.minimum(ev0, ev1, out=edges[..., 0])
    np.maximum(ev0, ev1, out=edges[..., 1])
    edges = edges.reshape(-1, 2)
    del ev0, ev1

    tri_base = (np.arange(n_patch, dtype=INDEX) * INDEX(n_tri))[:, None]  # (P, 1)
    edge_triangles: np.ndarray = np.empty((n_patch, n_loc, 2), dtype=INDEX)
    np.add(local_tri, tri_base[:, :, None], out=edge_triangles)
    np.copyto(edge_triangles, -1, where=local_tri < 0)  # column 0 always exists
    edge_triangles = edge_triangles.reshape(-1, 2)
    # local vertex Nv (a column of -1 appended to the map) stands for "no free vertex"
    padded = np.empty((n_patch, vmap.shape[1] + 1), dtype=INDEX)
    padded[:, :-1] = vmap
    padded[:, -1] = -1
    free_at = np.where(local_free < 0, vmap.shape[1], local_free).ravel()
    free_vertices = padded.take(free_at, axis=1).reshape(-1, 2)  # (P Ne, 2)
    del padded
    valence = np.tile(template.valence.astype(INDEX), n_patch)

    # Group the pooled slots by vertex pair; the first slot of a group is its edge.
    keys = edge_keys(edges[pool, 0], edges[pool, 1], n_vertices)
    order = np.argsort(keys, kind="stable")  # slots ascending within a group
    starts = np.ones(len(order), dtype=bool)
    starts[1:] = keys[order[1:]] != keys[order[:-1]]
    group = np.empty(len(pool), dtype=np.int64)
    group[order] = np.cumsum(starts) - 1
    first_slot = pool[order[starts]]  # (G,) the slot that keeps each pooled edge
    duplicate = pool[pool != first_slot[group]]

    # incidences (group, triangle, free vertex) of the pooled slots, by group then triangle
    pool_p, pool_e = np.divmod(pool, n_loc)
    parts: tuple[list[np.ndarray], list[np.ndarray], list[np.ndarray]] = ([], [], [])
    for j in (0, 1):  # one part per side j, then joined
        loc = local_tri[pool_e, j]
        has = loc >= 0
        parts[0].append(group[has])
        parts[1].append(loc[has] + pool_p[has] * n_tri)
        parts[2].append(vmap[pool_p[has], local_free[pool_e[has], j]])
    inc_group, inc_tri, inc_free = (np.concatenate(p) for p in parts)
    inc = np.lexsort((inc_tri, inc_group))
    inc_group, inc_tri, inc_free = inc_group[inc], inc_tri[inc], inc_free[inc]
    counts = np.bincount(inc_group, minlength=len(first_slot))
    start = np.cumsum(counts) - counts
    valence[first_slot] = counts
    edge_triangles[first_slot, 0] = inc_tri[start]
    free_vertices[first_slot, 0] = inc_free[start]
    two = counts >= 2
    edge_triangles[first_slot, 1] = -1
    free_vertices[first_slot, 1] = -1
    edge_triangles[first_slot[two], 1] = inc_tri[start[two] + 1]
    free_vertices[first_slot[two], 1] = inc_free[start[two] + 1]

    # number the kept slots
    triangle_slots = (
        template.triangle_edges[None]
        + (np.arange(n_patch, dtype=INDEX) * INDEX(n_loc))[:, None, None]
    )
    triangle_slots = triangle_slots.reshape(-1, 3)
    if len(duplicate):
        keep = np.ones(n_slots, dtype=bool)
        keep[duplicate] = False
        edge_of_slot = np.cumsum(keep, dtype=INDEX) - 1
        edge_of_slot[pool] = edge_of_slot[first_slot[group]]
        triangle_edges = edge_of_slot.take(triangle_slots)
        edges, edge_triangles = compress_pairs(edges, keep), compress_pairs(edge_triangles, keep)
        free_vertices, valence = compress_pairs(free_vertices, keep), valence[keep]
    else:
        edge_of_slot = None
        triangle_edges = triangle_slots
    junction = counts[inc_group] >= 3
    junction_edge = first_slot[inc_group[junction]]
    if edge_of_slot is not None:
        junction_edge = edge_of_slot[junction_edge]
    junction_incidence = np.stack([junction_edge, inc_tri[junction]], axis=1).astype(INDEX)
    return EdgeTopology(
        edges=edges,
        triangle_edges=triangle_edges,
        edge_triangles=edge_triangles,
        valence=valence,
        junction_incidence=junction_incidence.reshape(-1, 2),
        free_vertices=free_vertices,
    )


def patch_edge_counts(
    local_edges: np.ndarray, local_valence: np.ndarray, vertex_map: np.ndarray, n_vertices: int
) -> np.ndarray:
    """How many edges lie on 1, 2, 3, ... triangles in a structure of patch copies.

    The counts of :func:`barymesh.topology.edge_topology` (and of the template path in
    :func:`patch_topology`) without making any per-edge array: an edge with an end
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


def glued_edge_valence(template: PatchTemplate, vertex_map: np.ndarray, n_vertices: int) -> int:
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


def inverted_or_flat_patches(
    points: np.ndarray,
    vertex_map: np.ndarray,
    template_triangles: np.ndarray,
    columns: list[np.ndarray] | None = None,
) -> np.ndarray:
    """:func:`~barymesh.invariants.inverted_or_flat` of ``vertex_map[:, template_triangles]``.

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
            if lattice_flagged(x.take(vmap), y.take(vmap), n, diagonal):
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
        hit = np.flatnonzero(flagged(px, py, *(k[:size] for k in corners)))
        if len(hit):
            bad.append(hit + lo * n_tri)
    return np.concatenate(bad) if bad else np.empty(0, dtype=np.intp)


def _rows(corner: np.ndarray, nv: int, n_patches: int) -> np.ndarray:
    """Flat indices of template corner ``corner`` in each of ``n_patches`` rows of width nv."""
    return (np.arange(n_patches, dtype=np.intp)[:, None] * nv + corner[None, :]).ravel()


def patch_centroids(
    columns: list[np.ndarray],
    vertex_map: np.ndarray,
    template_triangles: np.ndarray,
    unwelded: bool = False,
) -> np.ndarray:
    """(P Nt, 3) barycentres of the triangles ``vertex_map[:, template_triangles]``.

    :attr:`barymesh.mesh.TriMesh.centroids` of those triangles bit for bit (the
    three corners added in the triangle's order, then divided by 3), read patch
    by patch: a block of patches' vertex coordinates is gathered once, (p, Nv),
    and the corners are taken along its rows with the template's (Nt,) corner
    indices. The general path gathers 3 T corners through index arrays of the
    mesh's size; this gathers P Nv coordinates (about T / 1.3 on a uniform
    template) and nothing at all for unwelded copies, whose patch p is rows
    p Nv … p Nv + Nv − 1 of each column.

    Parameters
    ----------
    columns : list of (V,) float64
        Contiguous x and y (and z) columns of the points; a column that is zero
        everywhere leaves zeros.
    vertex_map : (P, Nv) int
        Global vertex of each local vertex of each patch.
    template_triangles : (Nt, 3) int
        The template's triangles; triangle p Nt + t is patch p's triangle t.
    unwelded : bool
        Whether ``vertex_map`` is patch p's vertices p Nv … p Nv + Nv − 1 in
        order (:func:`barymesh.repeat.copies.is_unwelded_copies`): then read by slicing.
    """
    n_p, nv = vertex_map.shape
    n_tri = len(template_triangles)
    compiled = kernels(n_p * n_tri)
    if compiled is not None:  # the same sums, each centroid written once
        found = np.empty((n_p * n_tri, 3))
        padded, active = axes_of(columns)
        ids = np.ascontiguousarray(vertex_map, dtype=INDEX)
        local = np.ascontiguousarray(template_triangles, dtype=np.intp)
        compiled.centroids(*padded, active, ids, unwelded, nv, local, found)
        return found
    out = np.zeros((n_p, n_tri, 3))
    corners = [np.ascontiguousarray(template_triangles[:, k], dtype=np.intp) for k in range(3)]
    axes = [(a, x) for a, x in enumerate(columns) if np.logical_or.reduce(x)]  # x.any()
    rows = max(1, BLOCK // max(n_tri, 1))
    for lo in range(0, n_p, rows):
        vmap = None if unwelded else vertex_map[lo : lo + rows]
        for axis, x in axes:
            px = x.reshape(n_p, nv)[lo : lo + rows] if vmap is None else x.take(vmap)
            c = px.take(corners[0], axis=1)
            c += px.take(corners[1], axis=1)
            c += px.take(corners[2], axis=1)
            c /= 3.0
            out[lo : lo + rows, :, axis] = c
    return out.reshape(-1, 3)

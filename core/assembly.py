"""Edge topology of a structure made of template copies, without sorting all edges.

Each patch's edges and their triangles are known from the template. An edge
can coincide with an edge of another patch only if both its vertices are
shared with other patches (vertex multiplicity > 1); only those edges, a few
per patch on its glued sides, are matched globally by sorting. All others
keep their template incidence (and free vertices). The result equals
:func:`barymesh.topology.edge_topology` on the same triangles, up to edge order.
"""

from __future__ import annotations

import numpy as np

from .subdivision import PatchTemplate
from .topology import INDEX, EdgeTopology, compress_pairs, edge_keys


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
    # one part per side j, then joined
    inc_group: list[np.ndarray] | np.ndarray
    inc_tri: list[np.ndarray] | np.ndarray
    inc_free: list[np.ndarray] | np.ndarray
    inc_group, inc_tri, inc_free = [], [], []
    for j in (0, 1):
        loc = local_tri[pool_e, j]
        has = loc >= 0
        inc_group.append(group[has])
        inc_tri.append(loc[has] + pool_p[has] * n_tri)
        inc_free.append(vmap[pool_p[has], local_free[pool_e[has], j]])
    inc_group = np.concatenate(inc_group)
    inc_tri = np.concatenate(inc_tri)
    inc_free = np.concatenate(inc_free)
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

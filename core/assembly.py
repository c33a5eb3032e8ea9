"""Edge topology of a structure made of template copies, without sorting all edges.

Each patch's edges and their triangles are known from the template. An edge
can coincide with an edge of another patch only if both its vertices are
shared with other patches (vertex multiplicity > 1); only those edges, a few
per patch on its glued sides, are matched globally by sorting. All others
keep their template incidence. The result equals
:func:`core.topology.edge_topology` on the same triangles, up to edge order.
"""

from __future__ import annotations

import numpy as np

from .subdivision import PatchTemplate
from .topology import INDEX, EdgeTopology, edge_keys


def patch_triangles(template: PatchTemplate, vertex_map: np.ndarray) -> np.ndarray:
    """(P Nt, 3) global triangles from the (P, Nv) map of patch-local to global vertices."""
    return vertex_map[:, template.triangles].reshape(-1, 3)


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
        Edges that stay inside one patch come first (patch by patch), then
        the edges matched across patches.
    """
    n_patch = len(vertex_map)
    n_tri = len(template.triangles)
    n_loc = len(template.edges)
    multiplicity = np.bincount(vertex_map.ravel(), minlength=n_vertices)
    ev0 = vertex_map[:, template.edges[:, 0]]  # (P, Ne)
    ev1 = vertex_map[:, template.edges[:, 1]]
    shared = multiplicity > 1
    pool = shared[ev0] & shared[ev1]  # edges that may coincide across patches
    own = ~pool
    n_own = int(own.sum())

    edge_id = np.empty((n_patch, n_loc), dtype=INDEX)
    edge_id[own] = np.arange(n_own, dtype=INDEX)
    pool_p, pool_e = np.nonzero(pool)
    keys = edge_keys(ev0[pool_p, pool_e], ev1[pool_p, pool_e], n_vertices)
    uniq, group = np.unique(keys, return_inverse=True)
    group = group.ravel().astype(INDEX)
    edge_id[pool_p, pool_e] = n_own + group
    n_edges = n_own + len(uniq)

    edges = np.empty((n_edges, 2), dtype=INDEX)
    a, b = ev0[own], ev1[own]
    edges[:n_own, 0] = np.minimum(a, b)
    edges[:n_own, 1] = np.maximum(a, b)
    edges[n_own:, 0] = uniq // n_vertices
    edges[n_own:, 1] = uniq % n_vertices

    triangle_edges = edge_id[:, template.triangle_edges].reshape(-1, 3)

    tri_base = (np.arange(n_patch, dtype=INDEX) * n_tri)[:, None]  # (P, 1)
    edge_triangles = np.full((n_edges, 2), -1, dtype=INDEX)
    valence = np.empty(n_edges, dtype=INDEX)
    own_p, own_e = np.nonzero(own)
    local = template.edge_triangles[own_e]  # (n_own, 2)
    edge_triangles[:n_own] = np.where(local >= 0, local + tri_base[own_p], -1)
    valence[:n_own] = template.valence[own_e]

    # incidences of the pooled edges: (edge, triangle) for each template triangle on them
    inc_edge, inc_tri = [], []
    for col in (0, 1):
        loc = template.edge_triangles[pool_e, col]
        has = loc >= 0
        inc_edge.append(n_own + group[has])
        inc_tri.append(loc[has] + pool_p[has] * n_tri)
    inc_edge = np.concatenate(inc_edge)
    inc_tri = np.concatenate(inc_tri).astype(INDEX)
    order = np.lexsort((inc_tri, inc_edge))
    inc_edge, inc_tri = inc_edge[order], inc_tri[order]
    counts = np.bincount(inc_edge - n_own, minlength=len(uniq)).astype(INDEX)
    valence[n_own:] = counts
    start = np.cumsum(counts) - counts
    pooled = np.arange(n_own, n_edges)
    edge_triangles[pooled, 0] = inc_tri[start]
    two = counts >= 2
    edge_triangles[pooled[two], 1] = inc_tri[start[two] + 1]
    junction = valence[inc_edge] >= 3
    junction_incidence = np.stack([inc_edge[junction], inc_tri[junction]], axis=1)
    return EdgeTopology(
        edges=edges,
        triangle_edges=triangle_edges,
        edge_triangles=edge_triangles,
        valence=valence,
        junction_incidence=junction_incidence.astype(INDEX).reshape(-1, 2),
    )

"""Small shared checks for the core tests."""

import numpy as np

from core import MeshParams, build_mesh
from core.topology import edge_topology


def signed_areas(mesh):
    p = mesh.points[mesh.triangles]
    d1, d2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    return 0.5 * (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])


def edge_sets(edges, valence):
    """{(v0, v1): valence} of an edge table."""
    return {tuple(e): int(v) for e, v in zip(edges.tolist(), valence.tolist(), strict=True)}


def assert_topology_matches_generic(mesh):
    """The template fast path equals the general half-edge sort on the same triangles."""
    fast = mesh.topology
    slow = edge_topology(mesh.triangles, mesh.n_vertices)
    assert edge_sets(fast.edges, fast.valence) == edge_sets(slow.edges, slow.valence)
    # each triangle side maps to the same vertex pair in both
    assert np.array_equal(fast.edges[fast.triangle_edges], slow.edges[slow.triangle_edges])

    # same triangles on each edge
    def incidence(topo):
        pairs = zip(topo.edges.tolist(), topo.edge_triangles.tolist(), strict=True)
        return {tuple(e): tuple(t) for e, t in pairs}

    assert incidence(fast) == incidence(slow)


def components(mesh):
    """Connected components of the triangles through shared vertices."""
    from scipy.sparse.csgraph import connected_components

    return connected_components(mesh.vertex_adjacency, directed=False)[0]


def canonical_meshes():
    """Tiny meshes that cover one region, two regions and disjoint paper-mode patches."""
    return {
        "patch": build_mesh(MeshParams(structure="patch", patch_size=10.0, origin=(-5, -5))),
        "double-ring": build_mesh(
            MeshParams(
                structure="double_ring",
                mode="conforming",
                inner_radius=2.0,
                outer_radius=3.5,
                patch_size=1.0,
                angle_step=60.0,
                subdivisions=2,
            )
        ),
        "paper-ring": build_mesh(
            MeshParams(structure="ring", inner_radius=4.0, angle_step=90.0, subdivisions=2)
        ),
    }

"""The template fast path of the topology equals the general half-edge sort, junctions included.

Patches are glued side to side by their vertex map, as the structures do; here several
patches may be glued onto the same side of one patch, so an edge can lie on three or more
triangles (a junction), which no built structure produces on purpose.
"""

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from barymesh.repeat import patch_topology, patch_triangles
from barymesh.subdivision import patch_template
from barymesh.topology import INDEX, edge_topology


@st.composite
def glued_patches(draw):
    """(template, vertex_map (P, Nv), n_vertices): patches glued onto earlier patches' sides.

    Patch k > 0 glues one of its four sides (either way round) onto a side of an earlier
    patch, or stays apart; its other vertices are new, so no triangle loses a vertex.
    """
    template = patch_template(
        draw(st.sampled_from(["uniform", "barycentric"])),
        draw(st.integers(1, 2)),
        draw(st.sampled_from(["AD", "BC"])),
    )
    n_local = len(template.uv)
    n_patch = draw(st.integers(2, 5))
    vmap = np.empty((n_patch, n_local), dtype=np.int64)
    vmap[0] = np.arange(n_local)
    next_id = n_local
    for k in range(1, n_patch):
        vmap[k] = np.arange(next_id, next_id + n_local)
        next_id += n_local
        if draw(st.booleans()) or k == 1:
            target = draw(st.integers(0, k - 1))
            mine, theirs = draw(st.integers(0, 3)), draw(st.integers(0, 3))
            glued = vmap[target, template.sides[theirs]]
            if draw(st.booleans()):
                glued = glued[::-1]
            vmap[k, template.sides[mine]] = glued
    # number the used vertices 0..V-1 in a random order
    used = np.unique(vmap)
    relabel = np.empty(used.max() + 1, dtype=np.int64)
    relabel[used] = np.array(draw(st.permutations(range(len(used)))))
    return template, relabel[vmap], len(used)


def by_vertex_pair(topo):
    """{(v0, v1): (valence, triangles on the edge, free vertices)}, independent of edge order."""
    out = {}
    for e, (a, b) in enumerate(topo.edges.tolist()):
        tris = topo.edge_triangles[e].tolist()
        out[(a, b)] = (int(topo.valence[e]), tris, topo.free_vertices[e].tolist())
    junctions = {}
    for e, t in topo.junction_incidence.tolist():
        junctions.setdefault(tuple(topo.edges[e].tolist()), []).append(t)
    return out, {k: sorted(v) for k, v in junctions.items()}


@given(glued_patches())
def test_template_path_equals_the_half_edge_sort(case):
    template, vmap, n_vertices = case
    fast = patch_topology(template, vmap, n_vertices)
    slow = edge_topology(patch_triangles(template, vmap), n_vertices)
    assert by_vertex_pair(fast) == by_vertex_pair(slow)
    assert np.array_equal(fast.edges[fast.triangle_edges], slow.edges[slow.triangle_edges])
    assert fast.junction_incidence.shape[1] == 2
    for name in (
        "edges",
        "triangle_edges",
        "edge_triangles",
        "valence",
        "junction_incidence",
        "free_vertices",
    ):
        assert getattr(fast, name).dtype == INDEX, name


def test_three_patches_on_one_side_make_junctions():
    """Patches 1 and 2 both glued onto side 0 of patch 0: that side's n edges carry 3 triangles."""
    template = patch_template("uniform", 2, "AD")
    n_local = len(template.uv)
    vmap = np.arange(3 * n_local).reshape(3, n_local)
    vmap[1, template.sides[2]] = vmap[0, template.sides[0]]
    vmap[2, template.sides[0]] = vmap[0, template.sides[0]]
    used, vmap = np.unique(vmap, return_inverse=True)
    vmap = vmap.reshape(3, n_local)
    fast = patch_topology(template, vmap, len(used))
    assert (fast.valence >= 3).sum() == 2 and fast.valence.max() == 3
    assert len(fast.junction_incidence) == 6
    slow = edge_topology(patch_triangles(template, vmap), len(used))
    assert by_vertex_pair(fast) == by_vertex_pair(slow)


def test_patches_sharing_nothing_keep_their_template_topology():
    template = patch_template("uniform", 3, "BC")
    n_local = len(template.uv)
    vmap = np.arange(2 * n_local).reshape(2, n_local)
    fast = patch_topology(template, vmap, 2 * n_local)
    assert len(fast.edges) == 2 * len(template.edges)
    assert len(fast.junction_incidence) == 0
    assert by_vertex_pair(fast) == by_vertex_pair(
        edge_topology(patch_triangles(template, vmap), 2 * n_local)
    )
    for name in (
        "edges",
        "triangle_edges",
        "edge_triangles",
        "valence",
        "junction_incidence",
        "free_vertices",
    ):
        assert getattr(fast, name).dtype == INDEX, name

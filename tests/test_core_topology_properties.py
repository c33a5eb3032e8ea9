"""The general topology path on meshes with junctions, against plain-Python references.

Imported meshes can have an edge on three or more triangles (a junction). Such a mesh goes
through :func:`barymesh.topology.edge_topology` and the general branch of
:func:`barymesh.topology.triangle_adjacency`; here every one of them also has an interior edge,
so both the junction pairs and the interior pairs of the connectivity matrix are exercised.
References: an edge -> triangles dict built by plain Python (``tests.helpers``) and trimesh's
``face_adjacency`` (edges on exactly two faces).
"""

from dataclasses import replace

import numpy as np
import pytest
import trimesh
from helpers import junction_meshes, reference_connectivity, reference_edge_triangles
from hypothesis import given
from hypothesis import strategies as st

from barymesh import MeshParams, TriMesh, build_mesh
from barymesh.topology import BLOCK, INDEX, edge_topology, rwg_table, triangle_adjacency


def assert_index_dtypes(topo):
    """Every index array of a topology has the one index dtype."""
    for name in (
        "edges",
        "triangle_edges",
        "edge_triangles",
        "valence",
        "junction_incidence",
        "free_vertices",
    ):
        assert getattr(topo, name).dtype == INDEX, name


def imported(points, triangles):
    n = len(triangles)
    return TriMesh(points, triangles, np.zeros(n), np.ones(n), 1, mode="imported")


def test_junction_next_to_an_interior_edge_by_hand():
    """Triangles 0, 1, 2 on edge (0, 1) (a junction); triangle 3 shares edge (1, 2) with 0.

    Triangle 0 is connected to all three others, 1 and 2 only to each other and to 0, 3 only
    to 0: the matrix is symmetric although the interior pair (0, 3) is listed once.
    """
    tris = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4], [2, 1, 5]])
    topo = edge_topology(tris, 6)
    junction = topo.edges.tolist().index([0, 1])
    interior = topo.edges.tolist().index([1, 2])
    assert topo.valence[junction] == 3 and topo.valence[interior] == 2
    assert topo.interior_edges.tolist() == [interior]
    assert topo.junction_incidence.tolist() == [[junction, 0], [junction, 1], [junction, 2]]
    assert topo.edge_triangles[interior].tolist() == [0, 3]
    assert topo.free_vertices[interior].tolist() == [0, 5]
    adj = triangle_adjacency(4, topo).toarray()
    assert adj.tolist() == [[0, 1, 1, 1], [1, 0, 1, 0], [1, 1, 0, 0], [1, 0, 0, 0]]
    assert adj.dtype == np.int8


def test_two_triangles_sharing_two_edges_are_connected_once():
    """A degenerate pair (the same triangle twice, reversed) goes through the general branch."""
    tris = np.array([[0, 1, 2], [0, 2, 1]])
    topo = edge_topology(tris, 3)
    assert topo.valence.tolist() == [2, 2, 2]
    assert triangle_adjacency(2, topo).toarray().tolist() == [[0, 1], [1, 0]]


@given(junction_meshes())
def test_edges_and_incidence_match_a_plain_python_table(mesh):
    points, tris = mesh
    topo = edge_topology(tris, len(points))
    ref = reference_edge_triangles(tris)
    edges = [tuple(e) for e in topo.edges.tolist()]
    assert edges == sorted(ref)
    assert topo.valence.tolist() == [len(ref[e]) for e in edges]
    assert topo.edge_triangles.tolist() == [(ref[e] + [-1])[:2] for e in edges]
    assert topo.junction_incidence.tolist() == [
        [i, t] for i, e in enumerate(edges) if len(ref[e]) >= 3 for t in ref[e]
    ]
    # side k of every triangle is the edge from its vertex k to vertex k + 1
    sides = np.sort(np.stack([tris, np.roll(tris, -1, axis=1)], axis=-1), axis=-1)
    assert np.array_equal(topo.edges[topo.triangle_edges], sides)
    # the free vertex of each listed triangle is its vertex off the edge, -1 for no triangle
    for i, (a, b) in enumerate(edges):
        for j, t in enumerate(topo.edge_triangles[i]):
            if t >= 0:
                assert set(tris[t].tolist()) - {a, b} == {topo.free_vertices[i, j]}
            else:
                assert topo.free_vertices[i, j] == -1
    assert_index_dtypes(topo)


@given(junction_meshes())
def test_connectivity_is_symmetric_and_equals_the_reference(mesh):
    points, tris = mesh
    m = imported(points, tris)
    assert m.stats()["junction_edges"] >= 1 and m.stats()["interior_edges"] >= 1
    c = m.connectivity
    assert (c != c.T).nnz == 0
    coo = c.tocoo()
    assert set(zip(coo.row.tolist(), coo.col.tolist(), strict=True)) == reference_connectivity(tris)
    assert c.nnz == len(reference_connectivity(tris))
    assert set(np.unique(c.data).tolist()) == {1}


@given(junction_meshes())
def test_rwg_pairs_are_trimesh_face_adjacency(mesh):
    """trimesh pairs faces only across edges on exactly two faces: our RWG functions."""
    points, tris = mesh
    m = imported(points, tris)
    tm = trimesh.Trimesh(points, tris, process=False)
    theirs = {tuple(sorted(p)) for p in tm.face_adjacency.tolist()}
    ours = set(zip(m.rwg.t_plus.tolist(), m.rwg.t_minus.tolist(), strict=True))
    # trimesh keeps one pair for two faces sharing several edges; we keep one function per edge
    assert ours == theirs
    assert (m.rwg.t_plus < m.rwg.t_minus).all()
    ref = reference_edge_triangles(tris)
    assert {tuple(v) for v in m.rwg.vertices.tolist()} == {e for e, t in ref.items() if len(t) == 2}
    # every RWG pair is in the connectivity matrix, both ways
    c = m.connectivity
    assert (c[m.rwg.t_plus, m.rwg.t_minus] == 1).all()
    assert (c[m.rwg.t_minus, m.rwg.t_plus] == 1).all()


# -- manifold meshes in any triangle order (the row-by-row connectivity path) --------------


@st.composite
def shuffled_meshes(draw):
    """(points, triangles) of a small built mesh with its triangles shuffled and rotated.

    Without junctions the connectivity is built row by row; a shuffle puts triangles that do
    not touch at any pair of indices (0 and 1 in particular), and boundary edges anywhere.
    """
    params = draw(
        st.sampled_from(
            [
                MeshParams(structure="patch", subdivisions=1),
                MeshParams(structure="patch", subdivisions=3, diagonal="AD"),
                MeshParams(structure="triangle", subdivisions=3),
                MeshParams(structure="ring", mode="conforming", angle_step=45, subdivisions=1),
                MeshParams(angle_step=45, subdivisions=1),  # paper double ring: many pieces
            ]
        )
    )
    mesh = build_mesh(params)
    order = np.array(draw(st.permutations(range(mesh.n_triangles))))
    tris = np.roll(mesh.triangles[order], draw(st.integers(0, 2)), axis=1)
    return mesh.points, tris


@given(shuffled_meshes())
def test_connectivity_without_junctions_equals_the_reference(mesh):
    points, tris = mesh
    m = imported(points, tris)
    assert m.stats()["junction_edges"] == 0
    c = m.connectivity
    coo = c.tocoo()
    pairs = set(zip(coo.row.tolist(), coo.col.tolist(), strict=True))
    assert pairs == reference_connectivity(tris)
    assert c.nnz == len(pairs) == 2 * m.stats()["interior_edges"]
    assert c.dtype == np.int8 and set(np.unique(c.data).tolist()) == {1}
    # the row-by-row CSR has sorted column indices, as scipy's own constructors give
    assert c.has_sorted_indices and all(
        np.all(np.diff(c.indices[c.indptr[i] : c.indptr[i + 1]]) > 0) for i in range(len(tris))
    )


@pytest.mark.parametrize("with_junction", [False, True])
def test_rwg_table_finds_free_vertices_when_the_topology_has_none(with_junction):
    """The fallback of rwg_table (a topology without free vertices) gives the same table."""
    if with_junction:
        points = np.random.default_rng(1).random((6, 3))
        mesh = imported(points, np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4], [2, 1, 5]]))
    else:
        mesh = build_mesh(MeshParams(structure="double_ring", mode="conforming", angle_step=30))
    bare = replace(mesh.topology, free_vertices=None)
    table = rwg_table(mesh.points, mesh.triangles, bare)
    for name in (
        "edge",
        "vertices",
        "t_plus",
        "t_minus",
        "free_vertex_plus",
        "free_vertex_minus",
        "length",
    ):
        assert np.array_equal(getattr(table, name), getattr(mesh.rwg, name)), name
    assert len(table) == mesh.stats()["interior_edges"] > 0


def test_vertex_adjacency_counts_unused_vertices():
    """An imported file may list vertices no triangle uses: the matrix is still V x V."""
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [5, 5, 0.0]])
    mesh = imported(points, np.array([[0, 1, 2], [1, 3, 2]]))
    a = mesh.vertex_adjacency
    assert a.shape == (5, 5) and a.nnz == 2 * 5
    assert a.dtype == np.int8
    assert a[4].nnz == 0 and a[1, 2] == a[2, 1] == 1 and a[0, 3] == 0


@pytest.mark.parametrize("with_junction", [False, True])
def test_connectivity_is_t_by_t_when_the_last_triangle_is_alone(with_junction):
    """A last triangle with no neighbour still has its row and column (both code paths)."""
    tris = [[0, 1, 2], [2, 1, 3], [6, 7, 8]]
    if with_junction:
        tris[2:2] = [[1, 2, 4], [2, 1, 5]]  # edge (1, 2) on four triangles
    points = np.random.default_rng(2).random((9, 3))
    m = imported(points, np.array(tris))
    assert (m.stats()["junction_edges"] > 0) == with_junction
    assert m.connectivity.shape == (len(tris), len(tris))
    assert m.connectivity[len(tris) - 1].nnz == 0
    assert_index_dtypes(m.topology)
    assert m.rwg.edge.dtype == m.rwg.t_plus.dtype == m.rwg.free_vertex_minus.dtype == INDEX


def test_connectivity_across_blocks_of_triangles():
    """More triangles than one block of the row-by-row path: rows past the first block."""
    # r = 12 mm: 72 sectors of 5° (1.09 mm at mid track) are square n x n cells, n = 22:
    # 69,696 triangles
    mesh = build_mesh(
        MeshParams(
            structure="ring", mode="conforming", inner_radius=12, angle_step=5, subdivisions=22
        )
    )
    assert mesh.n_triangles > BLOCK
    topo = mesh.topology
    inner = topo.edge_triangles[topo.valence == 2]
    pairs = np.concatenate([inner, inner[:, ::-1]])  # both ways round each interior edge
    c = mesh.connectivity.tocoo()
    got = np.stack([c.row, c.col], axis=1)
    assert np.array_equal(np.unique(got, axis=0), np.unique(pairs, axis=0))
    assert c.nnz == len(pairs) == 2 * len(mesh.interior_edges)

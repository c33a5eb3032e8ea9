"""Edges, RWG table and connectivity, checked against trimesh and by hand."""

import numpy as np
import pytest
import trimesh

from barymesh import MeshParams, TriMesh, build_mesh
from barymesh.topology import edge_topology, triangle_adjacency

STRUCTURES = [
    {"structure": "patch"},
    {"structure": "patch", "subdivisions": 3, "diagonal": "AD"},
    {"angle_step": 20},
    {"structure": "ring", "mode": "conforming", "angle_step": 10},
    {"structure": "double_ring", "mode": "conforming", "angle_step": 10, "subdivisions": 2},
    {"structure": "split_ring", "mode": "conforming", "angle_step": 15},
    {"structure": "split_double_ring", "mode": "conforming", "angle_step": 15},
    {"structure": "square_split_double_ring", "mode": "paper"},
    {"structure": "square_split_double_ring", "mode": "conforming"},
    {"structure": "triangle", "subdivisions": 5},
]


@pytest.mark.parametrize("kw", STRUCTURES, ids=lambda kw: "-".join(map(str, kw.values())))
def test_shared_edges_agree_with_trimesh(kw):
    mesh = build_mesh(MeshParams(**kw))
    tm = trimesh.Trimesh(mesh.points, mesh.triangles, process=False)
    pairs = {tuple(sorted(p)) for p in tm.face_adjacency.tolist()}
    shared_edges = {tuple(sorted(e)) for e in tm.face_adjacency_edges.tolist()}
    ours_pairs = {(int(a), int(b)) for a, b in zip(mesh.rwg.t_plus, mesh.rwg.t_minus, strict=True)}
    assert ours_pairs == pairs
    assert {tuple(e) for e in mesh.rwg.vertices.tolist()} == shared_edges
    assert len(mesh.interior_edges) == len(tm.face_adjacency)
    # the connectivity matrix holds exactly these pairs, both ways
    c = mesh.connectivity.tocoo()
    assert {(int(i), int(j)) for i, j in zip(c.row, c.col, strict=True) if i < j} == pairs
    assert mesh.connectivity.nnz == 2 * len(mesh.interior_edges)
    assert (mesh.connectivity != mesh.connectivity.T).nnz == 0
    assert set(np.unique(mesh.connectivity.data)) == {1}


@pytest.mark.parametrize("kw", STRUCTURES, ids=lambda kw: "-".join(map(str, kw.values())))
def test_rwg_table_follows_makarov_convention(kw):
    mesh = build_mesh(MeshParams(**kw))
    rwg = mesh.rwg
    assert (rwg.t_plus < rwg.t_minus).all()
    for t, free in ((rwg.t_plus, rwg.free_vertex_plus), (rwg.t_minus, rwg.free_vertex_minus)):
        tri = mesh.triangles[t]
        # the edge's two vertices are in the triangle, the free vertex is the third one
        assert ((tri == rwg.vertices[:, :1]).any(1) & (tri == rwg.vertices[:, 1:]).any(1)).all()
        assert (tri == free[:, None]).any(1).all()
        assert ((free != rwg.vertices[:, 0]) & (free != rwg.vertices[:, 1])).all()
    expect = np.linalg.norm(
        mesh.points[rwg.vertices[:, 0]] - mesh.points[rwg.vertices[:, 1]], axis=1
    )
    assert np.allclose(rwg.length, expect)
    # f_n = l / (2 A±) ρ± has unit normal component on edge n from both sides (no charge
    # piles up on the edge): l h± / (2 A±) = 1, with h± the distance of the free vertex from
    # the edge's line, found here by projection, independently of the mesh's areas
    a, b = mesh.points[rwg.vertices[:, 0]], mesh.points[rwg.vertices[:, 1]]
    along = (b - a) / rwg.length[:, None]
    for t, free in ((rwg.t_plus, rwg.free_vertex_plus), (rwg.t_minus, rwg.free_vertex_minus)):
        rho = mesh.points[free] - a
        height = np.linalg.norm(rho - (rho * along).sum(1)[:, None] * along, axis=1)
        assert np.allclose(rwg.length * height / (2 * mesh.areas[t]), 1.0)


def test_paper_fig10_connectivity_matrix_rows():
    """Eq. 27: each triangle of the 32 connects to 1..3 others; corner triangles to one."""
    mesh = build_mesh(MeshParams(structure="patch", patch_size=10.0))
    degree = np.asarray(mesh.connectivity.sum(axis=1)).ravel()
    assert degree.min() == 1 and degree.max() == 3
    # the two corner triangles at A and D have a single neighbour
    assert (degree == 1).sum() == 2
    assert degree.sum() == 80


def test_junction_edges_are_reported_not_dropped():
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1.0]])
    tris = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    mesh = TriMesh(points, tris, np.zeros(3), np.ones(3), 1, mode="imported")
    s = mesh.stats()
    assert (s["edges"], s["junction_edges"], s["interior_edges"], s["boundary_edges"]) == (
        7,
        1,
        0,
        6,
    )
    junction = mesh.junction_edges[0]
    assert mesh.edges[junction].tolist() == [0, 1]
    assert mesh.topology.valence[junction] == 3
    assert mesh.topology.junction_incidence.tolist() == [
        [junction, 0],
        [junction, 1],
        [junction, 2],
    ]
    assert len(mesh.rwg) == 0  # no RWG function on a junction
    # the three triangles at the junction are all connected to each other
    assert mesh.connectivity.toarray().tolist() == [[0, 1, 1], [1, 0, 1], [1, 1, 0]]


def test_generic_edge_topology_by_hand():
    topo = edge_topology(np.array([[0, 1, 2], [2, 1, 3]]), 4)
    assert topo.edges.tolist() == [[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]]
    assert topo.valence.tolist() == [1, 1, 2, 1, 1]
    assert topo.edge_triangles.tolist() == [[0, -1], [0, -1], [0, 1], [1, -1], [1, -1]]
    assert topo.triangle_edges.tolist() == [[0, 2, 1], [2, 3, 4]]
    adj = triangle_adjacency(2, topo)
    assert adj.toarray().tolist() == [[0, 1], [1, 0]]


def test_vertex_adjacency_matches_edges():
    mesh = build_mesh(MeshParams(structure="patch"))
    a = mesh.vertex_adjacency
    assert a.shape == (25, 25) and a.nnz == 2 * 56
    assert (a != a.T).nnz == 0


def test_quality_of_the_paper_patch():
    mesh = build_mesh(MeshParams(structure="patch", patch_size=10.0))
    # right isosceles sub-triangles: 45° minimum angle, equal areas 100 / 32
    assert np.allclose(mesh.min_angles, 45.0)
    assert np.allclose(mesh.areas, 100 / 32)
    # l_max (l0 + l1 + l2) / (4 √3 A) of a right isosceles triangle is (√2 + 1) / √3
    assert np.allclose(mesh.aspect_ratios, (np.sqrt(2) + 1) / np.sqrt(3))
    s = mesh.stats()
    assert s["min_edge"] == pytest.approx(2.5) and s["max_edge"] == pytest.approx(2.5 * np.sqrt(2))


def test_mesh_arrays_are_read_only():
    mesh = build_mesh(MeshParams(structure="patch"))
    with pytest.raises(ValueError):
        mesh.points[0, 0] = 1.0
    with pytest.raises(ValueError):
        mesh.centroids[0, 0] = 1.0

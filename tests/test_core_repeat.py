"""The repetition record: made once by the build, checked at the door, kept by transforms."""

import numpy as np
import pytest

from barymesh import MeshParams, TriMesh, build_mesh
from barymesh.cell import Lattice, PixelGrid, UnitCell, build_cell
from barymesh.repeat import CHAIN, Repetition, patch_triangles
from barymesh.subdivision import patch_template


@pytest.mark.parametrize(
    ("params", "kind"),
    [
        (MeshParams(), "copies"),  # Fig. 12(a): nothing welded
        (MeshParams(structure="patch", patch_size=10.0), "copies"),
        (MeshParams(structure="double_ring", mode="conforming"), "chains"),
        (MeshParams(structure="split_double_ring", mode="conforming"), "chains"),
        (MeshParams(structure="ring", mode="conforming", angle_step=120.0), "patches"),  # m = 3
        (MeshParams(structure="square_split_double_ring", mode="paper", patch_size=0.5), "patches"),
        (MeshParams(structure="double_ring", mode="conforming", outer_radius=5.0), "patches"),
    ],
)
def test_the_build_records_the_kind_of_repetition_and_keeps_its_vertex_map(params, kind):
    mesh = build_mesh(params)
    rep = mesh.repetition
    assert rep.kind == kind
    assert rep.n_patches == mesh.n_patches
    assert not rep.vertex_map.flags.writeable
    # the record's map is the one the triangles were made from
    assert np.array_equal(patch_triangles(rep.template, rep.vertex_map), mesh.triangles)
    if kind == "chains":
        assert sum(rep.sectors) == mesh.n_patches and min(rep.sectors) >= CHAIN
        assert len(rep.closed) == len(rep.sectors)
    else:
        assert rep.sectors == rep.closed == ()
    # read back from the triangles, the same map and the same kind
    again = Repetition.of_triangles(rep.template, mesh.triangles, mesh.n_vertices)
    assert np.array_equal(again.vertex_map, rep.vertex_map)
    assert (again.kind, again.sectors, again.closed) == (rep.kind, rep.sectors, rep.closed)


def test_a_single_triangle_and_an_imported_mesh_have_no_record():
    assert build_mesh(MeshParams(structure="triangle")).repetition is None
    pts = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    assert TriMesh(pts, [[0, 1, 2]], [0], [1], 1, mode="imported").repetition is None


def test_bad_records_are_refused_naming_what_is_wrong():
    t = patch_template("uniform", 2, "BC")  # 9 vertices, 8 triangles
    with pytest.raises(ValueError, match=r"shape \(P, 9\).*got \(2, 8\)"):
        Repetition.of(t, np.zeros((2, 8), dtype=int), 20)
    with pytest.raises(ValueError, match="refers to vertex 17 .* 10 vertices"):
        Repetition.of(t, np.arange(18).reshape(2, 9), 10)
    with pytest.raises(ValueError, match="not whole copies of a template of 8 triangles"):
        Repetition.of_triangles(t, np.zeros((12, 3), dtype=int), 9)
    flipped = patch_triangles(t, np.arange(9)[None])[:, [0, 2, 1]]
    with pytest.raises(ValueError, match="not copies of the template"):
        Repetition.of_triangles(t, flipped, 9)
    mesh = build_mesh(MeshParams(structure="patch"))
    with pytest.raises(ValueError, match="repetition has 1 patches of 32 triangles"):
        TriMesh(
            mesh.points, mesh.triangles, mesh.patch_ids, mesh.regions, 2, repetition=mesh.repetition
        )
    with pytest.raises(TypeError, match="repetition must be a Repetition, got PatchTemplate"):
        TriMesh(mesh.points, mesh.triangles, mesh.patch_ids, mesh.regions, 1, repetition=t)


@pytest.mark.parametrize(
    "params",
    [
        MeshParams(),
        MeshParams(structure="double_ring", mode="conforming"),
        MeshParams(structure="square_split_double_ring", mode="paper", patch_size=0.5),
        MeshParams(structure="split_ring", mode="conforming", frequency=10e9),
    ],
)
def test_stats_do_not_depend_on_what_is_cached(params):
    # the algorithm is chosen by the record: the same figures, bit for bit, whether the
    # topology and the quality were asked for first or not
    fresh = build_mesh(params).stats()
    used = build_mesh(params)
    _ = used.topology, used.quality, used.edge_lengths
    assert list(used.stats().items()) == list(fresh.items())


def test_scaling_keeps_the_record_the_floor_and_a_scaled_lattice():
    mesh = build_mesh(MeshParams(structure="split_ring", mode="conforming"))
    metres = mesh.scaled(1e-3)
    assert metres.repetition is mesh.repetition
    assert metres.min_angle_floor == mesh.min_angle_floor
    assert metres.params is None  # its lengths are the unscaled mesh's
    grid = PixelGrid(np.ones((2, 2)), origin=(-1, -1))
    cm = build_cell(UnitCell(Lattice.rectangular(2.0), pixels=grid))
    assert cm.mesh.repetition.kind == "patches"  # pixels on one grid of points
    half = cm.mesh.scaled(0.5)
    assert half.repetition is cm.mesh.repetition
    assert half.lattice.a1 == (1.0, 0.0) and half.lattice.a2 == (0.0, 1.0)
    pairs, scaled_pairs = cm.mesh.periodic_pairs, half.periodic_pairs
    assert scaled_pairs.matched and pairs.matched and len(pairs.edges) == 16
    assert np.array_equal(scaled_pairs.edges, pairs.edges)

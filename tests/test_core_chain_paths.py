"""Shortcuts taken for rings of sectors and grid patches give what the general paths give.

A conforming ring whose vertices are numbered by formula repeats the topology
of a short chain of sectors (``barymesh.repeat.chains.chain_topology``) and takes its
largest edge valence from that chain in the invariant check; grid patches
reduce their quality edge by edge (``barymesh.repeat.lattice_quality_summary``).
Each shortcut is compared with the general path, and defects planted in a mesh
that takes the shortcut must still be refused.
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from barymesh import MeshParams, TriMesh, build_mesh
from barymesh.check import check_mesh
from barymesh.invariants import MeshInvariantError, _point_keys, duplicate_vertices
from barymesh.quality import quality_summary, triangle_quality
from barymesh.repeat import (
    CHAIN,
    Repetition,
    chain_valence,
    lattice_diagonal,
    lattice_quality_summary,
    patch_topology,
)
from barymesh.stats import count_distinct
from barymesh.subdivision import tensor_template
from barymesh.topology import edge_topology, rwg_table, triangle_adjacency

TOPOLOGY_FIELDS = (
    "edges",
    "triangle_edges",
    "edge_triangles",
    "valence",
    "junction_incidence",
    "free_vertices",
)


def assert_same_topology(got, expect):
    for name in TOPOLOGY_FIELDS:
        a, b = getattr(got, name), getattr(expect, name)
        assert a.dtype == b.dtype, name
        assert np.array_equal(a, b), name


RWG_FIELDS = (
    "edge",
    "vertices",
    "t_plus",
    "t_minus",
    "free_vertex_plus",
    "free_vertex_minus",
    "length",
)


def assert_same_rwg(mesh):
    """The repeated RWG table and connectivity equal those gathered from the topology."""
    fresh = rebuilt(mesh)
    got = fresh.rwg  # before the topology: the repeated rows
    expect = rwg_table(mesh.points, mesh.triangles, mesh.topology)
    for name in RWG_FIELDS:
        a, b = getattr(got, name), getattr(expect, name)
        assert a.dtype == b.dtype and a.shape == b.shape, name
        assert np.array_equal(a, b), name
        assert a.flags.c_contiguous, name
    got = rebuilt(mesh).connectivity
    expect = triangle_adjacency(mesh.n_triangles, mesh.topology)
    assert got.shape == expect.shape and got.has_sorted_indices
    for name in ("data", "indices", "indptr"):
        a, b = getattr(got, name), getattr(expect, name)
        assert a.dtype == b.dtype and np.array_equal(a, b), name


def rebuilt(mesh, points=None, triangles=None):
    """The mesh with other points or triangles, same template (nothing cached)."""
    points = mesh.points if points is None else points
    triangles = mesh.triangles if triangles is None else triangles
    return TriMesh(
        points,
        triangles,
        mesh.patch_ids,
        mesh.regions,
        mesh.n_patches,
        mesh.mode,
        mesh.tolerance,
        mesh.patch_rects,
        repetition=copies_of(mesh.repetition.template, triangles, len(points)),
    )


def copies_of(template, triangles, n_vertices):
    """The repetition of triangles that are copies of ``template``'s (the map read back)."""
    return Repetition.of_triangles(template, triangles, n_vertices)


def chains_of(mesh):
    """(sectors, closed) when the mesh takes the chain paths, else None."""
    rep = mesh.repetition
    return (rep.sectors, rep.closed) if rep.kind == "chains" else None


def chain_valence_of(mesh):
    """The valence the invariant check takes from the short chains, None off the chain path."""
    rep = mesh.repetition
    return chain_valence(rep.template, rep.closed) if rep.kind == "chains" else None


def general_patch_topology(mesh):
    """The patch path (only the glued edges sorted) on the mesh's template and vertex map."""
    rep = mesh.repetition
    return patch_topology(rep.template, rep.vertex_map, mesh.n_vertices)


RINGS = [
    MeshParams(structure="ring", mode="conforming", angle_step=30.0, subdivisions=3),
    MeshParams(structure="double_ring", mode="conforming"),
    MeshParams(structure="double_ring", mode="conforming", subdivisions=2, diagonal="AD"),
    MeshParams(structure="double_ring", mode="conforming", scheme="barycentric", angle_step=9.0),
    MeshParams(structure="ring", mode="conforming", subdivisions=5, angle_step=72.0),  # m = 5
    MeshParams(structure="ring", mode="conforming", subdivisions=1, angle_step=3.0),  # no interior
    MeshParams(structure="split_ring", mode="conforming", angle_step=20.0),  # open chains
    MeshParams(structure="split_ring", mode="conforming", subdivisions=2, origin=(3.0, -1.0)),
    # the near-square sectors: n x n_v cells (sides 0 and 2 longer than sides 1 and 3),
    # as many sectors per ring as its track's length asks for (36 and 57 here, n_v = 5)
    MeshParams(
        structure="double_ring",
        mode="conforming",
        subdivisions=8,
        angle_step=10.0,
        inner_radius=3.0,
        outer_radius=6.0,
    ),
    # 36 and 108 sectors, n_v = 1: a free vertex across a glued side is two sectors on
    MeshParams(
        structure="double_ring",
        mode="conforming",
        subdivisions=3,
        angle_step=10.0,
        inner_radius=1.5,
        outer_radius=6.0,
        diagonal="AD",
    ),
    MeshParams(structure="split_double_ring", mode="conforming"),  # two arcs per ring
    MeshParams(structure="double_ring", mode="conforming", subdivisions=6, grading=True),
    MeshParams(structure="split_ring", mode="conforming", grading=True, min_edge=0.05),
]


@pytest.mark.parametrize("params", RINGS)
def test_chain_topology_equals_the_patch_topology_bit_for_bit(params):
    mesh = build_mesh(params)
    chains = chains_of(mesh)
    assert chains is not None  # rings of sectors numbered by formula: the shortcut is taken
    ms, closed = chains
    assert min(ms) >= CHAIN and sum(ms) == mesh.n_patches
    assert all(closed) == ("split" not in params.structure)
    assert not any(closed) or all(closed)
    expect = general_patch_topology(mesh)
    assert_same_topology(mesh.topology, expect)
    general = edge_topology(mesh.triangles, mesh.n_vertices)
    assert len(mesh.edges) == len(general.edges)
    assert np.array_equal(np.bincount(mesh.topology.valence), np.bincount(general.valence))
    # the RWG table and the connectivity read the repeated topology like any other
    assert len(mesh.rwg) == np.count_nonzero(general.valence == 2)
    assert (mesh.connectivity != mesh.connectivity.T).nnz == 0
    euler = mesh.n_vertices - len(mesh.edges) + mesh.n_triangles
    assert euler == sum(0 if c else 1 for c in closed)  # a closed ring 0, an arc 1
    assert_same_rwg(mesh)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    structure=st.sampled_from(["ring", "double_ring", "split_ring", "split_double_ring"]),
    angle_step=st.floats(3.0, 120.0),
    subdivisions=st.integers(1, 6),
    diagonal=st.sampled_from(["BC", "AD"]),
    scheme=st.sampled_from(["uniform", "barycentric"]),
    outer=st.floats(5.0, 9.0),
    inner=st.floats(1.0, 4.0),
    grading=st.booleans(),
)
def test_chain_topology_equals_the_patch_topology_on_random_rings(
    structure, angle_step, subdivisions, diagonal, scheme, outer, inner, grading
):
    try:
        params = MeshParams(
            structure=structure,
            mode="conforming",
            angle_step=angle_step,
            outer_radius=outer,
            inner_radius=inner,
            grading=grading and scheme == "uniform",
            subdivisions=min(subdivisions, 3) if scheme == "barycentric" else subdivisions,
            diagonal=diagonal,
            scheme=scheme,
            max_triangles=200_000,
        )
        mesh = build_mesh(params)
    except ValueError:
        assume(False)
    expect = general_patch_topology(mesh)
    assert_same_topology(mesh.topology, expect)
    assert_same_rwg(mesh)


@pytest.mark.parametrize(
    "params",
    [
        MeshParams(structure="ring", mode="conforming", angle_step=120.0),  # m = 3 < CHAIN
        MeshParams(structure="ring", mode="conforming", subdivisions=1, angle_step=90.0),  # m = 4
        MeshParams(structure="double_ring", mode="conforming", outer_radius=5.0),  # touching
        MeshParams(structure="double_ring", mode="paper", angle_step=30.0),
        MeshParams(structure="square_split_double_ring", mode="conforming"),
    ],
)
def test_other_layouts_take_the_general_topology(params):
    mesh = build_mesh(params)
    assert chains_of(mesh) is None
    expect = general_patch_topology(mesh)
    assert_same_topology(mesh.topology, expect)


def test_renumbered_vertices_take_the_general_topology():
    # vertices 0 and 1 swapped everywhere: the same mesh, no longer the formula's numbering
    mesh = build_mesh(MeshParams(structure="double_ring", mode="conforming", angle_step=20.0))
    swap = np.arange(mesh.n_vertices)
    swap[[0, 1]] = [1, 0]
    points = mesh.points[np.argsort(swap)]
    renumbered = rebuilt(mesh, points, swap[mesh.triangles])
    assert chains_of(renumbered) is None
    expect = general_patch_topology(renumbered)
    assert_same_topology(renumbered.topology, expect)
    assert renumbered.stats()["edges"] == mesh.stats()["edges"]


def test_a_scaled_formula_ring_keeps_its_chains_and_its_floor():
    # millimetres to metres: same numbering, so the same repeated topology; the floor kept
    mesh = build_mesh(MeshParams(structure="split_double_ring", mode="conforming"))
    metres = mesh.scaled(1e-3)
    assert metres.params is None and metres.min_angle_floor == mesh.min_angle_floor
    assert chains_of(metres) == chains_of(mesh) is not None
    assert metres.repetition is mesh.repetition  # no coordinates in it: kept as it is
    assert_same_topology(metres.topology, mesh.topology)
    got, expect = metres.stats(), mesh.stats()
    assert got["min_angle_floor_deg"] == expect["min_angle_floor_deg"]
    assert got["edges"] == expect["edges"] and got["min_edge"] == pytest.approx(
        expect["min_edge"] * 1e-3, rel=1e-12
    )


# -- defects planted in meshes of the formula path are still refused ------------------


def ring_params():
    return MeshParams(structure="double_ring", mode="conforming", angle_step=20.0)


def test_the_invariant_check_takes_the_chain_valence_of_a_formula_ring():
    mesh = build_mesh(ring_params())
    assert chain_valence_of(mesh) == 2
    check_mesh(rebuilt(mesh), ring_params())


def test_two_rings_laid_on_each_other_are_refused_as_duplicate_vertices():
    # the outer ring moved onto the inner one: numbering by formula, every triangle
    # counter-clockwise, but every outer vertex at the same point as an inner one
    p = MeshParams(structure="double_ring", mode="conforming", angle_step=20.0, outer_radius=7.0)
    mesh = build_mesh(p)
    half = mesh.n_vertices // 2
    points = mesh.points.copy()
    points[half:] = points[:half]
    stacked = rebuilt(mesh, points)
    assert chains_of(stacked) is not None  # still the formula path
    # (the check looks among the vertices on the sectors' sides, where sectors are glued)
    sides = mesh.repetition.vertex_map[:, mesh.repetition.template.side_vertices]
    on_sides = len(np.unique(sides[sides < half]))
    with pytest.raises(MeshInvariantError, match=f"has {on_sides:,} vertices at the same point"):
        check_mesh(stacked, p)


def test_a_sector_glued_twice_is_refused_as_a_junction():
    # one more sector on the same vertices as sector 0: its edges on 4 triangles; the
    # vertex map is no longer the formula's, so the valence is counted in general
    mesh = build_mesh(MeshParams(structure="ring", mode="conforming", angle_step=30.0))
    per = len(mesh.repetition.template.triangles)
    triangles = np.vstack([mesh.triangles, mesh.triangles[:per]])
    twice = TriMesh(
        mesh.points,
        triangles,
        np.r_[mesh.patch_ids, mesh.patch_ids[:per]],
        np.r_[mesh.regions, mesh.regions[:per]],
        mesh.n_patches + 1,
        mesh.mode,
        repetition=copies_of(mesh.repetition.template, triangles, mesh.n_vertices),
    )
    assert chains_of(twice) is None and chain_valence_of(twice) is None
    with pytest.raises(MeshInvariantError, match="edges on 4 triangles"):
        check_mesh(twice, ring_params())


def test_a_sector_glued_to_a_third_neighbour_is_refused_as_a_junction():
    # a copy of sector 1 on new vertices a hair (1e-9) further out, but for its side 0,
    # which stays sector 0's side 2: those edges on 3 triangles, no two points equal
    mesh = build_mesh(MeshParams(structure="ring", mode="conforming", angle_step=30.0))
    t = mesh.repetition.template
    vmap = mesh.repetition.vertex_map
    extra = mesh.n_vertices + np.arange(len(t.uv))
    extra[t.sides[0]] = vmap[1, t.sides[0]]
    points = np.vstack([mesh.points, mesh.points[vmap[1]] * (1 + 1e-9)])
    vmap3 = np.vstack([vmap, extra])
    per = len(t.triangles)
    third = TriMesh(
        points,
        vmap3[:, t.triangles].reshape(-1, 3),
        np.r_[mesh.patch_ids, np.full(per, 12)],
        np.r_[mesh.regions, mesh.regions[:per]],
        mesh.n_patches + 1,
        mesh.mode,
        repetition=Repetition.of(t, vmap3, len(points)),
    )
    assert chains_of(third) is None  # not the formula: the valence is counted
    with pytest.raises(MeshInvariantError, match="edges on 3 triangles"):
        check_mesh(third, ring_params())


@pytest.mark.parametrize(
    ("plant", "message"),
    [
        (lambda pts: pts.__setitem__((5, 0), np.nan), "not finite"),
        (lambda pts: pts.__setitem__((slice(None), 1), -pts[:, 1]), "clockwise or flat"),
        (lambda pts: pts.__setitem__((slice(None), 1), pts[:, 1] * 1e-14), "clockwise or flat"),
    ],
)
def test_bad_coordinates_in_a_formula_ring_are_refused(plant, message):
    mesh = build_mesh(ring_params())
    points = mesh.points.copy()
    plant(points)
    bad = rebuilt(mesh, points)
    assert chains_of(bad) is not None
    with pytest.raises(MeshInvariantError, match=message):
        check_mesh(bad, ring_params())


# -- duplicate vertices: keys that tell point-symmetric points apart --------------------


def test_point_keys_tell_mirrored_points_apart_and_duplicates_are_counted_exactly():
    rng = np.random.default_rng(3)
    xy = rng.normal(size=(5000, 2))
    both = np.vstack([xy, -xy, xy * [-1, 1], xy * [1, -1]])  # (x, y), (−x, −y), ...
    keys = _point_keys(*(np.ascontiguousarray(both[:, k]) for k in (0, 1)))
    assert len(np.unique(keys)) == len(both)  # no sign pattern collides
    assert duplicate_vertices(both) == 0
    twins = np.vstack([both, both[[7, 7, 12000]], [[0.0, 0.0], [-0.0, 0.0], [0.0, -0.0]]])
    assert duplicate_vertices(twins) == 3 + 2  # 7 twice more, 12000 once; the zeros
    assert duplicate_vertices(twins, np.array([7, 20000, 20001, 3])) == 2
    assert duplicate_vertices(twins, np.array([7, 8, 9])) == 0


def test_distinct_regions_are_counted_without_sorting():
    assert count_distinct(np.array([], dtype=np.int32)) == 0
    assert count_distinct(np.array([2, 2, 2], dtype=np.int32)) == 1
    assert count_distinct(np.array([1, 2, 1, 2], dtype=np.int32)) == 2
    assert count_distinct(np.array([1, 5, 5, 1], dtype=np.int32)) == 2  # none between
    assert count_distinct(np.array([1, 5, 3, 1, 3], dtype=np.int32)) == 3
    assert count_distinct(np.array([-4, 900, 7, 7], dtype=np.int32)) == 3
    assert count_distinct(np.array([0, 1 << 30, 5], dtype=np.int64)) == 3


# -- grid patches: quality reduced edge by edge -------------------------------------------


@pytest.mark.parametrize("diagonal", ["BC", "AD"])
@pytest.mark.parametrize("degenerate", [False, True])
def test_lattice_quality_summary_equals_the_triangle_by_triangle_one(diagonal, degenerate):
    # grid patches distorted at random (some with a collapsed cell): the side range bit
    # for bit, the rest to rounding, NaN and zero angles where the general path has them
    mesh = build_mesh(
        MeshParams(structure="patch", mode="paper", subdivisions=6, diagonal=diagonal)
    )
    t = mesh.repetition.template
    assert lattice_diagonal(t.triangles, len(t.uv)) == diagonal
    rng = np.random.default_rng(1 if degenerate else 2)
    n_patches = 300
    nv = len(t.uv)
    points = (t.uv[None] + rng.normal(scale=0.05, size=(n_patches, nv, 2))).reshape(-1, 2)
    points += np.repeat(rng.uniform(-50, 50, (n_patches, 2)), nv, axis=0)
    if degenerate:
        points[nv * 17 + 8] = points[nv * 17 + 9]  # a zero side: angle 0, aspect inf
        a, b, c = nv * 40 + t.triangles[0]
        points[[b, c]] = points[a]  # a triangle shrunk to a point: 0/0
    vmap = np.arange(n_patches * nv).reshape(n_patches, nv)
    triangles = vmap[:, t.triangles].reshape(-1, 3)
    columns = [np.ascontiguousarray(points[:, k]) for k in (0, 1)]
    got = lattice_quality_summary(columns, vmap, diagonal)
    expect = quality_summary(points, triangles)
    q = triangle_quality(points, triangles)
    assert (got.shortest_side, got.longest_side) == (expect.shortest_side, expect.longest_side)
    assert got.min_angle_deg == pytest.approx(expect.min_angle_deg, rel=1e-12, abs=0.0)
    assert got.area == pytest.approx(float(q.areas.sum()), rel=1e-12)
    assert np.isnan(got.max_aspect_ratio) == np.isnan(expect.max_aspect_ratio) == degenerate
    if not degenerate:
        assert got.min_angle_deg > 0.0
        assert got.max_aspect_ratio == pytest.approx(expect.max_aspect_ratio, rel=1e-12)
    else:
        assert got.min_angle_deg == expect.min_angle_deg == 0.0


@pytest.mark.parametrize("diagonal", ["BC", "AD"])
def test_lattice_quality_summary_of_sector_grids_of_n_by_n_v_cells(diagonal):
    # a conforming sector's template: 6 graded cells across, 3 along; distorted at random
    t = tensor_template((0.0, 0.05, 0.2, 0.5, 0.8, 0.95, 1.0), (0.0, 0.3, 0.7, 1.0), diagonal)
    nv = len(t.uv)
    assert lattice_diagonal(t.triangles, nv) is None  # not an (n + 1)² grid
    assert lattice_diagonal(t.triangles, nv, (3, 6)) is None  # the cells the other way
    assert lattice_diagonal(t.triangles, nv, (6, 3)) == diagonal
    rng = np.random.default_rng(4)
    n_patches = 200
    points = (t.uv[None] + rng.normal(scale=0.02, size=(n_patches, nv, 2))).reshape(-1, 2)
    points += np.repeat(rng.uniform(-50, 50, (n_patches, 2)), nv, axis=0)
    vmap = np.arange(n_patches * nv).reshape(n_patches, nv)
    triangles = vmap[:, t.triangles].reshape(-1, 3)
    columns = [np.ascontiguousarray(points[:, k]) for k in (0, 1)]
    got = lattice_quality_summary(columns, vmap, diagonal, (6, 3))
    expect = quality_summary(points, triangles)
    q = triangle_quality(points, triangles)
    assert (got.shortest_side, got.longest_side) == (expect.shortest_side, expect.longest_side)
    assert got.min_angle_deg == pytest.approx(expect.min_angle_deg, rel=1e-12)
    assert got.max_aspect_ratio == pytest.approx(expect.max_aspect_ratio, rel=1e-12)
    assert got.area == pytest.approx(float(q.areas.sum()), rel=1e-12)


@pytest.mark.parametrize(
    "params",
    [
        MeshParams(structure="square_split_double_ring", mode="paper", patch_size=0.25),
        MeshParams(structure="double_ring", mode="conforming", subdivisions=5, diagonal="AD"),
        # sectors of 8 x 5 cells, and graded ones of 6 x 2
        MeshParams(
            structure="double_ring",
            mode="conforming",
            subdivisions=8,
            angle_step=10.0,
            inner_radius=3.0,
            outer_radius=6.0,
        ),
        MeshParams(structure="split_ring", mode="conforming", subdivisions=6, grading=True),
    ],
)
def test_stats_of_grid_patches_equal_the_general_figures(params):
    mesh = build_mesh(params)
    t = mesh.repetition.template
    cells = (len(t.sides[0]) - 1, len(t.sides[1]) - 1)
    assert lattice_diagonal(t.triangles, len(t.uv), cells) == params.diagonal  # grid path
    got = mesh.stats()
    assert "topology" not in mesh.__dict__ and "quality" not in mesh.__dict__  # stayed lazy
    full = build_mesh(params)
    full.quality  # noqa: B018  (the per-triangle path)
    expect = full.stats()
    for key in ("edges", "interior_edges", "boundary_edges", "junction_edges", "regions"):
        assert got[key] == expect[key], key
    assert (got["min_edge"], got["max_edge"]) == (expect["min_edge"], expect["max_edge"])
    for key in ("min_angle_deg", "max_aspect_ratio", "area"):
        assert got[key] == pytest.approx(expect[key], rel=1e-12), key


# -- unwelded copies (paper rings whose patches share no vertex) -----------------------


@pytest.mark.parametrize(
    "params",
    [
        MeshParams(),  # Fig. 12(a)
        MeshParams(structure="double_ring", mode="paper", subdivisions=4, angle_step=0.5),
        MeshParams(structure="ring", mode="paper", scheme="barycentric", subdivisions=2),
        MeshParams(structure="split_double_ring", mode="paper", diagonal="AD", origin=(2.0, 1.0)),
        MeshParams(structure="patch", mode="paper", subdivisions=7),
    ],
)
def test_copies_topology_equals_the_patch_topology_bit_for_bit(params):
    mesh = build_mesh(params)
    assert mesh.repetition.kind == "copies"
    expect = general_patch_topology(mesh)
    assert_same_topology(mesh.topology, expect)
    general = edge_topology(mesh.triangles, mesh.n_vertices)
    assert np.array_equal(np.bincount(mesh.topology.valence), np.bincount(general.valence))
    assert_same_rwg(mesh)


def test_welded_or_renumbered_patches_are_not_taken_for_copies():
    welded = build_mesh(MeshParams(structure="square_split_double_ring", patch_size=0.5))
    assert welded.repetition.kind != "copies"
    mesh = build_mesh(MeshParams(angle_step=30.0))
    # the last two vertices swapped: still unwelded, but not in template order
    swap = np.arange(mesh.n_vertices)
    swap[[-1, -2]] = swap[[-2, -1]]
    renumbered = rebuilt(mesh, mesh.points[np.argsort(swap)], swap[mesh.triangles])
    assert renumbered.repetition.kind != "copies"
    expect = general_patch_topology(renumbered)
    assert_same_topology(renumbered.topology, expect)

"""Regression tests of issue 10's core cases: never a wrong mesh, never a runaway.

Each case is a parameter set a new user tried that gave a wrong mesh, a
misleading message, an exception of another type or a memory blow-up. The
fuzz in ``test_core_properties.py`` draws cases like these at random.
"""

import functools
import re
import tracemalloc

import numpy as np
import pytest
from helpers import assert_clear_message, run_capped, signed_areas
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from scipy.spatial import cKDTree
from test_core_properties import params

from barymesh import MeshParams, build_mesh
from barymesh.check import check_mesh
from barymesh.invariants import MeshInvariantError, inverted_or_flat
from barymesh.mesh import TriMesh
from barymesh.placement import conforming_square_rects, paper_origins, predicted_patches
from barymesh.subdivision import graded_cell_count, graded_nodes
from barymesh.topology import edge_topology
from barymesh.weld import merge_pairs, weld_points

#: The issue's budget: no structure may need more memory than this per triangle.
BYTES_PER_TRIANGLE = 600


def peak_bytes(fn):
    """(result or exception, tracemalloc's peak in bytes) of calling ``fn``."""
    tracemalloc.start()
    try:
        try:
            out = fn()
        except ValueError as err:
            out = err
        return out, tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def assert_manifold_and_counter_clockwise(mesh):
    assert (signed_areas(mesh) > 0).all()
    topo = edge_topology(mesh.triangles, mesh.n_vertices)
    assert topo.valence.max() == 2
    assert len(np.unique(mesh.points[:, :2], axis=0)) == mesh.n_vertices


# -- 1. inverted triangles -----------------------------------------------------------


@pytest.mark.parametrize(
    ("structure", "levels", "angle_step", "sectors_per_ring"),
    [
        ("ring", 1, 120.0, 6),  # 12 of 36 triangles were clockwise with 3 sectors
        ("double_ring", 2, 90.0, 13),  # 84 of 576 with 4 sectors per ring
        ("double_ring", 3, 60.0, 13),  # 174 of 5,184 with 6 sectors per ring
    ],
)
def test_barycentric_conforming_rings_are_counter_clockwise(
    structure, levels, angle_step, sectors_per_ring
):
    p = MeshParams(
        structure=structure,
        mode="conforming",
        scheme="barycentric",
        subdivisions=levels,
        angle_step=angle_step,
    )
    mesh = build_mesh(p)
    rings = 2 if structure == "double_ring" else 1
    # sectors narrower than asked until no sub-triangle folds: 2 primaries x 6**levels each
    assert mesh.n_patches == rings * sectors_per_ring
    assert mesh.n_triangles == rings * sectors_per_ring * 2 * 6**levels
    assert p.predicted_triangles() == mesh.n_triangles
    assert_manifold_and_counter_clockwise(mesh)
    assert mesh.stats()["euler_characteristic"] == 0  # closed rings


def test_invariant_check_refuses_a_clockwise_triangle_naming_the_parameters():
    p = MeshParams(structure="patch", patch_size=2.0, subdivisions=1)
    good = build_mesh(p)
    flipped = good.triangles.copy()
    flipped[1] = flipped[1, [0, 2, 1]]
    bad = TriMesh(good.points, flipped, good.patch_ids, good.regions, 1, mode="paper")
    with pytest.raises(
        MeshInvariantError,
        match=r"patch with patch_size=2\.0, subdivisions=1 "
        r"has 1 of 2 triangles clockwise or flat",
    ):
        check_mesh(bad, p)
    assert isinstance(MeshInvariantError("x"), ValueError)


def test_invariant_check_refuses_flat_and_non_finite_triangles():
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, 1e-13], [0.0, 1.0]])
    # area 2.5e-14 is below 1e-12 x the longest edge squared (1): flat
    assert inverted_or_flat(pts, np.array([[0, 1, 2], [0, 1, 3]])).tolist() == [0]
    pts[3] = np.nan
    assert inverted_or_flat(pts, np.array([[0, 1, 3]])).tolist() == [0]


def test_invariant_check_refuses_a_conforming_junction():
    p = MeshParams(structure="patch", mode="conforming", subdivisions=1)
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.5, -1.0], [1.0, 1.0]])
    tri = np.array([[0, 1, 2], [0, 3, 1], [1, 4, 2]])
    ok = TriMesh(pts, tri, np.zeros(3), np.ones(3), 1, mode="conforming")
    check_mesh(ok, p)
    third = np.array([[0, 1, 2], [0, 3, 1], [1, 4, 2], [0, 1, 4]])  # edge 0-1 on three
    junction = TriMesh(pts, third, np.zeros(4), np.ones(4), 1, mode="conforming")
    with pytest.raises(MeshInvariantError, match="edges on 3 triangles"):
        check_mesh(junction, p)
    twin = np.vstack([pts, pts[4]])  # vertex 5 at the same point as vertex 4
    dup = TriMesh(
        twin, np.array([[0, 1, 2], [1, 5, 2]]), np.zeros(2), np.ones(2), 1, mode="conforming"
    )
    with pytest.raises(MeshInvariantError, match="1 vertices at the same point"):
        check_mesh(dup, p)


# -- 2. junctions in a conforming square ring ------------------------------------------


@pytest.mark.parametrize("closeness", [1e-9, 1e-8])
def test_square_ring_slot_leaving_slivers_is_refused_by_gap_width(closeness):
    kw = dict(
        structure="square_split_double_ring", mode="conforming", inner_radius=1, outer_radius=3
    )
    with pytest.raises(ValueError, match=r"gap_width=1\.99999") as err:
        MeshParams(**kw, gap_width=2 * (1 - closeness))
    message = str(err.value)
    assert "tolerance" not in message  # none was set
    limit = float(message.split("expected gap_width <= ")[1].split(" mm")[0])
    assert 1.9999 < limit < 2 * (1 - closeness)
    # the limit itself meshes: watertight, no junction, no duplicate vertex
    mesh = build_mesh(MeshParams(**kw, gap_width=limit))
    assert_manifold_and_counter_clockwise(mesh)


# -- 3. degenerate or non-finite meshes from validated values ----------------------------


@pytest.mark.parametrize(
    ("kw", "name"),
    [
        ({"structure": "patch", "origin": (1e17, 0)}, "origin"),
        ({"structure": "patch", "patch_size": 1e-200}, "patch_size"),
        ({"structure": "double_ring", "mode": "conforming", "patch_size": 1e-15}, "patch_size"),
        ({"structure": "ring", "mode": "conforming", "inner_radius": 1e300}, "inner_radius"),
        ({"structure": "patch", "patch_width": 1e300}, "patch_width"),
        ({"structure": "ring", "mode": "conforming", "inner_radius": 1e-9}, "inner_radius"),
    ],
)
def test_lengths_float64_cannot_mesh_are_refused(kw, name):
    with pytest.raises(ValueError, match=rf"^{name}="):
        MeshParams(**kw)


@pytest.mark.parametrize("scale", [1e-60, 1e-6, 1e6, 1e60])
def test_the_paper_structure_meshes_at_any_scale_float64_can_hold(scale):
    p = MeshParams(inner_radius=4 * scale, outer_radius=9 * scale, patch_size=scale)
    mesh = build_mesh(p)
    # Fig. 12(a) at any scale: 720 patches of 32 triangles and 25 vertices, none welded
    assert (mesh.n_triangles, mesh.n_vertices) == (23040, 18000)
    s = mesh.stats()
    assert s["area"] == pytest.approx(720 * scale**2)  # unit patches, none overlapping
    assert all(np.isfinite(v) for v in s.values() if isinstance(v, float))


def test_a_patch_far_from_the_origin_meshes_while_float64_resolves_it():
    far = build_mesh(MeshParams(structure="patch", origin=(1e6, -1e6)))
    assert far.n_triangles == 32 and (signed_areas(far) > 0.0299).all()  # 1/32 mm² each
    with pytest.raises(ValueError, match="origin="):
        MeshParams(structure="patch", origin=(1e8, 0))
    # a lone patch welds no points of two patches: 24 km out (float64 spacing 3.7e-9 mm,
    # above its default tolerance of 1e-9 mm) it still meshes, as the method page says
    assert build_mesh(MeshParams(structure="patch", origin=(2.4e7, 0))).n_triangles == 32


def test_a_ring_far_out_at_the_default_tolerance_is_refused_naming_its_origin():
    # issue 30's sixth fuzz run: at y = 7e7 mm float64 spaces numbers 1.49e-8 mm apart, and
    # two pairs of points of neighbouring patches stayed apart at the default 9.1e-9 mm
    kw = dict(
        structure="double_ring",
        inner_radius=1.0,
        outer_radius=2.78,
        patch_size=1.78,
        subdivisions=1,
    )
    with pytest.raises(ValueError, match=r"^origin=\(1.0, 70000000.0\) puts metal 7e\+07 mm out"):
        MeshParams(**kw, origin=(1.0, 7e7))
    set_tolerance = build_mesh(MeshParams(**kw, origin=(1.0, 7e7), tolerance=1e-4))
    assert set_tolerance.n_triangles == build_mesh(MeshParams(**kw)).n_triangles


def test_tolerance_below_float64_rounding_is_refused():
    with pytest.raises(ValueError, match=r"tolerance=1e-15 mm is too small"):
        MeshParams(tolerance=1e-15)


# -- 4. weld runaways ------------------------------------------------------------------


@pytest.mark.parametrize(
    "kw",
    [
        {"structure": "ring", "angle_step": 0.5, "tolerance": 0.05},  # 4.8 GiB before
        {"structure": "ring", "angle_step": 0.2, "tolerance": 0.1},  # 30 GiB before
        {"tolerance": 0.1},  # Fig. 12(a), tolerance slider at its maximum
        {"tolerance": 0.0562},  # slider position 32
        {"tolerance": 0.03},
        {
            "structure": "ring",
            "scheme": "barycentric",
            "subdivisions": 2,
            "angle_step": 0.2,
            "tolerance": 0.0139,
        },
    ],
)
def test_a_chaining_tolerance_is_refused_in_bounded_memory(kw):
    p = MeshParams(**{k: v for k, v in kw.items() if k != "tolerance"})
    err, peak = peak_bytes(lambda: build_mesh(MeshParams(**kw)))
    assert isinstance(err, ValueError)
    assert f"tolerance={kw['tolerance']:g} mm joins a chain of near points" in str(err)
    assert peak <= BYTES_PER_TRIANGLE * p.predicted_triangles()


def test_patches_within_the_default_tolerance_are_refused_naming_the_radius():
    # 3,644 patches within 2e-9 mm of each other tried to allocate 3.6 GiB
    with pytest.raises(ValueError, match=r"^inner_radius=1e-09 mm and angle_step=0\.0988 put"):
        MeshParams(structure="ring", inner_radius=1e-9, angle_step=0.0988, subdivisions=5)


@pytest.mark.parametrize(
    "kw",
    [
        # the heavily overlapping paper double ring of issue 10, item 5, welded up to
        # just below its neighbours' distance (2.56e-5 mm)
        {
            "structure": "double_ring",
            "inner_radius": 0.9159,
            "patch_size": 3.2376,
            "outer_radius": 5.6588,
            "angle_step": 0.0568,
            "subdivisions": 2,
            "tolerance": 2.5e-5,
        },
        {"structure": "square_split_double_ring", "tolerance": 0.1},
        {"structure": "square_split_double_ring", "mode": "conforming", "tolerance": 0.1},
        {"scheme": "barycentric", "subdivisions": 2, "tolerance": 0.002},
    ],
)
def test_large_tolerances_that_do_not_chain_build_in_bounded_memory(kw):
    mesh, peak = peak_bytes(lambda: build_mesh(MeshParams(**kw)))
    assert isinstance(mesh, TriMesh)
    assert peak <= BYTES_PER_TRIANGLE * mesh.n_triangles


def test_weld_measures_a_long_chain_without_a_pairwise_matrix():
    # 40,000 points 0.01 apart on a line: one chain, 400 long; all pairs would take 25 GB
    n = 40_000
    coords = np.column_stack([np.arange(n) * 0.01, np.zeros(n)])
    err, peak = peak_bytes(lambda: weld_points(coords, 0.015))
    assert "tolerance=0.015 mm joins a chain" in str(err)
    assert "ends are 399.99 mm apart" in str(err)
    assert peak < 20e6


def test_weld_keeps_a_cluster_whose_diameter_is_just_below_the_tolerance():
    # a regular 200-gon of diameter 0.999999: its bounding box diagonal exceeds 1
    t = np.linspace(0, 2 * np.pi, 200, endpoint=False)
    ring = 0.4999995 * np.column_stack([np.cos(t), np.sin(t)])
    pairs = np.column_stack([np.zeros(199, dtype=int), np.arange(1, 200)])
    ids, rep = merge_pairs(200, pairs, ring, 1.0)
    assert len(rep) == 1 and (ids == 0).all()
    with pytest.raises(ValueError, match="ends are 0.999999 mm apart"):
        merge_pairs(200, pairs, ring, 0.9999985)


# -- 11. exceptions that escaped as other types ------------------------------------------


@pytest.mark.parametrize(
    ("kw", "name"),
    [
        ({"inner_radius": 10**400}, "inner_radius"),  # was OverflowError
        ({"gap_angle": 10**400}, "gap_angle"),  # was OverflowError
        ({"gap_angle": 1e300}, "gap_angle"),
        ({"angle_step": 1e-320}, "angle_step"),  # was OverflowError
        ({"tolerance": 10**400}, "tolerance"),
        ({"structure": "triangle", "triangle_vertices": [1, 2, 3]}, "triangle_vertices"),
        ({"structure": np.array(["ring", "patch"])}, "structure"),  # was "truth value ambiguous"
        ({"subdivisions": 10**400}, "subdivisions"),
        ({"origin": (10**400, 0)}, "origin"),
        # issue 30's seventh fuzz run: any budget was taken, so 10**400 let a 320-million-
        # triangle ring through to the build (MemoryError); int32 indices end at 2**31 - 1
        ({"max_triangles": 10**400}, "max_triangles"),
        ({"max_triangles": 2**31}, "max_triangles"),
        ({"structure": "patch", "patch_size": 5e-324}, "patch_size"),  # was scipy in build_mesh
        ({"structure": "patch", "patch_size": 1e300}, "patch_size"),  # ditto
        # issue 30: the graded track's cell patch_size / n underflowed to 0 in _check_grading
        (
            {
                "structure": "double_ring",
                "mode": "conforming",
                "patch_size": 5e-324,
                "grading": True,
            },
            "patch_size",
        ),
        (
            {"structure": "ring", "mode": "conforming", "patch_size": 1e-320, "grading": True},
            "patch_size",
        ),
        # the cells across the track counted as log(cell / min_edge): OverflowError
        (
            {"structure": "ring", "mode": "conforming", "min_edge": 1e-320, "grading": True},
            "min_edge",
        ),
    ],
)
def test_every_bad_parameter_is_a_value_error_naming_it(kw, name):
    with pytest.raises(ValueError, match=rf"^{name}="):
        MeshParams(**kw)


@pytest.mark.parametrize(
    ("data", "match"),
    [
        ({1: 2}, "unknown parameter 1"),  # was TypeError
        ({1: 2, "radius": 3}, "unknown parameter"),  # mixed key types used to break sorting
        ({"triangle_vertices": [1, 2, 3], "structure": "triangle"}, "triangle_vertices="),
        ({"origin": 5}, "origin="),
    ],
)
def test_from_dict_refuses_with_value_errors(data, match):
    with pytest.raises(ValueError, match=match):
        MeshParams.from_dict(data)


def test_numpy_scalars_are_taken_as_numbers():
    p = MeshParams(
        subdivisions=np.int64(3), max_triangles=np.int32(100_000), inner_radius=np.float32(4.0)
    )
    assert (p.subdivisions, p.max_triangles) == (3, 100_000)
    assert type(p.subdivisions) is int and type(p.max_triangles) is int


def test_a_chain_at_the_default_tolerance_does_not_blame_a_tolerance_nobody_set():
    from barymesh.structures import _welded

    coords = np.column_stack([np.arange(100) * 0.01, np.zeros(100)])
    with pytest.raises(ValueError, match=r"with the default tolerance \(1e-09 of the") as err:
        _welded(MeshParams(), weld_points, coords, 0.015)
    assert "use a smaller tolerance" not in str(err.value)
    with pytest.raises(ValueError, match="use a smaller tolerance"):
        _welded(MeshParams(tolerance=0.015), weld_points, coords, 0.015)


@pytest.mark.parametrize("diagonal", ["BC", "AD"])
@pytest.mark.parametrize("scheme", ["uniform", "barycentric"])
def test_the_per_patch_check_finds_what_the_per_triangle_check_finds(diagonal, scheme):
    from barymesh.repeat import inverted_or_flat_patches
    from barymesh.structures import layout

    p = MeshParams(
        structure="ring", angle_step=30, subdivisions=2, diagonal=diagonal, scheme=scheme
    )
    lay = layout(p)
    vmap = lay.vertex_of_point.reshape(len(lay.xy), -1)
    mesh = build_mesh(p)
    pts = mesh.points.copy()
    assert inverted_or_flat_patches(pts, vmap, lay.template.triangles).tolist() == []
    rng = np.random.default_rng(7)
    for victim in rng.choice(mesh.n_vertices, 5, replace=False):
        moved = pts.copy()
        moved[victim, :2] += 0.6 * rng.standard_normal(2)  # folds some of its triangles
        want = inverted_or_flat(moved, mesh.triangles)
        got = inverted_or_flat_patches(moved, vmap, lay.template.triangles)
        assert got.tolist() == want.tolist()
    moved = pts.copy()
    moved[vmap[3, 0]] = moved[vmap[3, 1]]  # a flat (zero-area) triangle
    assert len(inverted_or_flat_patches(moved, vmap, lay.template.triangles)) > 0


@pytest.mark.parametrize(
    "kw",
    [
        {"structure": "patch", "subdivisions": 64},
        {"structure": "triangle", "subdivisions": 64},
        {"structure": "ring", "angle_step": 0.25},
        {"structure": "double_ring", "angle_step": 0.5},
        {"structure": "split_ring", "angle_step": 0.25},
        {"structure": "split_double_ring", "angle_step": 0.5},
        {"structure": "square_split_double_ring", "patch_size": 0.1},
        {"structure": "double_ring", "scheme": "barycentric", "subdivisions": 3, "angle_step": 5},
    ],
)
@pytest.mark.parametrize("mode", ["paper", "conforming"])
def test_every_structure_builds_within_the_memory_budget(kw, mode):
    p = MeshParams(**kw, mode=mode)
    build_mesh(p)  # templates are cached: measure the structure, not the first template
    mesh, peak = peak_bytes(lambda: build_mesh(p))
    assert mesh.n_triangles >= 4096  # large enough for fixed costs not to count
    assert peak <= BYTES_PER_TRIANGLE * mesh.n_triangles


def test_the_per_patch_valence_check_sees_a_patch_laid_twice():
    from barymesh.repeat import glued_edge_valence
    from barymesh.structures import layout

    p = MeshParams(structure="ring", mode="conforming", angle_step=30, subdivisions=3)
    lay = layout(p)
    vmap = lay.vertex_of_point.reshape(len(lay.xy), -1)
    n_vertices = len(lay.representative)
    assert glued_edge_valence(lay.template, vmap, n_vertices) == 2  # a closed band
    twice = np.vstack([vmap, vmap[:1]])  # sector 0 again: its inner edges on 4 triangles
    assert glued_edge_valence(lay.template, twice, n_vertices) == 4
    # a sector glued to one more neighbour at its side: that side's edges on 3
    third = vmap[1].copy()
    third[lay.template.sides[2]] = vmap[0, lay.template.sides[2]]
    third[lay.template.sides[0]] = n_vertices + np.arange(len(lay.template.sides[0]))
    ends = np.concatenate([lay.template.sides[0], lay.template.sides[2]])
    interior = np.setdiff1d(np.arange(vmap.shape[1]), ends)
    third[interior] = n_vertices + 100 + interior
    assert glued_edge_valence(lay.template, np.vstack([vmap, third]), n_vertices + 200) == 3


# -- 12. the outside fuzz of issue 4 (20,000 parameter sets) -------------------------------

NUMBER_FIELDS = (
    "inner_radius",
    "outer_radius",
    "patch_size",
    "angle_step",
    "gap_width",
    "gap_angle",
    "tolerance",
    "patch_width",
    "max_edge",
    "frequency",
    "cells_per_wavelength",
    "relative_permittivity",
    "growth_ratio",
    "min_edge",
)


@pytest.mark.parametrize("switch", [True, False, np.True_])
@pytest.mark.parametrize("name", NUMBER_FIELDS)
def test_booleans_are_refused_as_numbers(name, switch):
    # inner_radius=True was taken as 1 mm (and gave an OverflowError further on)
    with pytest.raises(
        ValueError,
        match=rf"^{name}={switch!r} is a true/false switch, not a "
        "number",
    ):
        MeshParams(**{name: switch})
    assert_clear_message(f"{name}={switch!r} is a true/false switch")


def test_a_boolean_in_the_origin_is_refused():
    with pytest.raises(ValueError, match=r"^origin=True is a true/false switch"):
        MeshParams(origin=(True, 0.0))


@pytest.mark.parametrize("max_edge", [1e-200, 5e-324, 1e-71, 9.9e-9])
def test_a_max_edge_float64_cannot_mesh_is_refused_by_name(max_edge):
    # max_edge=1e-200 was an OverflowError in the sizing message ("cannot convert float
    # infinity to integer" for 5e-324); the shortest edge float64 meshes at coordinates up
    # to 10 mm (the default double ring's extent) is 1e-8 x 10 mm
    p = MeshParams()
    assert p.extent == 10.0
    with pytest.raises(
        ValueError,
        match=rf"^max_edge={max_edge!r} mm is too short: float64 "
        r"cannot mesh edges below 1e-07 mm at coordinates up to 10 mm",
    ):
        MeshParams(max_edge=max_edge)


@pytest.mark.parametrize(
    ("scheme", "subdivisions", "needed"),
    [("uniform", 4, "n = 1.29e+08"), ("barycentric", 1, "levels = 29")],
)
def test_a_far_sizing_target_is_a_value_error_not_an_overflow(scheme, subdivisions, needed):
    # the patch's edges at the finest level are ~0.02 mm; 1.1e-8 mm asks 1e6 times finer
    p = MeshParams(structure="patch", scheme=scheme, subdivisions=subdivisions, max_edge=1.1e-8)
    with pytest.raises(
        ValueError, match=re.escape(f"it would take about {needed}, more than 1e+15 triangles")
    ):
        build_mesh(p)


TINY_SLOTS = [
    dict(
        structure="split_ring",
        inner_radius=17.784145362694343,
        patch_size=2.340888811656802,
        angle_step=120,
        subdivisions=8,
        diagonal="AD",
    ),
    dict(
        structure="split_double_ring",
        inner_radius=0.27249837260654886,
        patch_size=0.0363806385794857,
        outer_radius=0.3622957182118971,
        angle_step=360,
        subdivisions=6,
        diagonal="AD",
        gap_angle=90,
    ),
    dict(structure="square_split_double_ring", inner_radius=3.0, outer_radius=5.0),
]


def assert_sound_paper(mesh, tol):
    assert (signed_areas(mesh) > 0).all()
    assert len(cKDTree(mesh.points[:, :2]).query_pairs(tol)) == 0


@pytest.mark.parametrize("kw", TINY_SLOTS)
def test_a_conforming_slot_within_the_weld_tolerance_is_refused(kw):
    # gap widths of 1e-10 mm left 8 to 28 vertex pairs closer than the tolerance unwelded
    wide = 0.1 * kw["inner_radius"]
    tol = MeshParams(**kw, mode="conforming", gap_width=wide).weld_tolerance  # 1e-9 of the size
    refused = (
        r"^gap_width=1e-10 mm is too narrow: the faces of the slot would be within the "
        r"welding tolerance \(the default tolerance"
    )
    with pytest.raises(ValueError, match=refused) as err:
        MeshParams(**kw, mode="conforming", gap_width=1e-10)
    assert f"expected gap_width > {2 * tol:.3g} mm (twice the tolerance)" in str(err.value)
    with pytest.raises(ValueError, match=r"^gap_width=.* mm is too narrow.*\(tolerance 1e-06 mm\)"):
        MeshParams(**kw, mode="conforming", gap_width=1.5e-6, tolerance=1e-6)
    # paper mode drops the patches the slot touches: the same gap is a sound mesh there
    paper = MeshParams(**kw, mode="paper", gap_width=1e-10)
    assert_sound_paper(build_mesh(paper), paper.weld_tolerance)


@pytest.mark.parametrize("kw", TINY_SLOTS[:2])
def test_a_conforming_slot_just_wider_than_twice_the_tolerance_is_welded_correctly(kw):
    base = MeshParams(**kw, mode="conforming", gap_width=0.1 * kw["inner_radius"])
    gap = 3 * base.weld_tolerance
    p = MeshParams(**kw, mode="conforming", gap_width=gap)
    mesh = build_mesh(p)
    xy = mesh.points[:, :2]
    assert len(cKDTree(xy).query_pairs(p.weld_tolerance)) == 0  # no near pair left apart
    assert_manifold_and_counter_clockwise(mesh)
    assert mesh.n_triangles == p.predicted_triangles()
    # the slots stay open: every piece is a strip (a disk, Euler 1); a split ring is one
    # piece, a split double ring's two rings are cut into two halves each
    pieces = {"split_ring": 1, "split_double_ring": 4}[kw["structure"]]
    assert mesh.stats()["euler_characteristic"] == pieces


@pytest.mark.parametrize("inner_radius", [6.01, 6.5, 12.0, 30.0])
@pytest.mark.parametrize("gap_width", [11.9, 12.0])
def test_the_wide_slot_of_a_coarse_conforming_split_ring_is_built_to_its_prediction(
    inner_radius, gap_width
):
    # a conforming split ring with angle_step=360, patch_size=1 and gap_width about 12 mm
    # ran past 20 s: its size is predicted and the mesh is small and sound
    p = MeshParams(
        structure="split_ring",
        mode="conforming",
        angle_step=360,
        patch_size=1,
        gap_width=gap_width,
        inner_radius=inner_radius,
    )
    predicted = p.predicted_triangles()
    assert predicted <= 20 * 2 * 16  # a few sectors of 2 x 4² triangles
    mesh = build_mesh(p)
    assert mesh.n_triangles == predicted
    assert_manifold_and_counter_clockwise(mesh)
    assert mesh.stats()["euler_characteristic"] == 1  # an open strip
    assert len(cKDTree(mesh.points[:, :2]).query_pairs(p.weld_tolerance)) == 0


NESTED = functools.reduce(lambda v, _: [v], range(900), 1.0)


@pytest.mark.parametrize(
    "name",
    [
        "inner_radius",
        "origin",
        "structure",
        "triangle_vertices",
        "subdivisions",
        "max_triangles",
        "grading",
        "tolerance",
    ],
)
def test_a_900_deep_nested_value_gives_a_short_message_naming_the_parameter(name):
    kw = {name: NESTED}
    if name == "triangle_vertices":
        kw["structure"] = "triangle"
    with pytest.raises(ValueError, match=rf"^{name}=\[\[\[") as err:
        MeshParams(**kw)
    assert_clear_message(str(err.value))
    assert len(str(err.value)) < 200


# -- issue 30: runaways while checking --------------------------------------------------


def test_a_growth_ratio_next_to_one_is_refused_with_its_count_before_any_node_is_made():
    # grading toward a slot with growth_ratio 1.0000001 made 66 million sector ends one by
    # one (MemoryError after ~50 s at a 3 GiB cap); counted in O(1) now, under a 1 GiB cap
    out = run_capped(
        """
        from barymesh import MeshParams
        try:
            MeshParams(structure="split_double_ring", mode="conforming", inner_radius=29.18,
                outer_radius=30.405, patch_size=0.3169, angle_step=18.82, subdivisions=10,
                gap_width=12.07, gap_angle=540, grading=True, growth_ratio=1.0000001,
                max_triangles=300000)
        except ValueError as exc:
            print(exc)
        """
    )
    assert out.returncode == 0, out.stderr[-1500:]
    message = out.stdout.strip()
    found = re.match(r"these parameters would make ([\d,]+) triangles, above the budget", message)
    assert found, message
    assert int(found.group(1).replace(",", "")) > 10**9  # two slots' graded ends, both rings
    assert "max_triangles=300,000" in message and "growth_ratio" in message
    assert_clear_message(message)


@settings(max_examples=300, deadline=None)
@given(
    st.integers(1, 64),
    st.floats(1e-6, 1.0),
    st.one_of(st.floats(1.001, 2.0), st.sampled_from([1.5, 2.0, 1.1, 1.01])),
)
def test_graded_cell_count_is_the_number_of_graded_nodes(cells, fine, ratio):
    fine = min(fine, 1.0) / cells
    assert graded_cell_count(cells, fine, ratio) == len(graded_nodes(cells, fine, ratio)) - 1


def test_a_huge_paper_square_ring_is_counted_without_placing_its_patches():
    # issue 30: a paper-mode square split double ring of inner radius 1e5 mm placed its 8.8
    # million patches to count them (82 s, 4.4 GB before its refusal); the slot's patches
    # are counted near the slot alone now, under a 1 GiB cap
    out = run_capped(
        """
        from barymesh import MeshParams, build_mesh
        p = MeshParams(structure="square_split_double_ring", mode="paper", inner_radius=1e5,
            outer_radius=1e6, max_edge=5.57, max_triangles=300000)
        print(p.replace(subdivisions=1).predicted_triangles())
        try:
            build_mesh(p)
        except ValueError as exc:
            print(exc)
        """
    )
    assert out.returncode == 0, out.stderr[-1500:]
    count, message = out.stdout.splitlines()
    # a track of half side r holds 2 (2 r + 2) + 2 (2 r) patches of 1 mm (8,800,008 for
    # r = 1e5 and 1e6); the 1 mm slot removes the two patches it crosses on each of two
    # opposite sides of both rings (8); two triangles each at n = 1
    assert int(count) == 2 * (2 * 200_002 + 2 * 200_000 + 2 * 2_000_002 + 2 * 2_000_000 - 8)
    assert message == (
        "max_edge=5.57 mm asks for edges <= 5.57 mm, but the coarsest mesh already has "
        f"{int(count):,} triangles, above the budget max_triangles=300,000"
    )


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(params(modes=("paper",)))
def test_the_predicted_count_of_a_slotted_paper_ring_is_its_placed_patches(p):
    assume(p.structure.startswith(("split", "square")))
    assert predicted_patches(p) == len(paper_origins(p)[0])


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.floats(0.8, 6.0),
    st.floats(0.2, 2.0),
    st.floats(0.0, 3.0),
    st.floats(0.05, 1.5),
    st.sampled_from([0.0, 90.0, 180.0, 270.0]),
)
def test_the_predicted_count_of_a_conforming_square_ring_is_its_placed_rectangles(
    inner, size, spacing, gap, angle
):
    # issue 30's third fuzz run: the count placed every rectangle (MemoryError at 1e-6 mm
    # steps round a 1 mm ring); it is arithmetic now, and must stay the placed count
    try:
        p = MeshParams(
            structure="square_split_double_ring",
            mode="conforming",
            inner_radius=inner,
            outer_radius=inner + size + spacing,
            patch_size=size,
            gap_width=gap,
            gap_angle=angle,
        )
    except ValueError:
        assume(False)
    assert predicted_patches(p) == len(conforming_square_rects(p)[0])


def test_a_conforming_square_ring_of_micron_steps_is_refused_without_placing_it():
    # issue 30's third fuzz run: 1e-6 mm steps round a 1 mm ring, 16 million rectangles
    # (2 rings x 4 sides x 2 million) placed as Python tuples to be counted
    out, peak = peak_bytes(
        lambda: MeshParams(
            structure="square_split_double_ring",
            mode="conforming",
            inner_radius=1.0,
            outer_radius=1.000003,
            patch_size=1e-06,
            gap_width=0.5,
            max_triangles=4000,
        )
    )
    assert isinstance(out, ValueError) and "max_triangles=4,000" in str(out), out
    assert peak < 50e6, peak

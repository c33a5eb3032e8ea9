"""Invariants over random parameters (hypothesis), valid and hostile.

``make fuzz`` runs the hostile fuzz with 50,000 examples (``BARYMESH_FUZZ_EXAMPLES``).
"""

import dataclasses
import functools
import os
import tempfile
from pathlib import Path

import numpy as np
import pytest
from helpers import (
    address_space_cap,
    assert_clear_message,
    assert_topology_matches_generic,
    signed_areas,
)
from hypothesis import HealthCheck, assume, event, example, given, settings
from hypothesis import strategies as st
from scipy.spatial import cKDTree

from barymesh import STRUCTURES, MeshParams, build_mesh
from barymesh.io import read_mesh, write_mesh
from barymesh.structures import layout
from barymesh.topology import edge_topology

RINGS = ["ring", "double_ring", "split_ring", "split_double_ring", "square_split_double_ring"]


@st.composite
def params(draw, modes=("paper", "conforming")):
    structure = draw(st.sampled_from(RINGS + ["patch", "triangle"]))
    inner = draw(st.floats(0.8, 6.0))
    size = draw(st.floats(0.2, 2.0))
    outer = inner + size + draw(st.floats(0.0, 3.0))
    kw = dict(
        structure=structure,
        mode=draw(st.sampled_from(modes)),
        inner_radius=inner,
        outer_radius=outer,
        patch_size=size,
        angle_step=draw(st.floats(4.0, 120.0)),
        subdivisions=draw(st.integers(1, 5)),
        diagonal=draw(st.sampled_from(["BC", "AD"])),
        gap_width=draw(st.floats(0.05, 1.9)) * inner,
        gap_angle=draw(st.sampled_from([0.0, 90.0, 180.0]))
        if structure.startswith("square")
        else draw(st.floats(-360, 360)),
        origin=(draw(st.floats(-5, 5)), draw(st.floats(-5, 5))),
    )
    try:
        return MeshParams(**kw)
    except ValueError:
        assume(False)


def expected_euler(p):
    """V - E + F: 0 per closed ring, 1 per arc or patch."""
    rings = (
        2 if p.structure in ("double_ring", "split_double_ring", "square_split_double_ring") else 1
    )
    if (
        rings == 2
        and p.mode == "conforming"
        and abs(p.outer_radius - (p.inner_radius + p.patch_size)) <= p.weld_tolerance
    ):
        rings = 1  # touching rings (within the welding tolerance) are glued into one band
    if p.structure in ("patch", "triangle"):
        return 1
    if p.structure in ("ring", "double_ring"):
        return 0
    return rings * (1 if p.structure == "split_ring" else 2)


SETTINGS = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@SETTINGS
@given(params(modes=("conforming",)))
def test_conforming_meshes_are_manifold(p):
    mesh = build_mesh(p)
    valence = mesh.topology.valence
    assert valence.min() >= 1 and valence.max() <= 2
    assert mesh.stats()["euler_characteristic"] == expected_euler(p)
    assert_topology_matches_generic(mesh)


@SETTINGS
@given(params())
@example(  # a wide slot and coarse sectors: the end sectors' chords used to cross
    MeshParams(
        structure="split_ring",
        mode="conforming",
        inner_radius=3.0,
        outer_radius=3.5,
        patch_size=0.5,
        angle_step=66.0,
        subdivisions=1,
        gap_width=5.25,
    )
)
def test_triangles_are_proper_and_centroids_inside(p):
    mesh = build_mesh(p)
    assert (signed_areas(mesh) > 0).all()
    # barycentric coordinates of each centroid in its triangle are all positive
    pts = mesh.points[mesh.triangles][:, :, :2]
    c = mesh.centroids[:, :2]
    d1, d2, d = pts[:, 1] - pts[:, 0], pts[:, 2] - pts[:, 0], c - pts[:, 0]
    det = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    s = (d[:, 0] * d2[:, 1] - d[:, 1] * d2[:, 0]) / det
    t = (d1[:, 0] * d[:, 1] - d1[:, 1] * d[:, 0]) / det
    assert (s > 0).all() and (t > 0).all() and (s + t < 1).all()


@SETTINGS
@given(params())
def test_connectivity_is_symmetric_with_two_entries_per_shared_edge(p):
    mesh = build_mesh(p)
    conn = mesh.connectivity
    assert (conn != conn.T).nnz == 0
    if mesh.stats()["junction_edges"] == 0:
        assert conn.nnz == 2 * len(mesh.interior_edges)
    assert len(mesh.rwg) == len(mesh.interior_edges)


@SETTINGS
@given(params(modes=("paper",)))
def test_weld_merges_within_eps_and_never_beyond(p):
    if p.structure == "triangle":
        return
    lay = layout(p)
    mesh = build_mesh(p)
    eps = p.weld_tolerance
    flat = lay.xy.reshape(-1, 2)
    # every patch point is within ε of the vertex it became
    moved = np.linalg.norm(flat - mesh.points[lay.vertex_of_point, :2], axis=1)
    assert moved.max() <= eps
    # and no two distinct vertices are within ε of each other
    assert len(cKDTree(mesh.points[:, :2]).query_pairs(eps)) == 0


# -- hostile parameters: a clean error or a sound mesh ---------------------------------

FIELDS = tuple(f.name for f in dataclasses.fields(MeshParams))
#: Examples of the hostile fuzz: 2,000 in the normal run, 50,000 with ``make fuzz``.
FUZZ_EXAMPLES = int(os.environ.get("BARYMESH_FUZZ_EXAMPLES", "2000"))
#: Triangle budget inside the fuzz: large meshes are refused quickly, small ones checked fully.
FUZZ_BUDGET = 4_000
#: Meshes up to this size also go through a writer and back.
ROUND_TRIP_LIMIT = 1_000
#: Memory one hostile case may take beyond the test process (issue 30: the runaways took
#: 2 to 4.4 GB before their refusal); a budget of 4,000 triangles needs a few MB.
HOSTILE_MEMORY = 1 << 30
WRITERS = (".msh", ".vtu", ".vtp", ".vtk", ".stl", ".obj", ".mat")

NASTY = [
    0.0,
    -1.0,
    float("inf"),
    float("-inf"),
    float("nan"),
    5e-324,
    1e-320,
    1e-200,
    1e-15,
    1e17,
    1e300,
    10**400,
    -(10**400),
    "4,5",
    [1, 2],
    True,
    False,
    np.True_,
    np.array([1.0, 2.0]),
    None,
    {},
    {"a": 1},
    "x" * 3000,
    functools.reduce(lambda v, _: [v], range(900), 1.0),
]


def magnitude(lo=-320, hi=320):
    """Floats spread over decades (mantissa times a power of ten), inf past float64."""
    return st.builds(
        lambda m, e: m * 10.0**e if e < 308 else m * 1e300 * 10.0 ** (e - 300),
        st.floats(1.0, 9.99),
        st.integers(lo, hi),
    )


#: Values any parameter may be given by a hostile caller, beside its own extremes.
WILD = st.one_of(magnitude(), st.sampled_from(NASTY))
#: Extremes of each parameter a hostile caller may set (the others stay ordinary).
EXTREMES = {
    "inner_radius": WILD,
    "outer_radius": WILD,
    "patch_size": WILD,
    "patch_width": WILD,
    "tolerance": st.one_of(WILD, st.sampled_from([0.05, 0.1, 0.0562, 1e-14])),
    "angle_step": st.one_of(magnitude(-325, 3), st.sampled_from([1e-320, 5e-324, 0.0988, 361.0])),
    "subdivisions": st.sampled_from([0, 65, 7, 2.0, 2.5, 10**400, "3", None]),
    "gap_angle": st.one_of(magnitude(-5, 400), st.sampled_from(NASTY)),
    "origin": st.one_of(
        st.tuples(magnitude(), magnitude()),
        st.sampled_from([(1e17, 0.0), (1.0,), "xy", (float("nan"), 0), None]),
    ),
    "triangle_vertices": st.one_of(
        st.lists(st.tuples(magnitude(), magnitude()), min_size=3, max_size=3),
        st.sampled_from([[1, 2, 3], [(0, 0), (1, 0)], [(0, 0), (1, 1), (2, 2)], "abc"]),
    ),
    "structure": st.sampled_from(["Ring", "", None, 3]),
    "max_triangles": st.sampled_from([0, -1, 1, 2.5, True, 10**400]),
    "grading": st.sampled_from([True, 1, "yes", None, np.True_]),
    "growth_ratio": st.one_of(WILD, st.sampled_from([1.0, 1.0 + 1e-12, 2.0, 2.0 + 1e-12])),
    "min_edge": WILD,
    # issue 4: sizing targets float64 cannot mesh, booleans, slots within the weld tolerance
    "max_edge": st.one_of(WILD, st.sampled_from([1e-200, 5e-324, 1e-71, 1e-8, 0.05])),
    "frequency": st.one_of(WILD, st.sampled_from([1e9, 1e11, 1e30])),
    "cells_per_wavelength": WILD,
    "relative_permittivity": WILD,
    "gap_width": st.one_of(WILD, magnitude(-14, -6), st.sampled_from([1e-10, 11.9, 12.0])),
}


# strategies built once (building them inside the composite costs more than the mesh)
SCALE = st.one_of(st.just(1.0), st.just(1.0), magnitude(-120, 120))
RATIO = st.one_of(st.floats(0.05, 2.0), magnitude(-12, 1))
RING_GAP = st.one_of(st.floats(0.0, 1.0), st.floats(0.0, 1e-6))
OPENING = st.one_of(
    st.floats(0.01, 1.05),
    st.sampled_from([1 - 1e-9, 1 - 1e-8]),
    st.sampled_from([1e-11, 1e-9, 3e-9, 1e-8]),
)  # slots near the weld tolerance
ANGLE_STEP = st.one_of(
    st.floats(2.0, 120.0),
    st.floats(0.05, 360.0),
    st.sampled_from([360.0, 120.0, 90.0, 60.0, 0.5, 0.2, 0.0988]),
)
SUBDIVISIONS = st.one_of(st.integers(1, 4), st.integers(1, 64))
GAP_ANGLE = st.one_of(st.sampled_from([0.0, 90.0, 180.0, 270.0, -90.0]), st.floats(-720, 720))
ORIGIN = st.one_of(
    st.just((0.0, 0.0)),
    st.tuples(st.floats(-10, 10), st.floats(-10, 10)),
    st.tuples(magnitude(-3, 12), magnitude(-3, 12)),
)
TRIANGLE = st.lists(st.tuples(st.floats(-10, 10), st.floats(-10, 10)), min_size=3, max_size=3)
WILD_NAMES = st.one_of(st.just(()), st.lists(st.sampled_from(sorted(EXTREMES)), max_size=2))
#: Growth ratios of a graded mesh, with issue 30's ratios next to 1 (millions of sectors).
GROWTH = st.one_of(
    st.floats(1.01, 2.0), st.sampled_from([1 + 1e-9, 1 + 1e-7, 1.0000001, 1 + 1e-5, 1.001])
)


@st.composite
def hostile(draw):
    """Keyword arguments of MeshParams over every structure x mode x scheme x diagonal.

    An ordinary structure, often scaled as a whole by up to 1e±120 or moved far
    from the origin, with none, one or two parameters set to an extreme value.
    """
    structure = draw(st.sampled_from(STRUCTURES))
    scale = draw(SCALE)
    inner = draw(st.floats(0.3, 12.0))
    size = inner * draw(RATIO)
    scheme = draw(st.sampled_from(["uniform", "barycentric"]))
    kw = dict(
        structure=structure,
        mode=draw(st.sampled_from(["paper", "conforming"])),
        scheme=scheme,
        diagonal=draw(st.sampled_from(["BC", "AD"])),
        inner_radius=inner * scale,
        outer_radius=(inner + size * (1 + 2 * draw(RING_GAP))) * scale,
        patch_size=size * scale,
        angle_step=draw(ANGLE_STEP),
        subdivisions=draw(SUBDIVISIONS if scheme == "uniform" else st.integers(1, 3)),
        gap_width=2 * inner * draw(OPENING) * scale,
        gap_angle=draw(GAP_ANGLE),
        origin=tuple(c * scale for c in draw(ORIGIN)),
        max_triangles=FUZZ_BUDGET,
    )
    if draw(st.integers(0, 3)) == 0:
        kw["tolerance"] = scale * draw(magnitude(-16, -1))
    if draw(st.integers(0, 4)) == 0:
        kw["patch_width"] = size * scale * draw(st.floats(0.1, 3.0))
    if draw(st.integers(0, 5)) == 0:  # graded toward the metal edges
        kw["grading"] = True
        kw["growth_ratio"] = draw(GROWTH)
        if draw(st.booleans()):
            kw["min_edge"] = size * scale * draw(magnitude(-6, 0))
    if structure == "triangle" and draw(st.booleans()):
        kw["triangle_vertices"] = [(x * scale, y * scale) for x, y in draw(TRIANGLE)]
    for name in draw(WILD_NAMES):
        kw[name] = draw(EXTREMES[name])
    return kw


def names_a_parameter(message):
    return any(f"{name}=" in message for name in FIELDS) or "unknown parameter" in message


def assert_sound(mesh, p):
    """The mesh is finite, not flat, counter-clockwise, manifold in conforming mode, consistent."""
    pts, tri = mesh.points, mesh.triangles
    assert np.isfinite(pts).all()
    corners = pts[tri][:, :, :2]
    sides = corners[:, [1, 2, 0]] - corners
    longest = (sides**2).sum(axis=2).max(axis=1)
    area = signed_areas(mesh)
    assert (area >= 1e-12 * longest).all(), "a triangle is clockwise or flat"
    slow = edge_topology(tri, mesh.n_vertices)
    # the metric constraint: no two vertices within the welding tolerance stay apart
    near = cKDTree(pts[:, :2]).query_pairs(p.weld_tolerance)
    assert not near, f"{len(near)} vertex pairs within the tolerance {p.weld_tolerance:g} mm"
    if p.mode == "conforming":
        assert slow.valence.max() <= 2, "an edge on three or more triangles"
        assert len(np.unique(pts[:, :2], axis=0)) == mesh.n_vertices, "a duplicate vertex"
    s = mesh.stats()
    assert (s["triangles"], s["vertices"]) == (len(tri), len(pts))
    assert s["edges"] == len(slow.edges)
    assert s["edges"] == s["interior_edges"] + s["boundary_edges"] + s["junction_edges"]
    assert s["euler_characteristic"] == len(pts) - len(slow.edges) + len(tri)
    assert s["area"] == pytest.approx(area.sum(), rel=1e-9)
    assert len(mesh.rwg) == s["interior_edges"]
    conn = mesh.connectivity
    assert (conn != conn.T).nnz == 0
    if s["junction_edges"] == 0:
        assert conn.nnz == 2 * s["interior_edges"]
    if mesh.repetition is not None:  # the repeated fast path equals the general sort
        fast = mesh.topology
        assert np.array_equal(
            edge_rows(fast.edges, fast.edge_triangles, fast.valence),
            edge_rows(slow.edges, slow.edge_triangles, slow.valence),
        )
        assert np.array_equal(fast.edges[fast.triangle_edges], slow.edges[slow.triangle_edges])


def edge_rows(edges, edge_triangles, valence):
    """(E, 5) rows (v0, v1, t0, t1, valence) sorted by edge: order-free comparison."""
    rows = np.column_stack([edges, edge_triangles, valence]).astype(np.int64)
    return rows[np.lexsort(rows[:, 1::-1].T)]


def assert_round_trip(mesh, ext):
    with tempfile.TemporaryDirectory() as folder:
        back = read_mesh(write_mesh(mesh, Path(folder) / f"mesh{ext}"))
    assert (back.n_triangles, back.n_vertices) == (mesh.n_triangles, mesh.n_vertices)
    assert back.stats()["area"] == pytest.approx(mesh.stats()["area"], rel=1e-6)
    scale = np.abs(mesh.points).max()
    got = np.sort(back.points[back.triangles].reshape(-1, 3), axis=0)
    want = np.sort(mesh.points[mesh.triangles].reshape(-1, 3), axis=0)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-9 * scale)


@settings(
    max_examples=FUZZ_EXAMPLES,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
@given(hostile(), st.sampled_from(WRITERS))
@example(  # issue 30's second fuzz run: 5e-324 mm steps along a square ring's side overflowed
    kw=dict(
        structure="square_split_double_ring",
        mode="conforming",
        inner_radius=1.0,
        outer_radius=2.0,
        patch_size=5e-324,
        angle_step=1e-320,
        subdivisions=1,
        gap_width=1.0,
        max_triangles=4000,
        tolerance=0.1,
    ),
    ext=".msh",
)
@example(  # issue 30: graded toward a slot with a ratio next to 1 (66 million sector ends)
    kw=dict(
        structure="split_double_ring",
        mode="conforming",
        inner_radius=29.18,
        outer_radius=30.405,
        patch_size=0.3169,
        angle_step=18.82,
        subdivisions=10,
        gap_width=12.07,
        gap_angle=540,
        grading=True,
        growth_ratio=1.0000001,
        max_triangles=300000,
    ),
    ext=".msh",
)
@example(  # issue 30's second fuzz run: the frequency's refusal ran to 305 characters
    kw=dict(
        structure="ring",
        mode="conforming",
        inner_radius=3.625,
        outer_radius=3.6250000725,
        patch_size=7.250000000000001e-08,
        angle_step=5.0,
        subdivisions=1,
        gap_width=7.25,
        max_triangles=4000,
        tolerance=1e-08,
        patch_width=7.250000000000001e-08,
        frequency=1e11,
    ),
    ext=".msh",
)
@example(  # issue 30's fourth fuzz run: an obtuse triangle's vertices 0.2 mm apart (no edge
    # between them) stayed apart at a tolerance of 0.2 mm, as its edges (>= 0.6 mm) allowed
    kw=dict(
        structure="triangle",
        subdivisions=5,
        tolerance=0.2,
        triangle_vertices=[(0.0, 0.0), (0.0, 3.0), (1.0, -3.0)],
    ),
    ext=".msh",
)
@example(  # issue 30's fourth fuzz run: a sliver flat for the mesh check (area 3.8e-11 mm²
    # against 49 mm² of its longest edge squared) passed the parameters' own check
    kw=dict(
        structure="triangle",
        subdivisions=1,
        triangle_vertices=[(0.0, 0.0), (0.0, 2.0), (3.7751805944196904e-11, 7.0)],
    ),
    ext=".msh",
)
@example(  # issue 30's sixth fuzz run: a paper ring 7e7 mm out, where float64 spaces numbers
    # 1.5e-8 mm apart, kept two pairs unwelded at the default tolerance of 9.1e-9 mm
    kw=dict(
        structure="double_ring",
        inner_radius=1.0,
        outer_radius=2.7793676905776676,
        patch_size=1.7793676905776679,
        angle_step=2.0,
        subdivisions=1,
        gap_width=2.0,
        origin=(1.0, 70000000.0),
    ),
    ext=".msh",
)
@example(  # issue 30's seventh fuzz run: a budget of 10**400 let 320 million triangles
    # through to the build, which allocated until MemoryError (each failing case kept its
    # arrays while Hypothesis shrank it: 22 GB); no mesh can be indexed past 715,827,882
    kw=dict(
        structure="square_split_double_ring",
        inner_radius=5.0,
        outer_radius=5.0000005,
        patch_size=5e-7,
        angle_step=2.0,
        subdivisions=1,
        gap_width=0.1,
        max_triangles=10**400,
    ),
    ext=".msh",
)
@example(  # issue 30's seventh fuzz run: the sizing's refusal of subdivisions=6 (a patch
    # 10 mm out) after a wavelength of 2.7e111 mm ran to 300 characters
    kw=dict(
        structure="patch",
        scheme="barycentric",
        inner_radius=1.0,
        outer_radius=1.0001,
        patch_size=0.0001,
        subdivisions=1,
        origin=(-10.0, -2.56618974881814e-187),
        max_triangles=4000,
        cells_per_wavelength=1.4687500000000002e117,
        frequency=1.09375e-100,
    ),
    ext=".msh",
)
def test_hostile_parameters_give_a_named_error_or_a_sound_mesh(kw, ext):
    try:
        with address_space_cap(HOSTILE_MEMORY):  # a runaway is a MemoryError, not a swap
            p = MeshParams(**kw)
            mesh = build_mesh(p)
    except ValueError as err:
        assert names_a_parameter(str(err)), str(err)
        assert_clear_message(str(err))
        event(f"refused: {str(err).split('=')[0][-20:]}")
        return
    event(f"built: {p.mode} {'small' if mesh.n_triangles <= ROUND_TRIP_LIMIT else 'large'}")
    assert_sound(mesh, p)
    if mesh.n_triangles <= ROUND_TRIP_LIMIT:
        assert_round_trip(mesh, ext)

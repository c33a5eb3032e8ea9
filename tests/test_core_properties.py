"""Invariants over random valid parameters (hypothesis)."""

import numpy as np
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st
from scipy.spatial import cKDTree

from core import MeshParams, build_mesh
from core.structures import layout
from tests.helpers import assert_topology_matches_generic, signed_areas

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
        and p.outer_radius - p.inner_radius - p.patch_size < 1e-9
    ):
        rings = 1  # touching rings are welded into one band
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
    MeshParams(structure="split_ring", mode="conforming", inner_radius=3.0, outer_radius=3.5,
               patch_size=0.5, angle_step=66.0, subdivisions=1, gap_width=5.25)
)  # fmt: skip
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

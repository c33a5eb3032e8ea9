"""Counts and geometry of every structure, in both modes, against the paper and the issue."""

import math

import numpy as np
import pytest
from helpers import assert_topology_matches_generic, components, signed_areas

from barymesh import MeshParams, build_mesh


def counts(mesh):
    s = mesh.stats()
    return (
        s["patches"],
        s["triangles"],
        s["vertices"],
        s["edges"],
        s["interior_edges"],
        s["boundary_edges"],
    )


@pytest.mark.parametrize("n", [1, 2, 3, 4, 6, 9])
def test_square_patch_counts(n):
    mesh = build_mesh(MeshParams(structure="patch", subdivisions=n, patch_size=10.0))
    assert counts(mesh) == (1, 2 * n * n, (n + 1) ** 2, 3 * n * n + 2 * n, 3 * n * n - 2 * n, 4 * n)
    assert mesh.stats()["euler_characteristic"] == 1
    assert mesh.stats()["area"] == pytest.approx(100.0)


def test_paper_fig10_patch():
    """Fig. 10: a 10 x 10 mm patch is 32 triangles, 25 vertices, 56 edges, 40 shared."""
    mesh = build_mesh(MeshParams(structure="patch", patch_size=10.0))
    assert counts(mesh) == (1, 32, 25, 56, 40, 16)
    assert mesh.stats()["junction_edges"] == 0
    # the corners A, B, C, D and the paper's diagonal BC
    corners = {tuple(p) for p in mesh.points[:, :2].tolist()}
    assert {(0, 0), (10, 0), (0, 10), (10, 10)} <= corners
    assert mesh.connectivity.shape == (32, 32) and mesh.connectivity.nnz == 80
    # the centroids are the quadrature points: one per triangle, inside the square
    assert mesh.centroids.shape == (32, 3)
    assert ((mesh.centroids[:, :2] > 0) & (mesh.centroids[:, :2] < 10)).all()


def test_rectangular_patch_and_origin():
    mesh = build_mesh(MeshParams(structure="patch", patch_size=4, patch_width=2, origin=(1, 1)))
    assert mesh.points[:, 0].min() == 1 and mesh.points[:, 0].max() == 5
    assert mesh.points[:, 1].min() == 1 and mesh.points[:, 1].max() == 3
    assert mesh.stats()["area"] == pytest.approx(8.0)


@pytest.mark.parametrize("diagonal", ["BC", "AD"])
def test_diagonal_choice(diagonal):
    mesh = build_mesh(MeshParams(structure="patch", subdivisions=1, diagonal=diagonal))
    ((a, b),) = [tuple(e) for e in mesh.edges[mesh.interior_edges]]
    ends = {tuple(mesh.points[a, :2]), tuple(mesh.points[b, :2])}
    assert ends == ({(1.0, 0.0), (0.0, 1.0)} if diagonal == "BC" else {(0.0, 0.0), (1.0, 1.0)})


@pytest.mark.parametrize(
    ("patch_size", "angle_step", "patches", "triangles"),
    [(1, 1, 720, 23_040), (2, 1, 720, 23_040), (2, 10, 72, 2_304), (1, 20, 36, 1_152)],
    ids=["fig12a", "fig12b", "fig12c", "fig12d"],
)
def test_paper_fig12_double_rings(patch_size, angle_step, patches, triangles):
    p = MeshParams(patch_size=patch_size, angle_step=angle_step)
    mesh = build_mesh(p)
    s = mesh.stats()
    assert (s["patches"], s["triangles"]) == (patches, triangles)
    assert p.predicted_triangles() == triangles
    # patches share no vertices at these angles: each keeps 25 vertices and 40 shared edges
    assert s["vertices"] == 25 * patches
    assert s["interior_edges"] == 40 * patches
    assert s["junction_edges"] == 0
    # lower-left corners lie on the circles (Eqs. 28-29)
    lower_left = mesh.points[mesh.triangles[::32, 0], :2]
    assert np.isin(np.round(np.hypot(*lower_left.T), 9), [4.0, 9.0]).all()
    # patches overlap where their spacing r Δθ is below the patch size
    expect_overlap = 4 * math.radians(angle_step) < patch_size
    assert (s["overlap_ratio"] > 0.01) == expect_overlap


def test_paper_ring_patch_positions():
    mesh = build_mesh(MeshParams(structure="ring", angle_step=90, inner_radius=5, patch_size=1))
    origins = mesh.patch_rects[:, :2]
    assert np.allclose(origins, [[5, 0], [0, 5], [-5, 0], [0, -5]], atol=1e-12)
    assert np.allclose(mesh.patch_rects[:, 2:] - origins, 1.0)


def test_conforming_ring_issue_example():
    """r = 4, patch 1, 10°, n = 4: 111 square-ish cells round the circle.

    Square cells at the track's geometric mean radius √20 mm need 2π √20 x 4 = 112.4
    cells; 37 sectors (≤ 10°) of 4 x 3 cells make 111: 888 triangles (was 36 sectors
    of 4 x 4 cells, 1152), 555 vertices, 1443 edges (V − E + F = 0), 222 on the circles.
    """
    mesh = build_mesh(MeshParams(structure="ring", mode="conforming", angle_step=10))
    assert counts(mesh) == (37, 888, 555, 1443, 1221, 222)
    assert mesh.stats()["euler_characteristic"] == 0
    assert mesh.stats()["junction_edges"] == 0
    assert mesh.stats()["min_angle_deg"] >= 30.0
    # vertices on the true circles r + k h / n
    radius = np.hypot(mesh.points[:, 0], mesh.points[:, 1])
    assert np.allclose(np.round(radius * 4) / 4, radius, atol=1e-12)
    assert_topology_matches_generic(mesh)


@pytest.mark.parametrize("angle_step", [1, 7, 10, 45, 120, 360])
@pytest.mark.parametrize("n", [1, 2, 4])
def test_conforming_ring_formula(angle_step, n):
    m_asked = max(3, math.ceil(360 / angle_step - 1e-9))  # at least three sectors
    mesh = build_mesh(
        MeshParams(structure="ring", mode="conforming", angle_step=angle_step, subdivisions=n)
    )
    m = mesh.n_patches
    cols = len(mesh.boundary_edges) // 2  # cells round the circle
    assert m >= m_asked and cols % m == 0  # sectors no wider than asked, n_v cells each
    assert cols <= n * m_asked  # never more triangles than n x n sectors
    assert mesh.n_triangles == 2 * n * cols
    assert mesh.n_vertices == (n + 1) * cols
    assert len(mesh.boundary_edges) == 2 * cols
    assert mesh.stats()["euler_characteristic"] == 0
    assert mesh.topology.valence.max() <= 2
    assert_topology_matches_generic(mesh)


def test_conforming_double_ring_is_two_closed_rings():
    mesh = build_mesh(MeshParams(mode="conforming", angle_step=10))
    s = mesh.stats()
    assert (s["patches"], s["triangles"], s["euler_characteristic"], s["regions"]) == (
        72,
        2304,
        0,
        2,
    )
    assert components(mesh) == 2
    assert set(np.unique(mesh.regions)) == {1, 2}
    assert "overlap_ratio" not in s


def test_touching_conforming_rings_are_one_band():
    mesh = build_mesh(MeshParams(mode="conforming", angle_step=10, inner_radius=4, outer_radius=5))
    assert components(mesh) == 1
    # both rings cut alike (41 sectors of 4 x 3 cells, 123 cells round each circle): only
    # the innermost and outermost circles are boundary (was 36 sectors of 4 x 4, 2 x 144)
    cells = mesh.n_triangles // (2 * 2 * 4)
    assert (mesh.n_patches, cells) == (82, 123)
    assert mesh.stats()["boundary_edges"] == 2 * cells
    assert mesh.stats()["euler_characteristic"] == 0
    assert mesh.topology.valence.max() == 2
    assert_topology_matches_generic(mesh)


def _slot_distance(points, angle):
    u = np.array([math.cos(math.radians(angle)), math.sin(math.radians(angle))])
    along = points[:, :2] @ u
    across = points[:, 1] * u[0] - points[:, 0] * u[1]
    return along, across


@pytest.mark.parametrize("gap_angle", [0, 33, 180, 270])
def test_conforming_split_ring_ends_on_slot_sides(gap_angle):
    p = MeshParams(
        structure="split_ring", mode="conforming", angle_step=10, gap_width=1.2, gap_angle=gap_angle
    )
    mesh = build_mesh(p)
    s = mesh.stats()
    assert s["euler_characteristic"] == 1 and s["junction_edges"] == 0
    assert mesh.topology.valence.max() == 2
    along, across = _slot_distance(mesh.points, gap_angle)
    facing = along > 0
    # no metal inside the slot, and the two end columns (n + 1 vertices each) lie on its sides
    assert (np.abs(across[facing]) >= 0.6 - 1e-9).all()
    on_side = np.isclose(np.abs(across), 0.6, atol=1e-9) & facing
    assert on_side.sum() == 2 * (p.subdivisions + 1)
    radius = np.hypot(mesh.points[:, 0], mesh.points[:, 1])
    assert np.allclose(np.round(radius * 4) / 4, radius, atol=1e-12)
    # sectors no wider than the angle step
    span = 360 - 2 * math.degrees(math.asin(0.6 / 5))
    assert s["patches"] == math.ceil(span / 10)
    assert_topology_matches_generic(mesh)


def _rect_in_slot(rects, angle, width, both_sides):
    """Brute force: does a fine grid of sample points of each rectangle fall in the slot?"""
    t = np.linspace(0.001, 0.999, 40)
    gx, gy = np.meshgrid(t, t)
    hit = []
    for x0, y0, x1, y1 in rects:
        pts = np.stack([x0 + gx.ravel() * (x1 - x0), y0 + gy.ravel() * (y1 - y0)], 1)
        along, across = _slot_distance(pts, angle)
        inside = np.abs(across) < width / 2
        if not both_sides:
            inside &= along > 0
        hit.append(inside.any())
    return np.array(hit)


@pytest.mark.parametrize("gap_angle", [0, 20, 90, 135])
def test_paper_split_rings_drop_patches_in_the_slot(gap_angle):
    whole = build_mesh(MeshParams(structure="ring", angle_step=5))
    split = build_mesh(MeshParams(structure="split_ring", angle_step=5, gap_angle=gap_angle))
    assert not _rect_in_slot(split.patch_rects, gap_angle, 1.0, False).any()
    dropped = _rect_in_slot(whole.patch_rects, gap_angle, 1.0, False)
    assert dropped.sum() > 0
    assert split.n_patches == whole.n_patches - dropped.sum()
    double = build_mesh(
        MeshParams(structure="split_double_ring", angle_step=5, gap_angle=gap_angle)
    )
    assert not _rect_in_slot(double.patch_rects, gap_angle, 1.0, True).any()


def test_conforming_doubly_split_double_ring():
    p = MeshParams(structure="split_double_ring", mode="conforming", angle_step=5)
    mesh = build_mesh(p)
    assert components(mesh) == 4
    assert mesh.stats()["euler_characteristic"] == 4
    assert mesh.topology.valence.max() == 2
    assert_topology_matches_generic(mesh)


@pytest.mark.parametrize("mode", ["paper", "conforming"])
@pytest.mark.parametrize("gap_angle", [0, 90])
def test_square_doubly_split_double_ring(mode, gap_angle):
    p = MeshParams(
        structure="square_split_double_ring",
        mode=mode,
        gap_angle=gap_angle,
        inner_radius=4,
        outer_radius=6,
    )
    mesh = build_mesh(p)
    # two square rings, each cut by two slots: four pieces, each a disc
    assert components(mesh) == 4
    assert mesh.stats()["euler_characteristic"] == 4
    assert mesh.topology.valence.max() == 2
    # the tracks: between the squares of half side r and r + h
    x, y = np.abs(mesh.points[:, 0]), np.abs(mesh.points[:, 1])
    cheb = np.maximum(x, y)
    assert ((cheb >= 4 - 1e-9) & (cheb <= 5 + 1e-9) | (cheb >= 6 - 1e-9) & (cheb <= 7 + 1e-9)).all()
    across = y if gap_angle == 0 else x
    assert (across[cheb > 0] >= 0.5 - 1e-9).all()
    if mode == "conforming":
        # metal area: two square tracks minus the four slot crossings
        metal = (7**2 - 6**2 + 5**2 - 4**2) * 4 - 4 * 1.0 * 1.0
        assert mesh.stats()["area"] == pytest.approx(metal)


def test_equilateral_triangle():
    mesh = build_mesh(MeshParams(structure="triangle", patch_size=3))
    assert (mesh.n_triangles, mesh.n_vertices) == (16, 15)
    assert mesh.stats()["min_angle_deg"] == pytest.approx(60)
    assert mesh.stats()["area"] == pytest.approx(math.sqrt(3) / 4 * 9)


def test_triangle_from_any_vertices_keeps_orientation():
    mesh = build_mesh(
        MeshParams(structure="triangle", triangle_vertices=((0, 0), (0, 4), (3, 0)), subdivisions=3)
    )
    assert mesh.n_triangles == 9
    assert (signed_areas(mesh) > 0).all()
    assert mesh.stats()["area"] == pytest.approx(6.0)


@pytest.mark.parametrize(
    "kw",
    [
        {},
        {"mode": "conforming", "angle_step": 10},
        {"structure": "split_double_ring", "mode": "conforming", "angle_step": 10},
        {"structure": "square_split_double_ring"},
        {"structure": "patch", "scheme": "barycentric", "subdivisions": 2},
        {
            "structure": "ring",
            "mode": "conforming",
            "scheme": "barycentric",
            "subdivisions": 2,
            "angle_step": 15,
        },
    ],
)
def test_every_triangle_is_counter_clockwise_and_non_degenerate(kw):
    mesh = build_mesh(MeshParams(**kw))
    assert (signed_areas(mesh) > 1e-6).all()


def test_barycentric_conforming_ring_is_manifold():
    mesh = build_mesh(
        MeshParams(
            structure="ring", mode="conforming", scheme="barycentric", subdivisions=2, angle_step=15
        )
    )
    assert mesh.n_triangles == 24 * 2 * 36
    assert mesh.topology.valence.max() == 2
    assert mesh.stats()["euler_characteristic"] == 0
    assert_topology_matches_generic(mesh)


def test_build_mesh_stops_when_cancel_says_so():
    from barymesh import BuildCancelled

    calls = []

    def cancel():
        calls.append(1)
        return len(calls) >= 2  # let the first checkpoint pass, stop at the second

    with pytest.raises(BuildCancelled):
        build_mesh(MeshParams(), cancel=cancel)
    assert len(calls) == 2
    patch = build_mesh(MeshParams(structure="patch"), cancel=lambda: False)
    assert patch.stats()["triangles"] == 32

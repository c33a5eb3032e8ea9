"""Edge-graded meshes: the paper's topology kept, nodes crowded toward the metal's edges.

Checked here: with grading off every mesh is bit for bit what it was before grading existed
(digests computed with that code, ``tests/data/ungraded_mesh_digests.json``); a graded mesh
has the uniform mesh's triangles, edges and RWG table (only the points move); its nodes
crowd toward the outer edges (and not toward sides that continue into metal); hypothesis
property tests of the invariants. The convergence the grading is for:
``tests/test_mom_convergence.py``.
"""

from __future__ import annotations

import json
from pathlib import Path

import mesh_digests
import numpy as np
import pytest
from helpers import signed_areas
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from barymesh import MeshParams, build_mesh
from barymesh.cell import Element, Lattice, PixelGrid, UnitCell, build_cell, cell_from_dict
from barymesh.grading import (
    CORE_SLOPE,
    coons_uv,
    edge_nodes,
    first_cell,
    graded_barycentric,
    outline_sides,
)
from barymesh.subdivision import graded_patch_template, patch_template, uniform_subdivision

DATA = Path(__file__).parent / "data" / "ungraded_mesh_digests.json"
RWG_COLUMNS = ("edge", "vertices", "t_plus", "t_minus", "free_vertex_plus", "free_vertex_minus")


def assert_same_rwg_table(graded, uniform):
    """The same RWG table row for row, all but the edge lengths (the points moved)."""
    assert len(graded.rwg) == len(uniform.rwg)
    for name in RWG_COLUMNS:
        a, b = getattr(graded.rwg, name), getattr(uniform.rwg, name)
        np.testing.assert_array_equal(a, b, err_msg=name)


PROPERTY = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])


# -- with grading off, nothing moved ----------------------------------------------------------


def test_meshes_without_grading_are_bit_for_bit_those_made_before_grading_existed():
    stored = json.loads(DATA.read_text(encoding="utf-8"))
    now = mesh_digests.all_digests()
    assert set(now) == set(stored["digests"])
    assert len(now) >= 70  # every structure x mode x scheme x diagonal, presets, cells
    changed = sorted(k for k in now if now[k] != stored["digests"][k])
    assert changed == [], changed


def test_the_default_parameters_are_unchanged():
    p = MeshParams()
    assert (p.subdivisions, p.grading, p.structure, p.mode) == (4, False, "double_ring", "paper")
    assert MeshParams(structure="patch").subdivisions == 4  # ungraded: the paper's n = 4


# -- the 1-D nodes ------------------------------------------------------------------------------


@pytest.mark.parametrize("n", [1, 2, 3, 4, 7, 8, 16, 33, 64])
def test_edge_nodes_run_from_0_to_1_and_are_symmetric(n):
    nodes = edge_nodes(n)
    assert nodes[0] == 0.0 and nodes[-1] == 1.0 and len(nodes) == n + 1
    assert (np.diff(nodes) > 0).all()
    np.testing.assert_allclose(nodes + nodes[::-1], 1.0, atol=1e-15)
    one = edge_nodes(n, True, False)
    np.testing.assert_allclose(one, 2 * edge_nodes(2 * n)[: n + 1], atol=1e-15)  # half of 2n
    np.testing.assert_allclose(edge_nodes(n, False, True), 1 - one[::-1], atol=1e-15)
    assert edge_nodes(n, False, False).tolist() == (np.arange(n + 1) / n).tolist()


def test_edge_nodes_crowd_toward_the_ends_as_n_to_the_minus_4():
    for n in (16, 32, 64):
        cells = np.diff(edge_nodes(n))
        # the first cell: 34.2 / n^4 (power-4 layer); the core: 1.5 / n
        assert cells[0] == pytest.approx(34.17 / n**4, rel=1e-3)
        assert cells[n // 2] == pytest.approx(CORE_SLOPE / n, rel=1e-12)
        assert cells.max() <= CORE_SLOPE / n * (1 + 1e-12)
        assert (np.diff(cells[: n // 2]) >= -1e-15).all()  # growing toward the middle
    assert first_cell(16) == pytest.approx(np.diff(edge_nodes(16, True, False))[0])


# -- the template: same topology, points moved --------------------------------------------


@pytest.mark.parametrize("diagonal", ["BC", "AD"])
@pytest.mark.parametrize("n", [1, 2, 5, 16])
def test_graded_template_has_the_uniform_topology(n, diagonal):
    g, u = graded_patch_template(n, diagonal), patch_template("uniform", n, diagonal)
    for name in ("triangles", "edges", "triangle_edges", "edge_triangles", "valence"):
        np.testing.assert_array_equal(getattr(g, name), getattr(u, name), err_msg=name)
    assert len(g.triangles) == 2 * n * n and len(g.uv) == (n + 1) ** 2
    # the grid (a, b) at (g(a/n), g(b/n)): the uniform one mapped by the nodes
    np.testing.assert_array_equal(g.uv, edge_nodes(n)[np.rint(u.uv * n).astype(int)])


@pytest.mark.parametrize("n", [1, 3, 6, 16, 40])
def test_every_coons_variant_keeps_triangles_counter_clockwise(n):
    types = [(a, b) for a in (False, True) for b in (False, True)]
    tri = patch_template("uniform", n, "BC").triangles
    for sides in [(s, t, s, t) for s in types for t in types] + [
        (types[1], types[2], types[3], types[0]),
        (types[0], types[1], types[2], types[1]),
    ]:
        u, v = coons_uv(n, sides)
        p = np.stack([u, v], 1)[tri]
        cross = (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1]) - (
            p[:, 1, 1] - p[:, 0, 1]
        ) * (p[:, 2, 0] - p[:, 0, 0])
        assert (cross > 0).all(), sides


@pytest.mark.parametrize("n", [1, 2, 4, 9, 16])
def test_graded_barycentric_keeps_the_edges_on_the_primary_edges(n):
    bary, tri = uniform_subdivision(n)
    g = graded_barycentric(bary, n)
    nodes = edge_nodes(n)
    on_base = np.rint(bary[:, 1] * n) == 0  # t = 0: the edge P0 P1
    np.testing.assert_allclose(np.sort(g[on_base, 0]), nodes, atol=1e-15)
    assert (g >= -1e-15).all() and (g.sum(axis=1) <= 1 + 1e-15).all()
    p = g[tri]
    cross = (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1]) - (p[:, 1, 1] - p[:, 0, 1]) * (
        p[:, 2, 0] - p[:, 0, 0]
    )
    assert (cross > 0).all()


# -- structures: counts and topology of the uniform mesh --------------------------------------

GRADED = [
    dict(structure="patch", patch_size=8.0),
    dict(structure="patch", patch_size=5.0, patch_width=2.0, subdivisions=6, diagonal="AD"),
    dict(structure="triangle", subdivisions=9),
    dict(structure="triangle", triangle_vertices=[(0, 0), (3, 0.5), (1, 2)], subdivisions=5),
    dict(structure="double_ring", angle_step=15.0, subdivisions=3),  # paper: every patch
    dict(structure="square_split_double_ring", mode="paper", patch_size=0.5),
    dict(
        structure="square_split_double_ring",
        mode="conforming",
        inner_radius=2.0,
        outer_radius=3.5,
        gap_width=0.6,
        subdivisions=5,
    ),
]


@pytest.mark.parametrize("kw", GRADED, ids=lambda kw: f"{kw['structure']}-{kw.get('mode', '')}")
def test_a_graded_mesh_has_the_uniform_mesh_s_counts_triangles_and_rwg_table(kw):
    graded = MeshParams(**kw, grading=True)
    if "subdivisions" not in kw and graded.structure == "patch":
        assert graded.subdivisions == 16  # a graded patch's accuracy default
    uniform = graded.replace(grading=False)
    g, u = build_mesh(graded), build_mesh(uniform)
    assert g.n_triangles == u.n_triangles == graded.predicted_triangles()
    assert g.n_vertices == u.n_vertices
    np.testing.assert_array_equal(g.triangles, u.triangles)
    np.testing.assert_array_equal(g.topology.edges, u.topology.edges)
    assert_same_rwg_table(g, u)
    assert (signed_areas(g) > 0).all()
    assert not np.array_equal(g.points, u.points)  # the nodes did move
    shortest = g.stats()["min_edge"]
    assert graded.min_spacing * (1 - 1e-9) <= shortest < u.stats()["min_edge"]


def test_a_graded_patch_crowds_toward_all_four_edges():
    mesh = build_mesh(MeshParams(structure="patch", patch_size=8.0, grading=True))
    xs = np.unique(mesh.points[:, 0])
    ys = np.unique(mesh.points[:, 1])
    np.testing.assert_allclose(xs, 8.0 * edge_nodes(16), atol=1e-12)
    np.testing.assert_allclose(ys, 8.0 * edge_nodes(16), atol=1e-12)
    cells = np.diff(xs)
    assert cells[0] < 0.01 * cells[8]  # 4.2 µm at the edge, 0.75 mm in the middle


def test_a_strip_across_the_cell_is_graded_across_and_even_along():
    strip = MeshParams(structure="patch", patch_size=5.0, patch_width=10.0, grading=True)
    cell = UnitCell(Lattice.rectangular(10.0), (Element(strip, position=(-2.5, -5.0)),))
    cm = build_cell(cell)
    pairs = cm.periodic_pairs
    assert pairs.matched and len(pairs.edges) == 16  # its ends' 16 edges, node for node
    ys, xs = np.unique(cm.mesh.points[:, 1]), np.unique(cm.mesh.points[:, 0])
    np.testing.assert_allclose(np.diff(ys), 10.0 / 16, rtol=1e-9)  # no metal edge along y
    np.testing.assert_allclose(xs + 2.5, 5.0 * edge_nodes(16), atol=1e-12)  # its two edges
    # the same patch short of the sides is graded all round
    short = UnitCell(Lattice.rectangular(12.0), (Element(strip, position=(-2.5, -5.0)),))
    ys = np.unique(build_cell(short).mesh.points[:, 1])
    np.testing.assert_allclose(ys + 5.0, 10.0 * edge_nodes(16), atol=1e-12)


# -- pixels ----------------------------------------------------------------------------------


def test_outline_sides_of_a_lone_patch_two_patches_and_a_strip_with_its_copies():
    assert outline_sides(np.array([[0.0, 0, 1, 1]])).all()
    s = outline_sides(np.array([[0.0, 0, 1, 1], [1, 0, 2, 1]]))
    # the left patch: bottom and top graded toward the left edge only; its left side toward
    # both ends (the outline at y = 0 and y = 1), its right side (shared) likewise
    assert s[0].tolist() == [[True, False], [True, True], [True, False], [True, True]]
    assert s[1].tolist() == [[False, True], [True, True], [False, True], [True, True]]
    strip = np.array([[0.0, 0, 1, 3]])
    copies = strip + np.array([[0, 3, 0, 3], [0, -3, 0, -3]])
    assert outline_sides(strip, copies)[0].tolist() == [[True, True], [False, False]] * 2


def test_outline_sides_grade_toward_a_re_entrant_corner():
    # an L of three unit squares; (1, 1) is the re-entrant corner
    rects = np.array([[0.0, 0, 1, 1], [1, 0, 2, 1], [0, 1, 1, 2]])
    s = outline_sides(rects)
    assert s[0, 1].tolist() == [True, True]  # the shared side x = 1 of the corner square
    assert s[0, 2].tolist() == [True, True]  # its shared top side: toward (1, 1)
    assert s[1, 3].tolist() == [True, True]


def test_graded_pixels_keep_the_uniform_topology_and_crowd_toward_the_outline():
    mask = np.array([[1, 1, 0, 1], [0, 1, 1, 1], [1, 1, 0, 0]], dtype=bool)
    plain = UnitCell(pixels=PixelGrid(mask, pixel_size=0.5, origin=(-1.0, -0.75)))
    graded = plain.replace(pixels=plain.pixels.replaced(grading=True))
    u, g = build_cell(plain).mesh, build_cell(graded).mesh
    np.testing.assert_array_equal(g.triangles, u.triangles)
    assert_same_rwg_table(g, u)
    assert (signed_areas(g) > 0).all()
    # the vertices on the outline stay on it (the pixels' straight sides)
    boundary = np.unique(g.topology.edges[g.topology.boundary_edges])
    on_lines = np.isclose(
        np.remainder(g.points[boundary, :2] - (-1.0, -0.75), 0.5), 0.0, atol=1e-12
    ) | np.isclose(np.remainder(g.points[boundary, :2] - (-1.0, -0.75), 0.5), 0.5, atol=1e-12)
    assert on_lines.any(axis=1).all()
    # next to the outline the nodes crowd: the shortest edge is the graded first cell
    assert g.stats()["min_edge"] == pytest.approx(0.5 * first_cell(4), rel=1e-6)
    assert u.stats()["min_edge"] == pytest.approx(0.125)


def test_graded_pixels_across_the_cell_sides_stay_periodic():
    cell = cell_from_dict(
        {
            "format": "barymesh-cell",
            "version": 1,
            "lattice": {"rectangular": [2.0, 2.0]},
            "pixels": {
                "pixel_size": 0.5,
                "origin": [-1.0, -1.0],
                "grading": True,
                "rows": ["0110", "1111", "0110", "0110"],
            },
        }
    )
    cm = build_cell(cell)
    assert cell.pixels.grading and cm.periodic_pairs.matched and len(cm.periodic_pairs.edges)
    assert cm.notes == ()


# -- property tests --------------------------------------------------------------------------


@st.composite
def graded_patches(draw):
    kw = dict(
        structure="patch",
        patch_size=draw(st.floats(0.01, 100.0)),
        patch_width=draw(st.none() | st.floats(0.01, 100.0)),
        subdivisions=draw(st.integers(1, 40)),
        diagonal=draw(st.sampled_from(["BC", "AD"])),
        origin=(draw(st.floats(-50, 50)), draw(st.floats(-50, 50))),
        grading=True,
    )
    try:
        return MeshParams(**kw)
    except ValueError:
        assume(False)


@PROPERTY
@given(graded_patches())
def test_graded_patches_keep_the_invariants(p):
    mesh = build_mesh(p)
    n, topo = p.subdivisions, mesh.topology
    assert mesh.n_triangles == 2 * n * n and mesh.n_vertices == (n + 1) ** 2
    assert topo.valence.max() <= 2
    assert mesh.n_vertices - len(topo.edges) + mesh.n_triangles == 1  # a disc
    assert len(mesh.rwg) == (3 * 2 * n * n - 4 * n) // 2  # interior edges
    assert (signed_areas(mesh) > 0).all()
    x0, y0 = p.origin
    xy = mesh.points[:, :2]
    tol = 1e-12 * (abs(x0) + abs(y0) + p.patch_size + p.patch_height)
    assert (xy[:, 0] >= x0 - tol).all() and (xy[:, 0] <= x0 + p.patch_size + tol).all()
    assert (xy[:, 1] >= y0 - tol).all() and (xy[:, 1] <= y0 + p.patch_height + tol).all()
    # the boundary vertices lie on the four sides, graded along them as edge_nodes(n)
    bottom = np.sort(xy[np.abs(xy[:, 1] - y0) <= tol, 0])
    np.testing.assert_allclose((bottom - x0) / p.patch_size, edge_nodes(n), atol=1e-9)


@st.composite
def pixel_masks(draw):
    rows, cols = draw(st.integers(1, 5)), draw(st.integers(1, 5))
    bits = draw(st.lists(st.booleans(), min_size=rows * cols, max_size=rows * cols))
    mask = np.array(bits, dtype=bool).reshape(rows, cols)
    assume(mask.any())
    return mask, draw(st.integers(1, 5)), draw(st.sampled_from(["BC", "AD"]))


@PROPERTY
@given(pixel_masks())
def test_graded_pixel_grids_keep_the_invariants(case):
    mask, n, diagonal = case
    rows, cols = mask.shape
    grid = PixelGrid(mask, 1.0, (-cols / 2, -rows / 2), n, diagonal=diagonal, grading=True)
    cell = UnitCell(Lattice.rectangular(float(cols), float(rows)), pixels=grid)
    g = build_cell(cell).mesh
    u = build_cell(cell.replace(pixels=grid.replaced(grading=False))).mesh
    np.testing.assert_array_equal(g.triangles, u.triangles)
    assert g.n_vertices == u.n_vertices
    assert_same_rwg_table(g, u)
    assert (signed_areas(g) > 0).all()
    # every point stays in its pixel: the pixels' corners do not move
    corners = np.isclose(np.remainder(u.points[:, :2] + (cols / 2, rows / 2), 1.0), 0.0)
    np.testing.assert_array_equal(g.points[corners.all(axis=1)], u.points[corners.all(axis=1)])
    plain = cell.replace(pixels=grid.replaced(grading=False))
    assert build_cell(cell).periodic_pairs.matched == build_cell(plain).periodic_pairs.matched


@st.composite
def rect_assemblies(draw):
    """Unit squares on a small grid (every assembly of pixels)."""
    mask = draw(pixel_masks())[0]
    rows, cols = np.nonzero(mask)
    return np.stack([cols, rows, cols + 1, rows + 1], axis=1).astype(float)


@PROPERTY
@given(rect_assemblies())
def test_two_rectangles_sharing_a_side_grade_it_alike(rects):
    ends = outline_sides(rects)
    sides = {}  # the side's segment -> its flags, from every rectangle that has it
    for r, (x0, y0, x1, y1) in enumerate(rects):
        for k, seg in enumerate(
            [(x0, y0, x1, y0), (x1, y0, x1, y1), (x0, y1, x1, y1), (x0, y0, x0, y1)]
        ):
            sides.setdefault(seg, set()).add(tuple(ends[r, k]))
    assert all(len(flags) == 1 for flags in sides.values())

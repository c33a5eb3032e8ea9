"""Unit cells: welds between parts, refusals, contacts, periodic pairs and tiling (closed forms)."""

import numpy as np
import pytest
from helpers import assert_topology_matches_generic, run_capped, signed_areas

from barymesh import MeshParams
from barymesh.cell import (
    Element,
    Lattice,
    PixelGrid,
    UnitCell,
    build_cell,
    symmetrized,
    tile,
)
from barymesh.cell.files import load_cell_preset


def patch(size=1.0, n=4, **kw):
    return MeshParams(structure="patch", patch_size=size, subdivisions=n, **kw)


def pixels(rows, size=1.0, origin=(0.0, 0.0), n=4):
    return PixelGrid(np.array(rows, dtype=bool), pixel_size=size, origin=origin, subdivisions=n)


def euler(mesh):
    s = mesh.stats()
    return s["vertices"] - s["edges"] + s["triangles"]


# -- pixels ------------------------------------------------------------------


def test_two_edge_sharing_pixels_weld_into_one_patch_strip():
    cm = build_cell(UnitCell(pixels=pixels([[1, 1]])))
    s = cm.mesh.stats()
    # 2 x 32 triangles; 25 + 25 - 5 vertices; 56 + 56 - 4 edges; 40 + 40 + 4 RWG unknowns
    assert (s["triangles"], s["vertices"], s["edges"]) == (64, 45, 108)
    assert (s["interior_edges"], s["boundary_edges"], s["junction_edges"]) == (84, 24, 0)
    assert cm.notes == ()


@pytest.mark.parametrize("n", [1, 2, 3, 4])
@pytest.mark.parametrize("shape", [(1, 3), (2, 2), (3, 5)])
def test_full_pixel_block_counts_are_closed_forms(n, shape):
    r, c = shape
    cm = build_cell(UnitCell(pixels=pixels(np.ones(shape), n=n)))
    m = cm.mesh
    assert m.n_triangles == 2 * r * c * n * n
    assert m.n_vertices == (r * n + 1) * (c * n + 1)
    assert euler(m) == 1  # one disc
    assert m.stats()["boundary_edges"] == 2 * n * (r + c)
    assert m.n_patches == r * c


def test_corner_only_pixel_contact_is_reported_and_can_be_refused():
    cell = UnitCell(pixels=pixels([[1, 0], [0, 1]]))
    cm = build_cell(cell)
    assert cm.mesh.n_vertices == 25 + 25 - 1  # the shared corner
    assert cm.mesh.n_triangles == 64
    assert len(cm.notes) == 1
    assert "corner only" in cm.notes[0]
    assert "(row 0, column 0) and (row 1, column 1)" in cm.notes[0]
    with pytest.raises(ValueError, match=r"\(row 0, column 0\) and \(row 1, column 1\)"):
        build_cell(cell, refuse_corner_contacts=True)
    anti = PixelGrid(np.array([[0, 1], [1, 0]], bool)).corner_contacts()
    assert anti.tolist() == [[[0, 1], [1, 0]]]


def test_corner_contact_between_elements_in_conforming_mode():
    cell = UnitCell(
        elements=(
            Element(patch(), (0.0, 0.0), name="a"),
            Element(patch(), (1.0, 1.0), name="b"),
        ),
        mode="conforming",
    )
    cm = build_cell(cell)
    assert cm.mesh.n_vertices == 49
    assert any("single point" in n and "(1, 1)" in n for n in cm.notes)
    with pytest.raises(ValueError, match="single point"):
        build_cell(cell, refuse_corner_contacts=True)


def test_symmetries_of_a_painted_mask():
    m = np.zeros((6, 6), bool)
    m[0, 1] = m[2, 4] = True
    four = symmetrized(m, "4-fold")
    assert np.array_equal(four, np.rot90(four))
    assert not np.array_equal(four, four.T)  # a C4 pattern need not be mirror symmetric
    eight = symmetrized(m, "8-fold")
    assert np.array_equal(eight, np.rot90(eight)) and np.array_equal(eight, eight.T)
    assert np.array_equal(symmetrized(m, "mirror_x"), m | m[:, ::-1])
    assert np.array_equal(symmetrized(m, "mirror_y"), m | m[::-1])
    with pytest.raises(ValueError, match="symmetry='6-fold'"):
        symmetrized(m, "6-fold")
    with pytest.raises(ValueError, match="square mask"):
        symmetrized(np.zeros((2, 3)), "4-fold")


# -- elements -------------------------------------------------------------------


def test_paper_mode_welds_overlapping_patches_on_a_shared_lattice():
    # two 1 mm patches half a patch (two lattice steps) apart share 3 x 5 grid points
    cell = UnitCell(elements=(Element(patch(), name="a"), Element(patch(), (0.5, 0.0), name="b")))
    cm = build_cell(cell)
    assert cm.mesh.n_vertices == 25 + 25 - 15
    assert cm.mesh.n_triangles == 64
    assert cm.mesh.overlap_ratio == pytest.approx(0.25)  # union 1.5 of 2 mm²
    assert np.bincount(cm.mesh.regions).tolist() == [0, 32, 32]  # element index + 1


def test_conforming_mode_refuses_overlapping_elements_naming_both():
    cell = UnitCell(
        elements=(Element(patch(), name="left"), Element(patch(), (0.5, 0.25), name="right")),
        mode="conforming",
    )
    with pytest.raises(ValueError, match=r"'left' \(elements\[0\]\) and element 'right'"):
        build_cell(cell)


def test_conforming_mode_refuses_a_turned_element_overlapping_a_pixel():
    turned = Element(patch(0.5), (1.2, 0.5), rotation=45.0, name="diamond")
    cell = UnitCell(elements=(turned,), pixels=pixels([[0, 1]]), mode="conforming")
    with pytest.raises(ValueError, match=r"'diamond'.*pixel \(row 0, column 1\)"):
        build_cell(cell)


def test_conforming_touch_with_matching_vertices_is_welded():
    cell = UnitCell(
        elements=(Element(patch(), name="a"), Element(patch(), (1.0, 0.0), name="b")),
        mode="conforming",
    )
    cm = build_cell(cell)
    s = cm.mesh.stats()
    assert (s["vertices"], s["interior_edges"], s["boundary_edges"]) == (45, 84, 24)
    assert cm.notes == ()


def test_conforming_touch_with_hanging_vertices_is_reported():
    # n = 4 against n = 2 along x = 1: the side points y = 0.25, 0.75 of "fine" hang
    cell = UnitCell(
        elements=(Element(patch(n=4), name="fine"), Element(patch(n=2), (1.0, 0.0), name="coarse")),
        mode="conforming",
    )
    cm = build_cell(cell)
    assert cm.mesh.n_vertices == 25 + 9 - 3
    [note] = cm.notes
    assert "'fine' and 'coarse'" in note and "2 hanging" in note


def test_element_rotation_and_position():
    cm = build_cell(load_cell_preset("split-ring-pair"))
    left, right = cm.part_meshes
    # right = left turned 180° about its own centre: (-6, 0) + p -> (6, 0) - p
    assert np.allclose(right.points[:, :2], -left.points[:, :2], atol=1e-12)
    assert left.n_triangles == right.n_triangles
    assert cm.mesh.n_triangles == 2 * left.n_triangles


def test_per_element_statistics_of_the_double_ring_preset():
    cm = build_cell(load_cell_preset("double-ring-patch"))
    rings, centre = cm.part_stats()
    assert rings["name"] == "rings" and centre["name"] == "centre patch"
    assert rings["triangles"] == 2 * 180 * 32  # two rings of 360 / 2 patches
    # the centre patch says "grading": true and no subdivisions: graded at n = 16
    assert (centre["triangles"], centre["vertices"]) == (2 * 16**2, 17**2)
    assert centre["area"] == pytest.approx(9.0)
    assert np.bincount(cm.mesh.regions).tolist() == [0, 2 * 180 * 32, 2 * 16**2]
    assert cm.stats()["cell"]["triangles"] == 2 * 180 * 32 + 2 * 16**2
    assert cm.notes == ()


def test_cell_validation():
    with pytest.raises(ValueError, match="no metal"):
        UnitCell()
    with pytest.raises(ValueError, match=r"elements\[1\].name='a' is already"):
        UnitCell(elements=(Element(patch(), name="a"), Element(patch(), name="a")))
    with pytest.raises(ValueError, match="parallel"):
        Lattice((1.0, 0.0), (2.0, 0.0))
    with pytest.raises(ValueError, match=r"mask has shape \(0,\)"):
        PixelGrid(np.zeros(0, bool))
    with pytest.raises(ValueError, match="tolerance=0.2"):
        build_cell(UnitCell(pixels=pixels([[1]]), tolerance=0.2))
    # paper-mode double ring whose rings overlap cannot be put in a conforming cell
    overlapping = MeshParams(inner_radius=4.0, outer_radius=4.5)
    with pytest.raises(ValueError, match=r"elements\[0\] \('r'\) in conforming mode: outer_radius"):
        UnitCell(elements=(Element(overlapping, name="r"),), mode="conforming")


# -- periodicity --------------------------------------------------------------------


def _translated_edges_match(cm):
    pairs = cm.periodic_pairs
    m, lat = cm.mesh, cm.lattice
    for k, a in enumerate((lat.a1, lat.a2)):
        sel = pairs.edge_shift == k
        master = np.sort(m.points[m.edges[pairs.edges[sel, 0]], :2] + a, axis=1)
        slave = np.sort(m.points[m.edges[pairs.edges[sel, 1]], :2], axis=1)
        assert np.allclose(master, slave, atol=1e-9)
        vp = pairs.vertices[pairs.vertex_shift == k]
        assert np.allclose(m.points[vp[:, 0], :2] + a, m.points[vp[:, 1], :2], atol=1e-9)


def test_pixels_filling_the_cell_are_periodic():
    cell = UnitCell(
        Lattice.rectangular(3.0, 2.0), pixels=pixels(np.ones((2, 3)), origin=(-1.5, -1))
    )
    cm = build_cell(cell)
    pairs = cm.periodic_pairs
    assert pairs.matched
    # a1 joins the left and right sides (2 rows x n edges), a2 the bottom and top (3 columns x n)
    assert np.bincount(pairs.edge_shift).tolist() == [2 * 4, 3 * 4]
    assert np.bincount(pairs.vertex_shift).tolist() == [2 * 4 + 1, 3 * 4 + 1]
    _translated_edges_match(cm)


def test_metal_on_one_side_only_is_not_periodic():
    cell = UnitCell(Lattice.rectangular(4.0), elements=(Element(patch(), (-2.0, 0.0), name="p"),))
    cm = build_cell(cell)
    assert not cm.periodic_pairs.matched
    assert len(cm.periodic_pairs.unmatched_edges) == 4  # the patch's left side, n = 4
    assert any("no partner on the opposite side" in n for n in cm.notes)


def test_every_preset_builds_periodic_and_clean():
    for name, pairs_expected in [
        ("coding-16x16", True),
        ("double-ring-patch", False),
        ("hexagonal-rings", False),
        ("split-ring-pair", False),
    ]:
        cm = build_cell(load_cell_preset(name))
        assert cm.notes == (), name
        assert cm.periodic_pairs.matched, name
        assert (len(cm.periodic_pairs.edges) > 0) == pairs_expected, name
        assert cm.mesh.stats()["junction_edges"] == 0, name


def test_coding_preset_is_four_fold_symmetric_and_periodic():
    cell = load_cell_preset("coding-16x16")
    mask = cell.pixels.mask
    assert mask.shape == (16, 16)
    assert np.array_equal(mask, np.rot90(mask))
    assert len(cell.pixels.corner_contacts()) == 0
    cm = build_cell(cell)
    assert cm.mesh.n_triangles == 32 * int(mask.sum())
    # metal on the bottom row faces metal on the top row: n edges per pixel, per side
    pairs = cm.periodic_pairs
    assert np.bincount(pairs.edge_shift).tolist() == [4 * mask[:, 0].sum(), 4 * mask[0].sum()]
    _translated_edges_match(cm)


def test_hexagonal_lattice_preset():
    cell = load_cell_preset("hexagonal-rings")
    assert cell.lattice.kind == "hexagonal"
    assert cell.lattice.area == pytest.approx(12.0**2 * np.sqrt(3) / 2)
    cm = build_cell(cell)
    # r = 3..4 mm, n = 4: 86 square-ish cells round the circle at √12 mm (2π √12 x 4 = 87.1),
    # as 43 sectors (≤ 10°) of 4 x 2 cells: 16 triangles and 10 new vertices each
    assert (cm.mesh.n_triangles, cm.mesh.n_vertices) == (43 * 16, 43 * 10)
    arr = tile(cm, 3, 2)  # rings do not touch: nothing welds
    assert (arr.mesh.n_triangles, arr.mesh.n_vertices) == (6 * 43 * 16, 6 * 43 * 10)
    centres = arr.mesh.points[:, :2].reshape(6, -1, 2).mean(axis=1)
    d = np.linalg.norm(centres[:, None] - centres[None], axis=-1)
    assert np.isclose(d[d > 0].min(), 12.0)  # nearest neighbours one spacing apart


# -- tiling ---------------------------------------------------------------------


@pytest.mark.parametrize(("n1", "n2"), [(1, 1), (2, 3), (4, 1)])
def test_tiled_full_patch_is_one_grid(n1, n2):
    n = 4
    cell = UnitCell(
        Lattice.rectangular(2.0), elements=(Element(patch(2.0), (-1.0, -1.0), name="p"),)
    )
    arr = tile(cell, n1, n2)
    m = arr.mesh
    assert m.n_triangles == 2 * n * n * n1 * n2
    assert m.n_vertices == (n1 * n + 1) * (n2 * n + 1)
    assert euler(m) == 1 and m.stats()["junction_edges"] == 0
    assert arr.lattice.a1 == (2.0 * n1, 0.0) and arr.copies == (n1, n2)
    assert np.bincount(arr.periodic_pairs.edge_shift).tolist() == [n2 * n, n1 * n]
    _translated_edges_match(arr)


def test_tiled_coding_cell_counts_follow_from_its_periodic_pairs():
    cm = build_cell(load_cell_preset("coding-16x16"))
    n1, n2 = 3, 2
    arr = tile(cm, n1, n2)
    s, a = cm.mesh.stats(), arr.mesh.stats()
    m1, m2 = np.bincount(cm.periodic_pairs.edge_shift, minlength=2).tolist()
    seams = (n1 - 1) * n2 * m1 + n1 * (n2 - 1) * m2  # edge pairs glued inside the array
    assert a["triangles"] == n1 * n2 * s["triangles"]
    assert a["edges"] == n1 * n2 * s["edges"] - seams
    assert a["interior_edges"] == n1 * n2 * s["interior_edges"] + seams
    assert a["boundary_edges"] == n1 * n2 * s["boundary_edges"] - 2 * seams
    assert a["junction_edges"] == 0
    assert arr.periodic_pairs.matched


def test_tile_validates_counts():
    cell = UnitCell(pixels=pixels([[1]]))
    for bad in (0, -1, 1.5, True):
        with pytest.raises(ValueError, match="n1="):
            tile(cell, bad, 1)


def test_metal_beyond_the_cell_and_an_empty_pixel_grid_are_noted_not_built():
    cell = UnitCell(
        Lattice.rectangular(4.0),
        elements=(Element(patch(2.0), (1.0, -1.0), name="wide"),),  # x from 1 to 3 > 2
        pixels=PixelGrid(np.zeros((2, 2), bool)),
    )
    cm = build_cell(cell)
    assert cm.notes == (
        "'wide' reaches beyond the cell boundary: copies of the cell would overlap there",
    )
    wide, grid = cm.part_stats()
    assert (wide["name"], wide["triangles"]) == ("wide", 32)
    assert (grid["name"], grid["triangles"]) == ("pixels", 0)
    assert cm.mesh.n_triangles == 32


@pytest.mark.parametrize("name", ["coding-16x16", "double-ring-patch", "split-ring-pair"])
def test_cell_meshes_are_consistent_template_copies(name):
    cm = build_cell(load_cell_preset(name))
    assert_topology_matches_generic(cm.mesh)  # the fast per-patch topology path is right
    assert (signed_areas(cm.mesh) > 0).all()  # counter-clockwise after rotation
    arr = tile(cm, 2, 2)
    assert_topology_matches_generic(arr.mesh)


def test_edges_on_a_side_line_beyond_the_corner_are_on_no_side():
    # a patch outside the cell, x in [2, 3], y in [0, 2]: its left side lies on the cell's
    # right side (4 unmatched edges); its top side is on the line y = 2 but past the corner
    cell = UnitCell(Lattice.rectangular(4.0), elements=(Element(patch(2.0), (2.0, 0.0), name="p"),))
    pairs = build_cell(cell).periodic_pairs
    assert len(pairs.unmatched_edges) == 4


def test_the_cell_mesh_carries_its_periodic_pairs():
    """Issue 13's name: ``TriMesh.periodic_pairs`` of a cell's (or an array's) mesh, on its
    lattice; None for a structure's mesh, which has no lattice."""
    from barymesh import build_mesh

    cell = UnitCell(
        Lattice.rectangular(3.0, 2.0), pixels=pixels(np.ones((2, 3)), origin=(-1.5, -1))
    )
    cm = build_cell(cell)
    assert cm.mesh.lattice == cell.lattice
    assert cm.mesh.periodic_pairs is cm.periodic_pairs and cm.mesh.periodic_pairs.matched
    assert np.bincount(cm.mesh.periodic_pairs.edge_shift).tolist() == [2 * 4, 3 * 4]
    array = tile(cell, 2, 3)
    assert array.mesh.lattice == array.lattice == Lattice.rectangular(6.0, 6.0)
    pairs = array.mesh.periodic_pairs
    # the array's outer sides: 2 x 3 pixel rows on the left/right, 3 x 2 columns top/bottom
    assert pairs.matched and np.bincount(pairs.edge_shift).tolist() == [6 * 4, 6 * 4]
    assert build_mesh(MeshParams(structure="patch")).periodic_pairs is None


def test_two_overlapping_graded_rings_are_refused_without_all_pairs():
    # issue 30: two overlapping conforming double rings took 151 s in the overlap check: one
    # radius (the largest triangle's) for every pair made the candidates ~ all T² pairs. A
    # graded ring's cells span a factor of 90 in size; 42 million candidate pairs (1 GB)
    # before, refused here at the first overlap under a 1 GiB address-space cap
    out = run_capped(
        """
        from barymesh.cell import Element, Lattice, UnitCell, build_cell
        from barymesh import MeshParams
        ring = MeshParams(
            structure="double_ring", mode="conforming", inner_radius=1, outer_radius=4,
            patch_size=2, angle_step=120, subdivisions=16, grading=True, min_edge=1e-5,
            growth_ratio=1.1,
        )
        print(ring.predicted_triangles())
        cell = UnitCell(
            Lattice.rectangular(20, 20),
            (Element(ring, name="a"), Element(ring, (0.3, 0.0), name="b")),
            mode="conforming",
        )
        try:
            build_cell(cell)
        except ValueError as exc:
            print(exc)
        """
    )
    assert out.returncode == 0, out.stderr[-1500:]
    count, message = out.stdout.splitlines()
    assert int(count) == 38_016
    assert message.startswith("element 'a' (elements[0]) and element 'b' (elements[1]) overlap")

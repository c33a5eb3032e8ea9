"""Cell exports: metal outlines to DXF and GDSII (read back with ezdxf and gdstk), msh $Periodic."""

import math
import subprocess
import sys

import meshio
import numpy as np
import pytest

from barymesh import MeshParams
from barymesh.cell import Element, Lattice, PixelGrid, UnitCell, build_cell, tile
from barymesh.cell.files import load_cell_preset
from barymesh.cell.outline import (
    arc_angle_step,
    export_outline,
    outline_polygons,
    signed_area,
)
from barymesh.io import write_periodic_msh

try:  # the optional "cell" extra; everything but the two writers works without it
    import ezdxf
    import gdstk
except ImportError:  # pragma: no cover
    ezdxf = gdstk = None

needs_writers = pytest.mark.skipif(
    ezdxf is None or gdstk is None, reason="ezdxf and gdstk (the cell extra) are not installed"
)


def pixel_cell(rows, size=1.0, origin=(0.0, 0.0), lattice=None):
    grid = PixelGrid(np.array(rows, bool), pixel_size=size, origin=origin)
    return UnitCell(lattice or Lattice(), pixels=grid)


def dxf_loops(path):
    doc = ezdxf.readfile(path)
    assert doc.units == ezdxf.units.MM
    msp = doc.modelspace()
    loops = [np.array(e.get_points("xy")) for e in msp.query("LWPOLYLINE")]
    assert all(e.closed for e in msp.query("LWPOLYLINE"))
    return loops, list(msp.query("HATCH"))


def gds_area(path):
    lib = gdstk.read_gds(path)
    assert lib.unit == pytest.approx(1e-3) and lib.precision == pytest.approx(1e-9)
    [top] = lib.top_level()
    return sum(p.area() for p in top.polygons), top


# -- outlines --------------------------------------------------------------------


def test_pixel_ring_is_one_polygon_with_one_hole():
    ring = np.ones((3, 3), bool)
    ring[1, 1] = False
    [poly] = outline_polygons(pixel_cell(ring, size=0.5))
    assert poly.outer.shape == (4, 2) and len(poly.holes) == 1 and poly.holes[0].shape == (4, 2)
    assert signed_area(poly.outer) == pytest.approx(9 * 0.25)
    assert signed_area(poly.holes[0]) == pytest.approx(-0.25)  # clockwise
    assert poly.area == pytest.approx(8 * 0.25)


def test_pixels_meeting_at_a_corner_stay_two_polygons():
    polys = outline_polygons(pixel_cell([[1, 0], [0, 1]]))
    assert [len(p.outer) for p in polys] == [4, 4]
    assert [p.area for p in polys] == [pytest.approx(1.0)] * 2
    # an L of three pixels: one outline of 6 corners
    polys = outline_polygons(pixel_cell([[1, 1, 0], [1, 0, 0], [0, 0, 0], [0, 0, 0]]))
    assert sorted(len(p.outer) for p in polys) == [6]


def test_coding_cell_outline_area_is_the_pixel_count():
    cell = load_cell_preset("coding-16x16")
    polys = outline_polygons(cell)
    assert sum(p.area for p in polys) == pytest.approx(cell.pixels.mask.sum() * 0.25, abs=1e-12)
    # every corner of a pixel outline is a right angle: straight runs were reduced
    for p in polys:
        for loop in (p.outer, *p.holes):
            d = np.diff(np.vstack([loop, loop[:1]]), axis=0)
            turn = d[:, 0] * np.roll(d, -1, axis=0)[:, 1] - d[:, 1] * np.roll(d, -1, axis=0)[:, 0]
            assert np.all(np.abs(turn) > 0)


@pytest.mark.parametrize("chord_error", [0.1, 0.01, 0.001])
def test_ring_outline_area_within_the_chord_error(chord_error):
    cell = load_cell_preset("hexagonal-rings")  # ring r = 3, width 1
    [poly] = outline_polygons(cell, chord_error)
    r, big_r = 3.0, 4.0
    perimeter = 2 * math.pi * (r + big_r)
    exact = math.pi * (big_r**2 - r**2)
    assert abs(poly.area - exact) <= perimeter * chord_error
    assert len(poly.holes) == 1
    # every outline vertex lies on one of the two circles
    radii = np.linalg.norm(np.vstack([poly.outer, poly.holes[0]]), axis=1)
    assert np.allclose(np.minimum(abs(radii - r), abs(radii - big_r)), 0, atol=1e-12)
    # chords of the outer circle bulge inwards by at most the chord error
    step = np.radians(arc_angle_step(big_r, chord_error))
    assert big_r * (1 - math.cos(step / 2)) <= chord_error * (1 + 1e-12)


def test_outline_area_equals_mesh_area_within_the_chord_errors():
    cell = load_cell_preset("hexagonal-rings")  # conforming, r = 3..4 mm, n = 4
    mesh = build_cell(cell).mesh
    mesh_area = mesh.stats()["area"]
    chord = 0.005
    [poly] = outline_polygons(cell, chord)
    # the mesh's boundary points are 360° / (cells round a circle) apart on the circles
    cells = mesh.stats()["boundary_edges"] // 2
    mesh_chord = 4.0 * (1 - math.cos(math.radians(180.0 / cells)))
    perimeter = 2 * math.pi * 7.0
    assert abs(poly.area - mesh_area) <= perimeter * (chord + mesh_chord)
    # at the mesh's own sector width the outline is the mesh boundary: equal areas
    coarse = outline_polygons(cell, mesh_chord * (1 + 1e-9))
    assert coarse[0].area == pytest.approx(mesh_area, rel=1e-12)


def test_touching_elements_merge_and_the_split_ring_pair_has_two_pieces():
    two = UnitCell(
        elements=(
            Element(MeshParams(structure="patch"), name="a"),
            Element(MeshParams(structure="patch"), (1.0, 0.0), name="b"),
        )
    )
    [poly] = outline_polygons(two)
    assert poly.area == pytest.approx(2.0) and len(poly.outer) == 4
    polys = outline_polygons(load_cell_preset("split-ring-pair"))
    assert len(polys) == 2 and not polys[0].holes
    assert polys[0].area == pytest.approx(polys[1].area, rel=1e-9)


def test_tiled_outline_merges_metal_across_cell_sides():
    cell = pixel_cell([[1, 1], [1, 1]], origin=(-1.0, -1.0), lattice=Lattice.rectangular(2.0))
    [poly] = outline_polygons(cell, copies=(3, 2))
    assert poly.area == pytest.approx(24.0) and len(poly.outer) == 4


def test_overlapping_elements_have_no_outline():
    cell = UnitCell(
        elements=(
            Element(MeshParams(structure="patch"), name="a"),
            Element(MeshParams(structure="patch"), (0.5, 0.5), name="b"),
        )
    )
    build_cell(cell)  # fine as a paper-mode mesh
    with pytest.raises(ValueError, match="outline needs parts that do not overlap.*'a'.*'b'"):
        outline_polygons(cell)
    with pytest.raises(ValueError, match="chord_error=0"):
        outline_polygons(cell, 0)


# -- DXF and GDSII ---------------------------------------------------------------


@needs_writers
@pytest.mark.parametrize(
    "name", ["coding-16x16", "double-ring-patch", "hexagonal-rings", "split-ring-pair"]
)
def test_presets_round_trip_through_dxf_and_gds(name, tmp_path):
    cell = load_cell_preset(name)
    polys = export_outline(cell, tmp_path / f"{name}.dxf")
    area = sum(p.area for p in polys)
    loops, hatches = dxf_loops(tmp_path / f"{name}.dxf")
    assert len(loops) == sum(1 + len(p.holes) for p in polys)
    assert sum(signed_area(loop) for loop in loops) == pytest.approx(area, rel=1e-12)
    assert len(hatches) == len(polys)
    assert [len(h.paths) for h in hatches] == [1 + len(p.holes) for p in polys]
    export_outline(cell, tmp_path / f"{name}.gds")
    gds, top = gds_area(tmp_path / f"{name}.gds")
    perimeter = sum(
        np.linalg.norm(np.diff(np.vstack([loop, loop[:1]]), axis=0), axis=1).sum() for loop in loops
    )
    assert abs(gds - area) <= perimeter * 1e-6  # the 1 nm database grid
    assert {(p.layer, p.datatype) for p in top.polygons} == {(1, 0)}


@needs_writers
def test_gds_polygons_with_holes_keep_the_hole(tmp_path):
    ring = np.ones((3, 3), bool)
    ring[1, 1] = False
    export_outline(pixel_cell(ring), tmp_path / "ring.gds")
    area, top = gds_area(tmp_path / "ring.gds")
    assert area == pytest.approx(8.0, abs=1e-9)
    # no GDS polygon covers the hole's centre
    assert not any(gdstk.inside([(1.5, 1.5)], p)[0] for p in top.polygons)
    assert any(gdstk.inside([(0.5, 0.5)], p)[0] for p in top.polygons)  # the metal is there


def test_unknown_outline_format(tmp_path):
    with pytest.raises(ValueError, match=r"unknown outline format '\.svg'"):
        export_outline(pixel_cell([[1]]), tmp_path / "a.svg")


def test_core_does_not_import_the_export_libraries():
    code = (
        "import sys, core, barymesh.cell, barymesh.cell.outline, barymesh.io.gmsh_msh; "
        "print('ezdxf' in sys.modules, 'gdstk' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "False"]


# -- Gmsh $Periodic ----------------------------------------------------------------


def test_periodic_msh_round_trips_through_meshio(tmp_path):
    cm = build_cell(load_cell_preset("coding-16x16"))
    path = tmp_path / "coding.msh"
    write_periodic_msh(cm, path)
    m = meshio.read(path)
    pairs = cm.periodic_pairs
    assert np.allclose(m.points, cm.mesh.points)
    tri = m.get_cells_type("triangle")
    assert np.array_equal(tri, cm.mesh.triangles)
    assert len(m.get_cells_type("line")) == 2 * len(pairs.edges)
    assert m.field_data["pixels"].tolist() == [1, 2]
    assert m.field_data["a1_minus"].tolist() == [1001, 1]
    entries = {(stag, mtag): (affine, nodes) for _, (stag, mtag), affine, nodes in m.gmsh_periodic}
    assert set(entries) == {(2, 1), (4, 3)}
    for (slave, master), a in (((2, 1), (8.0, 0.0)), ((4, 3), (0.0, 8.0))):
        affine, nodes = entries[slave, master]
        t = np.asarray(affine).reshape(4, 4)
        assert np.allclose(t[:3, :3], np.eye(3)) and np.allclose(t[:2, 3], a)
        nodes = np.asarray(nodes)  # (slave, master), meshio makes them 0-based
        assert np.allclose(m.points[nodes[:, 1], :2] + a, m.points[nodes[:, 0], :2])
    assert len(entries[2, 1][1]) == int((pairs.vertex_shift == 0).sum())


def test_periodic_msh_of_an_array_and_in_metres(tmp_path):
    cell = pixel_cell([[1, 1]], origin=(-1.0, -0.5), lattice=Lattice.rectangular(2.0, 1.0))
    arr = tile(cell, 2, 3)
    write_periodic_msh(arr, tmp_path / "arr.msh", per_mm=1e-3)
    m = meshio.read(tmp_path / "arr.msh")
    assert len(m.get_cells_type("triangle")) == 6 * 64
    translations = sorted(tuple(np.asarray(a).reshape(4, 4)[:2, 3]) for *_, a, _ in m.gmsh_periodic)
    assert np.allclose(translations, [(0.0, 3e-3), (4e-3, 0.0)])


def test_periodic_msh_refuses_a_mesh_that_is_not_periodic(tmp_path):
    cell = UnitCell(
        Lattice.rectangular(4.0),
        elements=(Element(MeshParams(structure="patch"), (-2.0, 0.0), name="p"),),
    )
    with pytest.raises(ValueError, match="not periodic: 4 edge"):
        write_periodic_msh(build_cell(cell), tmp_path / "p.msh")
    assert not (tmp_path / "p.msh").exists()

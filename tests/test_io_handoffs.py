"""Hand-offs to the libraries users go on with: meshio, pyvista (VTK), scikit-rf, CSV, ParaView.

Each result is read back by the other library and compared with our own arrays.
"""

from __future__ import annotations

import ast
import csv
import subprocess
import sys
from pathlib import Path

import meshio
import numpy as np
import pytest
from helpers import imports_of

from barymesh import MeshParams, TriMesh, build_mesh
from barymesh.io.cross_sections import CSV_COLUMNS
from barymesh.io.current_vtu import write_current_vtu
from barymesh.mom import PlaneWave, VoltageSource, periodic_sweep, solve, sweep
from barymesh.presets import load_preset
from barymesh.quality import longest_sides

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def rings():
    """paper-fig8-dsdr: a conforming double ring of 2,752 triangles in two regions."""
    return build_mesh(load_preset("paper-fig8-dsdr")[0])


# -- TriMesh -----------------------------------------------------------------------------


def test_to_meshio_holds_the_mesh_and_its_figures(rings, tmp_path):
    m = rings.to_meshio(wavelength=30.0)
    assert [c.type for c in m.cells] == ["triangle"]
    np.testing.assert_array_equal(m.points, rings.points)
    np.testing.assert_array_equal(m.cells[0].data, rings.triangles)
    data = {k: v[0] for k, v in m.cell_data.items()}
    np.testing.assert_array_equal(data["patch_id"], rings.patch_ids)
    np.testing.assert_array_equal(data["region"], rings.regions)
    np.testing.assert_array_equal(data["area"], rings.areas)
    np.testing.assert_array_equal(data["min_angle"], rings.min_angles)
    np.testing.assert_array_equal(data["aspect_ratio"], rings.aspect_ratios)
    sides = longest_sides(rings.points, rings.triangles)
    np.testing.assert_array_equal(data["edge_wavelength"], sides / 30.0)
    # any format meshio writes, e.g. Abaqus, which barymesh itself does not
    meshio.write(tmp_path / "rings.inp", m)
    back = meshio.read(tmp_path / "rings.inp")
    assert len(back.cells_dict["triangle"]) == rings.n_triangles == 2_752
    # the arrays are copies: the mesh stays immutable
    m.points[0, 0] = 1e9
    assert rings.points[0, 0] != 1e9


def test_to_pyvista_is_the_same_surface_in_vtk(rings):
    pytest.importorskip("pyvista")
    import pyvista as pv

    from barymesh.app.view.polydata import to_pyvista

    poly = to_pyvista(rings)
    assert isinstance(poly, pv.PolyData)
    assert (poly.n_points, poly.n_cells) == (rings.n_vertices, rings.n_triangles)
    np.testing.assert_array_equal(poly.points, rings.points)
    np.testing.assert_array_equal(poly.faces.reshape(-1, 4)[:, 1:], rings.triangles)
    np.testing.assert_array_equal(poly.cell_data["region"], rings.regions)
    # VTK's own measure of every triangle's area is ours
    np.testing.assert_allclose(
        poly.compute_cell_sizes(length=False, volume=False).cell_data["Area"],
        rings.areas,
        rtol=1e-12,
    )
    assert "edge_wavelength" not in poly.cell_data
    assert "edge_wavelength" in to_pyvista(rings, wavelength=30.0).cell_data
    # the same dataset as pyvista's own reading of the meshio hand-off
    via_meshio = pv.from_meshio(rings.to_meshio())
    np.testing.assert_array_equal(via_meshio.points, poly.points)
    np.testing.assert_array_equal(via_meshio.cell_data["area"], poly.cell_data["area"])


def test_the_mesh_says_where_to_pyvista_went_and_hides_no_other_error():
    mesh = build_mesh(MeshParams(structure="patch", subdivisions=1))
    with pytest.raises(AttributeError, match=r"barymesh\.app\.view\.polydata\.to_pyvista"):
        mesh.to_pyvista()
    assert not hasattr(mesh, "to_pyvista")
    with pytest.raises(AttributeError, match="'TriMesh' object has no attribute 'nonsense'"):
        mesh.nonsense  # noqa: B018
    # an AttributeError inside a cached property is its own, not "no attribute"
    object.__setattr__(mesh, "repetition", object())  # (a frozen dataclass)
    with pytest.raises(AttributeError, match="'object' object has no attribute 'vertex_map'"):
        mesh.centroids  # noqa: B018


def test_the_core_loads_no_vtk_unless_asked_for_pyvista(tmp_path):
    code = (
        "import sys, barymesh, barymesh.io, barymesh.mom, barymesh.cell\n"
        "from barymesh import MeshParams, build_mesh\n"
        "from barymesh.io import write_mesh, EXPORT_EXTENSIONS\n"
        "m = build_mesh(MeshParams(structure='patch', subdivisions=2))\n"
        "m.to_meshio()\n"
        f"for ext in EXPORT_EXTENSIONS: write_mesh(m, {str(tmp_path)!r} + '/m' + ext)\n"
        "print(sorted({n.split('.')[0] for n in sys.modules} & {'vtk', 'vtkmodules', "
        "'pyvista', 'PySide6'}))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=300
    )
    assert out.stdout.strip() == "[]"


def test_the_core_never_imports_qt_vtk_or_pyvista():
    """core/ never imports Qt, VTK or pyvista, not even lazily inside a function."""
    found = []
    for path in sorted((ROOT / "core").rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        functions = [n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef)]
        for node, names in imports_of(tree):
            gui = [
                n for n in names if n.split(".")[0] in ("pyvista", "vtk", "vtkmodules", "PySide6")
            ]
            if gui:
                where = [f.name for f in functions if f.lineno <= node.lineno <= f.end_lineno]
                found.append((path.relative_to(ROOT).as_posix(), gui[0], where))
    assert found == []


# -- the free-space sweep as CSV ---------------------------------------------------------


def test_sweep_result_to_csv_reads_back_exactly(tmp_path):
    plate = build_mesh(MeshParams(structure="patch", patch_size=100.0, subdivisions=2))
    result = sweep(plate, [1e9, 1.5e9, 2e9], PlaneWave(polarization=(0, 1, 0)))
    path = tmp_path / "sweep.csv"
    result.to_csv(path)
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    assert tuple(rows[0]) == CSV_COLUMNS and len(rows) == 4
    table = np.array(rows[1:], dtype=float)
    np.testing.assert_array_equal(table[:, 0], result.frequencies)
    np.testing.assert_array_equal(table[:, 1], result.extinction_cross_section)
    np.testing.assert_array_equal(table[:, 2], result.scattering_cross_section)
    np.testing.assert_array_equal(
        table[:, 3], result.extinction_cross_section - result.scattering_cross_section
    )
    assert np.isnan(table[:, 4:6]).all()  # no input impedance for a plane wave
    np.testing.assert_array_equal(table[:, 6], result.condition_numbers)
    np.testing.assert_array_equal(table[:, 7], result.residuals)
    assert np.all(table[:, 1] > 0)


# -- the infinite array as a scikit-rf Network --------------------------------------------


@pytest.fixture(scope="module")
def l_cell():
    """An L of pixels (no mirror symmetry, so cross-polarised) in a 10 mm cell."""
    from barymesh.cell import Lattice, PixelGrid, UnitCell, build_cell

    mask = np.zeros((8, 8), dtype=bool)
    mask[1:7, 1:3] = True
    mask[1:3, 1:5] = True
    pixels = PixelGrid(mask, pixel_size=1.25, origin=(-5.0, -5.0), subdivisions=2)
    cell = UnitCell(lattice=Lattice.rectangular(10.0), pixels=pixels, mode="conforming")
    return build_cell(cell).mesh


def test_periodic_sweep_to_network_is_the_touchstone_file_in_memory(l_cell, tmp_path):
    skrf = pytest.importorskip("skrf")
    from barymesh.io.floquet import scattering_matrices

    result = periodic_sweep(l_cell, [10e9, 20e9, 35e9], interpolate=False)
    network = result.to_network()
    assert isinstance(network, skrf.Network) and network.nports == 4
    np.testing.assert_array_equal(network.f, result.frequencies)
    np.testing.assert_array_equal(network.s, scattering_matrices(result))  # full precision
    np.testing.assert_array_equal(network.z0, np.ones((3, 4)))
    assert "exp(+j w t)" in network.comments and network.name == "barymesh periodic sweep"
    result.to_touchstone(tmp_path / "rt.s4p")
    from_file = skrf.Network(str(tmp_path / "rt.s4p"))
    assert np.abs(from_file.s - network.s).max() < 1e-11  # the file keeps 12 digits
    assert np.abs(network.s[:, 0, 1]).min() > 0.05  # the L couples TE and TM
    one = periodic_sweep(l_cell, [10e9], interpolate=False, polarizations="incident")
    with pytest.raises(ValueError, match="polarizations='both'"):
        one.to_network()


def test_to_network_without_scikit_rf_says_how_to_get_it(l_cell, monkeypatch):
    result = periodic_sweep(l_cell, [10e9], interpolate=False)
    monkeypatch.setitem(sys.modules, "skrf", None)
    with pytest.raises(ImportError, match="needs scikit-rf: pip install scikit-rf"):
        result.to_network()


# -- the current for ParaView ---------------------------------------------------------------


def test_current_vtu_records_a_voltage_source_and_the_units(tmp_path):
    pv = pytest.importorskip("pyvista")
    x, y = np.meshgrid(np.linspace(-500, 500, 21), np.linspace(-10, 10, 3), indexing="ij")
    points = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    a = (np.arange(20)[:, None] * 3 + np.arange(2)[None, :]).ravel()
    tri = np.concatenate([np.column_stack([a, a + 3, a + 4]), np.column_stack([a, a + 4, a + 1])])
    strip = TriMesh(points, tri, np.zeros(len(tri), int), np.ones(len(tri), int), 1)
    feed = VoltageSource((0.0, -10.0), (0.0, 10.0), voltage=2.0)
    s = solve(strip, 140e6, feed)
    path = tmp_path / "dipole.vtu"
    write_current_vtu(
        path, strip, s.current_density, frequency=s.frequency, excitation=feed, note=np.arange(80.0)
    )
    grid = pv.read(path)
    np.testing.assert_array_equal(grid.points, points)
    j = np.asarray(grid.cell_data["J_real"]) + 1j * np.asarray(grid.cell_data["J_imag"])
    np.testing.assert_array_equal(j, s.current_density)  # 17 digits: exact
    fields = grid.field_data
    assert fields["frequency_hz"].tolist() == [140e6]
    assert fields["feed_start_mm"].tolist() == [[0.0, -10.0, 0.0]]
    assert fields["feed_end_mm"].tolist() == [[0.0, 10.0, 0.0]]
    assert fields["voltage_v"].tolist() == [2.0]
    assert fields["excitation"].tolist() == [
        "delta-gap voltage source of 2 V on the mesh edges along (0, -10, 0) to (0, 10, 0) mm"
    ]
    assert "note: as given" in list(fields["units"]) and "J_abs: A/m" in list(fields["units"])
    with pytest.raises(ValueError, match="note has 3 values; expected 80, one per triangle"):
        write_current_vtu(tmp_path / "bad.vtu", strip, s.current_density, note=np.ones(3))
    assert not (tmp_path / "bad.vtu").exists()

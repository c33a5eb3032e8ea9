"""The exports carry the quality report's figures per triangle (VTK files), read back by
meshio (and pyvista for our own .vtp writer)."""

import meshio
import numpy as np
import pytest

from barymesh import MeshParams, build_mesh
from barymesh.io import write_mesh
from barymesh.presets import load_preset
from barymesh.quality import longest_sides, quality_report


def cell_data_back(path):
    if path.suffix == ".vtp":  # meshio reads no PolyData: pyvista (VTK) does
        pv = pytest.importorskip("pyvista")
        poly = pv.read(path)
        return {k: np.asarray(poly.cell_data[k]) for k in poly.cell_data.keys()}
    m = meshio.read(path)
    return {k: np.asarray(v[0]).reshape(-1) for k, v in m.cell_data.items()}


@pytest.fixture(scope="module")
def dsdr():
    """paper-fig8-dsdr (conforming): 2,752 triangles of varied shape and size."""
    return build_mesh(load_preset("paper-fig8-dsdr")[0])


@pytest.mark.parametrize("ext", [".vtu", ".vtk", ".vtp"])
@pytest.mark.parametrize("unit", ["mm", "m"])
def test_vtk_files_carry_the_reports_figures(tmp_path, dsdr, ext, unit):
    sides = longest_sides(dsdr.points, dsdr.triangles)
    assert sides.min() < np.median(sides) < sides.max()
    wavelength = 10 * float(np.median(sides))  # some longest sides above λ/10, some under
    report = quality_report(dsdr, wavelength=wavelength, worst=5)
    data = cell_data_back(write_mesh(dsdr, tmp_path / f"q{ext}", unit=unit, wavelength=wavelength))
    assert len(data["min_angle"]) == dsdr.n_triangles == 2_752
    assert data["min_angle"].min() == pytest.approx(report["min_angle_deg"]["min"], rel=1e-15)
    assert np.count_nonzero(data["min_angle"] < 30) == report["min_angle_deg"]["below"] > 0
    assert data["aspect_ratio"].max() == pytest.approx(report["aspect_ratio"]["max"], rel=1e-15)
    assert np.count_nonzero(data["aspect_ratio"] > 3) == report["aspect_ratio"]["above"]
    over = report["edge_wavelength"]
    # edge/λ has no unit: the same numbers in a file in metres
    assert data["edge_wavelength"].max() == pytest.approx(over["max"], rel=1e-15)
    assert 0 < np.count_nonzero(data["edge_wavelength"] > 0.1) == over["above"] < 11_008
    for row in report["worst"]:
        t = row["triangle"]
        assert data["min_angle"][t] == pytest.approx(row["min_angle_deg"], rel=1e-15)
        assert data["edge_wavelength"][t] == pytest.approx(row["edge_wavelength"], rel=1e-15)


def test_edge_wavelength_of_the_papers_patch(tmp_path):
    """Fig. 10: every longest side is 2.5√2 mm; at λ = 30 mm that is 0.1179 > 1/10."""
    mesh = build_mesh(MeshParams(structure="patch", patch_size=10.0, subdivisions=4))
    data = cell_data_back(write_mesh(mesh, tmp_path / "p.vtu", wavelength=30.0))
    np.testing.assert_allclose(data["edge_wavelength"], 2.5 * np.sqrt(2) / 30.0, rtol=1e-15)


def test_no_wavelength_no_edge_field_and_solver_formats_stay_lean(tmp_path):
    mesh = build_mesh(MeshParams(structure="patch", subdivisions=2))
    for ext in (".vtu", ".vtk", ".vtp"):
        assert "edge_wavelength" not in cell_data_back(write_mesh(mesh, tmp_path / f"a{ext}"))
    # Gmsh keeps its tags only (what the solvers read); STL and OBJ carry only what their
    # readers make up (normals, group ids)
    msh = meshio.read(write_mesh(mesh, tmp_path / "a.msh", wavelength=30.0))
    assert set(msh.cell_data) == {"gmsh:physical", "gmsh:geometrical"}
    for ext in (".stl", ".obj"):
        back = meshio.read(write_mesh(mesh, tmp_path / f"a{ext}", wavelength=30.0))
        assert set(back.cell_data) <= {"facet_normals", "obj:group_ids"}


@pytest.mark.parametrize("ext", [".vtk", ".vtu"])
def test_vtk_itself_reads_every_cell_array(tmp_path, dsdr, ext):
    """VTK (ParaView's reader, through pyvista) gets every cell array with its values.

    VTK 9's legacy reader does not know meshio's ``vtktypeint32`` and then drops all the
    cell data of the file (meshio issue 1410), so the integer arrays are written as int64.
    """
    pv = pytest.importorskip("pyvista")
    wavelength = 30.0
    grid = pv.read(write_mesh(dsdr, tmp_path / f"d{ext}", unit="m", wavelength=wavelength))
    assert grid.n_cells == dsdr.n_triangles == 2_752
    assert set(grid.cell_data.keys()) == {
        "patch_id",
        "region",
        "area",
        "min_angle",
        "aspect_ratio",
        "edge_wavelength",
    }
    np.testing.assert_array_equal(grid.cell_data["patch_id"], dsdr.patch_ids)
    np.testing.assert_array_equal(grid.cell_data["region"], dsdr.regions)
    assert set(np.unique(grid.cell_data["region"]).tolist()) == {1, 2}  # the double ring
    np.testing.assert_allclose(grid.cell_data["area"], dsdr.areas * 1e-6, rtol=1e-15)
    np.testing.assert_allclose(grid.cell_data["min_angle"], dsdr.min_angles, rtol=1e-15)
    np.testing.assert_allclose(grid.cell_data["aspect_ratio"], dsdr.aspect_ratios, rtol=1e-15)
    sides = longest_sides(dsdr.points, dsdr.triangles)
    np.testing.assert_allclose(grid.cell_data["edge_wavelength"], sides / wavelength, rtol=1e-15)

"""Write every format, read it back with meshio (or scipy/pyvista) and with our importer."""

import meshio
import numpy as np
import pytest
import scipy.io
from helpers import canonical_meshes

from barymesh.io import EXPORT_EXTENSIONS, per_mm, read_mesh, write_mesh

pytestmark = pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")  # meshio STL

MESH_FORMATS = (".msh", ".vtu", ".vtp", ".vtk", ".stl", ".obj", ".mat")
MESHIO_FORMATS = {".msh": "gmsh", ".vtu": "vtu", ".vtk": "vtk", ".stl": "stl", ".obj": "obj"}


#: the names of tests.helpers.canonical_meshes(), built lazily by the tests that use them
MESH_NAMES = ("patch", "double-ring", "paper-ring")


def triangle_set(points, triangles, decimals=9):
    """Triangles as a set of sorted vertex coordinate triples (orientation and order free)."""
    p = np.round(np.asarray(points, dtype=np.float64)[:, :3], decimals) + 0.0  # no -0.0
    corners = p[np.asarray(triangles)]
    return {tuple(sorted(map(tuple, tri))) for tri in corners.tolist()}


def read_back(path):
    """(points, triangles) of a written file, read by a library other than ours."""
    ext = path.suffix
    if ext == ".mat":
        data = scipy.io.loadmat(path)
        return data["p"].T, data["t"][:3].T.astype(int) - 1
    if ext == ".vtp":
        pv = pytest.importorskip("pyvista")
        poly = pv.read(path)
        return np.asarray(poly.points), poly.faces.reshape(-1, 4)[:, 1:]
    m = meshio.read(path, file_format=MESHIO_FORMATS[ext])
    return m.points, np.concatenate([c.data for c in m.cells if c.type == "triangle"])


def test_every_export_extension_is_covered():
    assert set(EXPORT_EXTENSIONS) == set(MESH_FORMATS) | {".npz", ".csv"}


@pytest.mark.parametrize("name", MESH_NAMES)
@pytest.mark.parametrize("ext", MESH_FORMATS)
@pytest.mark.parametrize("unit", [None, "m", "mm", "um"])
def test_round_trip(tmp_path, name, ext, unit):
    mesh = canonical_meshes()[name]
    path = write_mesh(mesh, tmp_path / f"mesh{ext}", unit=unit)
    file_unit = unit or ("m" if ext == ".mat" else "mm")
    scale = per_mm(file_unit)
    expected = triangle_set(mesh.points * scale, mesh.triangles, decimals=9 - int(np.log10(scale)))

    # another library sees the same triangles, in the file's unit
    points, triangles = read_back(path)
    assert len(triangles) == mesh.n_triangles
    assert len(points) == mesh.n_vertices
    assert triangle_set(points, triangles, decimals=9 - int(np.log10(scale))) == expected

    # our importer brings them back in mm
    back = read_mesh(path, unit=unit)
    assert back.mode == "imported"
    assert (back.n_vertices, back.n_triangles) == (mesh.n_vertices, mesh.n_triangles)
    assert triangle_set(back.points, back.triangles) == triangle_set(mesh.points, mesh.triangles)
    assert back.ignored_cells == {}
    s, t = back.stats(), mesh.stats()
    for key in (
        "vertices",
        "triangles",
        "edges",
        "interior_edges",
        "boundary_edges",
        "junction_edges",
        "euler_characteristic",
    ):
        assert s[key] == t[key], key
    assert s["area"] == pytest.approx(t["area"], rel=1e-12)


@pytest.mark.parametrize("ext", [".msh", ".vtu", ".vtp", ".vtk"])
def test_regions_and_patches_survive(tmp_path, ext):
    mesh = canonical_meshes()["double-ring"]
    back = read_mesh(write_mesh(mesh, tmp_path / f"rings{ext}"))
    assert back.n_patches == mesh.n_patches
    assert back.stats()["regions"] == 2
    # same region for the same triangle (matched by centroid)
    order = np.lexsort(np.round(mesh.centroids, 9).T)
    back_order = np.lexsort(np.round(back.centroids, 9).T)
    assert np.array_equal(mesh.regions[order], back.regions[back_order])


def test_gmsh_tags_and_physical_names(tmp_path):
    mesh = canonical_meshes()["double-ring"]
    path = write_mesh(mesh, tmp_path / "rings.msh")
    text = path.read_text()
    assert text.startswith("$MeshFormat\n2.2 0 8\n")  # MSH 2.2 ASCII: what scuff-em reads
    assert '2 1 "inner_ring"' in text and '2 2 "outer_ring"' in text
    m = meshio.read(path)
    assert np.array_equal(m.cell_data["gmsh:physical"][0], mesh.regions)
    assert np.array_equal(m.cell_data["gmsh:geometrical"][0], mesh.patch_ids + 1)
    assert "$ElementData" not in text  # nothing a solver could choke on


def test_single_patch_is_named_patch(tmp_path):
    text = write_mesh(canonical_meshes()["patch"], tmp_path / "p.msh").read_text()
    assert '2 1 "patch"' in text


@pytest.mark.parametrize("ext", [".vtu", ".vtk"])
def test_vtk_cell_data(tmp_path, ext):
    mesh = canonical_meshes()["double-ring"]
    m = meshio.read(write_mesh(mesh, tmp_path / f"q{ext}", unit="m"))
    data = {k: np.asarray(v[0]).reshape(-1) for k, v in m.cell_data.items()}
    assert np.array_equal(data["patch_id"], mesh.patch_ids)
    assert np.array_equal(data["region"], mesh.regions)
    np.testing.assert_allclose(data["area"], mesh.areas * 1e-6)  # m² in a file in m
    np.testing.assert_allclose(data["min_angle"], mesh.min_angles)
    np.testing.assert_allclose(data["aspect_ratio"], mesh.aspect_ratios)


def test_vtp_cell_data_read_by_vtk(tmp_path):
    pv = pytest.importorskip("pyvista")
    mesh = canonical_meshes()["double-ring"]
    poly = pv.read(write_mesh(mesh, tmp_path / "q.vtp"))
    assert poly.n_cells == mesh.n_triangles
    assert np.array_equal(poly.cell_data["region"], mesh.regions)
    np.testing.assert_allclose(poly.cell_data["min_angle"], mesh.min_angles)
    np.testing.assert_allclose(poly.cell_data["area"], mesh.areas)


def test_vtp_written_by_vtk_is_read(tmp_path):
    """Binary and compressed PolyData as VTK itself writes it."""
    pv = pytest.importorskip("pyvista")
    mesh = canonical_meshes()["double-ring"]
    poly = pv.read(write_mesh(mesh, tmp_path / "q.vtp"))
    for binary in (True, False):
        out = tmp_path / f"vtk-{binary}.vtp"
        poly.save(out, binary=binary)
        back = read_mesh(out)
        assert triangle_set(back.points, back.triangles) == triangle_set(
            mesh.points, mesh.triangles
        )
        assert back.n_patches == mesh.n_patches


def test_mat_layout(tmp_path):
    mesh = canonical_meshes()["double-ring"]
    data = scipy.io.loadmat(write_mesh(mesh, tmp_path / "m.mat"))
    assert data["p"].shape == (3, mesh.n_vertices) and data["p"].dtype == np.float64
    assert data["t"].shape == (4, mesh.n_triangles)
    assert data["t"][:3].min() == 1 and data["t"][:3].max() == mesh.n_vertices  # 1-based
    assert np.all(data["t"][3] == 1)  # rwg1.m keeps only row 4 == 1
    np.testing.assert_allclose(data["p"].T, mesh.points * 1e-3)  # metres by default


def _cell_data_back(path):
    """Per-triangle data of a written VTK file, read by a library other than the writer."""
    if path.suffix == ".vtp":
        from barymesh.io.vtk_xml import read_vtp  # the writer is ours; read it with pyvista too

        pv = pytest.importorskip("pyvista")
        poly = pv.read(path)
        ours = read_vtp(path)[2]
        for key, values in ours.items():
            np.testing.assert_array_equal(values, np.asarray(poly.cell_data[key]))
        return {k: np.asarray(poly.cell_data[k]) for k in poly.cell_data.keys()}
    m = meshio.read(path)
    return {k: np.asarray(v[0]).reshape(-1) for k, v in m.cell_data.items()}


@pytest.mark.parametrize("ext", [".vtu", ".vtp", ".vtk"])
@pytest.mark.parametrize("unit", ["m", "mm", "um"])
def test_every_cell_data_field_in_every_unit(tmp_path, ext, unit):
    """Issue 10 #15(b): areas scale with the square of the length unit (0.1 mm² = 1e-7 m²)."""
    mesh = canonical_meshes()["double-ring"]
    data = _cell_data_back(write_mesh(mesh, tmp_path / f"q{ext}", unit=unit))
    s = per_mm(unit)
    assert set(data) >= {"patch_id", "region", "area", "min_angle", "aspect_ratio"}
    np.testing.assert_array_equal(data["patch_id"], mesh.patch_ids)
    np.testing.assert_array_equal(data["region"], mesh.regions)
    np.testing.assert_allclose(data["area"], mesh.areas * s**2, rtol=1e-12)
    np.testing.assert_allclose(data["min_angle"], mesh.min_angles, rtol=1e-12)
    np.testing.assert_allclose(data["aspect_ratio"], mesh.aspect_ratios, rtol=1e-12)


def test_patch_area_in_metres_is_square_metres(tmp_path):
    """The 10 mm patch is 1e-4 m² in a file written in metres (not 0.1, the factor once)."""
    mesh = canonical_meshes()["patch"]
    for ext in (".vtu", ".vtp", ".vtk"):
        data = _cell_data_back(write_mesh(mesh, tmp_path / f"p{ext}", unit="m"))
        assert data["area"].sum() == pytest.approx(1e-4, rel=1e-12)


@pytest.mark.parametrize("unit", ["m", "mm", "um"])
def test_rwg_tables_in_every_unit(tmp_path, unit):
    mesh = canonical_meshes()["double-ring"]
    s = per_mm(unit)
    npz = np.load(write_mesh(mesh, tmp_path / "r.npz", unit=unit))
    assert str(npz["unit"]) == unit
    np.testing.assert_allclose(npz["points"], mesh.points * s, rtol=1e-12)
    np.testing.assert_allclose(npz["centroids"], mesh.centroids * s, rtol=1e-12)
    np.testing.assert_allclose(npz["areas"], mesh.areas * s**2, rtol=1e-12)
    np.testing.assert_allclose(npz["length"], mesh.rwg.length * s, rtol=1e-12)
    write_mesh(mesh, tmp_path / "r.csv", unit=unit)
    centroids = np.loadtxt(tmp_path / "r_centroids.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(centroids[:, 1:4], mesh.centroids * s, rtol=1e-12)
    np.testing.assert_allclose(centroids[:, 4], mesh.areas * s**2, rtol=1e-12)
    table = np.loadtxt(tmp_path / "r.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(table[:, 7], mesh.rwg.length * s, rtol=1e-12)


@pytest.mark.parametrize("mode", ["inline", "appended-raw", "appended-base64", "ascii"])
def test_vtu_written_by_vtk_is_read(tmp_path, mode):
    """Our VTK XML reader against VTK's own writer in each of its data modes."""
    pv = pytest.importorskip("pyvista")
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridWriter

    mesh = canonical_meshes()["double-ring"]
    grid = pv.read(write_mesh(mesh, tmp_path / "q.vtu"))
    out = tmp_path / f"vtk-{mode}.vtu"
    writer = vtkXMLUnstructuredGridWriter()
    writer.SetFileName(str(out))
    writer.SetInputData(grid)
    if mode == "ascii":
        writer.SetDataModeToAscii()
    elif mode == "inline":
        writer.SetDataModeToBinary()
    else:
        writer.SetDataModeToAppended()
        writer.SetEncodeAppendedData(mode == "appended-base64")
        writer.SetHeaderTypeToUInt64()
    assert writer.Write() == 1
    if mode == "appended-raw":
        assert b'encoding="raw"' in out.read_bytes()
    back = read_mesh(out)
    assert triangle_set(back.points, back.triangles) == triangle_set(mesh.points, mesh.triangles)
    assert back.n_patches == mesh.n_patches
    assert sorted(np.unique(back.regions).tolist()) == [1, 2]

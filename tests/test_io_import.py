"""Import of files written by others: Gmsh 2.2/4.1 ASCII and binary, mixed cells, bad files."""

import meshio
import numpy as np
import pytest
import scipy.io

from barymesh.io import IMPORT_EXTENSIONS, MeshFileError, read_mesh

# two triangles of a unit square (mm) plus a boundary line and a point
POINTS = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [5, 5, 0]])
TRIANGLES = np.array([[0, 1, 2], [0, 2, 3]])


def mixed_mesh():
    return meshio.Mesh(
        POINTS,
        [
            ("vertex", np.array([[4]])),
            ("line", np.array([[0, 1], [1, 2], [2, 3]])),
            ("triangle", TRIANGLES),
            ("quad", np.array([[0, 1, 2, 3]])),
        ],
        cell_data={
            "gmsh:physical": [np.array([9]), np.array([5, 5, 5]), np.array([7, 7]), np.array([3])],
            "gmsh:geometrical": [
                np.array([1]),
                np.array([2, 2, 2]),
                np.array([4, 6]),
                np.array([1]),
            ],
        },
    )


# MSH 4.1 ASCII as Gmsh writes it: a point, a boundary line and two triangles, each on its
# own entity with a physical tag (meshio's 4.1 writer cannot write mixed cells)
MSH41 = """$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
3
0 3 "feed"
1 5 "edge"
2 7 "plate"
$EndPhysicalNames
$Entities
1 1 1 0
1 5 5 0 1 3
2 0 0 0 1 1 0 1 5 0
4 0 0 0 1 1 0 1 7 0
$EndEntities
$Nodes
2 5 1 5
0 1 0 1
5
5 5 0
2 4 0 4
1
2
3
4
0 0 0
1 0 0
1 1 0
0 1 0
$EndNodes
$Elements
3 6 1 6
0 1 15 1
1 5
1 2 1 3
2 1 2
3 2 3
4 3 4
2 4 2 2
5 1 2 3
6 1 3 4
$EndElements
"""


@pytest.mark.parametrize("binary", [False, True], ids=["ascii", "binary"])
def test_gmsh22_with_other_cells(tmp_path, binary):
    path = tmp_path / "mixed.msh"
    meshio.write(path, mixed_mesh(), file_format="gmsh22", binary=binary)
    mesh = read_mesh(path)
    assert mesh.n_triangles == 2
    assert mesh.n_vertices == 4  # the lone point belongs to no triangle
    assert mesh.ignored_cells == {"vertex": 1, "line": 3, "quad": 1}
    assert mesh.stats()["ignored_cells"] == {"vertex": 1, "line": 3, "quad": 1}
    assert mesh.regions.tolist() == [7, 7]  # physical tags
    assert mesh.n_patches == 2  # elementary tags 4 and 6
    assert mesh.stats()["interior_edges"] == 1
    np.testing.assert_allclose(mesh.areas.sum(), 1.0)


def test_gmsh41_ascii_with_other_cells(tmp_path):
    path = tmp_path / "gmsh41.msh"
    path.write_text(MSH41)
    mesh = read_mesh(path)
    assert (mesh.n_vertices, mesh.n_triangles) == (4, 2)
    assert mesh.ignored_cells == {"vertex": 1, "line": 3}
    assert mesh.regions.tolist() == [7, 7]
    np.testing.assert_allclose(mesh.areas.sum(), 1.0)


def test_gmsh41_binary(tmp_path):
    path = tmp_path / "b41.msh"
    meshio.write(
        path, meshio.Mesh(POINTS[:4], [("triangle", TRIANGLES)]), file_format="gmsh", binary=True
    )
    assert path.read_bytes().startswith(b"$MeshFormat\n4.1 1 8")
    mesh = read_mesh(path)
    assert (mesh.n_vertices, mesh.n_triangles) == (4, 2)
    assert mesh.ignored_cells == {}


def test_binary_stl(tmp_path):
    path = tmp_path / "b.stl"
    meshio.write(path, meshio.Mesh(POINTS[:4], [("triangle", TRIANGLES)]), binary=True)
    mesh = read_mesh(path, unit="m")
    assert (mesh.n_vertices, mesh.n_triangles) == (4, 2)
    np.testing.assert_allclose(mesh.areas.sum(), 1e6)  # 1 m² in mm²


def test_obj_with_quads_counts_them(tmp_path):
    path = tmp_path / "q.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nf 1 2 3 4\nf 2 5 3\n")
    mesh = read_mesh(path)
    assert mesh.n_triangles == 1 and mesh.ignored_cells == {"quad": 1}


def test_makarov_mat_defaults_to_metres(tmp_path):
    path = tmp_path / "m.mat"
    scipy.io.savemat(path, {"p": POINTS[:4].T, "t": np.vstack([TRIANGLES.T + 1, [1, 2]])})
    mesh = read_mesh(path)
    np.testing.assert_allclose(mesh.points, POINTS[:4] * 1000.0)
    assert mesh.regions.tolist() == [1, 2]  # row 4 of t
    assert read_mesh(path, unit="mm").areas.sum() == pytest.approx(1.0)


def test_supported_extensions():
    assert set(IMPORT_EXTENSIONS) == {".msh", ".vtk", ".vtu", ".vtp", ".stl", ".obj", ".mat"}


def _bad_files(tmp_path):
    garbage = b"\x00\x01 this is not a mesh \xff" * 10
    msh = tmp_path / "ok.msh"
    meshio.write(
        msh, meshio.Mesh(POINTS[:4], [("triangle", TRIANGLES)]), file_format="gmsh22", binary=False
    )
    truncated = tmp_path / "truncated.msh"
    truncated.write_text(msh.read_text()[: len(msh.read_text()) // 2])
    lines_only = tmp_path / "lines.msh"
    meshio.write(
        lines_only,
        meshio.Mesh(POINTS[:4], [("line", np.array([[0, 1], [1, 2]]))]),
        file_format="gmsh22",
        binary=False,
    )
    bad_mat = tmp_path / "bad.mat"
    scipy.io.savemat(bad_mat, {"q": np.zeros(3)})
    out_of_range = tmp_path / "range.mat"
    scipy.io.savemat(out_of_range, {"p": POINTS[:3].T, "t": np.array([[1], [2], [9], [1]])})
    files = {
        "empty": (tmp_path / "empty.msh", b"", "empty"),
        "garbage-msh": (tmp_path / "g.msh", garbage, "not a readable Gmsh"),
        "garbage-vtu": (tmp_path / "g.vtu", garbage, "it is not valid XML"),
        "garbage-vtp": (tmp_path / "g.vtp", garbage, "it is not valid XML"),
        "garbage-vtk": (tmp_path / "g.vtk", garbage, "not a readable VTK"),
        # bytes 80..84 of a binary STL count its triangles; here they do not match the size
        "garbage-stl": (tmp_path / "g.stl", garbage, "declares 544,501,614 triangles"),
        "garbage-mat": (tmp_path / "g.mat", garbage, "it is not a MATLAB file"),
        "wrong-xml": (tmp_path / "w.vtp", b'<VTKFile type="ImageData"/>', "PolyData"),
        "truncated": (truncated, None, "the file is truncated"),
        "no-triangles": (lines_only, None, "no triangles (only 2 line cells"),
        "no-p": (bad_mat, None, "no variable 'p'"),
        "index-out-of-range": (out_of_range, None, "refers to vertex 9 but p has 3 vertices"),
        "unsupported": (tmp_path / "m.ply", b"ply\n", "cannot read .ply"),
        "missing": (tmp_path / "nope.msh", None, "does not exist"),
        "folder": (tmp_path / "dir.msh", "dir", "is a folder"),
    }
    for path, content, _ in files.values():
        if content == "dir":
            path.mkdir()
        elif content is not None:
            path.write_bytes(content)
    return files


BAD = [
    "empty",
    "garbage-msh",
    "garbage-vtu",
    "garbage-vtp",
    "garbage-vtk",
    "garbage-stl",
    "garbage-mat",
    "wrong-xml",
    "truncated",
    "no-triangles",
    "no-p",
    "index-out-of-range",
    "unsupported",
    "missing",
    "folder",
]


@pytest.mark.parametrize("case", BAD)
def test_bad_files_name_the_file_and_the_problem(tmp_path, case):
    path, _, problem = _bad_files(tmp_path)[case]
    with pytest.raises(MeshFileError) as info:
        read_mesh(path)
    message = str(info.value)
    assert str(path) in message
    assert problem in message
    assert "\n" not in message
    assert isinstance(info.value, ValueError)


def test_bad_unit(tmp_path):
    with pytest.raises(ValueError, match="unit='km' is unknown"):
        read_mesh(tmp_path / "x.msh", unit="km")


@pytest.mark.parametrize("binary", [False, True], ids=["ascii", "binary"])
def test_gmsh41_as_meshio_writes_it(tmp_path, binary):
    """MSH 4.1 is read by our own reader: the same triangles, regions and patches as written."""
    from helpers import canonical_meshes

    from barymesh.io.meshio_formats import to_meshio

    mesh = canonical_meshes()["double-ring"]
    path = tmp_path / "rings.msh"
    m = to_meshio(mesh, ".msh", 1.0)
    meshio.write(path, m, file_format="gmsh", binary=binary)
    assert path.read_bytes().startswith(b"$MeshFormat\n4.1 " + (b"1" if binary else b"0"))
    back = read_mesh(path)
    assert (back.n_vertices, back.n_triangles) == (mesh.n_vertices, mesh.n_triangles)
    np.testing.assert_allclose(back.points[back.triangles], mesh.points[mesh.triangles])
    assert back.stats()["interior_edges"] == mesh.stats()["interior_edges"]
    # meshio's 4.1 writer puts all triangles in one entity without a physical group
    assert back.n_patches == 1 and back.regions.tolist() == [1] * mesh.n_triangles


def test_makarov_mat_version_4(tmp_path):
    """MATLAB v4 files (no header) are read after their variable headers are checked."""
    path = tmp_path / "v4.mat"
    scipy.io.savemat(
        path, {"p": POINTS[:4].T, "t": np.vstack([TRIANGLES.T + 1, [1, 1]])}, format="4"
    )
    mesh = read_mesh(path, unit="mm")
    assert mesh.n_triangles == 2 and mesh.areas.sum() == pytest.approx(1.0)

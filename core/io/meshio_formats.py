"""Gmsh, VTK, STL and OBJ through meshio.

Our meshes become one ``triangle`` cell block. Gmsh files carry the region
as physical tag (1: the patch or the inner ring, 2: the outer ring), with a
``$PhysicalNames`` entry, and the patch (or sector) as elementary tag
(patch id + 1), so a solver can tell the rings apart and our importer gets
the patches back. VTK files carry the per-triangle quality as cell data; Gmsh
files do not (solvers read them, and meshio would write it as ``$ElementData``
that doubles the file), nor do STL and OBJ, which have no cell data.
"""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import meshio
import numpy as np

from ..mesh import TriMesh
from ..quality import longest_sides

#: Extension -> meshio's format name, for the formats meshio writes.
MESHIO_WRITE = {".msh": "gmsh22", ".vtu": "vtu", ".vtk": "vtk", ".stl": "stl", ".obj": "obj"}


def region_names(mesh: TriMesh) -> dict[int, str]:
    """Physical names of the regions: ``patch``, ``ring``, ``inner_ring``, ``outer_ring``."""
    regions = np.unique(mesh.regions).tolist()
    if mesh.mode == "imported":
        return {r: f"region_{r}" for r in regions}
    if regions == [1] and mesh.n_patches == 1:
        return {1: "patch"}
    if regions == [1]:
        return {1: "ring"}
    names = {1: "inner_ring", 2: "outer_ring"}
    return {r: names.get(r, f"region_{r}") for r in regions}


def cell_quality(mesh: TriMesh, wavelength: float | None = None) -> dict[str, np.ndarray]:
    """Per-triangle data written to VTK files (names as in the window's colour menu).

    ``patch_id``, ``region`` (int64), ``area`` (mm²), ``min_angle`` (degrees),
    ``aspect_ratio``, each (T,); with ``wavelength`` (mm) also ``edge_wavelength``,
    the longest side of each triangle over λ (the figures of
    :func:`barymesh.quality.quality_report`).

    The integers are int64: meshio writes int32 to a legacy ``.vtk`` as ``vtktypeint32``,
    which VTK's own reader (ParaView, pyvista) does not know, and it then drops every cell
    array of the file (meshio issue 1410); ``vtktypeint64`` it reads.
    """
    data: dict[str, np.ndarray] = {
        "patch_id": mesh.patch_ids.astype(np.int64),
        "region": mesh.regions.astype(np.int64),
        "area": np.asarray(mesh.areas, dtype=np.float64),
        "min_angle": np.asarray(mesh.min_angles, dtype=np.float64),
        "aspect_ratio": np.asarray(mesh.aspect_ratios, dtype=np.float64),
    }
    if wavelength is not None:
        data["edge_wavelength"] = longest_sides(mesh.points, mesh.triangles) / float(wavelength)
    return data


def to_meshio(
    mesh: TriMesh, ext: str, per_mm: float, wavelength: float | None = None
) -> meshio.Mesh:
    """A meshio mesh for extension ``ext`` with coordinates in the file's unit.

    ``per_mm`` multiplies mm coordinates (and areas by its square); ``wavelength``
    (mm) adds ``edge_wavelength`` to the cell data of VTK files.
    """
    points = np.asarray(mesh.points, dtype=np.float64) * per_mm
    cells = [("triangle", np.asarray(mesh.triangles, dtype=np.int64))]
    if ext == ".msh":
        names = region_names(mesh)
        return meshio.Mesh(
            points,
            cells,
            cell_data={
                "gmsh:physical": [mesh.regions.astype(np.int32)],
                "gmsh:geometrical": [mesh.patch_ids.astype(np.int32) + 1],
            },
            field_data={name: np.array([tag, 2]) for tag, name in names.items()},
        )
    if ext in (".vtu", ".vtk"):
        data = cell_quality(mesh, wavelength)
        data["area"] = data["area"] * per_mm**2
        return meshio.Mesh(points, cells, cell_data={k: [v] for k, v in data.items()})
    return meshio.Mesh(points, cells)


def write_meshio(
    mesh: TriMesh, path: Path, ext: str, per_mm: float, wavelength: float | None = None
) -> None:
    """Write ``mesh`` to ``path`` in the format of extension ``ext`` (ASCII where it matters)."""
    fmt = MESHIO_WRITE[ext]
    m = to_meshio(mesh, ext, per_mm, wavelength)
    kwargs = {"binary": False} if fmt in ("gmsh22", "stl") else {}
    with contextlib.redirect_stderr(io.StringIO()):  # meshio prints warnings with rich
        meshio.write(path, m, file_format=fmt, **kwargs)

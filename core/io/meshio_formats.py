"""Gmsh, VTK, STL and OBJ through meshio.

Our meshes become one ``triangle`` cell block. Gmsh files (MSH 2.2 or 4.1,
:mod:`barymesh.io.gmsh_msh`) carry the region as physical tag (1: the patch or
the inner ring, 2: the outer ring), with a ``$PhysicalNames`` entry, and the
patch (or sector) as elementary tag (patch id + 1), so a solver can tell the
rings apart and our importer gets the patches back. VTK files carry the
per-triangle quality as cell data (:func:`barymesh.quality.cell_figures`); Gmsh
files do not (solvers read them, and meshio would write it as ``$ElementData``
that doubles the file), nor do STL and OBJ, which have no cell data.
"""

from __future__ import annotations

import contextlib
import io
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..mesh import TriMesh
from ..quality import cell_figures
from .gmsh_msh import check_msh_version, gmsh_mesh, region_names, write_gmsh

if TYPE_CHECKING:
    import meshio

#: Extension -> meshio's format name, for the formats meshio writes (.msh: see
#: :mod:`barymesh.io.gmsh_msh`, 2.2 or 4.1).
MESHIO_WRITE = {".msh": "gmsh22", ".vtu": "vtu", ".vtk": "vtk", ".stl": "stl", ".obj": "obj"}

__all__ = ["MESHIO_WRITE", "cell_quality", "region_names", "to_meshio", "write_meshio"]


def cell_quality(mesh: TriMesh, wavelength: float | None = None) -> dict[str, np.ndarray]:
    """Per-triangle data written to VTK files: :func:`barymesh.quality.cell_figures`."""
    return cell_figures(mesh, wavelength)


def to_meshio(
    mesh: TriMesh,
    ext: str,
    per_mm: float,
    wavelength: float | None = None,
    msh_version: str = "2.2",
) -> meshio.Mesh:
    """A meshio mesh for extension ``ext`` with coordinates in the file's unit.

    ``per_mm`` multiplies mm coordinates (and areas by its square); ``wavelength``
    (mm) adds ``edge_wavelength`` to the cell data of VTK files; ``msh_version``
    (``"2.2"`` or ``"4.1"``) is the Gmsh format a ``.msh`` is for
    (:func:`barymesh.io.gmsh_msh.gmsh_mesh`).
    """
    if ext == ".msh":
        return gmsh_mesh(mesh, per_mm, msh_version)
    import meshio  # here, not at the top: ``barymesh --help`` stays quick

    points = np.asarray(mesh.points, dtype=np.float64) * per_mm
    cells = [("triangle", np.asarray(mesh.triangles, dtype=np.int64))]
    if ext in (".vtu", ".vtk"):
        data = cell_quality(mesh, wavelength)
        data["area"] = data["area"] * per_mm**2
        return meshio.Mesh(points, cells, cell_data={k: [v] for k, v in data.items()})
    return meshio.Mesh(points, cells)


def write_meshio(
    mesh: TriMesh,
    path: Path,
    ext: str,
    per_mm: float,
    wavelength: float | None = None,
    msh_version: str = "2.2",
) -> None:
    """Write ``mesh`` to ``path`` in the format of extension ``ext`` (ASCII where it matters)."""
    if ext == ".msh":
        version = check_msh_version(msh_version)
        write_gmsh(path, to_meshio(mesh, ext, per_mm, wavelength, version), version)
        return
    import meshio

    fmt = MESHIO_WRITE[ext]
    m = to_meshio(mesh, ext, per_mm, wavelength)
    kwargs = {"binary": False} if fmt == "stl" else {}
    with contextlib.redirect_stderr(io.StringIO()):  # meshio prints warnings with rich
        meshio.write(path, m, file_format=fmt, **kwargs)

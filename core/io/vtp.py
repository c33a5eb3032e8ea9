"""Write VTK XML PolyData (``.vtp``), which meshio does not handle.

An ASCII file with the triangles as ``Polys`` and the per-triangle quality
as cell data (areas in the file's unit squared). The reader is in
:mod:`barymesh.io.vtk_xml`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..mesh import TriMesh
from .meshio_formats import cell_quality
from .vtk_ascii import data_array


def write_vtp(mesh: TriMesh, path: Path, per_mm: float, wavelength: float | None = None) -> None:
    """Write ``mesh`` as ASCII PolyData with coordinates multiplied by ``per_mm``.

    ``wavelength`` (mm) adds the cell array ``edge_wavelength``.
    """
    points = np.asarray(mesh.points, dtype=np.float64) * per_mm
    tri = np.asarray(mesh.triangles, dtype=np.int64)
    data = cell_quality(mesh, wavelength)
    data["area"] = data["area"] * per_mm**2
    parts = [
        '<?xml version="1.0"?>\n',
        '<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" '
        'header_type="UInt64">\n<PolyData>\n',
        f'<Piece NumberOfPoints="{len(points)}" NumberOfVerts="0" NumberOfLines="0" '
        f'NumberOfStrips="0" NumberOfPolys="{len(tri)}">\n',
        "<Points>\n",
        data_array("Points", points, 3),
        "</Points>\n",
        "<Polys>\n",
        data_array("connectivity", tri.reshape(-1)),
        data_array("offsets", 3 * np.arange(1, len(tri) + 1, dtype=np.int64)),
        "</Polys>\n",
        '<CellData Scalars="region">\n',
        *(data_array(name, values) for name, values in data.items()),
        "</CellData>\n</Piece>\n</PolyData>\n</VTKFile>\n",
    ]
    path.write_text("".join(parts), encoding="ascii")

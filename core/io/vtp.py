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

_VTK_TYPES = {
    np.dtype(np.float64): "Float64",
    np.dtype(np.int32): "Int32",
    np.dtype(np.int64): "Int64",
}


def _array(name: str, data: np.ndarray, components: int = 1) -> str:
    """One ASCII ``DataArray`` element, nine values a line."""
    data = np.asarray(data)
    fmt = "%.17g" if data.dtype.kind == "f" else "%d"
    flat = data.reshape(-1).tolist()
    body = "\n".join(" ".join(map(fmt.__mod__, flat[k : k + 9])) for k in range(0, len(flat), 9))
    return (
        f'<DataArray type="{_VTK_TYPES[data.dtype]}" Name="{name}" '
        f'NumberOfComponents="{components}" format="ascii">\n{body}\n</DataArray>\n'
    )


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
        _array("Points", points, 3),
        "</Points>\n",
        "<Polys>\n",
        _array("connectivity", tri.reshape(-1)),
        _array("offsets", 3 * np.arange(1, len(tri) + 1, dtype=np.int64)),
        "</Polys>\n",
        '<CellData Scalars="region">\n',
        *(_array(name, values) for name, values in data.items()),
        "</CellData>\n</Piece>\n</PolyData>\n</VTKFile>\n",
    ]
    path.write_text("".join(parts), encoding="ascii")

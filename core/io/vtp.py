"""VTK XML PolyData (``.vtp``), which meshio does not handle.

The writer emits an ASCII file with the triangles as ``Polys`` and the
per-triangle quality as cell data. The reader takes any PolyData piece
(ASCII, base64 binary, compressed or appended) and returns its points,
polygons and the types of cells it skipped (verts, lines, strips, and
polygons that are not triangles).
"""

from __future__ import annotations

from pathlib import Path
from xml.etree import ElementTree as ET

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


def write_vtp(mesh: TriMesh, path: Path, per_mm: float) -> None:
    """Write ``mesh`` as ASCII PolyData with coordinates multiplied by ``per_mm``."""
    points = np.asarray(mesh.points, dtype=np.float64) * per_mm
    tri = np.asarray(mesh.triangles, dtype=np.int64)
    data = cell_quality(mesh)
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


def _reader(root: ET.Element):
    """meshio's VTU data-array decoder, configured from ``root``'s attributes."""
    from meshio.vtu._vtu import VtuReader, get_grid  # noqa: F401 (private but stable API)

    reader = VtuReader.__new__(VtuReader)
    reader.compression = root.attrib.get("compressor")
    reader.header_type = root.attrib.get("header_type", "UInt32")
    reader.byte_order = root.attrib.get("byte_order")
    reader.appended_data = None
    for child in root:
        if child.tag == "AppendedData":
            if child.attrib.get("encoding") != "base64":
                raise ValueError("raw appended data is not supported; save with base64 encoding")
            text = (child.text or "").strip()
            if not text.startswith("_"):
                raise ValueError("malformed AppendedData section")
            reader.appended_data = text[1:]
    return reader


def read_vtp(path: Path) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray], dict[str, int]]:
    """``(points (V, 3), triangles (T, 3), cell_data, ignored_cells)`` of a PolyData file."""
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as exc:
        if b'encoding="raw"' in Path(path).read_bytes()[: 1 << 20]:
            from meshio.vtu._vtu import _parse_raw_binary

            root = _parse_raw_binary(str(path))
        else:
            raise ValueError(f"not valid XML ({exc})") from None
    if root.tag != "VTKFile" or root.attrib.get("type") != "PolyData":
        raise ValueError(
            f"expected a VTK XML PolyData file, found <{root.tag} type={root.attrib.get('type')!r}>"
        )
    reader = _reader(root)
    pieces = root.findall("./PolyData/Piece")
    if not pieces:
        raise ValueError("no PolyData Piece found")
    points, triangles, ignored = [], [], {}
    cell_data: dict[str, list[np.ndarray]] = {}
    offset = 0
    for piece in pieces:
        pts_el = piece.find("./Points/DataArray")
        if pts_el is None:
            raise ValueError("a Piece has no Points")
        pts = np.asarray(reader.read_data(pts_el), dtype=np.float64).reshape(-1, 3)
        n_points = int(piece.attrib.get("NumberOfPoints", len(pts)))
        if len(pts) != n_points:
            raise ValueError(f"{len(pts)} points where NumberOfPoints says {n_points}")
        for kind in ("Verts", "Lines", "Strips"):
            count = int(piece.attrib.get(f"NumberOf{kind}", 0))
            if count:
                ignored[kind.lower()] = ignored.get(kind.lower(), 0) + count
        tri = np.empty((0, 3), dtype=np.int64)
        keep = np.zeros(0, dtype=bool)
        polys = piece.find("Polys")
        if polys is not None:
            arrays = {el.attrib.get("Name"): el for el in polys.findall("DataArray")}
            if "connectivity" not in arrays or "offsets" not in arrays:
                raise ValueError("Polys needs connectivity and offsets arrays")
            conn = np.asarray(reader.read_data(arrays["connectivity"]), dtype=np.int64).ravel()
            ends = np.asarray(reader.read_data(arrays["offsets"]), dtype=np.int64).ravel()
            starts = np.concatenate([[0], ends[:-1]])
            sizes = ends - starts
            if len(ends) and (np.any(sizes < 1) or ends[-1] > len(conn)):
                raise ValueError("Polys offsets do not match the connectivity")
            keep = sizes == 3
            if np.any(~keep):
                ignored["polygon"] = ignored.get("polygon", 0) + int((~keep).sum())
            tri = conn[starts[keep, None] + np.arange(3)]
            if tri.size and (tri.min() < 0 or tri.max() >= len(pts)):
                raise ValueError(f"Polys refer to point {int(tri.max())} of {len(pts)}")
            n_other = sum(int(piece.attrib.get(f"NumberOf{k}", 0)) for k in ("Verts", "Lines"))
            cd = piece.find("CellData")
            if cd is not None:
                for el in cd.findall("DataArray"):
                    values = np.asarray(reader.read_data(el))
                    if values.ndim == 2 and values.shape[1] == 1:
                        values = values[:, 0]
                    if len(values) == n_other + len(keep) + int(
                        piece.attrib.get("NumberOfStrips", 0)
                    ):
                        values = values[n_other : n_other + len(keep)]
                    if len(values) == len(keep):
                        cell_data.setdefault(el.attrib.get("Name", ""), []).append(values[keep])
        points.append(pts)
        triangles.append(tri + offset)
        offset += len(pts)
    cell_data_out = {k: np.concatenate(v) for k, v in cell_data.items() if len(v) == len(pieces)}
    return np.concatenate(points), np.concatenate(triangles), cell_data_out, ignored

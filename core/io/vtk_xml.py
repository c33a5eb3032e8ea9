"""Read VTK XML PolyData (``.vtp``) and UnstructuredGrid (``.vtu``) files safely.

Handles every encoding VTK writes: ASCII, inline base64 binary, appended
base64 or raw data, uncompressed or compressed (zlib, LZMA), 32- or 64-bit
headers, either byte order. Every count the file declares is checked against
:mod:`barymesh.io.limits` and against the bytes really present, and every
compressed block's declared size against what zlib can reach from its
compressed size, before anything is allocated; blocks are then inflated in
bounded chunks and refused as soon as one inflates beyond what it declared.
A decompression bomb is thus refused in milliseconds with a few kB of memory.
"""

from __future__ import annotations

import base64
import binascii
import lzma
import re
import warnings
import zlib
from pathlib import Path
from typing import Literal
from xml.etree import ElementTree as ET

import numpy as np

from .limits import MAX_CELLS, MAX_POINTS, ZLIB_MAX_RATIO, Damaged, check_count, parse_count

_DTYPES = {
    "Float32": np.float32,
    "Float64": np.float64,
    "Int8": np.int8,
    "Int16": np.int16,
    "Int32": np.int32,
    "Int64": np.int64,
    "UInt8": np.uint8,
    "UInt16": np.uint16,
    "UInt32": np.uint32,
    "UInt64": np.uint64,
}
_COMPRESSORS = ("vtkZLibDataCompressor", "vtkLZMADataCompressor")
#: VTK cell type -> name in messages (and in ``TriMesh.ignored_cells``).
_CELL_NAMES = {
    1: "vertex",
    2: "poly_vertex",
    3: "line",
    4: "poly_line",
    5: "triangle",
    6: "triangle_strip",
    7: "polygon",
    8: "pixel",
    9: "quad",
    10: "tetra",
    11: "voxel",
    12: "hexahedron",
    13: "wedge",
    14: "pyramid",
    21: "line3",
    22: "triangle6",
    23: "quad8",
    24: "tetra10",
    25: "hexahedron20",
    42: "polyhedron",
}
VTK_TRIANGLE = 5
_SINGULAR = {"Verts": "vertex cell", "Lines": "line", "Polys": "polygon", "Strips": "strip"}
#: Output is inflated this many bytes at a time.
_CHUNK = 1 << 20
#: Connectivity entries a file may declare (cells of up to 8 points on average).
_MAX_CONNECTIVITY = 8 * MAX_CELLS


def _b64_chars(n_bytes: int) -> int:
    """Base64 characters that encode ``n_bytes`` bytes."""
    return -(-n_bytes // 3) * 4


def _b64(text: bytes, what: str) -> bytes:
    try:
        return base64.b64decode(text, validate=True)
    except (binascii.Error, ValueError):
        raise Damaged(f"the {what} array is not valid base64") from None


class _ArrayReader:
    """Decodes the ``DataArray`` elements of one file with bounded memory."""

    def __init__(self, root: ET.Element, appended: bytes | None, raw: bool) -> None:
        self.compressor = root.attrib.get("compressor") or None
        if self.compressor is not None and self.compressor not in _COMPRESSORS:
            raise Damaged(
                f"its compressor {self.compressor!r} is not supported "
                f"(expected {' or '.join(_COMPRESSORS)})"
            )
        header = root.attrib.get("header_type", "UInt32")
        if header not in ("UInt32", "UInt64"):
            raise Damaged(f"its header_type {header!r} is not UInt32 or UInt64")
        order = root.attrib.get("byte_order", "LittleEndian")
        if order not in ("LittleEndian", "BigEndian"):
            raise Damaged(f"its byte_order {order!r} is not LittleEndian or BigEndian")
        self.order: Literal["<", ">"] = "<" if order == "LittleEndian" else ">"
        self.header = np.dtype(_DTYPES[header]).newbyteorder(self.order)
        self.appended, self.raw = appended, raw

    # -- one array -----------------------------------------------------------------------

    def read(
        self,
        el: ET.Element | None,
        what: str,
        count: int | None,
        components: int = 1,
        limit: int = _MAX_CONNECTIVITY,
    ) -> np.ndarray:
        """The values of ``el``: ``(count * components,)``; ``count=None``: as declared.

        ``what`` names the array in messages; ``limit`` bounds the number of
        values when ``count`` is not known in advance.
        """
        if el is None:
            raise Damaged(f"it has no {what} array")
        type_name = el.attrib.get("type", "")
        if type_name not in _DTYPES:
            raise Damaged(f"the {what} array has type {type_name[:20]!r}, not a VTK number type")
        dtype = np.dtype(_DTYPES[type_name]).newbyteorder(self.order)
        declared = parse_count(el.attrib.get("NumberOfComponents", "1"), "components", 64)
        if declared != components and not (count is None and declared == 1):
            raise Damaged(f"the {what} array has {declared} components; expected {components}")
        expected = None if count is None else count * components
        fmt = el.attrib.get("format", "ascii")
        if fmt == "ascii":
            values = self._ascii(el.text or "", dtype, what, expected, limit)
        elif fmt in ("binary", "appended"):
            if fmt == "binary":
                source: bytes | memoryview = "".join((el.text or "").split()).encode(
                    "ascii", "replace"
                )
                encoded = True
            else:
                if self.appended is None:
                    raise Damaged(f"the {what} array is appended but the file has no AppendedData")
                offset = parse_count(el.attrib.get("offset", ""), "offset", len(self.appended))
                source, encoded = memoryview(self.appended)[offset:], not self.raw
            n_bytes = None if expected is None else expected * dtype.itemsize
            limit_bytes = limit * dtype.itemsize
            data = self._binary(source, encoded, what, n_bytes, limit_bytes)
            if len(data) % dtype.itemsize:
                raise Damaged(f"the {what} array holds {len(data)} bytes, not whole {type_name}")
            values = np.frombuffer(data, dtype=dtype)
        else:
            raise Damaged(f"the {what} array has format {fmt[:20]!r}, not ascii/binary/appended")
        if expected is not None and len(values) != expected:
            raise Damaged(f"the {what} array holds {len(values):,} values; expected {expected:,}")
        return values

    @staticmethod
    def _ascii(text: str, dtype: np.dtype, what: str, expected: int | None, limit: int):
        most = (len(text) + 1) // 2  # "1 2 3" holds at most (length + 1) / 2 numbers
        if expected is not None and expected > most:
            raise Damaged(f"the {what} array holds at most {most:,} values; expected {expected:,}")
        if not text.strip():
            return np.empty(0, dtype=dtype)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            try:
                values = np.fromstring(text, dtype=np.float64, sep=" ")
            except (DeprecationWarning, ValueError):
                raise Damaged(f"the {what} array holds text that is not a number") from None
        if len(values) > limit:
            raise Damaged(f"the {what} array holds {len(values):,} values; at most {limit:,}")
        if dtype.kind in "iu":
            if not np.all(np.isfinite(values)) or np.any(values % 1 != 0):
                raise Damaged(f"the {what} array holds values that are not whole numbers")
            info = np.iinfo(dtype)
            if values.size and (values.min() < info.min or values.max() > info.max):
                raise Damaged(f"the {what} array holds values outside its type {dtype.name}")
        return values.astype(dtype.newbyteorder("="))

    def _binary(self, source, encoded: bool, what: str, n_bytes: int | None, limit: int):
        """Decode one binary array from ``source`` (base64 text or raw bytes)."""
        hb = self.header.itemsize

        def take(n: int, pos: int) -> tuple[bytes, int]:
            """``n`` bytes from position ``pos`` of ``source``; returns them and the next pos."""
            if not encoded:
                if pos + n > len(source):
                    raise Damaged(f"the {what} array ends early (the file is truncated)")
                return bytes(source[pos : pos + n]), pos + n
            chars = _b64_chars(n)
            if pos + chars > len(source):
                raise Damaged(f"the {what} array ends early (the file is truncated)")
            return _b64(bytes(source[pos : pos + chars]), what)[:n], pos + chars

        if self.compressor is None:
            if encoded:
                # header and data are either one base64 stream or two (header padded)
                chars = _b64_chars(hb)
                head = bytes(source[:chars])
                size = int(np.frombuffer(_b64(head, what)[:hb], self.header)[0])
                self._check_size(size, n_bytes, limit, what)
                if b"=" in head:
                    return take(size, chars)[0]
                return take(hb + size, 0)[0][hb:]
            size = int(np.frombuffer(take(hb, 0)[0], self.header)[0])
            self._check_size(size, n_bytes, limit, what)
            return take(size, hb)[0]

        first, _ = take(hb, 0)
        n_blocks = int(np.frombuffer(first, self.header)[0])
        available = len(source) * 3 // 4 if encoded else len(source)
        if n_blocks * hb > available:
            raise Damaged(
                f"the {what} array declares {n_blocks:,} compressed blocks; "
                "the file is too short for them"
            )
        head, pos = take((3 + n_blocks) * hb, 0)
        header = np.frombuffer(head, self.header).astype(np.int64)
        block, last = int(header[1]), int(header[2])
        sizes = header[3:]
        raw = np.full(n_blocks, block, dtype=np.int64)
        if n_blocks and last:
            raw[-1] = last
        self._check_size(int(raw.sum()), n_bytes, limit, what)
        if np.any(sizes < 0) or int(sizes.sum()) > available:
            raise Damaged(
                f"the {what} array declares {int(sizes.sum()):,} compressed bytes; "
                f"the file holds {available:,}"
            )
        if np.any(raw > ZLIB_MAX_RATIO * sizes + 64):
            raise Damaged(
                f"the {what} array declares a block of {int(raw.max()):,} bytes from "
                f"{int(sizes[np.argmax(raw)]):,} compressed bytes, more than compression can "
                "reach (a damaged or hostile file)"
            )
        packed, _ = take(int(sizes.sum()), pos)
        out = bytearray(int(raw.sum()))
        at, start = 0, 0
        for want, csize in zip(raw.tolist(), sizes.tolist(), strict=True):
            self._inflate(packed[start : start + csize], want, out, at, what)
            at += want
            start += csize
        return out

    @staticmethod
    def _check_size(size: int, n_bytes: int | None, limit: int, what: str) -> None:
        if n_bytes is not None and size != n_bytes:
            raise Damaged(f"the {what} array declares {size:,} bytes; its count needs {n_bytes:,}")
        if size < 0 or size > limit:
            raise Damaged(
                f"the {what} array declares {size:,} bytes; barymesh reads at most {limit:,}"
            )

    def _inflate(self, packed: bytes, want: int, out: bytearray, at: int, what: str) -> None:
        """Inflate one block into ``out[at:at + want]``, never producing more than ``want + 1``."""
        zlib_mode = self.compressor == "vtkZLibDataCompressor"
        d = zlib.decompressobj() if zlib_mode else lzma.LZMADecompressor()
        done, tail = 0, packed
        try:
            while True:
                room = min(_CHUNK, want - done + 1)
                chunk = d.decompress(tail, room)
                if done + len(chunk) > want:
                    raise Damaged(
                        f"a compressed block of the {what} array inflates to more "
                        f"than the {want:,} bytes it declares"
                    )
                out[at + done : at + done + len(chunk)] = chunk
                done += len(chunk)
                tail = b"" if isinstance(d, lzma.LZMADecompressor) else d.unconsumed_tail
                if d.eof or (not chunk and not tail):
                    break
        except (zlib.error, lzma.LZMAError):
            raise Damaged(f"a compressed block of the {what} array is corrupt") from None
        if done != want:
            raise Damaged(
                f"a compressed block of the {what} array inflates to {done:,} bytes; "
                f"it declares {want:,}"
            )


# -- the file ----------------------------------------------------------------------------


def _parse(path: Path) -> tuple[ET.Element, bytes | None, bool]:
    """The XML root, the appended data (without its ``_``) and whether it is raw."""
    data = path.read_bytes()
    appended, raw = None, False
    match = re.search(rb"<AppendedData\b[^>]*>", data)
    if match and re.search(rb'encoding\s*=\s*["\']raw["\']', match.group(0)):
        stop = data.rfind(b"</AppendedData>")
        underscore = data.find(b"_", match.end())
        if stop < 0 or underscore < 0 or underscore > stop:
            raise Damaged("its raw AppendedData section is not closed (the file is truncated)")
        appended, raw = data[underscore + 1 : stop], True
        data = data[: match.end()] + data[stop:]
    if b"<!DOCTYPE" in data or b"<!ENTITY" in data:
        raise Damaged("it declares a DOCTYPE or entities, which VTK files never have")
    try:
        root = ET.fromstring(data)
    except ET.ParseError as exc:
        line, column = exc.position
        raise Damaged(f"it is not valid XML (at line {line}, column {column})") from None
    if not raw:
        section = root.find("AppendedData")
        if section is not None:
            if section.attrib.get("encoding", "base64") != "base64":
                raise Damaged("its AppendedData encoding is neither raw nor base64")
            text = "".join((section.text or "").split())
            if not text.startswith("_"):
                raise Damaged("its AppendedData section does not start with '_'")
            appended = text[1:].encode("ascii", "replace")
    return root, appended, raw


def _root(path: Path, kind: str) -> tuple[ET.Element, _ArrayReader]:
    root, appended, raw = _parse(path)
    if root.tag != "VTKFile" or root.attrib.get("type") != kind:
        found = root.attrib.get("type")
        raise Damaged(f"it is not VTK XML {kind} (it holds <{root.tag[:30]} type={found!r}>)")
    return root, _ArrayReader(root, appended, raw)


def _offsets(arrays: _ArrayReader, section: ET.Element | None, count: int, what: str):
    """``(starts, ends)`` of ``count`` cells of ``section`` and its connectivity array."""
    if section is None:
        raise Damaged(f"it declares {count:,} {what} but has no section for them")
    named = {el.attrib.get("Name"): el for el in section.findall("DataArray")}
    ends = arrays.read(named.get("offsets"), f"{what} offsets", count).astype(np.int64)
    starts = np.concatenate([[0], ends[:-1]])
    if np.any(ends <= starts):
        raise Damaged(f"the {what} offsets do not increase (every cell needs a point)")
    total = int(ends[-1]) if count else 0
    check_count(total, f"{what} connectivity entries", _MAX_CONNECTIVITY)
    conn = arrays.read(named.get("connectivity"), f"{what} connectivity", total).astype(np.int64)
    return starts, ends, conn


def _check_indices(tri: np.ndarray, n_points: int, what: str) -> None:
    if not tri.size:
        return
    low, high = int(tri.min()), int(tri.max())
    if low < 0:
        raise Damaged(f"a {what} refers to point {low}; point indices start at 0")
    if high >= n_points:
        raise Damaged(
            f"a {what} refers to point {high:,} but there are {n_points:,} points "
            "(indices start at 0)"
        )


def _cell_data(arrays, piece, n_cells: int, keep: slice | np.ndarray) -> dict[str, np.ndarray]:
    """One-component cell data of ``piece``, restricted to ``keep``."""
    data = {}
    section = piece.find("CellData")
    for el in [] if section is None else section.findall("DataArray"):
        if el.attrib.get("NumberOfComponents", "1") != "1" or el.attrib.get("type") not in _DTYPES:
            continue  # vectors, strings: not regions or patches
        name = el.attrib.get("Name", "")
        data[name] = arrays.read(el, f"cell data {name[:40]!r}", n_cells)[keep]
    return data


def _points(arrays: _ArrayReader, piece: ET.Element) -> tuple[int, np.ndarray]:
    n = parse_count(piece.attrib.get("NumberOfPoints", "0"), "points", MAX_POINTS)
    el = piece.find("./Points/DataArray")
    return n, arrays.read(el, "Points", n, 3).astype(np.float64).reshape(-1, 3)


def _merge(pieces: list[tuple[np.ndarray, np.ndarray, dict]]):
    points, triangles, offset = [], [], 0
    for pts, tri, _ in pieces:
        points.append(pts)
        triangles.append(tri + offset)
        offset += len(pts)
    names = set.intersection(*(set(d) for _, _, d in pieces))
    data = {name: np.concatenate([d[name] for _, _, d in pieces]) for name in names}
    return np.concatenate(points), np.concatenate(triangles), data


def read_vtp(path: Path):
    """``(points (V, 3), triangles (T, 3), cell_data, ignored_cells)`` of a ``.vtp`` file.

    Triangles are the ``Polys`` of three points; verts, lines, strips and other
    polygons are counted in ``ignored_cells``. Raises :class:`Damaged` saying
    what is wrong.
    """
    root, arrays = _root(path, "PolyData")
    pieces: list[tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]] = []  # (points, tri, data)
    ignored: dict[str, int] = {}
    elements = root.findall("./PolyData/Piece")
    if not elements:
        raise Damaged("it has no PolyData Piece")
    for piece in elements:
        n_points, pts = _points(arrays, piece)
        counts = {
            kind: parse_count(piece.attrib.get(f"NumberOf{kind}", "0"), kind.lower(), MAX_CELLS)
            for kind in ("Verts", "Lines", "Polys", "Strips")
        }
        check_count(sum(counts.values()), "cells", MAX_CELLS)
        tri, keep = np.empty((0, 3), dtype=np.int64), np.zeros(0, dtype=bool)
        for kind, count in counts.items():
            if not count:
                continue
            starts, ends, conn = _offsets(arrays, piece.find(kind), count, kind.lower())
            _check_indices(conn, n_points, _SINGULAR[kind])
            if kind != "Polys":
                ignored[kind.lower()] = ignored.get(kind.lower(), 0) + count
                continue
            keep = ends - starts == 3
            if not keep.all():
                ignored["polygon"] = ignored.get("polygon", 0) + int((~keep).sum())
            tri = conn[starts[keep, None] + np.arange(3)]
        first = counts["Verts"] + counts["Lines"]  # VTK orders cells verts, lines, polys, strips
        total = sum(counts.values())
        where = np.zeros(total, dtype=bool)
        where[first : first + counts["Polys"]] = keep
        pieces.append((pts, tri, _cell_data(arrays, piece, total, where)))
    points, triangles, data = _merge(pieces)
    return points, triangles, data, ignored


def read_vtu(path: Path):
    """``(points (V, 3), triangles (T, 3), cell_data, ignored_cells)`` of a ``.vtu`` file.

    Triangles are the cells of VTK type 5; every other type is counted in
    ``ignored_cells`` by name. Raises :class:`Damaged` saying what is wrong.
    """
    root, arrays = _root(path, "UnstructuredGrid")
    pieces: list[tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]] = []  # (points, tri, data)
    ignored: dict[str, int] = {}
    elements = root.findall("./UnstructuredGrid/Piece")
    if not elements:
        raise Damaged("it has no UnstructuredGrid Piece")
    for piece in elements:
        n_points, pts = _points(arrays, piece)
        n_cells = parse_count(piece.attrib.get("NumberOfCells", "0"), "cells", MAX_CELLS)
        tri, keep = np.empty((0, 3), dtype=np.int64), np.zeros(n_cells, dtype=bool)
        if n_cells:
            section = piece.find("Cells")
            if section is None:  # as _offsets says
                raise Damaged(f"it declares {n_cells:,} cells but has no section for them")
            starts, ends, conn = _offsets(arrays, section, n_cells, "cells")
            named = {el.attrib.get("Name"): el for el in section.findall("DataArray")}
            types = arrays.read(named.get("types"), "cell types", n_cells).astype(np.int64)
            _check_indices(conn, n_points, "cell")
            keep = types == VTK_TRIANGLE
            if np.any(ends[keep] - starts[keep] != 3):
                raise Damaged("a triangle cell (type 5) does not have 3 points")
            tri = conn[starts[keep, None] + np.arange(3)]
            kinds, numbers = np.unique(types[~keep], return_counts=True)
            for kind, number in zip(kinds.tolist(), numbers.tolist(), strict=True):
                name = _CELL_NAMES.get(kind, f"VTK type {kind}")
                ignored[name] = ignored.get(name, 0) + number
        pieces.append((pts, tri, _cell_data(arrays, piece, n_cells, keep)))
    points, triangles, data = _merge(pieces)
    return points, triangles, data, ignored

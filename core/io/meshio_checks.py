"""Cheap checks of the counts a file declares, before meshio reads it.

meshio trusts the counts in legacy VTK, STL and Gmsh (binary 2.2, 4.x)
headers and allocates for them; these checks compare each declared count
with :mod:`barymesh.io.limits` and with the bytes the file really holds, so a
count of 10^12 is refused at once instead of after gigabytes of allocation.
"""

from __future__ import annotations

import re
from pathlib import Path

from .limits import MAX_CELLS, MAX_POINTS, Damaged, check_count

#: Legacy VTK keyword -> (what, limit, numbers per declared item or None: use the size).
_VTK_KEYWORDS = {
    b"POINTS": ("points", MAX_POINTS, 3),
    b"CELLS": ("cells", MAX_CELLS, None),
    b"POLYGONS": ("polygons", MAX_CELLS, None),
    b"TRIANGLE_STRIPS": ("triangle strips", MAX_CELLS, None),
    b"LINES": ("lines", MAX_CELLS, None),
    b"VERTICES": ("vertices", MAX_CELLS, None),
    b"CELL_TYPES": ("cell types", MAX_CELLS, 1),
    b"CELL_DATA": ("cell data values", MAX_CELLS, 1),
    b"POINT_DATA": ("point data values", MAX_POINTS, 1),
}
_VTK_LINE = re.compile(
    rb"^[ \t]*(" + b"|".join(_VTK_KEYWORDS) + rb")[ \t]+(\S+)(?:[ \t]+(\S+))?", re.MULTILINE
)
_VTK_TYPES = (
    rb"bit|unsigned_char|char|unsigned_short|short|unsigned_int|int|unsigned_long|"
    rb"long|float|double|vtktypeint64|vtktypeuint64|vtkIdType"
)
#: ``FIELD`` arrays: ``name components tuples type``; ``SCALARS``: ``name type [components]``.
_VTK_FIELD = re.compile(
    rb"^[ \t]*\S+[ \t]+(\d+)[ \t]+(\d+)[ \t]+(?:" + _VTK_TYPES + rb")[ \t\r]*$", re.MULTILINE
)
_VTK_SCALARS = re.compile(rb"^[ \t]*SCALARS[ \t]+\S+[ \t]+\S+[ \t]+(\S+)", re.MULTILINE)
_MSH_SECTION = re.compile(rb"^\$(Nodes|Elements)[ \t\r]*\n([^\n]*)", re.MULTILINE)


def _number(token: bytes, what: str) -> int:
    if not token.isdigit() or len(token) > 30:
        raise Damaged(
            f"the number of {what} is {token[:30].decode('latin-1')!r}, not a whole number"
        )
    return int(token)


def _fits(numbers: int, what: str, count: int, size: int) -> None:
    if numbers > size:
        raise Damaged(f"it declares {count:,} {what} but the file has only {size:,} bytes")


def check_declared_counts(path: Path, ext: str) -> None:
    """Raise :class:`Damaged` if ``path`` declares more than it can hold or we read."""
    size = path.stat().st_size
    with open(path, "rb") as fh:
        data = fh.read()
    if ext == ".vtk":
        for match in _VTK_LINE.finditer(data):
            what, limit, per_item = _VTK_KEYWORDS[match.group(1)]
            count = check_count(_number(match.group(2), what), what, limit)
            numbers = count * per_item if per_item else None
            if per_item is None and match.group(3):
                numbers = _number(match.group(3), f"{what} entries")
            _fits(numbers or 0, what, count, size)
        for match in _VTK_FIELD.finditer(data):
            components = _number(match.group(1), "field components")
            tuples = _number(match.group(2), "field tuples")
            _fits(components * tuples, "field values", components * tuples, size)
        for match in _VTK_SCALARS.finditer(data):
            if not 1 <= _number(match.group(1), "scalar components") <= 4:
                raise Damaged(
                    f"a SCALARS line declares {match.group(1).decode('latin-1')[:20]} "
                    "components; VTK allows 1 to 4"
                )
    elif ext == ".stl" and not data[:5].lower() == b"solid" and len(data) >= 84:
        count = int.from_bytes(data[80:84], "little")
        if 84 + 50 * count != size:
            raise Damaged(
                f"its header declares {count:,} triangles ({84 + 50 * count:,} bytes) "
                f"but the file has {size:,} bytes"
            )
    elif ext == ".msh":
        head = re.match(rb"\s*\$MeshFormat\s+(\S+)\s+(\S+)\s+(\S+)", data)
        binary_4 = head is not None and head.group(1).startswith(b"4") and head.group(2) == b"1"
        for match in _MSH_SECTION.finditer(data):
            what = "nodes" if match.group(1) == b"Nodes" else "elements"
            limit = MAX_POINTS if what == "nodes" else MAX_CELLS
            if binary_4:  # four size_t: blocks, count, smallest and largest tag
                start = match.start(2)
                count = int.from_bytes(data[start + 8 : start + 16], "little")
            else:
                tokens = match.group(2).split()
                if not tokens:
                    continue
                count = _number(tokens[1] if len(tokens) == 4 else tokens[0], what)
            check_count(count, what, limit)
            _fits(count, what, count, size)

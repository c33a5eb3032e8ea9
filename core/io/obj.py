"""Read Wavefront OBJ (``.obj``) triangles.

Faces may give ``v``, ``v/vt``, ``v//vn`` or ``v/vt/vn`` per corner and
indices may be absolute (1-based) or relative (negative: -1 is the last
vertex defined before the face), as the OBJ specification allows. Faces of
three corners are triangles; quads, larger polygons, lines (``l``) and
points (``p``) are counted in ``ignored_cells``. Texture coordinates,
normals, groups and materials are not used.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .limits import MAX_CELLS, MAX_POINTS, Damaged, check_count

_IGNORED = {"l": "line", "p": "vertex"}


def _corner(token: str, line: int, before: int) -> int:
    """0-based vertex index of one face corner ``v[/vt][/vn]``."""
    head = token.split("/", 1)[0]
    try:
        index = int(head)
    except ValueError:
        raise Damaged(f"line {line}: face corner {token[:30]!r} is not a vertex index") from None
    if index > 0:
        return index - 1
    if index == 0:
        raise Damaged(
            f"line {line}: a face refers to vertex 0; OBJ indices start at 1 "
            "(or count back from -1)"
        )
    if before + index < 0:
        raise Damaged(
            f"line {line}: a face refers to vertex {index}, but only {before:,} vertices precede it"
        )
    return before + index


def read_obj(path: Path):
    """``(points (V, 3), triangles (T, 3), ignored_cells)`` of an OBJ file."""
    text = path.read_bytes().decode("latin-1")  # OBJ is ASCII; comments may hold anything
    coords: list[list[str]] = []
    faces: list[list[int]] = []
    ignored: dict[str, int] = {}
    for number, raw in enumerate(text.splitlines(), start=1):
        parts = raw.split()
        if not parts:
            continue
        key = parts[0]
        if key == "v":
            if len(parts) < 4:
                raise Damaged(f"line {number}: a vertex needs x, y and z")
            coords.append(parts[1:4])
        elif key == "f":
            if len(parts) < 4:
                raise Damaged(f"line {number}: a face needs at least 3 vertices")
            corners = [_corner(t, number, len(coords)) for t in parts[1:]]
            if len(corners) == 3:
                faces.append(corners)
            else:
                kind = "quad" if len(corners) == 4 else "polygon"
                ignored[kind] = ignored.get(kind, 0) + 1
        elif key in _IGNORED:
            ignored[_IGNORED[key]] = ignored.get(_IGNORED[key], 0) + 1
    check_count(len(coords), "vertices", MAX_POINTS)
    check_count(len(faces) + sum(ignored.values()), "faces", MAX_CELLS)
    try:
        points = np.array(coords, dtype=np.float64).reshape(-1, 3)
    except ValueError:
        bad = next(c for c in coords if not all(_is_number(v) for v in c))
        raise Damaged(f"a vertex has coordinates {' '.join(bad)[:40]!r}, not numbers") from None
    triangles = np.array(faces, dtype=np.int64).reshape(-1, 3)
    if triangles.size and triangles.max() >= len(points):
        raise Damaged(
            f"a face refers to vertex {int(triangles.max()) + 1:,} but the file "
            f"defines {len(points):,} vertices"
        )
    return points, triangles, ignored


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True

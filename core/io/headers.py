"""What a mesh file must look like before it is read: its size, its first and last bytes.

Checked by :func:`barymesh.io.read_mesh` before any reader sees the file, on a few
kilobytes at its start and end, so a file that cannot be what its extension says (a
sparse gigabyte of NUL bytes named ``.obj``, a ``.msh`` without ``$MeshFormat``) or that
is larger than :func:`barymesh.io.limits.max_file_bytes` is refused at once instead of
after reading it all; and an ASCII STL cut short (no ``endsolid``, which meshio does not
ask for) is refused like the other formats' missing end markers.
"""

from __future__ import annotations

import re
from pathlib import Path

from .limits import MAX_FILE_ENV, Damaged, format_size

#: Bytes read from the start of a file to recognise it (and from the end of an ASCII STL).
HEAD_BYTES = 1 << 16
_BOM = b"\xef\xbb\xbf"
#: Formats that are text throughout (legacy VTK and VTK XML may hold binary data after
#: their text header; STL, MSH and .mat may be binary).
_TEXT = (".obj",)


def check_file(path: Path, ext: str, name: str, max_bytes: int) -> None:
    """Raise :class:`~barymesh.io.limits.Damaged` if ``path`` cannot be a mesh file of ``ext``.

    Parameters
    ----------
    path : Path
        A regular, non-empty file.
    ext : str
        Its extension, lower case (``.msh``, ``.stl``, ...).
    name : str
        The format's name for messages (``IMPORT_FORMATS``).
    max_bytes : int
        The largest file read.
    """
    size = path.stat().st_size
    if size > max_bytes:
        raise Damaged(
            f"the file is {format_size(size)}, more than the {format_size(max_bytes)} "
            f"barymesh reads; raise the limit with read_mesh(max_bytes=...) or {MAX_FILE_ENV}"
        )
    with open(path, "rb") as fh:
        head = fh.read(HEAD_BYTES)
        fh.seek(max(0, size - 4096))
        tail = fh.read()
    start = (head[len(_BOM) :] if head.startswith(_BOM) else head).lstrip()
    nul = head.find(b"\0")
    xml = ext in (".vtu", ".vtp")
    problem = None
    if ext in _TEXT and nul >= 0:
        problem = f"byte {nul:,} is a NUL byte, in a text format"
    elif ext == ".msh" and not start.startswith(b"$MeshFormat"):
        problem = "it does not start with $MeshFormat"
    elif ext == ".vtk" and not start.startswith(b"# vtk DataFile"):
        problem = "it does not start with '# vtk DataFile'"
    elif xml and not start.startswith(b"<"):
        problem = "it does not start with '<'"
    if problem is not None:
        raise Damaged(
            f"it is not valid XML ({problem})" if xml else f"not a {name} file ({problem})"
        )
    if ext == ".stl" and _ascii_stl(head, size) and not _ends_solid(tail):
        raise Damaged(
            "the ASCII STL does not end with 'endsolid': the file is cut short (truncated)"
        )


def _ascii_stl(head: bytes, size: int) -> bool:
    """Whether an STL is ASCII: it starts with ``solid`` and is not binary's exact size."""
    if not head.lstrip()[:5].lower() == b"solid":
        return False
    if len(head) >= 84:  # some binary exporters start their 80-byte header with "solid"
        count = int.from_bytes(head[80:84], "little")
        if 84 + 50 * count == size:
            return False
    return True


def _ends_solid(tail: bytes) -> bool:
    lines = [line.strip() for line in tail.splitlines() if line.strip()]
    return bool(lines) and re.match(rb"endsolid\b", lines[-1].lower()) is not None

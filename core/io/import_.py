"""Read triangle meshes from Gmsh, VTK, STL, OBJ and Makarov ``.mat`` files.

Only triangles are meshed surfaces: other cells are skipped and counted in
``TriMesh.ignored_cells``. Coordinates are converted to mm. The result is a
``TriMesh`` with ``mode="imported"``, so the same topology analysis (edges,
RWG table, quality) runs as for our own meshes.
"""

from __future__ import annotations

import contextlib
import errno
import io
import logging
import os
import re
import stat
import warnings
from pathlib import Path

import numpy as np

from ..mesh import TriMesh
from ..topology import INDEX
from .gmsh22 import msh2_kind, read_gmsh22
from .gmsh41 import msh4_kind, read_gmsh41
from .headers import check_file
from .limits import Damaged, max_file_bytes
from .makarov import read_makarov
from .meshio_checks import check_declared_counts
from .obj import read_obj
from .units import per_mm
from .vtk_xml import read_vtp, read_vtu

log = logging.getLogger(__name__)

#: Extension -> (format name, meshio file format or None for our own reader).
IMPORT_FORMATS = {
    ".msh": ("Gmsh MSH 2.2/4.1, ASCII or binary", "gmsh"),
    ".vtk": ("VTK legacy", "vtk"),
    ".vtu": ("VTK XML unstructured grid", "vtu"),
    ".vtp": ("VTK XML polydata", None),
    ".stl": ("STL, ASCII or binary", "stl"),
    ".obj": ("Wavefront OBJ", "obj"),
    ".mat": ("MATLAB p/t (Makarov)", None),
}
IMPORT_EXTENSIONS = tuple(IMPORT_FORMATS)
#: Cell data names that hold our regions and patches (ours first, then Gmsh's tags).
_REGION_KEYS = ("region", "gmsh:physical")
_PATCH_KEYS = ("patch_id", "gmsh:geometrical")


class MeshFileError(ValueError):
    """A mesh file cannot be imported; the message names the file and the problem."""


def read_mesh(path: str | Path, unit: str | None = None, max_bytes: int | None = None) -> TriMesh:
    """Import the triangles of a mesh file.

    Parameters
    ----------
    path : str or Path
        ``.msh``, ``.vtk``, ``.vtu``, ``.vtp``, ``.stl``, ``.obj`` or ``.mat``.
    unit : {"m", "mm", "um"}, optional
        Length unit of the file's coordinates; default mm, but m for ``.mat``.
    max_bytes : int, optional
        Largest file read (bytes); default :func:`barymesh.io.limits.max_file_bytes`
        (2 GiB, or the ``BARYMESH_MAX_FILE_BYTES`` environment variable). The size and
        the first bytes are checked before the file is read.

    Returns
    -------
    TriMesh
        Coordinates in mm, ``mode="imported"``; regions and patches from the
        file's cell data where it has them (ours, or Gmsh's physical and
        elementary tags), else one region and one patch.

    Raises
    ------
    MeshFileError
        (a ``ValueError``) for a missing, damaged, empty or unsupported file.
    """
    path = Path(path)
    ext = path.suffix.lower()
    if ext not in IMPORT_FORMATS:
        raise MeshFileError(
            f"{path}: cannot read {ext or 'files without an extension'}; "
            f"expected one of {', '.join(IMPORT_EXTENSIONS)}"
        )
    name, meshio_format = IMPORT_FORMATS[ext]
    if unit is None:
        unit = "m" if ext == ".mat" else "mm"
    to_mm = 1.0 / per_mm(unit)
    problem = file_problem(path)
    if problem:
        raise MeshFileError(f"{path}: {problem}")
    try:
        limit = max_file_bytes() if max_bytes is None else int(max_bytes)
        check_file(path, ext, f"readable {name}", limit)
    except Damaged as exc:
        raise MeshFileError(f"{path}: {exc}") from None
    regions: np.ndarray | None
    patch_ids: np.ndarray | None
    ignored: dict[str, int]  # cell type -> cells of it that are not triangles
    try:
        if ext == ".mat":
            points, triangles, regions = read_makarov(path)
            patch_ids, ignored = None, {}
        elif ext in (".vtp", ".vtu"):
            points, triangles, data, ignored = (read_vtp if ext == ".vtp" else read_vtu)(path)
            regions, patch_ids = _first(data, _REGION_KEYS), _first(data, _PATCH_KEYS)
        elif ext == ".obj":
            points, triangles, ignored = read_obj(path)
            regions = patch_ids = None
        elif ext == ".msh" and _msh_version(path) == 2:
            points, triangles, regions, patch_ids, ignored = read_gmsh22(path)
        elif ext == ".msh" and _msh_version(path) == 4:
            points, triangles, regions, patch_ids, ignored = read_gmsh41(path.read_bytes())
        else:
            check_declared_counts(path, ext)
            points, triangles, regions, patch_ids, ignored = _read_meshio(path, meshio_format)
        return _assemble(path, points, triangles, regions, patch_ids, ignored, to_mm)
    except MeshFileError:
        raise
    except Damaged as exc:
        raise MeshFileError(f"{path}: {exc}") from None
    except MemoryError:
        raise MeshFileError(f"{path}: too large to read into memory") from None
    except UnicodeDecodeError as exc:
        raise MeshFileError(
            f"{path}: not a readable {name} file (byte {exc.start:,} is not text)"
        ) from None
    except RecursionError:
        raise MeshFileError(f"{path}: not a readable {name} file (nested too deeply)") from None
    except Exception as exc:  # every parser failure becomes one clear message
        raise MeshFileError(f"{path}: not a readable {name} file ({_reason(exc, path)})") from None


def file_problem(path: Path) -> str | None:
    """Why ``path`` cannot be read as a mesh file, in a few words; None if it can.

    Says what the path really is: missing, a folder, a named pipe, a device,
    a dangling or looping symbolic link, unreadable or empty. Never opens a
    pipe or a device (that could block or never end).
    """
    link = ""
    try:
        if path.is_symlink():
            link = f"a symbolic link to {os.readlink(path)}"
        info = path.stat()
    except FileNotFoundError:
        return f"the path is {link}, which does not exist" if link else "the file does not exist"
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            return "the path is a symbolic link loop (it leads back to itself)"
        return f"cannot be read: {exc.strerror or exc}"
    mode = info.st_mode
    kinds = (
        (stat.S_ISDIR, "a folder"),
        (stat.S_ISFIFO, "a named pipe (FIFO)"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
    )
    for test, kind in kinds:
        if test(mode):
            return (
                f"the path is {link}, which is {kind}, not a file"
                if link
                else (f"the path is {kind}, not a file")
            )
    if not stat.S_ISREG(mode):
        return "the path is not a regular file"
    try:
        with open(path, "rb"):
            pass
    except OSError as exc:
        return f"cannot be read: {exc.strerror or exc}"
    if info.st_size == 0:
        return "the file is empty"
    return None


def _msh_version(path: Path) -> int | None:
    """2 or 4 for MSH 2.x or 4.1 files (read by our own readers), else None (meshio)."""
    with open(path, "rb") as fh:
        head = fh.read(256)
    return 2 if msh2_kind(head) else 4 if msh4_kind(head) else None


_INTERNALS = (
    (
        re.compile(r"cannot reshape array of size \d+ into shape"),
        "its counts do not match its data, perhaps truncated",
    ),
    (re.compile(r"codec can't decode"), "it holds bytes that are not text"),
    (re.compile(r"index -?\d+ is out of bounds"), "it refers to an entry that does not exist"),
    (re.compile(r"invalid literal for int|could not convert string"), "a number is malformed"),
    (
        re.compile(r"values to unpack|unpack requires|buffer size|not enough data"),
        "malformed, perhaps truncated",
    ),
    (re.compile(r"meshio|ReadError|does not recognise"), "its content does not match the format"),
)


def _reason(exc: BaseException, path: Path) -> str:
    """The first line of a parser's message, without the path and without numpy's words."""
    text = str(exc).strip()
    text = text.splitlines()[0] if text else type(exc).__name__
    text = text.replace(str(path), "").replace(path.name, "").strip(" :")
    if isinstance(exc, AssertionError | IndexError | StopIteration) or not text:
        return "malformed, perhaps truncated"
    for pattern, plain in _INTERNALS:
        if pattern.search(text):
            return plain
    return text or type(exc).__name__


def _first(data: dict, keys: tuple[str, ...]) -> np.ndarray | None:
    for key in keys:
        if key in data:
            return np.asarray(data[key]).reshape(-1)
    return None


def _read_meshio(path: Path, file_format: str | None):
    import meshio

    # meshio.read prints a ReadError's message on stdout and calls sys.exit(1); it warns
    # through rich on stderr, and numpy warns (e.g. an overflow while sniffing whether an
    # STL is binary): keep all of that off our command line and turn it into one error
    out, err = io.StringIO(), io.StringIO()
    with (
        contextlib.redirect_stdout(out),
        contextlib.redirect_stderr(err),
        warnings.catch_warnings(),
    ):
        warnings.simplefilter("ignore")
        try:
            m = meshio.read(path, file_format=file_format)
        except SystemExit:
            said = [line.strip() for line in out.getvalue().splitlines() if line.strip()]
            raise ValueError(said[0] if said else "its content does not match the format") from None
    noise = (out.getvalue() + err.getvalue()).strip()
    if noise:
        log.info("meshio on %s: %s", path, noise)
    triangles: list[np.ndarray] = []
    regions: list[np.ndarray | None] = []
    patches: list[np.ndarray | None] = []
    ignored: dict[str, int] = {}
    for k, block in enumerate(m.cells):
        if block.type != "triangle":
            ignored[block.type] = ignored.get(block.type, 0) + len(block.data)
            continue
        data = np.asarray(block.data)
        if data.ndim != 2 or data.shape[1] != 3:
            raise Damaged(
                f"a block of triangles holds {data.size:,} vertex indices in shape "
                f"{data.shape}, not 3 per triangle (the file is damaged)"
            )
        triangles.append(data.astype(np.int64))
        cell_data = {key: values[k] for key, values in m.cell_data.items()}
        regions.append(_first(cell_data, _REGION_KEYS))
        patches.append(_first(cell_data, _PATCH_KEYS))
    tri = np.concatenate(triangles) if triangles else np.empty((0, 3), dtype=np.int64)
    reg = _joined(regions) if triangles else None
    pat = _joined(patches) if triangles else None
    return np.asarray(m.points, dtype=np.float64), tri, reg, pat, ignored


def _joined(blocks: list[np.ndarray | None]) -> np.ndarray | None:
    """The blocks' values end to end, or None if a block has none."""
    present = [b for b in blocks if b is not None]
    return np.concatenate(present) if len(present) == len(blocks) else None


def _assemble(path, points, triangles, regions, patch_ids, ignored, to_mm) -> TriMesh:
    triangles = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    if len(triangles) == 0:
        skipped = ", ".join(f"{n} {kind}" for kind, n in sorted(ignored.items()))
        extra = f" (only {skipped} cells, which are not surfaces)" if skipped else ""
        raise MeshFileError(f"{path}: the file holds no triangles{extra}")
    points = np.asarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] not in (2, 3):
        raise MeshFileError(f"{path}: points have shape {points.shape}; expected (V, 3)")
    if not np.all(np.isfinite(points)):
        raise MeshFileError(f"{path}: some coordinates are not finite numbers")
    if triangles.min() < 0:
        raise MeshFileError(
            f"{path}: a triangle refers to vertex {int(triangles.min())}, "
            "which cannot exist (a negative index)"
        )
    if triangles.max() >= len(points):
        raise MeshFileError(
            f"{path}: a triangle refers to vertex {int(triangles.max()):,} (counted from 0) "
            f"but there are {len(points):,} vertices"
        )
    # keep only the vertices the triangles use (files often carry extra nodes)
    used, inverse = np.unique(triangles, return_inverse=True)
    if len(used) < len(points):
        log.info("%s: dropped %d vertices no triangle uses", path, len(points) - len(used))
    points = points[used]
    triangles = inverse.reshape(-1, 3)
    n = len(triangles)
    if regions is not None and len(regions) and not np.any(np.asarray(regions) != 0):
        regions = None  # Gmsh's physical tag 0: no physical group
    regions = _labels(regions, n, default=1)
    patch_ids = _labels(patch_ids, n, default=0)  # renumbered 0.. below (Gmsh tags are 1..)
    _, patch_ids = np.unique(patch_ids, return_inverse=True)
    return TriMesh(
        points=points * to_mm,
        triangles=triangles.astype(INDEX),
        patch_ids=patch_ids.reshape(-1).astype(INDEX),
        regions=regions.astype(INDEX),
        n_patches=int(patch_ids.max()) + 1,
        mode="imported",
        tolerance=0.0,
        ignored_cells=dict(ignored),
    )


def _labels(values: np.ndarray | None, n: int, default: int) -> np.ndarray:
    if values is None or len(values) != n:
        return np.full(n, default, dtype=np.int64)
    values = np.asarray(values)
    if not np.issubdtype(values.dtype, np.number) or not np.all(np.isfinite(values)):
        return np.full(n, default, dtype=np.int64)
    return np.asarray(values, dtype=np.int64)

"""Write a mesh to a file whose extension picks the format, atomically and in a chosen unit."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ..mesh import TriMesh
from .atomic import ExportCancelled, ExportError, atomic_path
from .gmsh_msh import check_msh_version
from .makarov import write_makarov
from .meshio_formats import write_meshio
from .rwg import write_rwg_csv, write_rwg_npz
from .units import per_mm
from .vtp import write_vtp


@dataclass(frozen=True)
class ExportFormat:
    """One file format we write: its name, default unit and a line for users."""

    name: str
    default_unit: str
    notes: str


EXPORT_FORMATS = {
    ".msh": ExportFormat(
        "Gmsh MSH 2.2 ASCII",
        "mm",
        "physical tag = region, elementary tag = patch + 1 (scuff-em, bempp-cl, OpenModes)",
    ),
    ".vtu": ExportFormat("VTK XML unstructured grid", "mm", "cell data: quality, region, patch"),
    ".vtp": ExportFormat("VTK XML polydata", "mm", "cell data: quality, region, patch"),
    ".vtk": ExportFormat("VTK legacy", "mm", "cell data: quality, region, patch"),
    ".stl": ExportFormat("STL ASCII", "mm", "triangles only"),
    ".obj": ExportFormat("Wavefront OBJ", "mm", "triangles only"),
    ".mat": ExportFormat("MATLAB p/t (Makarov)", "m", "p 3xN, t 4xM 1-based, row 4 = 1"),
    ".npz": ExportFormat("RWG table + connectivity (NumPy)", "mm", "0-based indices"),
    ".csv": ExportFormat(
        "RWG table + connectivity (CSV)", "mm", "also NAME_connectivity.csv, NAME_centroids.csv"
    ),
}
EXPORT_EXTENSIONS = tuple(EXPORT_FORMATS)


def export_filters() -> list[str]:
    """File-dialog filters for the formats :func:`write_mesh` writes, one per format.

    The one list every export dialog offers (the mesh's and the array's), so a dialog
    never offers an extension that then fails with "cannot write".

    >>> export_filters()[0]
    'Gmsh MSH 2.2 ASCII (*.msh)'
    """
    return [f"{fmt.name} (*{ext})" for ext, fmt in EXPORT_FORMATS.items()]


def filter_extension(chosen: str) -> str | None:
    """The extension of a filter of :func:`export_filters` (None for another filter).

    >>> filter_extension("STL ASCII (*.stl)")
    '.stl'
    """
    for ext, fmt in EXPORT_FORMATS.items():
        if chosen == f"{fmt.name} (*{ext})":
            return ext
    return None


def export_format(path: str | Path) -> ExportFormat:
    """The format of ``path`` from its extension; ``ValueError`` if we cannot write it."""
    ext = Path(path).suffix.lower()
    try:
        return EXPORT_FORMATS[ext]
    except KeyError:
        raise ValueError(
            f"{path}: cannot write {ext or 'files without an extension'}; "
            f"expected one of {', '.join(EXPORT_EXTENSIONS)}"
        ) from None


def export_unit(path: str | Path, unit: str | None = None) -> str:
    """The unit a write of ``path`` uses: ``unit``, else the format's default."""
    fmt = export_format(path)
    if unit is None:
        return fmt.default_unit
    per_mm(unit)  # validates
    return unit


def describe_export(
    path: str | Path, unit: str | None = None, msh_version: str | None = "2.2"
) -> str:
    """``"out.msh (Gmsh MSH 2.2 ASCII, mm)"`` for messages (``msh_version`` of a .msh).

    >>> describe_export("cell.msh", msh_version="4.1")
    'cell.msh (Gmsh MSH 4.1 ASCII, mm)'
    """
    name = export_format(path).name
    if Path(path).suffix.lower() == ".msh":
        name = name.replace("2.2", check_msh_version(msh_version))
    return f"{path} ({name}, {export_unit(path, unit)})"


def write_mesh(
    mesh: TriMesh,
    path: str | Path,
    unit: str | None = None,
    wavelength: float | None = None,
    *,
    cancelled: Callable[[], bool] | None = None,
    msh_version: str | None = "2.2",
) -> Path:
    """Write ``mesh`` to ``path``; the extension picks the format (see ``EXPORT_FORMATS``).

    Parameters
    ----------
    mesh : TriMesh
        Coordinates in mm.
    path : str or Path
    unit : {"m", "mm", "um"}, optional
        Length unit of the file; default ``"mm"``, except ``.mat`` (``"m"``).
    wavelength : float, optional
        λ in mm: VTK files (``.vtu``, ``.vtp``, ``.vtk``) then also carry the cell
        array ``edge_wavelength`` (longest side of each triangle over λ).
    cancelled : callable, optional
        Asked before the write starts and once the file is written, before it replaces
        ``path``: True raises :class:`ExportCancelled`, and no file (not even a
        temporary one) is left. For an export in a worker thread with a Cancel button.
    msh_version : {"2.2", "4.1"}
        The Gmsh format of a ``.msh``: 2.2 (the default, which the solvers of
        Makarov's era read) or 4.1 (Gmsh 4's own; the patches are its entities).

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ValueError
        For an extension, a unit or an MSH version we do not know.
    ExportError
        When the file cannot be written (the message names the path and why).
    ExportCancelled
        When ``cancelled()`` said so (a subclass of ``ExportError``).
        The write is atomic: the target is either the complete new file or
        untouched.
    """
    path = Path(path)
    ext = path.suffix.lower()
    u = export_unit(path, unit)
    factor = per_mm(u)
    version = check_msh_version(msh_version)

    def check() -> None:
        if cancelled is not None and cancelled():
            raise ExportCancelled(f"export of {path} cancelled")

    check()
    if ext == ".csv":
        write_rwg_csv(mesh, path, factor, u, before_rename=check)
        return path
    with atomic_path(path) as tmp:
        if ext == ".mat":
            write_makarov(mesh, tmp, factor)
        elif ext == ".npz":
            write_rwg_npz(mesh, tmp, factor, u)
        elif ext == ".vtp":
            write_vtp(mesh, tmp, factor, wavelength)
        else:
            write_meshio(mesh, tmp, ext, factor, wavelength, version)
        if not tmp.exists():
            raise ExportError(f"cannot write {path}: the writer produced no file")
        check()
    return path

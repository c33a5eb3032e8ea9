"""Mesh files in and out: Gmsh, VTK, STL, OBJ, Makarov's .mat, RWG tables.

Pure Python over numpy, scipy.io and meshio; no Qt, VTK or pyvista.

>>> import tempfile, pathlib
>>> from barymesh import MeshParams, build_mesh
>>> mesh = build_mesh(MeshParams(structure="patch", patch_size=10.0))
>>> with tempfile.TemporaryDirectory() as folder:
...     path = write_mesh(mesh, pathlib.Path(folder) / "patch.msh")
...     read_mesh(path).stats()["triangles"]
32
"""

from .atomic import (
    ExportCancelled,
    ExportError,
    atomic_path,
    atomic_paths,
    atomic_write,
    atomic_write_bytes,
    atomic_write_text,
    remove_stale_temp_files,
)
from .export import (
    EXPORT_EXTENSIONS,
    EXPORT_FORMATS,
    ExportFormat,
    describe_export,
    export_filters,
    export_format,
    export_unit,
    filter_extension,
    write_mesh,
)
from .gmsh_msh import MSH_VERSIONS, write_periodic_msh
from .import_ import IMPORT_EXTENSIONS, IMPORT_FORMATS, MeshFileError, read_mesh
from .units import PER_MM, UNITS, per_mm

__all__ = [
    "EXPORT_EXTENSIONS",
    "EXPORT_FORMATS",
    "IMPORT_EXTENSIONS",
    "IMPORT_FORMATS",
    "MSH_VERSIONS",
    "PER_MM",
    "UNITS",
    "ExportCancelled",
    "ExportError",
    "ExportFormat",
    "MeshFileError",
    "atomic_path",
    "atomic_paths",
    "atomic_write",
    "atomic_write_bytes",
    "atomic_write_text",
    "describe_export",
    "export_filters",
    "export_format",
    "export_unit",
    "filter_extension",
    "per_mm",
    "read_mesh",
    "remove_stale_temp_files",
    "write_mesh",
    "write_periodic_msh",
]

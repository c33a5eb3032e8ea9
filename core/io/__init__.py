"""Mesh files in and out: Gmsh, VTK, STL, OBJ, Makarov's .mat, RWG tables.

Pure Python over numpy, scipy.io and meshio; no Qt, VTK or pyvista.
"""

from .atomic import ExportError, atomic_path, atomic_write

__all__ = ["ExportError", "atomic_path", "atomic_write"]

"""barymesh core: RWG-ready triangle meshes of metasurface unit cells.

Pure numpy/scipy; no Qt, VTK or pyvista.

>>> from barymesh import MeshParams, build_mesh
>>> build_mesh(MeshParams(structure="patch")).stats()["triangles"]
32
"""

from .build import BuildCancelled, build_mesh
from .mesh import TriMesh
from .params import DIAGONALS, MODES, SCHEMES, STRUCTURES, MeshParams
from .topology import INDEX, EdgeTopology, RWGTable

__all__ = [
    "DIAGONALS",
    "BuildCancelled",
    "INDEX",
    "MODES",
    "SCHEMES",
    "STRUCTURES",
    "EdgeTopology",
    "MeshParams",
    "RWGTable",
    "TriMesh",
    "build_mesh",
]
__version__ = "0.2.0"

"""barymesh core: RWG-ready triangle meshes of metasurface unit cells.

Pure numpy/scipy; no Qt, VTK or pyvista.

>>> from barymesh import MeshParams, build_mesh
>>> build_mesh(MeshParams(structure="patch")).stats()["triangles"]
32

The names below are imported when first asked for (PEP 562): ``import barymesh`` itself
loads neither numpy nor scipy, so the ``barymesh`` command can answer Ctrl-C pressed while
it starts with one line (:mod:`barymesh.app.launch`) instead of a traceback.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .build import BuildCancelled, build_mesh
    from .mesh import TriMesh
    from .params import DIAGONALS, MODES, SCHEMES, STRUCTURES, MeshParams
    from .topology import INDEX, EdgeTopology, RWGTable

#: Each public name and the submodule that defines it.
_WHERE = {
    "BuildCancelled": "build",
    "build_mesh": "build",
    "TriMesh": "mesh",
    "DIAGONALS": "params",
    "MODES": "params",
    "SCHEMES": "params",
    "STRUCTURES": "params",
    "MeshParams": "params",
    "INDEX": "topology",
    "EdgeTopology": "topology",
    "RWGTable": "topology",
}

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


def __getattr__(name: str) -> Any:
    if name not in _WHERE:
        raise AttributeError(f"module 'barymesh' has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{_WHERE[name]}", __name__), name)
    globals()[name] = value  # asked once
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))

"""Unit cells: several elements and a pixel grid in one periodic cell.

>>> import numpy as np
>>> from core.cell import Lattice, PixelGrid, UnitCell, build_cell
>>> cell = UnitCell(Lattice.rectangular(2.0), pixels=PixelGrid(np.ones((2, 2)), origin=(-1, -1)))
>>> cm = build_cell(cell)
>>> cm.mesh.n_triangles, cm.periodic_pairs.matched, len(cm.periodic_pairs.edges)
(128, True, 16)
"""

from .build import CellMesh, build_cell, tile
from .model import SYMMETRIES, Element, Lattice, PixelGrid, UnitCell, symmetrized
from .periodic import PeriodicPairs, periodic_pairs

__all__ = [
    "SYMMETRIES",
    "CellMesh",
    "Element",
    "Lattice",
    "PeriodicPairs",
    "PixelGrid",
    "UnitCell",
    "build_cell",
    "periodic_pairs",
    "symmetrized",
    "tile",
]

"""Unit cells: several elements and a pixel grid in one periodic cell.

>>> import numpy as np
>>> from barymesh.cell import Lattice, PixelGrid, UnitCell, build_cell
>>> cell = UnitCell(Lattice.rectangular(2.0), pixels=PixelGrid(np.ones((2, 2)), origin=(-1, -1)))
>>> cm = build_cell(cell)
>>> cm.mesh.n_triangles, cm.periodic_pairs.matched, len(cm.periodic_pairs.edges)
(128, True, 16)
"""

from .build import CellMesh, build_cell, tile
from .files import (
    CellFileError,
    cell_from_dict,
    cell_preset_names,
    cell_preset_path,
    cell_to_dict,
    load_cell,
    load_cell_preset,
    read_cell_document,
    save_cell,
)
from .model import SYMMETRIES, Element, Lattice, PixelGrid, UnitCell, symmetrized
from .outline import (
    OutlinePolygon,
    export_outline,
    outline_polygons,
    write_outline_dxf,
    write_outline_gds,
)
from .periodic import PeriodicPairs, periodic_pairs

__all__ = [
    "SYMMETRIES",
    "CellFileError",
    "CellMesh",
    "Element",
    "Lattice",
    "OutlinePolygon",
    "PeriodicPairs",
    "PixelGrid",
    "UnitCell",
    "build_cell",
    "cell_from_dict",
    "cell_preset_names",
    "cell_preset_path",
    "cell_to_dict",
    "export_outline",
    "load_cell",
    "load_cell_preset",
    "outline_polygons",
    "periodic_pairs",
    "read_cell_document",
    "save_cell",
    "symmetrized",
    "tile",
    "write_outline_dxf",
    "write_outline_gds",
]

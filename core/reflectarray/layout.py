"""A designed reflectarray as one unit cell of :mod:`barymesh.cell`, for files and export.

Every element of the array is the library's cell with the element's parameter value set
by the study's own path code (:meth:`barymesh.study.spec.Base.design`, the path the
library varied), built and checked by :func:`barymesh.cell.cell_from_dict`, and its parts
moved to the element's position. The array's lattice is N1 a1 by N2 a2: the cell tiles
into the same array of arrays, and one copy is the aperture.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..cell.files import cell_from_dict, cell_to_dict
from ..cell.model import Element, Lattice, UnitCell
from ..study.spec import Base, parse_path

if TYPE_CHECKING:
    from .designer import Reflectarray


def array_cell(design: Reflectarray, name: str | None = None) -> UnitCell:
    """The array of ``design`` as one :class:`barymesh.cell.UnitCell` (see the module)."""
    lib = design.library
    cell = lib.cell
    if cell is None:
        raise ValueError(
            "the library has no cell (it was not made by reflection_library), so the "
            "elements cannot be built; make the library from a cell, or set its cell="
        )
    tokens = parse_path(lib.parameter)
    if tokens[0] != "elements":
        raise ValueError(
            f"the library's parameter {lib.parameter!r} is not an element's; to_cell builds "
            "elements of different sizes, so it needs a path such as elements[0].patch_size"
        )
    if cell.pixels is not None:
        raise ValueError(
            "the library's cell has a pixel grid; a cell holds one grid, so the array cannot "
            "repeat it per element (draw the pixels as elements instead)"
        )
    base = Base("cell", cell_to_dict(cell))
    built: dict[float, tuple[Element, ...]] = {}
    elements: list[Element] = []
    for (i, j), (x, y, _), value in zip(
        design.indices.tolist(), design.positions.tolist(), design.parameter.tolist(), strict=True
    ):
        if value not in built:
            try:
                one = cell_from_dict(base.design({lib.parameter: value}), "the library's cell")
            except ValueError as exc:
                raise ValueError(f"{lib.parameter}={value:g}: the cell refuses it: {exc}") from None
            built[value] = one.elements
        for el in built[value]:
            elements.append(
                Element(
                    el.params,
                    (el.position[0] + x, el.position[1] + y),
                    el.rotation,
                    f"{el.name} ({i}, {j})",
                )
            )
    n1, n2 = design.aperture
    a1, a2 = cell.lattice.a1, cell.lattice.a2
    lattice = Lattice((n1 * a1[0], n1 * a1[1]), (n2 * a2[0], n2 * a2[1]))
    theta, phi = design.beam
    bits = "continuous phase" if design.bits is None else f"{design.bits}-bit phase"
    description = (
        f"reflectarray of {n1} x {n2} '{cell.name}' cells, {lib.parameter} per element; "
        f"{design.frequency / 1e9:g} GHz, feed at {design.feed} mm, beam theta={theta:g} "
        f"phi={phi:g} deg, {bits}"
    )
    return UnitCell(
        lattice=lattice,
        elements=tuple(elements),
        mode=cell.mode,
        tolerance=cell.tolerance,
        name=name if name is not None else f"{cell.name}-reflectarray-{n1}x{n2}",
        description=description,
    )

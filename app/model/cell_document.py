"""The window's unit cell without Qt: the cell, which elements are hidden, which one is
selected, and the edits of the Elements and Lattice panels as pure functions.

Every edit returns a new :class:`CellState` (validated: a state that exists is one the
core accepts), so :class:`barymesh.app.model.AppModel` keeps them on its undo stack as it keeps
parameters.

>>> from barymesh.cell import Lattice, UnitCell, Element
>>> from barymesh import MeshParams
>>> s = CellState.of(UnitCell(Lattice.rectangular(20), (Element(MeshParams(structure="patch"), name="a"),)))
>>> s = s.added(MeshParams(structure="ring"))
>>> [el.name for el in s.cell.elements], s.selected
(['a', 'ring'], 1)
>>> s.with_hidden(0, True).visible.part_names
('ring',)
"""  # noqa: E501

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Any

from barymesh import MeshParams
from barymesh.cell import Element, Lattice, UnitCell

#: Copies per direction the array preview offers (a view setting, not part of the cell).
MAX_COPIES = 50

#: Lattice kinds the Lattice panel offers (an oblique lattice comes from a file only).
LATTICE_KINDS = ("rectangular", "hexagonal")


def unique_name(base: str, taken: set[str] | tuple[str, ...]) -> str:
    """``base``, or ``base 2``, ``base 3``… whichever is not in ``taken``.

    >>> unique_name("ring", {"ring", "ring 2"}), unique_name("patch", ())
    ('ring 3', 'patch')
    """
    taken = set(taken)
    stem = re.sub(r" \d+$", "", base.strip()) or "element"
    if base not in taken:
        return base
    k = 2
    while f"{stem} {k}" in taken:
        k += 1
    return f"{stem} {k}"


@dataclass(frozen=True)
class CellState:
    """A unit cell as the window edits it.

    Attributes
    ----------
    cell : UnitCell
        Every element, hidden ones included (what Save cell writes).
    hidden : tuple of bool
        One per element: a hidden element is not meshed.
    selected : int or None
        The element the Parameters panel edits (not compared: two states that differ
        only in their selection make the same mesh and are the same undo step).
    visible : UnitCell
        The cell that is meshed: ``cell`` without its hidden elements (computed; a state
        whose visible cell the core refuses, e.g. with no metal left, cannot exist).
    """

    cell: UnitCell
    hidden: tuple[bool, ...] = ()
    selected: int | None = field(default=None, compare=False)
    visible: UnitCell = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        n = len(self.cell.elements)
        hidden = tuple(bool(h) for h in self.hidden) or (False,) * n
        if len(hidden) != n:
            raise ValueError(f"hidden has {len(hidden)} entries; expected one per element ({n})")
        object.__setattr__(self, "hidden", hidden)
        if self.selected is not None and not 0 <= self.selected < n:
            object.__setattr__(self, "selected", n - 1 if n else None)
        if any(hidden):
            shown = tuple(el for el, h in zip(self.cell.elements, hidden, strict=True) if not h)
            if not shown and self.cell.pixels is None:
                raise ValueError("every element is hidden: the cell would have no metal to mesh")
            visible = self.cell.replace(elements=shown)
        else:
            visible = self.cell
        object.__setattr__(self, "visible", visible)

    @classmethod
    def of(cls, cell: UnitCell) -> CellState:
        """A freshly opened cell: nothing hidden, the first element selected."""
        return cls(cell, (False,) * len(cell.elements), 0 if cell.elements else None)

    @property
    def elements(self) -> tuple[Element, ...]:
        return self.cell.elements

    @property
    def params(self) -> MeshParams | None:
        """The selected element's parameters (in the cell's mode), or None."""
        return None if self.selected is None else self.elements[self.selected].params

    def _with(
        self, elements: list[Element], hidden: list[bool], selected: int | None, **cell_changes: Any
    ) -> CellState:
        return CellState(
            self.cell.replace(elements=tuple(elements), **cell_changes), tuple(hidden), selected
        )

    def _check(self, k: int) -> None:
        if not isinstance(k, int) or not 0 <= k < len(self.elements):
            raise ValueError(f"element {k!r} does not exist; the cell has {len(self.elements)}")

    # -- edits ---------------------------------------------------------------------------

    def with_selected(self, k: int | None) -> CellState:
        if k is not None:
            self._check(k)
        return CellState(self.cell, self.hidden, k)

    def with_params(self, params: MeshParams) -> CellState:
        """The selected element with ``params``; a new mode is the whole cell's."""
        if self.selected is None:
            raise ValueError("no element is selected: select one in the Elements panel")
        els = list(self.elements)
        old = els[self.selected]
        els[self.selected] = Element(params, old.position, old.rotation, old.name)
        return self._with(els, list(self.hidden), self.selected, mode=params.mode)

    def added(
        self,
        params: MeshParams,
        name: str | None = None,
        position: tuple[float, float] = (0.0, 0.0),
    ) -> CellState:
        """A new element at the end (selected), named after its structure by default."""
        name = unique_name(name or params.structure, tuple(el.name for el in self.elements))
        params = params.replace(mode=self.cell.mode)
        els = [*self.elements, Element(params, position, 0.0, name)]
        return self._with(els, [*self.hidden, False], len(els) - 1)

    def duplicated(self, k: int) -> CellState:
        """A copy of element ``k`` right after it (selected), named ``name 2``…"""
        self._check(k)
        el = self.elements[k]
        copy = Element(
            el.params,
            el.position,
            el.rotation,
            unique_name(el.name, tuple(e.name for e in self.elements)),
        )
        els, hidden = list(self.elements), list(self.hidden)
        els.insert(k + 1, copy)
        hidden.insert(k + 1, hidden[k])
        return self._with(els, hidden, k + 1)

    def deleted(self, k: int) -> CellState:
        self._check(k)
        els, hidden = list(self.elements), list(self.hidden)
        del els[k], hidden[k]
        selected = min(k, len(els) - 1) if els else None
        return self._with(els, hidden, selected)

    def moved(self, k: int, step: int) -> CellState:
        """Element ``k`` moved ``step`` places in the list (parts are meshed in order)."""
        self._check(k)
        j = k + step
        if not 0 <= j < len(self.elements):
            raise ValueError(f"element {self.elements[k].name!r} cannot move further")
        els, hidden = list(self.elements), list(self.hidden)
        els.insert(j, els.pop(k))
        hidden.insert(j, hidden.pop(k))
        return self._with(els, hidden, j)

    def with_hidden(self, k: int, hide: bool) -> CellState:
        self._check(k)
        hidden = list(self.hidden)
        hidden[k] = bool(hide)
        return self._with(list(self.elements), hidden, self.selected)

    def renamed(self, k: int, name: str) -> CellState:
        self._check(k)
        el = self.elements[k]
        name = name.strip() if isinstance(name, str) else name
        els = list(self.elements)
        els[k] = Element(el.params, el.position, el.rotation, name)
        return self._with(els, list(self.hidden), self.selected)

    def placed(self, k: int, position: Any = None, rotation: Any = None) -> CellState:
        """Element ``k`` moved to ``position`` (x, y mm) and/or turned to ``rotation`` (°)."""
        self._check(k)
        el = self.elements[k]
        new = Element(
            el.params,
            el.position if position is None else position,
            el.rotation if rotation is None else rotation,
            el.name,
        )
        els = list(self.elements)
        els[k] = new
        return self._with(els, list(self.hidden), self.selected)

    def with_lattice(self, kind: str, period1: Any, period2: Any = None) -> CellState:
        """A rectangular lattice of periods (``period1``, ``period2``) or a hexagonal one
        of spacing ``period1``."""
        if kind == "rectangular":
            lattice = Lattice.rectangular(period1, period2)
        elif kind == "hexagonal":
            lattice = Lattice.hexagonal(period1)
        else:
            raise ValueError(
                f"lattice kind={kind!r} is unknown; expected one of {', '.join(LATTICE_KINDS)}"
            )
        return CellState(self.cell.replace(lattice=lattice), self.hidden, self.selected)


@dataclass(frozen=True)
class CellTarget:
    """A cell to mesh, as the meshing controller sees a build: like :class:`MeshParams`
    it predicts its triangles and has a ``tolerance`` (the worker builds it off the GUI
    thread above the same size, and with an explicit tolerance always)."""

    cell: UnitCell
    sized = False  # the subdivisions are the elements' own, not chosen by the mesher

    @property
    def tolerance(self) -> float | None:
        return self.cell.tolerance

    def predicted_triangles(self) -> int:
        return predicted_triangles(self.cell)


def lattice_periods(lattice: Lattice) -> tuple[float, float]:
    """The two lengths the Lattice panel shows: |a1| and |a2| (mm)."""
    return math.hypot(*lattice.a1), math.hypot(*lattice.a2)


def predicted_triangles(target: MeshParams | UnitCell) -> int:
    """Triangles a build of ``target`` (parameters or a cell) will make, before building."""
    if isinstance(target, MeshParams):
        return target.predicted_triangles()
    total = sum(el.params.predicted_triangles() for el in target.elements)
    if target.pixels is not None:
        total += int(target.pixels.mask.sum()) * target.pixels.patch_params().predicted_triangles()
    return int(total)

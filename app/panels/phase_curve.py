"""The numbers behind the Solve dock's "Reflection phase" tab (numpy only, no Qt).

The tab shows one S-curve: the co-polar reflection of a unit cell's infinite array at one
frequency against one of the cell's parameters, as :func:`barymesh.mom.reflection_library`
solves it. :func:`solve_curve` is the one adapter between the tab and that function: it
solves the values in two passes, every :data:`PREVIEW_STEP`-th value (and the last) first,
handed to ``on_preview`` so that the tab can draw a coarse curve at once, then the rest;
each pass runs in the solver's child process
(:func:`barymesh.app.panels.array_sweep.in_solver_process`, which the Infinite array's
sweeps use too), one value after the other, and stops before its next value when
``cancel()`` says so. The two passes together are the library of all the values, the same
numbers as one call of :func:`~barymesh.mom.reflection_library` (each value is solved on
its own either way).

The parameter is a path as a study's axis names it (``elements[0].inner_radius``,
``lattice.rectangular[0]``): :func:`parameter_paths` lists the cell's, :func:`value_of`
reads one, :func:`cell_with` sets it (by the study's own :class:`barymesh.study.spec.Base`),
:func:`state_with` sets it in the window's cell (hidden elements kept) and
:func:`curve_key` says whether two cells have the same curve (they differ at most in the
parameter itself: the curve stays, only the cell's mark moves).
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np

from barymesh.app.model.cell_document import CellState
from barymesh.app.model.specs import applies
from barymesh.cell import UnitCell, cell_to_dict

#: The first pass solves every this-many-th value (and the last): the preview curve.
PREVIEW_STEP = 4
#: Most values a curve takes (each is one fill, solved for TE and TM incidence).
MAX_VALUES = 201
#: An element's parameters that set how it is meshed, not its shape.
MESH_SETTINGS = frozenset(
    (
        "angle_step",
        "origin",
        "tolerance",
        "max_edge",
        "min_edge",
        "frequency",
        "cells_per_wavelength",
        "relative_permittivity",
        "growth_ratio",
        "max_triangles",
    )
)


@dataclass(frozen=True)
class PhaseInputs:
    """What the tab's fields say.

    Attributes
    ----------
    parameter : str
        The path varied, as a study's axis names it.
    values : (V,) float
        Its values, distinct, in the order drawn.
    frequency : float
        Hz.
    theta, phi : float
        Direction the wave comes from (degrees).
    polarization : str
        ``"TE"`` or ``"TM"``: whose diagonal entry is the co-polar R.
    stack : barymesh.mom.Stack or None
        The layers around the sheet and the ground plane (None: the sheet in vacuum).
    """

    parameter: str
    values: tuple[float, ...]
    frequency: float
    theta: float
    phi: float
    polarization: str
    stack: Any = None

    def incidence(self) -> dict[str, Any]:
        """The ``incidence`` of :func:`barymesh.mom.reflection_library`."""
        return {"theta": self.theta, "phi": self.phi, "pol": self.polarization}


def _numbers(node: Any, path: str) -> list[tuple[str, float]]:
    """(path, value) of the real numbers in ``node`` (a number or a list of them)."""
    if isinstance(node, list):
        out = []
        for i, value in enumerate(node):
            out += _numbers(value, f"{path}[{i}]")
        return out
    if isinstance(node, float) and math.isfinite(node):  # ints (subdivisions) are counts
        return [(path, node)]
    return []


def parameter_paths(cell: UnitCell) -> list[tuple[str, float]]:
    """(path, value) of every real-valued parameter of ``cell``'s geometry a study's axis
    can vary: each element's position, rotation and the sizes its structure uses (the
    Parameters panel's, :func:`barymesh.app.model.specs.applies`), position and rotation,
    then the lattice's
    periods and the pixel grid's pixel size. Whole numbers (subdivisions), switches and
    the mesher's own settings (:data:`MESH_SETTINGS`) are left out: a curve over them is
    no reflection-phase curve.

    >>> from barymesh.cell import Element, Lattice
    >>> from barymesh import MeshParams
    >>> cell = UnitCell(Lattice.rectangular(10.0), (Element(MeshParams(structure="patch",
    ...     patch_size=6.0, subdivisions=2)),))
    >>> print(", ".join(p for p, _v in parameter_paths(cell)))
    elements[0].patch_size, elements[0].position[0], elements[0].position[1], \
elements[0].rotation, lattice.rectangular[0], lattice.rectangular[1]
    """
    data = cell_to_dict(cell)
    out: list[tuple[str, float]] = []
    for k, element in enumerate(data.get("elements") or []):
        structure = element.get("structure", "")
        sizes = [
            n
            for n in element
            if n not in (*MESH_SETTINGS, "position", "rotation") and applies(n, structure)
        ]
        for name in (*sizes, "position", "rotation"):
            if name in element:
                out += _numbers(element[name], f"elements[{k}].{name}")
    for name, value in (data.get("lattice") or {}).items():
        out += _numbers(value, f"lattice.{name}")
    pixels = data.get("pixels") or {}
    if "pixel_size" in pixels:
        out += _numbers(pixels["pixel_size"], "pixels.pixel_size")
    return out


def value_of(cell: UnitCell, path: str) -> float:
    """The value at ``path`` in ``cell``; ValueError if it has none there."""
    from barymesh.study.spec import parse_path  # the study's: scipy, not at start-up

    node: Any = cell_to_dict(cell)
    for token in parse_path(path):
        try:
            node = node[token]
        except (KeyError, IndexError, TypeError):
            raise ValueError(f"the cell has no parameter {path!r}") from None
    if isinstance(node, bool) or not isinstance(node, int | float):
        raise ValueError(f"the cell's {path!r} is not a number")
    return float(node)


def cell_with(cell: UnitCell, path: str, value: float) -> UnitCell:
    """``cell`` with ``path`` set to ``value`` (the study's own setter); ValueError naming
    the path and the value when the cell refuses it."""
    from barymesh.study.spec import Base

    base = Base("cell", cell_to_dict(cell))
    try:
        return base.build(base.design({path: float(value)}))
    except (TypeError, ValueError, OverflowError) as exc:
        text = str(exc)
        for prefix in ("study spec: ", f"axes.{path}: ", "cell: ", f"{path}: "):
            text = text.removeprefix(prefix)
        raise ValueError(f"{path} = {value:g}: the cell refuses it: {text}") from None


def check_values(cell: UnitCell, path: str, values: tuple[float, ...]) -> None:
    """Raise ValueError (one line) at the first value of ``path`` the cell refuses."""
    for v in values:
        cell_with(cell, path, v)


def default_range(cell: UnitCell, path: str) -> tuple[float, float]:
    """A first range for ``path``: half its value to one and a half times it, narrowed
    towards the value until the cell takes both ends (a patch no wider than its lattice).

    >>> from barymesh.cell import Element, Lattice
    >>> from barymesh import MeshParams
    >>> cell = UnitCell(Lattice.rectangular(10.0), (Element(MeshParams(structure="patch",
    ...     patch_size=6.0, subdivisions=2)),))
    >>> default_range(cell, "elements[0].patch_size")
    (3.0, 9.0)
    """
    v = value_of(cell, path)
    if v == 0:
        return (0.0, 90.0) if path.endswith("rotation") else (-1.0, 1.0)
    low = 0.5 * v
    for factor in (1.5, 1.25, 1.1, 1.0):
        try:
            check_values(cell, path, (low, factor * v))
        except ValueError:
            continue
        return (low, factor * v) if v > 0 else (factor * v, low)
    return (low, v) if v > 0 else (v, low)


def curve_key(cell: UnitCell, path: str) -> str:
    """What the curve over ``path`` depends on in ``cell``: everything but that value."""
    from barymesh.study.spec import parse_path

    data = cell_to_dict(cell)
    data.pop("name", None)
    data.pop("description", None)
    tokens = parse_path(path)
    node: Any = data
    try:
        for token in tokens[:-1]:
            node = node[token]
        node[tokens[-1]] = None
    except (KeyError, IndexError, TypeError):
        pass
    return json.dumps(data, sort_keys=True)


def state_with(state: CellState, path: str, value: float) -> CellState:
    """The window's cell ``state`` with ``path`` (a path of its visible cell, the one
    meshed and solved) set to ``value``: hidden elements and the selection kept."""
    from barymesh.study.spec import parse_path

    tokens = parse_path(path)
    if tokens[0] == "elements" and len(tokens) > 1 and isinstance(tokens[1], int):
        shown = [i for i, h in enumerate(state.hidden) if not h]
        full = "".join(
            f"[{t}]" if isinstance(t, int) else f".{t}"
            for t in ("elements", shown[tokens[1]], *tokens[2:])
        ).lstrip(".")
    else:
        full = path
    cell = cell_with(state.cell, full, value)
    return CellState(cell, state.hidden, state.selected)


def passes(n: int) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """(the preview's indices, the rest's) of ``n`` values.

    >>> passes(7)
    ((0, 4, 6), (1, 2, 3, 5))
    >>> passes(2)
    ((0, 1), ())
    """
    first = sorted({*range(0, n, PREVIEW_STEP), n - 1})
    return tuple(first), tuple(i for i in range(n) if i not in first)


def coverage(library: Any) -> float:
    """Degrees of phase the curve covers (its unwrapped ∠R's span at its one frequency)."""
    phase = np.asarray(library.phase_deg)[:, 0]
    return float(np.ptp(phase)) if len(phase) else 0.0


def solve_values(
    cell: UnitCell,
    inputs: PhaseInputs,
    values: tuple[float, ...],
    progress: Callable[[int, int], None] | None = None,
    cancel: Callable[[], bool] | None = None,
) -> Any:
    """:func:`barymesh.mom.reflection_library` of ``values``, one value at a time (a
    ``cancel()`` is seen before each): a ReflectionLibrary of them, in their order."""
    from barymesh.mom import SolveCancelled, reflection_library

    parts = []
    for i, v in enumerate(values):
        if cancel is not None and cancel():
            raise SolveCancelled(f"the phase curve was cancelled after {i} of {len(values)}")
        parts.append(
            reflection_library(
                cell,
                inputs.parameter,
                [v],
                inputs.frequency,
                incidence=inputs.incidence(),
                stack=inputs.stack,
            )
        )
        if progress is not None:
            progress(i + 1, len(values))
    return joined(parts, values)


def joined(parts: list[Any], values: tuple[float, ...]) -> Any:
    """One ReflectionLibrary of the libraries ``parts`` (one frequency, the same inputs),
    its values in the order of ``values``: the one call's, the first part's cell kept."""
    from barymesh.mom import ReflectionLibrary

    have = np.concatenate([p.values for p in parts])
    order = [int(np.flatnonzero(have == v)[0]) for v in values]
    reflection = np.concatenate([p.reflection for p in parts])[order]
    v = np.asarray(values, dtype=float)
    for a in (v, reflection):
        a.setflags(write=False)
    first = parts[0]
    notes = dict.fromkeys(w for p in parts for w in p.warnings)
    return ReflectionLibrary(
        first.parameter,
        v,
        first.frequencies,
        reflection,
        first.polarization,
        first.incidence,
        first.reference_plane,
        first.stack,
        tuple(notes),
        first.cell,  # the designer builds its elements from it (Reflectarray.to_cell)
    )


def solve_curve(
    cell: UnitCell,
    inputs: PhaseInputs,
    on_preview: Callable[[Any], None] | None = None,
    progress: Callable[[int, int], None] | None = None,
    cancel: Callable[[], bool] | None = None,
    in_process: bool = True,
) -> Any:
    """The ReflectionLibrary of ``cell`` over ``inputs``: the preview's values first, then
    the rest, in the solver's process (``in_process`` False: here); ``on_preview(library)``
    of the preview's values is called while the rest is solved. ``progress(done, total)``
    counts values; raises ``barymesh.mom.SolveCancelled`` when ``cancel()`` turns true."""
    from barymesh.app.panels.array_sweep import in_solver_process

    values = inputs.values
    first, rest = passes(len(values))
    total = len(values)
    chosen = tuple(values[i] for i in first)

    def counted(k: int, _n: int, offset: int = 0) -> None:
        if progress is not None:
            progress(offset + k, total)

    def solve(part: tuple[float, ...], offset: int, meanwhile: Any = None) -> Any:
        count = partial(counted, offset=offset)
        if not in_process:
            if meanwhile is not None:
                meanwhile()
            return solve_values(cell, inputs, part, count, cancel)
        return in_solver_process(
            solve_values, (cell, inputs, part), len(part), count, cancel, meanwhile
        )

    preview = solve(chosen, 0)
    if not rest:
        return joined([preview], values)
    # the rest is solved in the child while the preview is drawn here
    shown = None if on_preview is None else partial(on_preview, preview)
    others = solve(tuple(values[i] for i in rest), len(first), shown)
    return joined([preview, others], values)

"""Solver-grade meshes: the mesh a part gets where it is made to be solved.

The mesher's defaults draw the paper's meshes; a solver wants meshes that converge. Where
a mesh is made to be solved (``barymesh solve``, with or without ``--periodic``, and
studies), a part that does not say ``grading`` itself is meshed solver-grade:

* a patch (or strip) or a triangle is graded toward its edges (:mod:`barymesh.grading`)
  with at least :data:`~barymesh.params.GRADED_SUBDIVISIONS` (16) segments per primary
  edge: within 0.005 in |R| and 0.5° of converged references at 736 RWG unknowns
  (``benchmarks/convergence.py``); a cross likewise with at least
  :data:`~barymesh.params.GRADED_CROSS_SUBDIVISIONS` (8) per piece; a pixel grid is
  graded toward the outline of the painted region, its subdivisions kept;
* every part has its edges within λ/10 at the highest frequency solved, λ in the
  densest medium (``relative_permittivity``: εr μr of the densest layer; 1 in vacuum):
  the subdivisions are raised to the smallest n that meets it, never lowered.

Rings keep their construction (the paper's overlapping patches, or conforming sectors
whose grading adds cells across the track: ``grading=True`` asks for it). A part that
says ``grading`` (true or false) in its preset, parameter file, ``--set`` or cell file
is taken as given: the shipped presets of published meshes (the paper's figures,
Makarov's plates) say ``"grading": false``, and ``barymesh solve --mesh-as-given``
takes every part as given.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .build import build_mesh
from .cell.model import Element, PixelGrid, UnitCell
from .constants import wavelength
from .params import (
    MAX_BARYCENTRIC_LEVELS,
    MAX_UNIFORM_SUBDIVISIONS,
    SINGLE_STRUCTURES,
    MeshParams,
    default_subdivisions,
)
from .sizing import RULE_CELLS_PER_WAVELENGTH
from .subdivision import edge_vectors

#: The largest part the λ/10 rule may ask for (triangles): far beyond what the solvers'
#: memory holds (the periodic solver's tables take 200 bytes per triangle pair: 80 GB at
#: 20,000 triangles), so a frequency too high for
#: it is refused at once, before any large mesh is built.
SOLVER_TRIANGLES = 20_000
#: Structures the solver-grade default grades (a patch or strip, a triangle, a cross).
GRADED_BY_DEFAULT = (*SINGLE_STRUCTURES, "cross")


def lambda_subdivisions(
    params: MeshParams, frequency: float, relative_permittivity: float = 1.0
) -> int:
    """The smallest subdivisions of ``params`` whose edges are all within λ/10.

    λ = c0 / (f √εr) at ``frequency`` (Hz) in a medium of ``relative_permittivity`` (for a
    magnetic layer pass εr μr). Measured on the meshes built (:mod:`barymesh.sizing`);
    a part that would need more than :data:`SOLVER_TRIANGLES` triangles (or its own
    ``max_triangles``) is refused with a ``ValueError`` before it is built.

    >>> lambda_subdivisions(MeshParams(structure="patch", patch_size=8.0), 35e9)
    14
    """
    trial = params.replace(
        frequency=frequency,
        relative_permittivity=relative_permittivity,
        cells_per_wavelength=float(RULE_CELLS_PER_WAVELENGTH),
        max_edge=None,
        max_triangles=min(params.max_triangles, SOLVER_TRIANGLES),
    )
    try:
        chosen = build_mesh(trial).params
    except ValueError as exc:
        target = wavelength(frequency, relative_permittivity) / RULE_CELLS_PER_WAVELENGTH
        need = re.search(r"it would take (about )?n = \S+, (about )?([\d,]+) triangles", str(exc))
        size = f"{need[2] or ''}{need[3]} triangles" if need else "more triangles"
        raise ValueError(
            f"the solver-grade mesh of the {params.structure}, with edges within λ/10 = "
            f"{target:.4g} mm at {frequency / 1e9:g} GHz, would take {size}, more than the "
            f"{trial.max_triangles:,} a solve can hold; solve lower frequencies, or the mesh "
            "as given (barymesh solve --mesh-as-given)"
        ) from None
    assert chosen is not None  # a built mesh carries the parameters it was sized with
    return int(chosen.subdivisions)


def _pixel_lambda_subdivisions(
    grid: PixelGrid, frequency: float, relative_permittivity: float
) -> int:
    """The smallest subdivisions whose pixel edges are all within λ/10 (from the template:
    a pixel grid is one patch template copied)."""
    target = wavelength(frequency, relative_permittivity) / RULE_CELLS_PER_WAVELENGTH
    top = MAX_UNIFORM_SUBDIVISIONS if grid.scheme == "uniform" else MAX_BARYCENTRIC_LEVELS
    for n in range(1, top + 1):
        d = edge_vectors(grid.scheme, n, grid.diagonal, grid.grading)
        if float(np.hypot(d[:, 0], d[:, 1]).max()) * grid.pixel_size <= target:
            return n
    return top


def solver_params(
    params: MeshParams,
    *,
    frequency: float | None = None,
    relative_permittivity: float = 1.0,
    grade: bool = True,
) -> MeshParams:
    """The solver-grade parameters of a part (see the module's description).

    Parameters
    ----------
    params : MeshParams
    frequency : float, optional
        The highest frequency to be solved (Hz): edges within λ/10 there.
    relative_permittivity : float
        εr (εr μr) of the densest medium around the sheet; 1.0 in vacuum.
    grade : bool
        Grade a patch or triangle that is not graded yet (False: only the λ/10 rule).

    Returns
    -------
    MeshParams
        ``params`` itself when nothing changes. Parameters that size themselves
        (``frequency`` or ``max_edge`` set) are graded but keep their own sizing.

    Examples
    --------
    >>> p = solver_params(MeshParams(structure="patch", patch_size=8.0))
    >>> p.grading, p.subdivisions
    (True, 16)
    >>> solver_params(p, frequency=40e9).subdivisions  # the λ/10 rule at 40 GHz
    23
    """
    out = params
    if grade and not out.grading and out.structure in GRADED_BY_DEFAULT and out.scheme == "uniform":
        floor = default_subdivisions(out.structure, True)
        out = out.replace(grading=True, subdivisions=max(out.subdivisions, floor))
    if frequency is not None and not out.sized:
        n = lambda_subdivisions(out, frequency, relative_permittivity)
        if n > out.subdivisions:
            out = out.replace(subdivisions=n)
    return out


def solver_cell(
    cell: UnitCell,
    *,
    frequency: float | None = None,
    relative_permittivity: float = 1.0,
    grade: Sequence[bool] | None = None,
    grade_pixels: bool = True,
) -> UnitCell:
    """The solver-grade cell: :func:`solver_params` on every element, a graded pixel grid.

    Parameters
    ----------
    cell : UnitCell
    frequency, relative_permittivity : as for :func:`solver_params`
    grade : sequence of bool, optional
        Per element, whether it is made solver-grade (False for one whose file says
        ``grading``: it is taken as given); all by default.
    grade_pixels : bool
        Make the pixel grid solver-grade (False when its file says ``grading``).

    Returns
    -------
    UnitCell
        ``cell`` itself when nothing changes.
    """
    flags = [True] * len(cell.elements) if grade is None else list(grade)
    if len(flags) != len(cell.elements):
        raise ValueError(
            f"grade has {len(flags)} flags for the cell's {len(cell.elements)} elements"
        )
    elements = []
    for el, flag in zip(cell.elements, flags, strict=True):
        p = el.params
        if flag:
            p = solver_params(p, frequency=frequency, relative_permittivity=relative_permittivity)
        elements.append(el if p is el.params else Element(p, el.position, el.rotation, el.name))
    pixels = cell.pixels
    if pixels is not None and grade_pixels:
        if not pixels.grading and pixels.scheme == "uniform":
            pixels = pixels.replaced(grading=True)
        if frequency is not None:
            n = _pixel_lambda_subdivisions(pixels, frequency, relative_permittivity)
            if n > pixels.subdivisions:
                pixels = pixels.replaced(subdivisions=n)
    changed = pixels is not cell.pixels or any(
        a is not b for a, b in zip(elements, cell.elements, strict=True)
    )
    return cell.replace(elements=tuple(elements), pixels=pixels) if changed else cell


def says_grading(data: Any) -> bool:
    """Whether a part's description (a parameter or element dict) says ``grading`` itself.

    >>> says_grading({"structure": "patch"}), says_grading({"grading": False})
    (False, True)
    """
    return isinstance(data, Mapping) and "grading" in data


def document_grading(document: Any) -> tuple[tuple[bool, ...], bool]:
    """(per element, pixels): which parts of a cell document may be graded for solving.

    A part may be graded unless it says ``grading`` itself (:func:`says_grading`).
    """
    if not isinstance(document, Mapping):
        return (), True
    elements = document.get("elements") or []
    flags = tuple(not says_grading(e) for e in elements) if isinstance(elements, list) else ()
    return flags, not says_grading(document.get("pixels"))

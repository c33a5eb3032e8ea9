"""The mesh the window's solvers solve: the solver-grade mesh of what is on screen.

The window draws a structure or a unit cell as its parameters say (the paper's meshes); a
solve wants a mesh that converges. As ``barymesh solve`` and ``barymesh periodic`` do
(without ``--mesh-as-given``), the Solve dock and the Infinite array tab solve the
solver-grade mesh (:mod:`barymesh.solver_grade`: graded toward the metal's edges, every
edge within λ/10 at the highest frequency solved, λ in the densest layer) of the
parameters or the cell behind the mesh on screen. An imported mesh file is solved as
read: nothing says how it was made; so is a shipped preset that says ``grading`` itself
(the published meshes: the paper's figures, Makarov's plates), as long as its parameters
are the preset's (:func:`gradable`), as the command line takes ``--preset`` of those.

:func:`solver_mesh` builds that mesh; it runs in a worker thread (a build of a few
thousand triangles takes a good part of a second: never on the GUI thread) and keeps
the last few meshes it built, so that Live sweeps and solves at a clicked frequency do
not build the same mesh again. numpy only: no Qt, VTK or pyvista.
"""

from __future__ import annotations

import functools
import threading
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from barymesh import MeshParams, TriMesh, build_mesh

#: How many solver-grade meshes :func:`solver_mesh` keeps (a Live sweep and a click on
#: its curve ask for the same one; a slider's previous positions are seldom asked again).
CACHED_MESHES = 4

#: What the core's refusal suggests on the command line, and the window's words for it.
_COMMAND_LINE_HINT = "the mesh as given (barymesh solve --mesh-as-given)"
_WINDOW_HINT = "the mesh as drawn (untick “Solver-grade mesh”)"

_CACHE: OrderedDict[Any, TriMesh | None] = OrderedDict()  # None: the mesh as drawn
_CACHE_LOCK = threading.Lock()


class SolverGradeRefused(ValueError):
    """The λ/10 rule asks for more triangles than a solve holds: a refusal with its
    reason (shown in one line, the last good result kept), not a fault."""


@dataclass(frozen=True, eq=False)
class SolvedMesh:
    """The mesh a solve was run on, beside the mesh the view shows.

    Attributes
    ----------
    mesh : TriMesh
        The mesh solved.
    shown : TriMesh
        The mesh on screen when the solve was asked for (``mesh`` itself when it was
        solved as drawn, or when the solver-grade mesh is the same).
    """

    mesh: TriMesh
    shown: TriMesh

    @property
    def graded(self) -> bool:
        """Whether the mesh solved is another than the one drawn."""
        return self.mesh is not self.shown

    def describe(self, unknowns: int, shown_unknowns: int | None = None) -> str:
        """What was solved, in words that never let the two meshes be confused.

        ``unknowns`` is the solve's count; ``shown_unknowns`` the drawn mesh's (its RWG
        table is computed when not given).

        >>> from barymesh import MeshParams, build_mesh
        >>> drawn = build_mesh(MeshParams(structure="patch", subdivisions=4))
        >>> SolvedMesh(drawn, drawn).describe(40)
        'solved on the mesh as drawn: 40 unknowns'
        """
        if not self.graded:
            return f"solved on the mesh as drawn: {unknowns:,} unknowns"
        if shown_unknowns is None:
            shown_unknowns = len(self.shown.rwg)
        return (
            f"solved on the solver-grade mesh: {unknowns:,} unknowns (the view shows the "
            f"mesh as drawn, {shown_unknowns:,} unknowns)"
        )


@functools.cache
def published_params() -> tuple[MeshParams, ...]:
    """The parameters of the shipped presets that say ``grading`` themselves (the
    published meshes), read once."""
    from barymesh.presets import given_keys, load_preset, preset_names

    found = []
    for name in preset_names():
        try:
            if "grading" in given_keys(name):
                found.append(load_preset(name)[0])
        except (OSError, ValueError):  # a broken preset file is the Presets menu's to say
            continue
    return tuple(found)


def gradable(result: Any) -> bool:
    """Whether :func:`solver_mesh` may solve another mesh than ``result.mesh``: a unit
    cell, or a structure built from parameters that are not a published preset's."""
    if result is None or result.mesh is None:
        return False
    if result.cell is not None:
        return True
    return (
        result.params is not None
        and result.source == "parameters"
        and result.params not in published_params()
    )


def solver_mesh(
    result: Any, top_frequency: float | None, relative_permittivity: float = 1.0
) -> SolvedMesh:
    """The solver-grade mesh of a window's :class:`~barymesh.app.model.build.MeshResult`.

    Parameters
    ----------
    result : MeshResult
        The build on screen: its ``cell`` (a unit cell) or its ``params`` (a structure
        built from parameters; an imported file, ``source`` a path, is taken as read).
    top_frequency : float or None
        The highest frequency to be solved (Hz): every edge within λ/10 there.
    relative_permittivity : float
        εr μr of the densest layer around the sheet (1.0 in vacuum).

    Returns
    -------
    SolvedMesh
        Whose ``mesh`` is ``result.mesh`` itself when the solver grade changes nothing.

    Raises
    ------
    SolverGradeRefused
        A ``ValueError``: one line from :mod:`barymesh.solver_grade` in the window's
        words, when the λ/10 rule asks for more triangles than a solve holds
        (:data:`barymesh.solver_grade.SOLVER_TRIANGLES`).
    """
    from barymesh.cell import build_cell
    from barymesh.solver_grade import solver_cell, solver_params

    shown = result.mesh
    if result.cell is not None:
        target: Any = result.cell
        grade: Callable[..., Any] = solver_cell
        build = lambda graded: build_cell(graded).mesh  # noqa: E731
    elif gradable(result):
        target, grade, build = result.params, solver_params, build_mesh
    else:
        return SolvedMesh(shown, shown)
    key: tuple[Any, float | None, float] | None = (
        target,
        top_frequency,
        float(relative_permittivity),
    )
    try:
        hash(key)
    except TypeError:  # a part that cannot be a key: built every time
        key = None
    with _CACHE_LOCK:
        hit = key is not None and key in _CACHE
        built = _CACHE.get(key) if hit else None
        if hit:
            _CACHE.move_to_end(key)
    if not hit:
        try:
            graded = grade(
                target, frequency=top_frequency, relative_permittivity=relative_permittivity
            )
        except ValueError as exc:
            raise SolverGradeRefused(str(exc).replace(_COMMAND_LINE_HINT, _WINDOW_HINT)) from None
        built = None if graded is target else build(graded)  # None: the same as drawn
        if key is not None:
            with _CACHE_LOCK:
                _CACHE[key] = built
                while len(_CACHE) > CACHED_MESHES:
                    _CACHE.popitem(last=False)
    return SolvedMesh(shown if built is None else built, shown)

"""Building what the window shows, off the GUI thread: a structure's or a unit cell's mesh,
its statistics and the prepared scene, as one :class:`MeshResult` that never raises."""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from barymesh import BuildCancelled, MeshParams, TriMesh, build_mesh
from barymesh.app.model.cell_document import CellTarget
from barymesh.cell import UnitCell, build_cell

log = logging.getLogger(__name__)


@dataclass
class MeshResult:
    """One finished (or failed) mesh build."""

    generation: int
    params: MeshParams | None
    mesh: TriMesh | None = None
    stats: dict[str, Any] = field(default_factory=dict)
    seconds: float = 0.0
    scene: Any = None  # barymesh.app.view.scene_data.SceneData, prepared off the GUI thread
    error: str | None = None
    source: str = "parameters"  # or the path of an imported mesh file
    cancelled: bool = False  # abandoned because a newer request or Cancel came
    timings: dict[str, float] = field(default_factory=dict)  # stage -> seconds
    cell: UnitCell | None = None  # the (visible) unit cell meshed instead of ``params``
    cell_mesh: Any = None  # its barymesh.cell.CellMesh: parts, periodic pairs, notes
    cell_stats: dict[str, Any] = field(default_factory=dict)  # CellMesh.stats()

    @property
    def target(self) -> MeshParams | CellTarget | None:
        """What was built, as :meth:`barymesh.app.model.AppModel.build_target` asks for it."""
        return CellTarget(self.cell) if self.cell is not None else self.params


def compute(
    params: MeshParams | CellTarget,
    generation: int = 0,
    prepare: Callable[[TriMesh], Any] | None = None,
    cancel: Callable[[], bool] | None = None,
) -> MeshResult:
    """Build the mesh and its statistics (and ``prepare(mesh)``, e.g. the scene datasets).

    Never raises: a failure comes back as ``MeshResult.error``, a build abandoned because
    ``cancel()`` returned True (checked by the core between its stages and here between
    build, statistics and ``prepare``) as ``MeshResult.cancelled``. ``seconds`` is the
    time of ``build_mesh`` plus the statistics (topology), what a user waits for;
    ``timings`` has each stage. A unit cell (a :class:`barymesh.app.model.cell_document.CellTarget`
    in place of ``params``) is built by :func:`compute_cell`.
    """
    if isinstance(params, CellTarget):
        return compute_cell(params.cell, generation, prepare, cancel)
    return _timed_build(
        lambda: (build_mesh(params, cancel=cancel), None),
        _Origin(params=params),
        generation,
        prepare,
        cancel,
    )


def compute_cell(
    cell: UnitCell,
    generation: int = 0,
    prepare: Callable[[TriMesh], Any] | None = None,
    cancel: Callable[[], bool] | None = None,
) -> MeshResult:
    """:func:`compute` of a unit cell: :func:`barymesh.cell.build_cell`, the whole cell's
    statistics, every part's and the periodic match (``cell_stats``). A refusal of the
    core (overlapping elements in conforming mode) comes back as ``error``."""

    def build() -> tuple[TriMesh, Any]:
        cell_mesh = build_cell(cell)
        return cell_mesh.mesh, cell_mesh

    return _timed_build(build, _Origin(cell=cell), generation, prepare, cancel)


@dataclass(frozen=True)
class _Origin:
    """What a build was of: parameters, or a unit cell (then ``params`` is ``None``)."""

    params: MeshParams | None = None
    cell: UnitCell | None = None

    def refusal(self, exc: Exception) -> str | None:
        """The message of a refusal of the core that is not a failure: a cell's
        ``ValueError`` (overlapping elements, a tolerance); ``None`` for a failure."""
        if self.cell is not None and isinstance(exc, ValueError):
            return f"cell {self.cell.name!r}: {exc}"
        return None

    def __str__(self) -> str:
        return f"cell {self.cell.name!r}" if self.cell is not None else str(self.params)


def _timed_build(
    build: Callable[[], tuple[TriMesh, Any]],
    origin: _Origin,
    generation: int,
    prepare: Callable[[TriMesh], Any] | None,
    cancel: Callable[[], bool] | None,
) -> MeshResult:
    """The one path of :func:`compute` and :func:`compute_cell`: ``build()`` returns the
    mesh and the cell mesh it belongs to (or ``None``), then the statistics, the cell's
    statistics and ``prepare``, timed, with ``cancel`` checked between the stages."""
    timings: dict[str, float] = {}
    known: dict[str, Any] = {"cell": origin.cell}

    def check() -> None:
        if cancel is not None and cancel():
            raise BuildCancelled("the build was cancelled")

    try:
        start = time.perf_counter()
        mesh, cell_mesh = build()
        timings["build"] = time.perf_counter() - start
        check()
        stats = mesh.stats()
        seconds = time.perf_counter() - start
        timings["statistics"] = seconds - timings["build"]
        cell_stats = cell_mesh.stats() if cell_mesh is not None else {}
        check()
        scene = None
        if prepare is not None:
            begin = time.perf_counter()
            scene = prepare(mesh)
            timings["scene"] = time.perf_counter() - begin
            check()
    except BuildCancelled:
        return MeshResult(
            generation, origin.params, error="cancelled", cancelled=True, timings=timings, **known
        )
    except Exception as exc:  # noqa: BLE001 - reported in the window, never a crash
        message = origin.refusal(exc)
        if message is None:
            log.exception("meshing failed for %s", origin)
            message = f"meshing failed: {exc}"
        return MeshResult(generation, origin.params, error=message, **known)
    return MeshResult(
        generation,
        origin.params,
        mesh,
        stats,
        seconds,
        scene,
        timings=timings,
        cell_mesh=cell_mesh,
        cell_stats=cell_stats,
        **known,
    )

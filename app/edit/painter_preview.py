"""The pixel painter's preview, built in its worker thread: numpy arrays only, no VTK.

:func:`build_preview` meshes the painted cell with :func:`barymesh.cell.build_cell` and
describes what to draw as :class:`barymesh.app.view.polydata.Layer` objects (plain arrays);
the window's scene (:mod:`barymesh.app.edit.painter_scene`) wraps them for VTK on the GUI
thread. The small layer makers here (squares, lines, segments) serve both sides.
"""

from __future__ import annotations

import dataclasses
import logging
import time
from typing import Any

import numpy as np

from barymesh.app.view.polydata import Layer
from barymesh.cell import CellMesh, UnitCell, build_cell
from barymesh.params import DEFAULT_MAX_TRIANGLES
from barymesh.subdivision import patch_template

log = logging.getLogger(__name__)

#: Larger meshes draw each pixel as one square (the same flat colour: the triangles are
#: seen through their edges), which keeps a frame of a 128 x 128 grid cheap.
FACES_AS_TRIANGLES = 40_000


@dataclasses.dataclass
class Built:
    """A mesh built in the worker for one mask, with the layers to draw it (plain
    arrays: the GUI thread wraps them for VTK)."""

    generation: int
    mask: np.ndarray
    cell_mesh: CellMesh | None = None
    error: str | None = None
    faces: Layer | None = None
    edges: Layer | None = None
    stats: dict[str, Any] | None = None
    seconds: float = 0.0
    lifted: np.ndarray | None = None  # (V, 3) points raised over the faces
    edge_pairs: np.ndarray | None = None  # (E, 2) the mesh's edges
    midpoints: np.ndarray | None = None  # (E, 2) their midpoints, to clip to the view


def build_preview(cell: UnitCell | None, mask: np.ndarray, dz: float, generation: int) -> Built:
    """Mesh ``cell`` and make its face and edge layers (thread-safe: no VTK object is
    made; never raises)."""
    start = time.perf_counter()
    if cell is None:
        return Built(generation, mask, faces=Layer(), edges=Layer(), stats=None)
    grid = cell.pixels
    assert grid is not None  # the painter's cells hold a pixel grid
    per_pixel = len(patch_template(grid.scheme, grid.subdivisions, grid.diagonal).triangles)
    count = per_pixel * int(mask.sum())
    if count > DEFAULT_MAX_TRIANGLES:
        return Built(
            generation,
            mask,
            error=(
                f"{int(mask.sum()):,} pixels make {count:,} triangles, more than the budget "
                f"of {DEFAULT_MAX_TRIANGLES:,}"
            ),
        )
    try:
        cm = build_cell(cell)
    except Exception as exc:  # noqa: BLE001 - shown in the window, the last mesh stays
        if not isinstance(exc, ValueError):
            log.exception("building the painted cell failed")
        return Built(generation, mask, error=str(exc))
    mesh = cm.mesh
    points = np.asarray(mesh.points, dtype=np.float64)
    triangles = np.asarray(mesh.triangles)
    if mesh.n_triangles > FACES_AS_TRIANGLES:  # pixels as one square each, elements as they are
        pixel_region = len(cell.elements) + 1
        own = triangles[np.asarray(mesh.regions) != pixel_region]
        quads = squares_layer(np.asarray(grid.origin), grid.pixel_size, np.argwhere(mask), 0.0)
        faces = quads
        if len(own):
            faces = Layer(
                np.vstack([quads.points, points]),
                faces=(*quads.face_blocks, own + len(quads.points)),
            )
    else:
        faces = Layer(points, faces=np.asarray(triangles, dtype=np.int64))
    lifted = points.copy()
    lifted[:, 2] += dz
    e = np.asarray(mesh.edges)
    midpoints = 0.5 * (points[e[:, 0], :2] + points[e[:, 1], :2])
    stats = mesh.stats()
    return Built(
        generation,
        mask,
        cm,
        None,
        faces,
        lines_layer(lifted, e),
        stats,
        time.perf_counter() - start,
        lifted,
        e,
        midpoints,
    )


def lines_layer(points: np.ndarray, pairs: np.ndarray) -> Layer:
    """The line cells ``pairs`` (k, 2) over all of ``points`` (V, 3)."""
    if len(pairs) == 0:
        return Layer()
    return Layer(points, lines=np.asarray(pairs, dtype=np.int64))


def squares_layer(origin: np.ndarray, size: float, cells: np.ndarray, z: float) -> Layer:
    """Squares of side ``size`` for the (row, column) pairs ``cells`` (K, 2), at height z."""
    if len(cells) == 0:
        return Layer()
    lower = origin + size * cells[:, ::-1].astype(np.float64)  # (K, 2) x, y
    offsets = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=np.float64) * size
    xy = (lower[:, None, :] + offsets[None]).reshape(-1, 2)
    pts = np.column_stack([xy, np.full(len(xy), z)])
    return Layer(pts, faces=np.arange(len(xy), dtype=np.int64).reshape(-1, 4))


def segments_layer(a: np.ndarray, b: np.ndarray, z: float) -> Layer:
    """Line segments from ``a`` (k, 2) to ``b`` (k, 2) at height z."""
    pts = np.column_stack([np.stack([a, b], axis=1).reshape(-1, 2), np.full(2 * len(a), z)])
    return Layer(pts, lines=np.arange(2 * len(a), dtype=np.int64).reshape(-1, 2))

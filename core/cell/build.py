"""Meshing a unit cell: every part built, placed, welded into one mesh; arrays of cells.

Parts are the elements, in order, then the pixel grid. Each part is meshed
on its own (:func:`barymesh.build.build_mesh` for an element, one square patch
per set pixel for the grid), placed, and all parts are welded together by
the metric constraint of :mod:`barymesh.weld` (vertices closer than the cell's
tolerance are one vertex). In the merged mesh ``regions`` is the part
number, 1-based (element k has region k + 1, the pixel grid the last one),
as Gmsh physical groups are.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from ..build import build_mesh
from ..grading import outline_sides
from ..mesh import TriMesh
from ..params import DEFAULT_MAX_TRIANGLES, MAX_BUDGET, MeshParams, budget_too_large
from ..repeat import Repetition
from ..structures import outline_rects
from ..subdivision import PatchTemplate, graded_patch_template, patch_template
from ..topology import INDEX
from ..values import echo
from ..weld import merge_pairs, weld_points
from .contacts import hanging_vertices, overlapping_triangles, pinch_vertices
from .model import Element, Lattice, PixelGrid, UnitCell
from .periodic import PeriodicPairs, periodic_pairs, side_vertices

log = logging.getLogger(__name__)


@dataclass(frozen=True, eq=False)
class CellMesh:
    """The welded mesh of a unit cell (or of an array of cells) and what was found.

    Attributes
    ----------
    mesh : TriMesh
        All parts welded; ``regions`` = part number (element index + 1, the
        pixel grid last), ``patch_ids`` numbered across parts.
    cell : UnitCell
    lattice : Lattice
        The cell's lattice, or for an array of n1 x n2 cells the lattice
        (n1 a1, n2 a2) of the array as a whole.
    part_meshes : tuple of TriMesh
        Each part alone, placed (their own regions: inner / outer ring).
    contact_notes : tuple of str
        How the parts meet: hanging vertices, corner contacts, metal beyond
        the cell (see :attr:`notes` for these and the periodic check).
    copies : (n1, n2)
    """

    mesh: TriMesh
    cell: UnitCell
    lattice: Lattice
    part_meshes: tuple[TriMesh, ...]
    contact_notes: tuple[str, ...]
    copies: tuple[int, int] = (1, 1)

    @cached_property
    def periodic_pairs(self) -> PeriodicPairs:
        """Edges on the cell boundary and their partners on the opposite side
        (the mesh's own :attr:`TriMesh.periodic_pairs`)."""
        if self.mesh.lattice is not None and self.mesh.tolerance == self.cell.weld_tolerance:
            return self.mesh.periodic_pairs
        return periodic_pairs(self.mesh, self.lattice, self.cell.weld_tolerance)

    @property
    def notes(self) -> tuple[str, ...]:
        """Things a solver should know, empty when all is well.

        The contact notes, then a note when edges on the cell's sides have no
        partner on the opposite side (the mesh is not periodic).
        """
        pairs = self.periodic_pairs
        if pairs.matched:
            return self.contact_notes
        mesh = self.mesh
        mid = mesh.points[mesh.edges[pairs.unmatched_edges[0]], :2].mean(axis=0)
        return self.contact_notes + (
            f"{len(pairs.unmatched_edges)} boundary edge(s) on the cell's sides have no partner "
            f"on the opposite side (first near ({mid[0]:.6g}, {mid[1]:.6g}) mm): the mesh is "
            "not periodic there",
        )

    @property
    def part_names(self) -> tuple[str, ...]:
        return self.cell.part_names

    def part_stats(self) -> list[dict[str, Any]]:
        """Statistics of every part alone (:meth:`TriMesh.stats` plus its ``name``)."""
        return [
            {"name": n, **m.stats()} for n, m in zip(self.part_names, self.part_meshes, strict=True)
        ]

    def stats(self) -> dict[str, Any]:
        """JSON-ready statistics: the whole cell, each part, the periodic match, the notes."""
        pairs = self.periodic_pairs
        return {
            "cell": self.mesh.stats(),
            "parts": self.part_stats(),
            "copies": list(self.copies),
            "periodic_edge_pairs": int(len(pairs.edges)),
            "unmatched_periodic_edges": int(len(pairs.unmatched_edges)),
            "notes": list(self.notes),
        }


@dataclass(frozen=True)
class _Part:
    xy: np.ndarray  # (V, 2) placed points
    triangles: np.ndarray  # (T, 3)
    patch_ids: np.ndarray  # (T,)
    n_patches: int
    rects: np.ndarray | None  # (P, 4) x0, y0, x1, y1 or None
    template: PatchTemplate | None
    mesh: TriMesh  # the part alone
    min_spacing: float


def _element_part(element, mesh: TriMesh) -> _Part:
    """The placed part of ``element``, whose own mesh (in its frame) is ``mesh``."""
    xy = element.place(mesh.points[:, :2])
    rects = None
    if mesh.patch_rects is not None and element.rotation % 90.0 == 0.0:
        lo = element.place(mesh.patch_rects[:, :2])
        hi = element.place(mesh.patch_rects[:, 2:])
        rects = np.concatenate([np.minimum(lo, hi), np.maximum(lo, hi)], axis=1)
    p = element.params
    # the layout's template (conforming rings: their sector template)
    template = None if mesh.repetition is None else mesh.repetition.template
    placed = TriMesh(
        xy,
        mesh.triangles,
        mesh.patch_ids,
        mesh.regions,
        mesh.n_patches,
        mesh.mode,
        mesh.tolerance,
        rects,
        {},
        mesh.repetition,
    )
    return _Part(
        xy, mesh.triangles, mesh.patch_ids, mesh.n_patches, rects, template, placed, p.min_spacing
    )


def _pixel_part(cell: UnitCell, grid: PixelGrid) -> _Part:
    """One square patch per set pixel of ``grid`` (the cell's), on one exact grid of points.

    A graded grid keeps that grid's numbering (which point is which vertex) and moves
    each pixel's points toward the outline of the painted region
    (:func:`pixel_outline_uv`); a point shared by pixels gets the same place from each.
    """
    params = grid.patch_params()
    template = patch_template(grid.scheme, grid.subdivisions, grid.diagonal)
    rows, cols = np.nonzero(grid.mask)
    n_pix = len(rows)
    p = grid.pixel_size
    corner = np.stack([cols, rows], axis=1).astype(np.float64)  # in pixels
    if template.lattice:
        n = template.segments
        ncol = grid.shape[1] * n + 1
        a = np.tile(np.arange(n + 1), n + 1)
        b = np.repeat(np.arange(n + 1), n + 1)
        gx = cols[:, None] * n + a[None, :]  # (K, Nv) grid column of every patch point
        gy = rows[:, None] * n + b[None, :]
        keys, first, ids = np.unique(
            (gy * ncol + gx).ravel(), return_index=True, return_inverse=True
        )
        if grid.grading:
            local = (corner[:, None, :] + pixel_outline_uv(cell, grid)) * p
            xy = np.asarray(grid.origin) + local.reshape(-1, 2)[first]
        else:
            gy_u, gx_u = np.divmod(keys, ncol)
            xy = np.asarray(grid.origin) + p * np.stack([gx_u, gy_u], axis=1) / n
    else:
        local = (corner[:, None, :] + template.uv[None]) * p + np.asarray(grid.origin)
        ids, rep = weld_points(local.reshape(-1, 2), 0.25 * params.min_spacing)
        xy = local.reshape(-1, 2)[rep]
    ids = ids.reshape(n_pix, -1).astype(INDEX)
    triangles = ids.take(template.triangles.ravel(), axis=1).reshape(-1, 3)
    per = len(template.triangles)
    patch_ids = np.repeat(np.arange(n_pix, dtype=INDEX), per)
    lower = np.asarray(grid.origin) + p * corner
    rects = np.concatenate([lower, lower + p], axis=1)
    mesh = TriMesh(
        np.column_stack([xy, np.zeros(len(xy))]),
        triangles,
        patch_ids,
        np.ones(len(triangles), dtype=INDEX),
        n_pix,
        cell.mode,
        cell.weld_tolerance,
        rects if cell.mode == "paper" else None,
        {},
        Repetition.of(template, ids, len(xy)),
    )
    return _Part(xy, triangles, patch_ids, n_pix, rects, template, mesh, params.min_spacing)


def element_images(lattice: Lattice, element: Element) -> np.ndarray | None:
    """(K, 4) rectangles of ``element``'s copies in the 8 neighbouring cells, in its frame.

    For a graded element laid out on rectangles (a patch or strip, a conforming square
    ring; :func:`barymesh.structures.outline_rects`) turned by a multiple of 90°: the
    copies that touch it (x0, y0, x1, y1), so that :func:`barymesh.build.build_mesh`
    does not grade toward sides where the metal runs on into the next cell. None
    for anything else, or when no copy touches.
    """
    rects = outline_rects(element.params)
    if rects is None or element.rotation % 90.0 != 0.0:
        return None
    a1, a2 = np.asarray(lattice.a1), np.asarray(lattice.a2)
    lo = element.place(rects[:, :2])
    hi = element.place(rects[:, 2:])
    placed = np.concatenate([np.minimum(lo, hi), np.maximum(lo, hi)], axis=1)
    tol = element.params.weld_tolerance
    box = np.concatenate([placed[:, :2].min(axis=0) - tol, placed[:, 2:].max(axis=0) + tol])
    images = []
    for i in (-1, 0, 1):
        for j in (-1, 0, 1):
            if i or j:
                shift = np.tile(i * a1 + j * a2, 2)
                moved = placed + shift
                touching = (moved[:, :2] <= box[2:]).all(axis=1) & (moved[:, 2:] >= box[:2]).all(
                    axis=1
                )
                images.append(moved[touching])
    found = np.concatenate(images)
    if not len(found):
        return None
    # back into the element's frame: undo the translation, then the turn
    turn = Element(element.params, (0.0, 0.0), -element.rotation, element.name)
    back_lo = turn.place(found[:, :2] - np.asarray(element.position))
    back_hi = turn.place(found[:, 2:] - np.asarray(element.position))
    return np.concatenate([np.minimum(back_lo, back_hi), np.maximum(back_lo, back_hi)], axis=1)


def pixel_outline_uv(cell: UnitCell, grid: PixelGrid) -> np.ndarray:
    """(K, (n + 1)², 2) graded points of the K set pixels (row by row), in pixel units.

    Each pixel's template points (:func:`barymesh.subdivision.graded_patch_template`)
    graded toward the outline of the painted region
    (:func:`barymesh.grading.outline_sides`, on the pixels' integer corners). When the
    grid spans the cell exactly (a rectangular lattice whose periods are the grid's
    sides, its corner on the cell's), the region continues into the neighbouring
    cells: their pixels are the outline's neighbours, so pixels painted across the
    cell's sides are not graded toward them and the two sides match for the periodic
    pairs.
    """
    rows, cols = np.nonzero(grid.mask)
    rects = np.stack([cols, rows, cols + 1, rows + 1], axis=1).astype(np.float64)
    neighbours = None
    if _spans_cell(cell, grid):
        height, width = grid.shape
        shifts = [(i * width, j * height) for i in (-1, 0, 1) for j in (-1, 0, 1) if i or j]
        neighbours = np.concatenate([rects + np.array([dx, dy, dx, dy]) for dx, dy in shifts])
    ends = outline_sides(rects, neighbours)
    kinds, inverse = np.unique(ends.reshape(len(rects), 8), axis=0, return_inverse=True)
    n, diagonal = grid.subdivisions, grid.diagonal
    uv = np.stack(
        [
            graded_patch_template(n, diagonal, tuple(map(tuple, k.reshape(4, 2).tolist()))).uv
            for k in kinds
        ]
    )
    return uv[inverse.ravel()]


def _spans_cell(cell: UnitCell, grid: PixelGrid) -> bool:
    """Whether ``grid`` covers ``cell``'s rectangular lattice cell exactly (to its tolerance)."""
    lat = cell.lattice
    if lat.kind != "rectangular":
        return False
    tol = cell.weld_tolerance
    height, width = grid.shape
    px, py = lat.a1[0], lat.a2[1]
    return (
        abs(width * grid.pixel_size - px) <= tol
        and abs(height * grid.pixel_size - py) <= tol
        and abs(grid.origin[0] + px / 2) <= tol
        and abs(grid.origin[1] + py / 2) <= tol
    )


def _check_overlaps(cell: UnitCell, parts: list[_Part]) -> None:
    """Conforming mode: refuse parts whose metal overlaps, naming both."""
    boxes = [np.concatenate([q.xy.min(axis=0), q.xy.max(axis=0)]) for q in parts]
    tol = cell.weld_tolerance
    for k in range(len(parts)):
        for m in range(k + 1, len(parts)):
            a, b = boxes[k], boxes[m]
            if (a[:2] >= b[2:] - tol).any() or (b[:2] >= a[2:] - tol).any():
                continue
            pairs = overlapping_triangles(
                parts[k].xy, parts[k].triangles, parts[m].xy, parts[m].triangles, tol, limit=1
            )
            if len(pairs):
                tk, tm = pairs[0]
                where = parts[k].xy[parts[k].triangles[tk]].mean(axis=0)
                other = _describe_part(cell, m, parts[m], tm)
                raise ValueError(
                    f"{_describe_part(cell, k, parts[k], tk)} and {other} overlap (first near "
                    f"({where[0]:.6g}, {where[1]:.6g}) mm); conforming mode needs parts that "
                    "at most touch: move one, or use paper mode"
                )


def _describe_part(cell: UnitCell, k: int, part: _Part, triangle: int) -> str:
    if k < len(cell.elements):
        return f"element {cell.elements[k].name!r} (elements[{k}])"
    grid = cell.pixels
    assert grid is not None  # parts past the elements are the pixels'
    rows, cols = np.nonzero(grid.mask)
    pix = part.patch_ids[triangle]
    return f"pixel (row {rows[pix]}, column {cols[pix]})"


def _check_tolerance(cell: UnitCell, parts: list[_Part]) -> None:
    limit = 0.5 * min(q.min_spacing for q in parts)
    if cell.weld_tolerance >= limit:
        raise ValueError(
            f"tolerance={cell.weld_tolerance!r} mm is too large for this cell: it must be below "
            f"half the smallest sub-triangle edge of its parts, {limit:.6g} mm"
        )


def build_cell(
    cell: UnitCell,
    *,
    refuse_corner_contacts: bool = False,
    max_triangles: int = DEFAULT_MAX_TRIANGLES,
) -> CellMesh:
    """Mesh a unit cell: all parts welded into one mesh, contacts checked.

    Parameters
    ----------
    cell : UnitCell
    refuse_corner_contacts : bool
        Raise ``ValueError`` instead of noting pixels (or, in conforming mode,
        any parts) that meet at a single corner.
    max_triangles : int
        Triangle budget of the whole cell: a cell whose parts together would
        have more (:meth:`UnitCell.predicted_triangles`) is refused before any
        part is built. At most :data:`barymesh.params.MAX_BUDGET` (715,827,882,
        what int32 indices number); a larger one is refused itself.

    Returns
    -------
    CellMesh

    Raises
    ------
    ValueError
        In conforming mode, when two parts overlap (the message names both);
        corner contacts with ``refuse_corner_contacts``; a tolerance too large;
        more triangles than ``max_triangles``.

    Examples
    --------
    >>> from barymesh.cell import PixelGrid
    >>> cm = build_cell(UnitCell(pixels=PixelGrid(np.array([[True, True]]))))
    >>> cm.mesh.n_triangles, cm.mesh.n_vertices
    (64, 45)
    """
    if not isinstance(cell, UnitCell):
        raise TypeError(f"cell must be a UnitCell, got {echo(cell)}")
    _check_budget(cell.predicted_triangles(), max_triangles, "the cell's parts")
    # elements alike in all but place are built once (a graded one's images in the
    # neighbouring cells, in its own frame, do not depend on where it is)
    built: dict[tuple[MeshParams, bytes], TriMesh] = {}
    keys = []
    for el in cell.elements:
        images = element_images(cell.lattice, el)
        key = (el.params, b"" if images is None else images.tobytes())
        if key not in built:
            built[key] = build_mesh(el.params, neighbours=images)
        keys.append(key)
    parts: list[_Part | None] = [
        _element_part(el, built[key]) for el, key in zip(cell.elements, keys, strict=True)
    ]
    if cell.pixels is not None and cell.pixels.mask.any():
        parts.append(_pixel_part(cell, cell.pixels))
    elif cell.pixels is not None:
        parts.append(None)  # an empty grid: a part without metal
    present = [q for q in parts if q is not None]
    _check_tolerance(cell, present)
    notes: list[str] = []
    contacts = _pixel_corner_contacts(cell)
    if len(contacts):
        first = _pixel_pair(contacts[0])
        if refuse_corner_contacts:
            raise ValueError(
                f"{len(contacts)} pixel pair(s) touch at a corner only, first {first}; a single "
                "shared point is a junction risk for solvers: fill or clear a neighbour"
            )
        notes.append(
            f"{len(contacts)} pixel pair(s) touch at a corner only (first {first}): "
            "a junction risk for solvers"
        )
    if cell.mode == "conforming":
        _check_overlaps(cell, [q for q in parts if q is not None])
    mesh, part_of_vertex = _merge(cell, parts)
    if cell.mode == "conforming":
        notes += _conforming_notes(cell, mesh, part_of_vertex, refuse_corner_contacts)
    notes += _outside_notes(cell, parts)
    meshes = tuple(q.mesh if q is not None else _empty_mesh(cell) for q in parts)
    result = CellMesh(mesh, cell, cell.lattice, meshes, tuple(notes))
    for note in result.notes:  # checks the periodic match too
        log.info("cell %r: %s", cell.name, note)
    return result


def _check_budget(predicted: int, max_triangles: int, what: str) -> None:
    """Refuse ``predicted`` triangles above the budget, before anything is allocated."""
    if (
        isinstance(max_triangles, bool)
        or not isinstance(max_triangles, int | np.integer)
        or (max_triangles < 1)
    ):
        raise ValueError(
            f"max_triangles={echo(max_triangles)} is invalid; expected an integer >= 1"
        )
    if max_triangles > MAX_BUDGET:  # refused itself: below it, every count would pass
        raise ValueError(budget_too_large(int(max_triangles)))
    if predicted > max_triangles:
        raise ValueError(
            f"{what} would make {predicted:,} triangles, above the budget max_triangles="
            f"{max_triangles:,}; use fewer or coarser elements (a larger angle_step or "
            "patch_size, fewer subdivisions), fewer copies, or raise max_triangles"
        )


def _empty_mesh(cell: UnitCell) -> TriMesh:
    return TriMesh(
        np.zeros((0, 3)),
        np.zeros((0, 3), INDEX),
        np.zeros(0, INDEX),
        np.zeros(0, INDEX),
        0,
        cell.mode,
        cell.weld_tolerance,
    )


def _pixel_pair(pair: np.ndarray) -> str:
    (r0, c0), (r1, c1) = pair.tolist()
    return f"(row {r0}, column {c0}) and (row {r1}, column {c1})"


def _pixel_corner_contacts(cell: UnitCell) -> np.ndarray:
    if cell.pixels is None:
        return np.empty((0, 2, 2), dtype=np.int64)
    return cell.pixels.corner_contacts()


def _merge(cell: UnitCell, parts: list[_Part | None]) -> tuple[TriMesh, np.ndarray]:
    """Weld all parts into one TriMesh; also the part (0-based) of every vertex."""
    present = [(k, q) for k, q in enumerate(parts) if q is not None]
    xy = np.concatenate([q.xy for _, q in present])
    offsets = np.cumsum([0] + [len(q.xy) for _, q in present])
    patch_offsets = np.cumsum([0] + [q.n_patches for _, q in present])
    if len(present) > 1:
        ids, rep = weld_points(xy, cell.weld_tolerance)
    else:
        ids, rep = np.arange(len(xy), dtype=INDEX), np.arange(len(xy), dtype=INDEX)
    triangles = np.concatenate([ids[q.triangles + offsets[i]] for i, (_, q) in enumerate(present)])
    patch_ids = np.concatenate([q.patch_ids + patch_offsets[i] for i, (_, q) in enumerate(present)])
    regions = np.concatenate([np.full(len(q.triangles), k + 1, INDEX) for k, q in present])
    part_of_point = np.concatenate([np.full(len(q.xy), k) for k, q in present])
    rects = None
    if cell.mode == "paper" and all(q.rects is not None for _, q in present):
        rects = np.concatenate([q.rects for _, q in present])
    templates = {id(q.template) for _, q in present}
    template = present[0][1].template if len(templates) == 1 else None
    repetition = (
        None if template is None else Repetition.of_triangles(template, triangles, len(rep))
    )
    mesh = TriMesh(
        points=np.column_stack([xy[rep], np.zeros(len(rep))]),
        triangles=triangles,
        patch_ids=patch_ids,
        regions=regions,
        n_patches=int(patch_offsets[-1]),
        mode=cell.mode,
        tolerance=cell.weld_tolerance,
        patch_rects=rects,
        repetition=repetition,
        lattice=cell.lattice,
    )
    return mesh, part_of_point[rep]


def _conforming_notes(
    cell: UnitCell, mesh: TriMesh, part_of_vertex: np.ndarray, refuse_corners: bool
) -> list[str]:
    notes = []
    xy = mesh.points[:, :2]
    topo = mesh.topology
    tol = cell.weld_tolerance
    hang = hanging_vertices(xy, topo.edges, topo.boundary_edges, max(tol, 1e-9 * cell.lattice.size))
    if len(hang):
        names = cell.part_names
        edge_part = mesh.regions[topo.edge_triangles[hang[:, 0], 0]] - 1
        vert_part = part_of_vertex[hang[:, 1]]
        pair = np.sort(np.stack([edge_part, vert_part], axis=1), axis=1)
        keys, first, count = np.unique(pair, axis=0, return_index=True, return_counts=True)
        for (a, b), i, c in zip(keys.tolist(), first.tolist(), count.tolist(), strict=True):
            p = xy[hang[i, 1]]
            notes.append(
                f"{names[a]!r} and {names[b]!r} touch with {c} hanging vertex(es) "
                f"(first at ({p[0]:.6g}, {p[1]:.6g}) mm): their sides do not share vertices, "
                "so the mesh is not conforming there"
            )
    pinch = pinch_vertices(topo, mesh.n_vertices)
    # the ends of a side with hanging vertices are reported with them
    pinch = np.setdiff1d(pinch, topo.edges[hang[:, 0]])
    if cell.pixels is not None:  # pixel against pixel: reported from the mask already
        pinch = pinch[part_of_vertex[pinch] != len(cell.elements)]
    if len(pinch):
        p = xy[pinch[0]]
        message = (
            f"{len(pinch)} vertex(es) where metal meets at a single point (first at "
            f"({p[0]:.6g}, {p[1]:.6g}) mm): a junction risk for solvers"
        )
        if refuse_corners:
            raise ValueError(message)
        notes.append(message)
    return notes


def _outside_notes(cell: UnitCell, parts: list[_Part | None]) -> list[str]:
    notes = []
    lat = cell.lattice
    tol = cell.weld_tolerance
    for name, q in zip(cell.part_names, parts, strict=True):
        if q is None:
            continue
        frac = lat.fractional(q.xy)
        side = side_vertices(q.xy, lat, tol)
        outside = (np.abs(frac) > 0.5) & (side == 0)
        if outside.any():
            notes.append(
                f"{name!r} reaches beyond the cell boundary: copies of the cell would overlap there"
            )
    return notes


def tile(
    cell: UnitCell | CellMesh, n1: int, n2: int, *, max_triangles: int = DEFAULT_MAX_TRIANGLES
) -> CellMesh:
    """An n1 x n2 array of the cell as one welded mesh, centred on the origin.

    Copy (i, j) is the cell moved by (i − (n1 − 1)/2) a1 + (j − (n2 − 1)/2) a2;
    vertices of neighbouring copies closer than the cell's tolerance are
    welded. The result's lattice is (n1 a1, n2 a2), so its periodic pairs are
    those of the array as a whole.

    Parameters
    ----------
    cell : UnitCell or CellMesh
        A built cell is not built again.
    n1, n2 : int
        Copies along a1 and a2, >= 1.
    max_triangles : int
        Triangle budget of the array (and of the cell when it is built here), at
        most :data:`barymesh.params.MAX_BUDGET`.

    Returns
    -------
    CellMesh

    Examples
    --------
    >>> from barymesh.cell import PixelGrid
    >>> one = PixelGrid(np.ones((1, 1)), origin=(-0.5, -0.5))
    >>> full = UnitCell(Lattice.rectangular(1.0), pixels=one)
    >>> tile(full, 3, 2).mesh.n_vertices  # (3 n + 1)(2 n + 1), n = 4
    117
    """
    for name, n in (("n1", n1), ("n2", n2)):
        if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
            raise ValueError(f"{name}={n!r} is invalid; expected an integer >= 1")
    per = cell.mesh.n_triangles if isinstance(cell, CellMesh) else None
    if per is None:
        if not isinstance(cell, UnitCell):
            raise TypeError(f"cell must be a UnitCell or a CellMesh, got {echo(cell)}")
        per = cell.predicted_triangles()
    _check_budget(per * n1 * n2, max_triangles, f"{n1} x {n2} copies of {per:,} triangles")
    base = cell if isinstance(cell, CellMesh) else build_cell(cell, max_triangles=max_triangles)
    unit = base.cell
    lat = base.lattice
    a1, a2 = np.asarray(lat.a1), np.asarray(lat.a2)
    i, j = np.meshgrid(np.arange(n1) - (n1 - 1) / 2, np.arange(n2) - (n2 - 1) / 2, indexing="ij")
    shifts = i.ravel()[:, None] * a1 + j.ravel()[:, None] * a2  # (n1 n2, 2)
    m = base.mesh
    v, copies = m.n_vertices, len(shifts)
    xy = (m.points[None, :, :2] + shifts[:, None, :]).reshape(-1, 2)
    tol = unit.weld_tolerance
    frac = lat.fractional(m.points)
    inside = (np.abs(frac) <= 0.5 + tol / lat.size + 1e-12).all()
    if inside:  # only vertices on the cell's sides can meet a neighbour's
        near = (side_vertices(m.points, lat, tol) != 0).any(axis=1)
        candidates = (np.flatnonzero(near)[None, :] + (np.arange(copies) * v)[:, None]).ravel()
    else:
        candidates = np.arange(len(xy))
    from scipy.spatial import cKDTree  # here: ``barymesh --help`` stays quick

    found = cKDTree(xy[candidates]).query_pairs(tol, output_type="ndarray")
    ids, rep = merge_pairs(len(xy), candidates[found], xy, tol)
    offsets = (np.arange(copies) * v).astype(INDEX)
    triangles = ids[(m.triangles[None] + offsets[:, None, None]).reshape(-1, 3)]
    patch_ids = (m.patch_ids[None] + (np.arange(copies) * m.n_patches)[:, None]).ravel()
    rects = None
    if m.patch_rects is not None:
        rects = (m.patch_rects[None] + np.tile(shifts, 2)[:, None, :]).reshape(-1, 4)
    array_lattice = Lattice(tuple(n1 * a1), tuple(n2 * a2))
    mesh = TriMesh(
        points=np.column_stack([xy[rep], np.zeros(len(rep))]),
        triangles=triangles,
        patch_ids=patch_ids,
        regions=np.tile(m.regions, copies),
        n_patches=m.n_patches * copies,
        mode=m.mode,
        tolerance=m.tolerance,
        patch_rects=rects,
        repetition=_tiled_repetition(m, ids, copies, len(rep)),
        lattice=array_lattice,
    )
    return CellMesh(
        mesh,
        unit,
        array_lattice,
        base.part_meshes,
        base.contact_notes,
        (base.copies[0] * n1, base.copies[1] * n2),
    )


def _tiled_repetition(
    m: TriMesh, ids: np.ndarray, copies: int, n_vertices: int
) -> Repetition | None:
    """The repetition of ``copies`` copies of ``m``, point p of the copies at vertex ``ids[p]``."""
    if m.repetition is None:
        return None
    vmap = m.repetition.vertex_map
    offsets = (np.arange(copies) * m.n_vertices).astype(INDEX)
    tiled = ids[(vmap[None] + offsets[:, None, None]).reshape(-1, vmap.shape[1])]
    return Repetition.of(m.repetition.template, tiled, n_vertices)

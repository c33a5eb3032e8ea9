"""Layouts of patches for every structure, in both modes.

A layout places copies of the patch template: ``xy[p, i]`` is where local
vertex i of patch p lands, and ``vertex_of_point`` says which global vertex
each of those points is (after the weld of the chosen mode).

Where the patches go is :mod:`barymesh.placement` (the paper's Eqs. 28–35 in paper
mode, exact tilings of square rings in conforming mode) and how conforming circular
rings are cut into sectors is :mod:`barymesh.sectors`. Paper-mode patches are welded by
the metric constraint (:mod:`barymesh.weld`); neighbouring conforming sectors are glued
topologically (exactly).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .grading import outline_sides
from .params import RELATIVE_TOLERANCE, MeshParams
from .placement import conforming_square_rects, cross_rects, paper_origins
from .repeat import sector_chain_vertices
from .repeat.compiled import kernels
from .sectors import (
    arc_theta,
    gap_directions,
    ring_radii,
    rings_touch,
    sector_plan,
    slot_half_angle,
)
from .subdivision import PatchTemplate, graded_patch_template, patch_template
from .topology import BLOCK
from .weld import NearPointChain, merge_pairs, weld_lattice_patches, weld_points


@dataclass(frozen=True)
class Layout:
    """Patches of one structure, ready to be assembled into a mesh.

    Attributes
    ----------
    template : PatchTemplate
    xy : (P, Nv, 2) float64
        Position of every patch-local vertex.
    regions : (P,) int
        Region of each patch (1 = the patch or the inner ring, 2 = the outer ring).
    vertex_of_point : (P * Nv,) int
        Global vertex of every patch-local vertex.
    representative : (V,) int
        One patch-local point per global vertex (its coordinates are used).
    rects : (P, 4) float64 or None
        (x0, y0, x1, y1) of each axis-aligned patch in paper mode.
    min_angle_floor : float or None
        Conforming circular rings (uniform scheme): the best smallest angle
        (degrees) their geometry allows this construction (see :class:`SectorPlan`).
    points : (P Nv, 3) float64 or None
        When nothing is welded (every point its own vertex) and the layout wrote
        them directly: the mesh's points, z = 0, of which ``xy`` is a read-only view.
    columns : two (P Nv,) float64 or None
        With ``points``: contiguous, read-only copies of their x and y (what
        :attr:`barymesh.mesh.TriMesh.columns` would make), written in the same pass.
    """

    template: PatchTemplate
    xy: np.ndarray
    regions: np.ndarray
    vertex_of_point: np.ndarray
    representative: np.ndarray
    rects: np.ndarray | None
    min_angle_floor: float | None = None
    points: np.ndarray | None = None
    columns: tuple[np.ndarray, np.ndarray] | None = None


def _conforming_ring_layout(params: MeshParams) -> Layout:
    plan = sector_plan(params)
    arcs, template = plan.arcs, plan.template
    split = bool(gap_directions(params))
    h = params.patch_size
    u, v = template.uv[:, 0], template.uv[:, 1]
    nv = len(u)
    n_total = len(arcs) * sum(plan.sectors)
    xy = np.empty((n_total, nv, 2))
    regions, pairs, chains = [], [], []
    sides = template.sides
    n_patches = 0
    first_patch = {}  # (ring, arc) -> first patch index
    for ring, radius in enumerate(ring_radii(params)):
        rho = radius + u * h  # (Nv,)
        m = plan.sectors[ring]
        for a, (start, end, closed) in enumerate(arcs):
            if split:
                alpha = slot_half_angle(params, rho)
                lo, hi = start + alpha, end - alpha
            else:
                lo, hi = np.full(nv, start), np.full(nv, end)
            if split:
                theta = arc_theta(lo, hi, np.arange(m), v, m, plan.sector_bounds(ring))
                cos, sin = np.cos(theta), np.sin(theta)
            else:
                # the angle depends on v alone: evaluate cos and sin once per row of the template
                rows, row_of = np.unique(v, return_inverse=True)
                first = np.unique(row_of, return_index=True)[1]
                k = np.arange(m)[:, None] + rows[None, :]
                theta = np.radians(lo[first] + k * (hi[first] - lo[first]) / m)
                cos, sin = np.cos(theta).take(row_of, axis=1), np.sin(theta).take(row_of, axis=1)
            pts = xy[n_patches : n_patches + m]
            np.multiply(rho, cos, out=pts[..., 0])
            np.multiply(rho, sin, out=pts[..., 1])
            regions.append(np.full(m, ring + 1))
            first_patch[ring, a] = n_patches
            chains.append((m, closed))
            # glue side 2 (v = 1) of sector k to side 0 (v = 0) of sector k + 1
            nxt = np.arange(1, m + 1)
            cur = np.arange(m)
            if closed:
                nxt %= m
            else:
                cur, nxt = cur[:-1], nxt[:-1]
            base = n_patches * nv
            pairs.append(
                np.stack(
                    [
                        (base + cur[:, None] * nv + sides[2][None, :]).ravel(),
                        (base + nxt[:, None] * nv + sides[0][None, :]).ravel(),
                    ],
                    axis=1,
                )
            )
            n_patches += m
    touching = rings_touch(params)
    if any(params.origin):
        xy += np.asarray(params.origin)
    floor = plan.min_angle_floor
    if not touching and _sides_in_rows(template):
        ids, rep = sector_chain_vertices(template, [c[0] for c in chains], [c[1] for c in chains])
        return Layout(template, xy, np.concatenate(regions), ids, rep, None, floor)
    if touching:
        # touching rings (as many sectors): the inner ring's outer circle is the
        # outer ring's inner circle
        for a in range(len(arcs)):
            p0 = first_patch[0, a] + np.arange(plan.sectors[0])
            p1 = first_patch[1, a] + np.arange(plan.sectors[1])
            pairs.append(
                np.stack(
                    [
                        (p0[:, None] * nv + sides[1][None, :]).ravel(),
                        (p1[:, None] * nv + sides[3][None, :]).ravel(),
                    ],
                    axis=1,
                )
            )
    vertex_of_point, rep = merge_pairs(n_patches * nv, np.concatenate(pairs))
    return Layout(template, xy, np.concatenate(regions), vertex_of_point, rep, None, floor)


def _sides_in_rows(template: PatchTemplate) -> bool:
    """True when side 0 (v = 0) is the first local vertices and side 2 (v = 1) the last."""
    sides, nv = template.sides, len(template.uv)
    s = len(sides[0])
    return (
        len(sides[2]) == s
        and np.array_equal(sides[0], np.arange(s))
        and np.array_equal(sides[2], np.arange(nv - s, nv))
    )


def _rect_points(
    template: PatchTemplate, rects: np.ndarray
) -> tuple[np.ndarray, np.ndarray, tuple[np.ndarray, np.ndarray]]:
    """:func:`_rect_layout`'s points written as a mesh's: (xy, points, (x, y)).

    The same products and sums as :func:`_rect_layout`, block by block, into the
    contiguous x and y columns, copied from cache into a (P Nv, 3) array whose z is
    zero (at large sizes one compiled loop, :func:`barymesh.repeat.kernels.rect_points`,
    writes both); ``xy`` is that array's (P, Nv, 2) view. For patches that nothing welds:
    their points are the mesh's, without an interleaved layout to copy them from
    and a second pass to take the columns out again.
    """
    n_p, nv = len(rects), len(template.uv)
    u, v = template.uv[None, :, 0], template.uv[None, :, 1]
    compiled = kernels(n_p * len(template.triangles))
    points = np.empty((n_p * nv, 3)) if compiled is not None else np.zeros((n_p * nv, 3))
    x, y = np.empty((2, n_p, nv))
    grid = points.reshape(n_p, nv, 3)
    if compiled is not None:  # the same products and sums, each value written once
        uv = [np.ascontiguousarray(c[0]) for c in (u, v)]
        compiled.rect_points(*uv, np.ascontiguousarray(rects), points, x.ravel(), y.ravel())
    else:
        rows = max(1, BLOCK // max(nv, 1))
        for lo in range(0, n_p, rows):
            r = rects[lo : lo + rows]
            bx, by = x[lo : lo + rows], y[lo : lo + rows]
            np.multiply(u, r[:, 2:3], out=bx)
            bx += r[:, :1]
            np.multiply(v, r[:, 3:4], out=by)
            by += r[:, 1:2]
            grid[lo : lo + rows, :, 0] = bx
            grid[lo : lo + rows, :, 1] = by
    xy = grid[..., :2]
    for a in (x, y, xy):
        a.flags.writeable = False
    return xy, points, (x.reshape(-1), y.reshape(-1))


def _rect_layout(template: PatchTemplate, rects: np.ndarray) -> np.ndarray:
    """(P, Nv, 2) template points on the axis-aligned rectangles (x0, y0, wx, wy).

    x0 + u wx and y0 + v wy, written straight into the interleaved output block by
    block (the same products and sums, so the same points as computing x and y
    whole and stacking them, without those two temporaries and their copy).
    """
    u, v = template.uv[None, :, 0], template.uv[None, :, 1]
    out = np.empty((len(rects), len(template.uv), 2))
    rows = max(1, BLOCK // max(len(template.uv), 1))
    for lo in range(0, len(rects), rows):
        r = rects[lo : lo + rows]
        x, y = out[lo : lo + rows, :, 0], out[lo : lo + rows, :, 1]
        np.multiply(u, r[:, 2:3], out=x)
        x += r[:, :1]
        np.multiply(v, r[:, 3:4], out=y)
        y += r[:, 1:2]
    return out


# -- entry points ----------------------------------------------------------


def patch_template_of(params: MeshParams) -> PatchTemplate:
    """The template every patch of ``params`` is a copy of (its topology, and its points
    unless the patches are graded toward an outline they share)."""
    if params.grading and not params.track_graded:
        return graded_patch_template(params.subdivisions, params.diagonal)
    return patch_template(params.scheme, params.subdivisions, params.diagonal)


def outline_rects(params: MeshParams) -> np.ndarray | None:
    """(P, 4) rectangles (x0, y0, x1, y1) a graded structure is laid out on, or None.

    A graded patch (or strip) and a graded conforming square ring meet their neighbours
    side to side and grade toward the outline of their rectangles
    (:func:`barymesh.grading.outline_sides`); everything else (ungraded, rings of
    sectors or of overlapping paper patches, a triangle) is None.
    """
    if not params.grading or params.track_graded:
        return None
    if params.structure == "patch":
        x, y = params.origin
        return np.array([[x, y, x + params.patch_size, y + params.patch_height]])
    if params.structure == "cross":
        return _corners(cross_rects(params))
    if params.structure == "square_split_double_ring" and params.mode == "conforming":
        return _corners(conforming_square_rects(params)[0])
    return None


def _outline_layout(
    params: MeshParams, rects: np.ndarray, neighbours: np.ndarray | None
) -> np.ndarray:
    """(P, Nv, 2) points of patches on the rectangles (x0, y0, wx, wy) that meet side to
    side, each graded toward the outline of their union (:func:`barymesh.grading.outline_sides`).
    """
    corners = _corners(rects)
    ends = outline_sides(corners, neighbours, params.weld_tolerance)
    n, diagonal = params.subdivisions, params.diagonal
    kinds, inverse = np.unique(ends.reshape(len(rects), 8), axis=0, return_inverse=True)
    uv = np.stack(
        [
            graded_patch_template(n, diagonal, tuple(map(tuple, k.reshape(4, 2).tolist()))).uv
            for k in kinds
        ]
    )[inverse.ravel()]  # (P, Nv, 2)
    x = rects[:, :1] + uv[..., 0] * rects[:, 2:3]
    y = rects[:, 1:2] + uv[..., 1] * rects[:, 3:4]
    return np.stack([x, y], axis=-1)


def layout(params: MeshParams, neighbours: np.ndarray | None = None) -> Layout:
    """Place and weld the patches of ``params.structure`` (not ``triangle``).

    ``neighbours`` (K, 4): rectangles (x0, y0, x1, y1) of metal beyond a graded patch or
    conforming square ring (its copies in the neighbouring cells of an array), whose
    shared sides are then no metal edges to grade toward.
    """
    s = params.structure
    if s == "triangle":
        raise ValueError("the triangle structure has no patch layout")
    template = patch_template_of(params)
    outlined = params.grading and not params.track_graded
    h, w = params.patch_size, params.patch_height
    nv = len(template.uv)
    if s == "patch":
        rects = np.array([[params.origin[0], params.origin[1], h, w]])
        if outlined and neighbours is not None and len(neighbours):
            xy = _outline_layout(params, rects, neighbours)
        else:
            xy = _rect_layout(template, rects)
        ids = np.arange(nv, dtype=np.int32)
        return Layout(template, xy, np.ones(1, dtype=np.int32), ids, ids, _corners(rects))
    if s == "cross":  # five patches meeting side to side, in either mode
        rects = cross_rects(params)
        if outlined:
            xy = _outline_layout(params, rects, neighbours)
        else:
            xy = _rect_layout(template, rects)
        ids, rep = _welded(params, weld_points, xy.reshape(-1, 2), params.weld_tolerance)
        rects_out = _corners(rects) if params.mode == "paper" else None
        return Layout(template, xy, np.ones(5, dtype=np.int32), ids, rep, rects_out)
    if params.mode == "conforming":
        if s == "square_split_double_ring":
            rects, regions = conforming_square_rects(params)
            if outlined:
                xy = _outline_layout(params, rects, neighbours)
            else:
                xy = _rect_layout(template, rects)
            ids, rep = _welded(params, weld_points, xy.reshape(-1, 2), params.weld_tolerance)
            return Layout(template, xy, regions.astype(np.int32), ids, rep, None)
        return _conforming_ring_layout(params)
    origins, regions = paper_origins(params)
    rects = np.empty((len(origins), 4))  # (x0, y0, h, w), without broadcast_to's overhead
    rects[:, :2] = origins
    rects[:, 2] = h
    rects[:, 3] = w
    if template.lattice:  # welded from the origins alone: the points are written after
        step = (h / template.segments, w / template.segments)
        ids, rep = _welded(
            params, weld_lattice_patches, origins, step, template.segments, params.weld_tolerance
        )
        if len(rep) == len(ids):  # nothing welded: the points are the mesh's, written once
            xy, points, columns = _rect_points(template, rects)
            corners = _corners(rects)
            regions = regions.astype(np.int32)
            return Layout(template, xy, regions, ids, rep, corners, None, points, columns)
        xy = _rect_layout(template, rects)
    else:
        xy = _rect_layout(template, rects)
        ids, rep = _welded(params, weld_points, xy.reshape(-1, 2), params.weld_tolerance)
    return Layout(template, xy, regions.astype(np.int32), ids, rep, _corners(rects))


def _welded(
    params: MeshParams, weld: Callable[..., tuple[np.ndarray, np.ndarray]], *args: Any
) -> tuple[np.ndarray, np.ndarray]:
    """``weld(*args)``, its chain error reworded when the user set no tolerance."""
    try:
        return weld(*args)
    except NearPointChain as err:
        if params.tolerance is not None:
            raise
        raise ValueError(
            f"{err.finding}, with the default tolerance ({RELATIVE_TOLERANCE:g} of the size): "
            "patches nearly coincide; move them apart (angle_step, patch_size, the radii) or "
            "set a tolerance"
        ) from None


def _corners(rects: np.ndarray) -> np.ndarray:
    """(x0, y0, wx, wy) to (x0, y0, x1, y1)."""
    return np.concatenate([rects[:, :2], rects[:, :2] + rects[:, 2:]], axis=1)

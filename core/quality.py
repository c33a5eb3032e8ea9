"""Per-triangle quality: area, minimum angle and aspect ratio.

All three come from one pass over the corner coordinates, gathered column by
column (several times faster than gathering (T, 3, 3) blocks) in cache-sized
blocks of triangles, because the statistics panel recomputes them for every
new mesh.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .topology import BLOCK


class TriangleQuality(NamedTuple):
    """Per-triangle quality arrays, each (T,) float64."""

    areas: np.ndarray
    min_angles_deg: np.ndarray
    aspect_ratios: np.ndarray


#: Below this |cross product| its square is subnormal: the area takes the square root.
_TINY_CROSS = 1e-150
_RAD_TO_DEG = 180.0 / np.pi  # what np.degrees multiplies by, without its slower loop


def _sides_and_areas(
    columns: list[np.ndarray],
    triangles: np.ndarray,
    edge_lengths: np.ndarray | None = None,
    triangle_edges: np.ndarray | None = None,
) -> tuple[list[np.ndarray], np.ndarray]:
    """Lengths of sides k (vertex k to k + 1) and areas, from per-column gathers.

    ``columns`` are the 2 or 3 coordinate columns of the points, each (V,) float64.
    With ``edge_lengths`` (E,) and this block's ``triangle_edges`` (t, 3), the sides
    are taken from the edges: the same sums of squares, so the same values.
    """
    c = [[np.take(col, triangles[:, i]) for col in columns] for i in range(3)]  # c[i][k]
    u = [c[1][k] - c[0][k] for k in range(len(columns))]  # side 0
    v = [c[2][k] - c[0][k] for k in range(len(columns))]  # side 2 reversed: same squares
    if edge_lengths is not None and triangle_edges is not None:
        sides = [np.take(edge_lengths, triangle_edges[:, k]) for k in range(3)]
    else:
        w = [c[2][k] - c[1][k] for k in range(len(columns))]  # side 1
        sides = [np.sqrt(sum(x * x for x in d)) for d in (u, w, v)]
    if len(columns) == 2:
        cross = u[0] * v[1] - u[1] * v[0]
        # sqrt(c²) is |c| exactly unless c² underflows
        area = np.abs(cross)
        tiny = area < _TINY_CROSS
        if tiny.any():
            area[tiny] = np.sqrt(cross[tiny] ** 2)
        area *= 0.5
        return sides, area
    cross2 = (
        (u[1] * v[2] - u[2] * v[1]) ** 2
        + (u[2] * v[0] - u[0] * v[2]) ** 2
        + (u[0] * v[1] - u[1] * v[0]) ** 2
    )
    return sides, 0.5 * np.sqrt(cross2)


def triangle_quality(
    points: np.ndarray,
    triangles: np.ndarray,
    columns: list[np.ndarray] | None = None,
    edge_lengths: np.ndarray | None = None,
    triangle_edges: np.ndarray | None = None,
) -> TriangleQuality:
    """Areas, smallest angles (degrees) and aspect ratios of all triangles at once.

    The smallest angle lies opposite the shortest side and is at most 60°, so it
    is ``arcsin(2 A / (b c))`` with b, c the two longer sides (accurate for
    slivers, where the law of cosines loses digits). The aspect ratio is
    l_max (l_0 + l_1 + l_2) / (4 √3 A): 1 for an equilateral triangle, growing
    without bound as a triangle flattens.

    Parameters
    ----------
    points : (V, 2) or (V, 3) float64
    triangles : (T, 3) int
    columns : list of (V,) float64, optional
        Contiguous copies of the x and y columns of ``points`` and of z unless it
        is zero everywhere, to save making them again.
    edge_lengths : (E,) float64, optional
    triangle_edges : (T, 3) int, optional
        Both or neither: the mesh's edge lengths and the edge of each triangle
        side; the sides are then taken from them instead of computed again.

    Examples
    --------
    >>> pts = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> q = triangle_quality(pts, np.array([[0, 1, 2]]))
    >>> float(q.areas[0]), round(float(q.min_angles_deg[0]), 9)
    (0.5, 45.0)
    """
    points = np.asarray(points)
    triangles = np.asarray(triangles)
    n = len(triangles)
    out = TriangleQuality(np.empty(n), np.empty(n), np.empty(n))
    if columns is None:
        columns = [np.ascontiguousarray(points[:, k]) for k in range(points.shape[1])]
        if len(columns) == 3 and not columns[2].any():
            columns = columns[:2]  # z = 0 everywhere adds exact zeros: same values without it
    for lo in range(0, n, BLOCK):  # cache-sized blocks: no large temporaries
        hi = min(lo + BLOCK, n)
        sides_of = None if triangle_edges is None else triangle_edges[lo:hi]
        (l0, l1, l2), area = _sides_and_areas(columns, triangles[lo:hi], edge_lengths, sides_of)
        longest = np.maximum(np.maximum(l0, l1), l2)
        shortest = np.minimum(np.minimum(l0, l1), l2)
        perimeter = l0 + l1 + l2
        middle = perimeter - longest - shortest
        with np.errstate(invalid="ignore", divide="ignore"):
            sine = np.clip(2.0 * area / (longest * middle), 0.0, 1.0)
            np.divide(longest * perimeter, 4.0 * np.sqrt(3.0) * area, out=out.aspect_ratios[lo:hi])
        angle = np.arcsin(sine, out=sine)
        angle *= _RAD_TO_DEG
        angle[~np.isfinite(angle)] = 0.0
        out.areas[lo:hi] = area
        out.min_angles_deg[lo:hi] = angle
    return out


class QualitySummary(NamedTuple):
    """What the statistics need of the per-triangle quality: extremes and a sum."""

    min_angle_deg: float
    max_aspect_ratio: float
    area: float
    shortest_side: float
    longest_side: float


def quality_summary(
    points: np.ndarray, triangles: np.ndarray, columns: list[np.ndarray] | None = None
) -> QualitySummary:
    """Smallest angle, largest aspect ratio, total area and side range, no per-triangle arrays.

    The figures of :func:`triangle_quality` reduced block by block: the smallest
    angle is the arcsine of the smallest sine (the arcsine rises with its
    argument), taken once per block instead of once per triangle; a triangle
    whose angle is undefined (0/0) gives 0 as there. Agrees with the reductions
    of :func:`triangle_quality` to rounding (the area sum is grouped by block);
    the side range is the range of the mesh's edge lengths bit for bit (every edge is
    a side of a triangle, and a side's length is computed from the same sum of squares). All zero
    without triangles.

    Parameters
    ----------
    points : (V, 2) or (V, 3) float64
    triangles : (T, 3) int
    columns : list of (V,) float64, optional
        As for :func:`triangle_quality`.
    """
    triangles = np.asarray(triangles)
    n = len(triangles)
    if n == 0:
        return QualitySummary(0.0, 0.0, 0.0, 0.0, 0.0)
    if columns is None:
        columns = [np.ascontiguousarray(points[:, k]) for k in range(points.shape[1])]
        if len(columns) == 3 and not columns[2].any():
            columns = columns[:2]
    sine_min, aspect_max, area_sum, short, long_ = [], [], [], [], []
    for lo in range(0, n, BLOCK):
        (l0, l1, l2), area = _sides_and_areas(columns, triangles[lo : lo + BLOCK])
        longest = np.maximum(np.maximum(l0, l1), l2)
        shortest = np.minimum(np.minimum(l0, l1), l2)
        perimeter = l0 + l1 + l2
        middle = perimeter - longest - shortest
        with np.errstate(invalid="ignore", divide="ignore"):
            sine = np.clip(2.0 * area / (longest * middle), 0.0, 1.0)
            aspect = longest * perimeter
            aspect /= 4.0 * np.sqrt(3.0) * area
        sine_min.append(sine.min())  # NaN when some angle is undefined
        aspect_max.append(aspect.max())  # NaN propagates as in the per-triangle maximum
        area_sum.append(area.sum())
        short.append(shortest.min())
        long_.append(longest.max())
    smallest_sine = np.min(sine_min)
    angle = float(np.arcsin(smallest_sine)) * _RAD_TO_DEG
    return QualitySummary(
        min_angle_deg=angle if np.isfinite(angle) else 0.0,
        max_aspect_ratio=float(np.max(aspect_max)),
        area=float(np.sum(area_sum)),
        shortest_side=float(np.min(short)),
        longest_side=float(np.max(long_)),
    )

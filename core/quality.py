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


_LATTICES: dict[tuple[int, bytes], str | None] = {}


def lattice_diagonal(template_triangles: np.ndarray, nv: int) -> str | None:
    """``"BC"`` or ``"AD"`` when the triangles cut the (n + 1)² grid's cells along it.

    The grid point (a, b) is local vertex b (n + 1) + a, as in a uniform patch
    template; each cell is two counter-clockwise triangles. None otherwise.
    """
    key = (nv, template_triangles.tobytes())
    if key not in _LATTICES:
        n = round(np.sqrt(nv)) - 1
        found = None
        if (n + 1) ** 2 == nv and len(template_triangles) == 2 * n * n:
            got = _canonical(template_triangles)
            for diagonal in ("BC", "AD"):
                if np.array_equal(got, _canonical(_lattice_triangles(n, diagonal))):
                    found = diagonal
        _LATTICES[key] = found
    return _LATTICES[key]


def _canonical(triangles: np.ndarray) -> np.ndarray:
    """Triangles as rows rotated to start at their smallest vertex, sorted (orientation kept)."""
    t = np.asarray(triangles)
    t = np.take_along_axis(t, (np.argmin(t, axis=1)[:, None] + np.arange(3)) % 3, axis=1)
    return t[np.lexsort(t.T[::-1])]


def _lattice_triangles(n: int, diagonal: str) -> np.ndarray:
    """(2 n², 3) counter-clockwise triangles of the grid's cells cut along ``diagonal``."""
    b, a = np.divmod(np.arange(n * n), n)
    p00 = b * (n + 1) + a
    p10, p01, p11 = p00 + 1, p00 + n + 1, p00 + n + 2
    if diagonal == "BC":
        return np.concatenate([np.stack([p00, p10, p01], 1), np.stack([p11, p01, p10], 1)])
    return np.concatenate([np.stack([p00, p10, p11], 1), np.stack([p00, p11, p01], 1)])


def lattice_quality_summary(
    columns: list[np.ndarray], vertex_map: np.ndarray, diagonal: str
) -> QualitySummary:
    """:func:`quality_summary` of planar grid patches, from their vertices and grid edges.

    Each patch's vertices are gathered once (not three corners per triangle)
    and every grid edge, horizontal, vertical or diagonal, is measured once for
    the two triangles beside it. The side lengths and the range of sides are
    those of :func:`quality_summary` bit for bit (the same sums of squares); a
    triangle's cross product is taken between its two grid legs instead of
    from its first corner, so areas, angles and aspect ratios agree to
    rounding.

    Parameters
    ----------
    columns : list of two (V,) float64
        x and y of the points (planar meshes only).
    vertex_map : (P, (n + 1)²) int
        Global vertex of each grid point (a, b) = local vertex b (n + 1) + a of
        each patch, whose triangles cut the grid cells along ``diagonal``
        (:func:`lattice_diagonal`).
    diagonal : {"BC", "AD"}
    """
    x, y = columns
    nv = vertex_map.shape[1]
    n = round(np.sqrt(nv)) - 1
    n_patches = len(vertex_map)
    if n_patches == 0 or n < 1:
        return QualitySummary(0.0, 0.0, 0.0, 0.0, 0.0)
    per_block = max(1, BLOCK // (2 * n * n))
    sine_max_inverse, aspect_max, area_sum, short, long_ = [], [], [], [], []
    for lo in range(0, n_patches, per_block):
        vmap = vertex_map[lo : lo + per_block]
        px = x.take(vmap).reshape(-1, n + 1, n + 1)  # [patch, b, a]
        py = y.take(vmap).reshape(-1, n + 1, n + 1)
        hx, hy = px[:, :, 1:] - px[:, :, :-1], py[:, :, 1:] - py[:, :, :-1]  # (p, n + 1, n)
        vx, vy = px[:, 1:, :] - px[:, :-1, :], py[:, 1:, :] - py[:, :-1, :]  # (p, n, n + 1)
        if diagonal == "BC":  # from (a + 1, b) to (a, b + 1)
            dx, dy = px[:, 1:, :-1] - px[:, :-1, 1:], py[:, 1:, :-1] - py[:, :-1, 1:]
            legs = ((slice(None, -1), slice(None, -1)), (slice(1, None), slice(1, None)))
        else:  # from (a, b) to (a + 1, b + 1)
            dx, dy = px[:, 1:, 1:] - px[:, :-1, :-1], py[:, 1:, 1:] - py[:, :-1, :-1]
            legs = ((slice(None, -1), slice(1, None)), (slice(1, None), slice(None, -1)))
        lh = np.sqrt(hx * hx + hy * hy)
        lv = np.sqrt(vx * vx + vy * vy)
        ld = np.sqrt(dx * dx + dy * dy)
        short += [lh.min(), lv.min(), ld.min()]
        long_ += [lh.max(), lv.max(), ld.max()]
        for h_rows, v_cols in legs:  # the two triangles of every cell
            l0, l1 = lh[:, h_rows], lv[:, :, v_cols]
            twice = hx[:, h_rows] * vy[:, :, v_cols]
            twice -= hy[:, h_rows] * vx[:, :, v_cols]
            np.abs(twice, out=twice)  # twice the area
            tiny = twice < _TINY_CROSS
            if tiny.any():  # as in _sides_and_areas: the square root of the square
                twice[tiny] = np.sqrt(twice[tiny] ** 2)
            longest = np.maximum(l0, l1)
            np.maximum(longest, ld, out=longest)
            perimeter = l0 + l1
            perimeter += ld
            # longest × middle side = longest × (perimeter − longest − shortest)
            product = np.minimum(l0, l1)
            np.minimum(product, ld, out=product)
            product += longest
            np.subtract(perimeter, product, out=product)
            product *= longest
            perimeter *= longest
            with np.errstate(invalid="ignore", divide="ignore"):
                product /= twice  # 1 / sine of the smallest angle
                perimeter /= twice  # the aspect ratio times 2 √3
            sine_max_inverse.append(product.max())  # NaN when some angle is undefined
            aspect_max.append(perimeter.max())
            area_sum.append(twice.sum())
    with np.errstate(divide="ignore"):
        smallest_sine = np.clip(1.0 / np.max(sine_max_inverse), 0.0, 1.0)
    angle = float(np.arcsin(smallest_sine)) * _RAD_TO_DEG
    return QualitySummary(
        min_angle_deg=angle if np.isfinite(angle) else 0.0,
        max_aspect_ratio=float(np.max(aspect_max) / (2.0 * np.sqrt(3.0))),
        area=0.5 * float(np.sum(area_sum)),
        shortest_side=float(np.min(short)),
        longest_side=float(np.max(long_)),
    )

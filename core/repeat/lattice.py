"""Grid patches: a template that is a lattice of cells, each cut along one diagonal.

A uniform patch template (and a conforming sector's tensor template) is a grid
of (n_u + 1) x (n_v + 1) points; grid point (a, b) is local vertex
b (n_u + 1) + a, and each cell is two counter-clockwise triangles cut along
the diagonal ``"BC"`` or ``"AD"``. Copy p of the template puts grid point
(a, b) at global vertex ``vertex_map[p, b (n_u + 1) + a]``, so a patch's
vertices read as a (n_v + 1, n_u + 1) array and its grid edges are
differences of neighbouring entries (no per-corner gathers)::

    b = 2   8 --- 9 ---10 ---11         "AD" (drawn): cell (a, b) = (0, 0) is
            |   / |   / |   / |         the triangles (0, 1, 5) and (0, 5, 4)
    b = 1   4 --- 5 --- 6 --- 7         "BC": (0, 1, 4) and (5, 4, 1), cut
            |   / |   / |   / |         from (a + 1, b) to (a, b + 1)
    b = 0   0 --- 1 --- 2 --- 3
          a = 0   1     2     3         local vertex b (n_u + 1) + a, (n_u, n_v) = (3, 2)

The general paths are :func:`barymesh.quality.quality_summary` and
:func:`barymesh.invariants.inverted_or_flat` over every triangle's corners; the
functions here give the side range bit for bit and the rest to rounding
(``tests/test_core_chain_paths.py``).
"""

from __future__ import annotations

import numpy as np

from ..invariants import FLAT
from ..quality import RAD_TO_DEG, TINY_CROSS, QualitySummary
from ..topology import BLOCK

_LATTICES: dict[tuple[int, tuple[int, int] | None, bytes], str | None] = {}


def lattice_diagonal(
    template_triangles: np.ndarray, nv: int, cells: tuple[int, int] | None = None
) -> str | None:
    """``"BC"`` or ``"AD"`` when the triangles cut the grid's cells along it.

    The grid is (n + 1)² points, or (n_u + 1) x (n_v + 1) with ``cells`` =
    (n_u, n_v) (a conforming sector's :func:`barymesh.subdivision.tensor_template`);
    the grid point (a, b) is local vertex b (n_u + 1) + a, as in a uniform patch
    template; each cell is two counter-clockwise triangles. None otherwise.
    """
    key = (nv, cells, template_triangles.tobytes())
    if key not in _LATTICES:
        if cells is None:
            n = round(np.sqrt(nv)) - 1
            cells = (n, n)
        n_u, n_v = cells
        found = None
        if (n_u + 1) * (n_v + 1) == nv and len(template_triangles) == 2 * n_u * n_v:
            got = _canonical(template_triangles)
            for diagonal in ("BC", "AD"):
                if np.array_equal(got, _canonical(_lattice_triangles(n_u, diagonal, n_v))):
                    found = diagonal
        _LATTICES[key] = found
    return _LATTICES[key]


def _canonical(triangles: np.ndarray) -> np.ndarray:
    """Triangles as rows rotated to start at their smallest vertex, sorted (orientation kept)."""
    t = np.asarray(triangles)
    t = np.take_along_axis(t, (np.argmin(t, axis=1)[:, None] + np.arange(3)) % 3, axis=1)
    return t[np.lexsort(t.T[::-1])]


def _lattice_triangles(n: int, diagonal: str, n_v: int | None = None) -> np.ndarray:
    """(2 n n_v, 3) counter-clockwise triangles of the grid's cells cut along ``diagonal``.

    n cells along a (u), ``n_v`` (default n) along b (v).
    """
    b, a = np.divmod(np.arange(n * (n if n_v is None else n_v)), n)
    p00 = b * (n + 1) + a
    p10, p01, p11 = p00 + 1, p00 + n + 1, p00 + n + 2
    if diagonal == "BC":
        return np.concatenate([np.stack([p00, p10, p01], 1), np.stack([p11, p01, p10], 1)])
    return np.concatenate([np.stack([p00, p10, p11], 1), np.stack([p00, p11, p01], 1)])


def lattice_quality_summary(
    columns: list[np.ndarray],
    vertex_map: np.ndarray,
    diagonal: str,
    cells: tuple[int, int] | None = None,
) -> QualitySummary:
    """:func:`~barymesh.quality.quality_summary` of planar grid patches, from their vertices
    and grid edges.

    Each patch's vertices are gathered once (not three corners per triangle)
    and every grid edge, horizontal, vertical or diagonal, is measured once for
    the two triangles beside it. The side lengths and the range of sides are
    those of :func:`~barymesh.quality.quality_summary` bit for bit (the same sums of squares); a
    triangle's cross product is taken between its two grid legs instead of
    from its first corner, so areas, angles and aspect ratios agree to
    rounding.

    Parameters
    ----------
    columns : list of two (V,) float64
        x and y of the points (planar meshes only).
    vertex_map : (P, (n_u + 1) (n_v + 1)) int
        Global vertex of each grid point (a, b) = local vertex b (n_u + 1) + a of
        each patch, whose triangles cut the grid cells along ``diagonal``
        (:func:`lattice_diagonal`).
    diagonal : {"BC", "AD"}
    cells : (int, int), optional
        (n_u, n_v), the cells along a and along b; (n, n) by default, n + 1 the
        square root of the points per patch.
    """
    x, y = columns
    nv = vertex_map.shape[1]
    if cells is None:
        n = round(np.sqrt(nv)) - 1
        cells = (n, n)
    n_u, n_v = cells
    n_patches = len(vertex_map)
    if n_patches == 0 or min(n_u, n_v) < 1:
        return QualitySummary(0.0, 0.0, 0.0, 0.0, 0.0)
    per_block = max(1, BLOCK // (2 * n_u * n_v))
    sine_max_inverse, aspect_max, area_sum, short, long_ = [], [], [], [], []
    for lo in range(0, n_patches, per_block):
        vmap = vertex_map[lo : lo + per_block]
        px = x.take(vmap).reshape(-1, n_v + 1, n_u + 1)  # [patch, b, a]
        py = y.take(vmap).reshape(-1, n_v + 1, n_u + 1)
        hx, hy = px[:, :, 1:] - px[:, :, :-1], py[:, :, 1:] - py[:, :, :-1]  # (p, n_v + 1, n_u)
        vx, vy = px[:, 1:, :] - px[:, :-1, :], py[:, 1:, :] - py[:, :-1, :]  # (p, n_v, n_u + 1)
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
            tiny = twice < TINY_CROSS
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
    angle = float(np.arcsin(smallest_sine)) * RAD_TO_DEG
    return QualitySummary(
        min_angle_deg=angle if np.isfinite(angle) else 0.0,
        max_aspect_ratio=float(np.max(aspect_max) / (2.0 * np.sqrt(3.0))),
        area=0.5 * float(np.sum(area_sum)),
        shortest_side=float(np.min(short)),
        longest_side=float(np.max(long_)),
    )


def lattice_flagged(px: np.ndarray, py: np.ndarray, n: int, diagonal: str) -> bool:
    """Whether a triangle of these grid patches is clockwise or flat (stricter, see below).

    Each cell's two triangles have two grid edges as legs (h along a, v along
    b); the longest edge squared is at most 2 (|h|² + |v|²), which is tested
    against (a stricter test: exact indices are found by the caller).

    Parameters
    ----------
    px, py : (p, (n + 1)²) float64
        Vertex coordinates of p patches in grid order.
    """
    x = px.reshape(-1, n + 1, n + 1)  # [patch, b, a]
    y = py.reshape(-1, n + 1, n + 1)
    hx, hy = x[:, :, 1:] - x[:, :, :-1], y[:, :, 1:] - y[:, :, :-1]  # (p, n + 1, n)
    vx, vy = x[:, 1:, :] - x[:, :-1, :], y[:, 1:, :] - y[:, :-1, :]  # (p, n, n + 1)
    h2 = hx * hx
    h2 += hy * hy
    v2 = vx * vx
    v2 += vy * vy
    if diagonal == "BC":  # (a, b, c): h(j, i) x v(j, i); (d, c, b): h(j + 1, i) x v(j, i + 1)
        legs = ((slice(None, -1), slice(None, -1)), (slice(1, None), slice(1, None)))
    else:  # (a, b, d): h(j, i) x v(j, i + 1); (a, d, c): h(j + 1, i) x v(j, i)
        legs = ((slice(None, -1), slice(1, None)), (slice(1, None), slice(None, -1)))
    for h_rows, v_cols in legs:
        cross = hx[:, h_rows] * vy[:, :, v_cols]
        cross -= hy[:, h_rows] * vx[:, :, v_cols]
        bound = h2[:, h_rows] + v2[:, :, v_cols]
        bound *= 4 * FLAT
        if not (cross >= bound).all():  # NaN counts as bad
            return True
    return False

"""Level of detail for dense meshes: a triangle-index raster and the part of a mesh in view.

A view draws every triangle, edge and centroid only while that stays within a frame's
budget on a software rasteriser (:data:`DETAIL_TRIANGLES`). Above it the window shows
an *overview*: an image of the faces in which each texel holds the index of the triangle
covering its centre (:func:`triangle_raster`), coloured per triangle like the faces
would be, drawn as one textured rectangle. Its cost on screen depends on the texture's
size, not the mesh's. When the camera rests on a part holding few enough triangles
(:func:`triangles_in_rect`), the full detail of that part is drawn over the overview.

Everything here is plain numpy and safe to call from a worker thread.
"""

from __future__ import annotations

import numpy as np

#: Meshes up to this many triangles are drawn in full (faces, edges, centroids): about
#: 100 ms per frame with Mesa's llvmpipe at 1000 x 800 px on one core.
DETAIL_TRIANGLES = 40_000
#: Longest side of the overview raster (texels) when the view's size is not known.
RASTER_SIDE = 1024
#: Bounds of the raster's longest side when it follows the view (about one texel a pixel).
MIN_SIDE, MAX_SIDE = 256, 2048
#: Memory bound of one overview (texels): about 21 bytes each (colours, five colouring
#: arrays, coverage), so at most about 44 MB.
MAX_TEXELS = 1 << 21
#: Point-in-triangle tests one raster may cost (about a second in numpy); a mesh whose
#: triangles overlap many times over (paper mode at tiny angle steps) gets fewer texels.
RASTER_TESTS = 8_000_000
#: Cells of the grid :func:`overlap_counts_at` sorts rectangles into, at most about.
_GRID_CELLS = 1 << 20
#: Test points generated per block of the rasteriser (bounds its temporary memory).
_BLOCK_TESTS = 1 << 22


def raster_side(pixels: tuple[int, int] | None) -> int:
    """Longest raster side for a view of ``pixels`` = (width, height): one texel a pixel
    of the view's longer side, within [:data:`MIN_SIDE`, :data:`MAX_SIDE`]."""
    if not pixels or min(pixels) <= 0:
        return RASTER_SIDE
    return int(np.clip(max(pixels), MIN_SIDE, MAX_SIDE))


def raster_shape(
    bounds: tuple[float, float, float, float], side: int = RASTER_SIDE
) -> tuple[int, int]:
    """(rows, columns) of a raster of at most ``side`` texels covering ``bounds``."""
    x0, x1, y0, y1 = bounds
    w, h = max(x1 - x0, 1e-12), max(y1 - y0, 1e-12)
    scale = side / max(w, h)
    scale = min(scale, np.sqrt(MAX_TEXELS / (w * h)))  # the memory bound
    return max(1, int(np.ceil(h * scale))), max(1, int(np.ceil(w * scale)))


def overview_raster(
    points: np.ndarray,
    triangles: np.ndarray,
    bounds: tuple[float, float, float, float],
    side: int = RASTER_SIDE,
    tests: int = RASTER_TESTS,
) -> np.ndarray:
    """:func:`triangle_raster` over ``bounds`` with at most ``side`` texels on a side, fewer
    where that would cost more than ``tests`` point-in-triangle tests (heavy overlaps).

    Returns
    -------
    (rows, columns) int32
    """
    tri = np.asarray(triangles)
    shape = raster_shape(bounds, side)
    if len(tri) == 0:
        return np.full(shape, -1, dtype=np.int32)
    x0, x1, y0, y1 = bounds
    per_mm = shape[1] / max(x1 - x0, 1e-300)
    ext = []
    for axis in (0, 1):
        c = np.asarray(points[:, axis], dtype=np.float32)
        a, b, d = (c.take(tri[:, k]) for k in range(3))
        ext.append(
            (np.maximum(np.maximum(a, b), d) - np.minimum(np.minimum(a, b), d)).astype(np.float64)
        )
    # tests(s) ~ sum((wx s + 1)(wy s + 1)) - T for s texels per mm (a box of one texel
    # costs no test): solve tests(s) = budget
    qa = float(np.dot(ext[0], ext[1]))
    qb = float(ext[0].sum() + ext[1].sum())
    qc = -float(tests)
    cost = qa * per_mm**2 + qb * per_mm
    if cost > tests:
        s = (-qb + np.sqrt(qb * qb - 4 * qa * qc)) / (2 * qa) if qa > 0 else -qc / qb
        shape = raster_shape(bounds, max(64, int(side * s / per_mm)))
    return triangle_raster(points, tri, bounds, shape)


def triangle_raster(
    points: np.ndarray,
    triangles: np.ndarray,
    bounds: tuple[float, float, float, float],
    shape: tuple[int, int],
) -> np.ndarray:
    """The triangle covering each texel centre of a raster over ``bounds`` (seen from +z).

    Point-in-triangle tests at the texel centres, vectorised over all triangles grouped
    by the size of their texel bounding boxes, so the work is of the order of
    (triangles + covered texels, overlaps counted as often as they overlap). A triangle
    whose box holds a single texel claims that texel untested (it is smaller than a texel
    and touches it; this keeps the cost of a mesh far denser than the raster linear).
    Where triangles overlap (paper mode), one of them is shown.

    Parameters
    ----------
    points : (V, 2) or (V, 3) float
        Vertex coordinates (x, y used).
    triangles : (T, 3) int
    bounds : (x0, x1, y0, y1)
        The rectangle the raster covers; texel (0, 0) is its lower left corner.
    shape : (rows, columns)

    Returns
    -------
    (rows, columns) int32
        Triangle index per texel, -1 where no triangle covers the centre.

    Examples
    --------
    >>> pts = np.array([[0.0, 0.0], [3.0, 0.0], [0.0, 2.0], [3.0, 2.0]])
    >>> triangle_raster(pts, np.array([[0, 1, 2], [1, 3, 2]]), (0, 3, 0, 2), (2, 3))
    array([[0, 0, 1],
           [0, 1, 1]], dtype=int32)
    """
    rows, cols = int(shape[0]), int(shape[1])
    out = np.full((rows, cols), -1, dtype=np.int32)
    tri = np.asarray(triangles)
    if len(tri) == 0:
        return out
    x0, x1, y0, y1 = (float(v) for v in bounds)
    sx = cols / max(x1 - x0, 1e-300)
    sy = rows / max(y1 - y0, 1e-300)
    # vertex coordinates in texel units (texel centres at i + 0.5)
    px = ((np.asarray(points[:, 0], dtype=np.float64) - x0) * sx).astype(np.float32)
    py = ((np.asarray(points[:, 1], dtype=np.float64) - y0) * sy).astype(np.float32)
    lo_x = np.full(len(tri), np.inf, dtype=np.float32)
    hi_x = np.full(len(tri), -np.inf, dtype=np.float32)
    lo_y, hi_y = lo_x.copy(), hi_x.copy()
    for k in range(3):
        corner = tri[:, k]
        cx_, cy_ = px.take(corner), py.take(corner)
        np.minimum(lo_x, cx_, out=lo_x)
        np.maximum(hi_x, cx_, out=hi_x)
        np.minimum(lo_y, cy_, out=lo_y)
        np.maximum(hi_y, cy_, out=hi_y)
    i0 = np.maximum(np.ceil(lo_x - 0.5), 0).astype(np.int32)
    i1 = np.minimum(np.floor(hi_x - 0.5), cols - 1).astype(np.int32)
    j0 = np.maximum(np.ceil(lo_y - 0.5), 0).astype(np.int32)
    j1 = np.minimum(np.floor(hi_y - 0.5), rows - 1).astype(np.int32)
    del lo_x, hi_x, lo_y, hi_y
    w, h = i1 - i0 + 1, j1 - j0 + 1
    # a box of one texel: the triangle claims it (no test; it is smaller than a texel, and
    # its neighbours would claim the texel anyway), the rest are tested exactly
    one = (w == 1) & (h == 1)
    out[j0[one], i0[one]] = np.flatnonzero(one).astype(np.int32)
    many = np.flatnonzero((w > 0) & (h > 0) & ~one)
    if len(many) == 0:
        return out
    tm = tri[many]
    ax, bx, cx = (px.take(tm[:, k]).astype(np.float64) for k in range(3))
    ay, by, cy = (py.take(tm[:, k]).astype(np.float64) for k in range(3))
    i0, j0, w, h = i0[many], j0[many], w[many], h[many]
    # twice the signed area; degenerate triangles cover nothing
    area2 = (bx - ax) * (cy - ay) - (cx - ax) * (by - ay)
    live = area2 != 0
    sign = np.sign(area2)
    tol = 1e-6 * np.abs(area2)
    # edge functions A x + B y + C >= 0 inside (signs folded in, tolerance in C)
    coef = []
    for ux, uy, vx, vy in ((ax, ay, bx, by), (bx, by, cx, cy), (cx, cy, ax, ay)):
        coef.append(
            (-(vy - uy) * sign, (vx - ux) * sign, ((vy - uy) * ux - (vx - ux) * uy) * sign + tol)
        )
    del ax, bx, cx, ay, by, cy
    # group by the exact texel box (w, h): no test is wasted, no mask needed
    key = w.astype(np.int64) * (1 << 32) + h
    ids = np.flatnonzero(live)
    ids = ids[np.argsort(key[ids], kind="stable")]
    keys = key[ids]
    starts = np.flatnonzero(np.r_[True, keys[1:] != keys[:-1]])
    ends = np.r_[starts[1:], len(ids)]
    coef32 = [tuple(c.astype(np.float32) for c in abc) for abc in coef]
    for s, e in zip(starts, ends, strict=True):
        gw, gh = int(w[ids[s]]), int(h[ids[s]])
        dx = np.tile(np.arange(gw, dtype=np.float32), gh)
        dy = np.repeat(np.arange(gh, dtype=np.float32), gw)
        step = max(1, _BLOCK_TESTS // (gw * gh))
        for lo in range(s, e, step):
            t = ids[lo : min(e, lo + step)]
            # texel centres relative to the box corner: x = i0 + 0.5 + dx
            ox = (i0[t] + 0.5).astype(np.float32)[:, None]
            oy = (j0[t] + 0.5).astype(np.float32)[:, None]
            inside = None
            for ea, eb, ec in coef32:
                a_, b_ = ea[t, None], eb[t, None]
                value = a_ * dx + b_ * dy
                value += a_ * ox + b_ * oy + ec[t, None]
                inside = value >= 0 if inside is None else inside & (value >= 0)
            assert inside is not None  # a triangle has three edges
            rows_, cols_ = np.nonzero(inside)
            hit = t[rows_]
            out[j0[hit] + (cols_ // gw), i0[hit] + (cols_ % gw)] = many[hit]
    return out


def triangles_in_rect(
    centroids: np.ndarray, rect: tuple[float, float, float, float], margin: float = 0.0
) -> np.ndarray:
    """Indices of the triangles whose centroid lies in ``rect`` grown by ``margin``.

    Parameters
    ----------
    centroids : (T, 2) or (T, 3) float
    rect : (x0, x1, y0, y1)
    margin : float

    Returns
    -------
    (k,) int64
    """
    x0, x1, y0, y1 = rect
    c = np.asarray(centroids)
    keep = (c[:, 0] >= x0 - margin) & (c[:, 0] <= x1 + margin)
    keep &= (c[:, 1] >= y0 - margin) & (c[:, 1] <= y1 + margin)
    return np.flatnonzero(keep)


def count_grid(
    points: np.ndarray, bounds: tuple[float, float, float, float], side: int = 256
) -> np.ndarray:
    """How many of ``points`` fall in each cell of a ``side`` x ``side`` grid over ``bounds``.

    Returns
    -------
    (side, side) int32
        Row j, column i: the cell [x0 + i w, x0 + (i + 1) w) x [y0 + j h, ...).
    """
    x0, x1, y0, y1 = (float(v) for v in bounds)
    p = np.asarray(points)
    i = np.clip(((p[:, 0] - x0) * side / max(x1 - x0, 1e-300)).astype(np.int64), 0, side - 1)
    j = np.clip(((p[:, 1] - y0) * side / max(y1 - y0, 1e-300)).astype(np.int64), 0, side - 1)
    return np.bincount(j * side + i, minlength=side * side).reshape(side, side).astype(np.int32)


def count_in_rect(
    grid: np.ndarray,
    bounds: tuple[float, float, float, float],
    rect: tuple[float, float, float, float],
) -> int:
    """At least the number of points of :func:`count_grid` ``grid`` inside ``rect``: the
    cells it touches are counted whole (cost: the grid's size, not the points')."""
    rows, cols = grid.shape
    x0, x1, y0, y1 = (float(v) for v in bounds)
    a, b, c, d = rect
    i0 = int(np.clip(np.floor((a - x0) * cols / max(x1 - x0, 1e-300)), 0, cols))
    i1 = int(np.clip(np.floor((b - x0) * cols / max(x1 - x0, 1e-300)) + 1, 0, cols))
    j0 = int(np.clip(np.floor((c - y0) * rows / max(y1 - y0, 1e-300)), 0, rows))
    j1 = int(np.clip(np.floor((d - y0) * rows / max(y1 - y0, 1e-300)) + 1, 0, rows))
    return int(grid[j0:j1, i0:i1].sum())


def overlap_count_raster(
    rects: np.ndarray, bounds: tuple[float, float, float, float], shape: tuple[int, int]
) -> np.ndarray:
    """How many of the rectangles ``rects`` cover each texel centre of a raster.

    Exact at the texel centres, in O(P + texels): each rectangle adds +1/-1 at the
    corners of the texel block whose centres it covers, and two cumulative sums spread
    them.

    Parameters
    ----------
    rects : (P, 4) float
        Axis-aligned rectangles (x0, y0, x1, y1) — paper-mode patches.
    bounds : (x0, x1, y0, y1)
    shape : (rows, columns)

    Returns
    -------
    (rows, columns) int32

    Examples
    --------
    >>> overlap_count_raster(np.array([[0, 0, 2, 1], [1, 0, 3, 1]]), (0, 3, 0, 1), (1, 3))
    array([[1, 2, 1]], dtype=int32)
    """
    rows, cols = int(shape[0]), int(shape[1])
    r = np.asarray(rects, dtype=np.float64).reshape(-1, 4)
    x0, x1, y0, y1 = (float(v) for v in bounds)
    sx = cols / max(x1 - x0, 1e-300)
    sy = rows / max(y1 - y0, 1e-300)
    # texel i's centre is x0 + (i + 0.5) / sx: covered for ceil(a - 0.5) <= i <= floor(b - 0.5)
    i0 = np.clip(np.ceil((r[:, 0] - x0) * sx - 0.5), 0, cols).astype(np.int64)
    i1 = np.clip(np.floor((r[:, 2] - x0) * sx - 0.5) + 1, 0, cols).astype(np.int64)
    j0 = np.clip(np.ceil((r[:, 1] - y0) * sy - 0.5), 0, rows).astype(np.int64)
    j1 = np.clip(np.floor((r[:, 3] - y0) * sy - 0.5) + 1, 0, rows).astype(np.int64)
    ok = (i1 > i0) & (j1 > j0)
    i0, i1, j0, j1 = i0[ok], i1[ok], j0[ok], j1[ok]
    diff = np.zeros((rows + 1) * (cols + 1), dtype=np.int32)
    for jj, ii, sign in ((j0, i0, 1), (j0, i1, -1), (j1, i0, -1), (j1, i1, 1)):
        np.add.at(diff, jj * (cols + 1) + ii, sign)
    grid = diff.reshape(rows + 1, cols + 1)
    return np.cumsum(np.cumsum(grid, axis=0), axis=1)[:rows, :cols].astype(np.int32)


def overlap_counts_at(rects: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """How many of the rectangles ``rects`` cover each point of ``xy`` (sides included).

    Exact: a grid of cells a quarter of a rectangle wide; a rectangle counts at once for
    every point of the cells it covers whole, and is tested only against the points of
    the cells its sides cross (vectorised; about points x rectangles over a point x 2
    tests).

    Parameters
    ----------
    rects : (P, 4) float
        (x0, y0, x1, y1) each.
    xy : (k, 2) or (k, 3) float

    Returns
    -------
    (k,) int64

    Examples
    --------
    >>> overlap_counts_at(np.array([[0, 0, 2, 1], [1, 0, 3, 1]]),
    ...                   np.array([[0.5, 0.5], [1.5, 0.5], [5, 5]]))
    array([1, 2, 0])
    """
    r = np.asarray(rects, dtype=np.float64).reshape(-1, 4)
    xy = np.asarray(xy, dtype=np.float64)
    if len(xy) == 0 or len(r) == 0:
        return np.zeros(len(xy), dtype=np.int64)
    x, y = xy[:, 0], xy[:, 1]
    near = (r[:, 2] >= x.min()) & (r[:, 0] <= x.max()) & (r[:, 3] >= y.min()) & (r[:, 1] <= y.max())
    r = r[near]  # (a detail's few points: only the rectangles around them)
    if len(r) == 0:
        return np.zeros(len(xy), dtype=np.int64)
    cell = 0.25 * float(np.median(np.maximum(r[:, 2] - r[:, 0], r[:, 3] - r[:, 1])))
    ox, oy = min(float(x.min()), float(r[:, 0].min())), min(float(y.min()), float(r[:, 1].min()))
    wide = max(float(x.max()), float(r[:, 2].max())) - ox
    high = max(float(y.max()), float(r[:, 3].max())) - oy
    # at most about _GRID_CELLS cells (rectangles far apart on a wide plate: larger cells)
    cell = max(cell, np.sqrt(wide * high / _GRID_CELLS), 1e-9 * max(wide, high, 1.0))
    cols = int(wide // cell) + 1
    rows = int(high // cell) + 1
    ix0, ix1 = ((r[:, 0] - ox) // cell).astype(np.int64), ((r[:, 2] - ox) // cell).astype(np.int64)
    iy0, iy1 = ((r[:, 1] - oy) // cell).astype(np.int64), ((r[:, 3] - oy) // cell).astype(np.int64)
    pc = ((y - oy) // cell).astype(np.int64) * cols + ((x - ox) // cell).astype(np.int64)
    # cells strictly inside a rectangle's cell range are covered whole: a 2D difference
    # array counts them for all their points at once
    diff = np.zeros((rows + 1) * (cols + 1), dtype=np.int64)
    inner = (ix1 - ix0 >= 2) & (iy1 - iy0 >= 2)
    a0, a1, b0, b1 = ix0[inner] + 1, ix1[inner], iy0[inner] + 1, iy1[inner]
    for jj, ii, sign in ((b0, a0, 1), (b0, a1, -1), (b1, a0, -1), (b1, a1, 1)):
        diff += np.bincount(jj * (cols + 1) + ii, minlength=len(diff)) * sign
    whole = np.cumsum(np.cumsum(diff.reshape(rows + 1, cols + 1), axis=0), axis=1)
    out = whole[:rows, :cols].ravel()[pc]
    # (cell, rectangle) pairs of the cells on a rectangle's rim: tested point by point
    nx, ny = ix1 - ix0 + 1, iy1 - iy0 + 1
    per = nx * ny
    rid = np.repeat(np.arange(len(r)), per)
    k = np.arange(int(per.sum())) - np.repeat(np.cumsum(per) - per, per)
    ci, cj = ix0[rid] + k % nx[rid], iy0[rid] + k // nx[rid]
    rim = (ci == ix0[rid]) | (ci == ix1[rid]) | (cj == iy0[rid]) | (cj == iy1[rid])
    cells, rid = (cj * cols + ci)[rim], rid[rim]
    order = np.argsort(cells, kind="stable")
    cells, rid = cells[order], rid[order]
    start = np.searchsorted(cells, pc, side="left")
    count = np.searchsorted(cells, pc, side="right") - start
    point = np.repeat(np.arange(len(xy)), count)
    cand = rid[
        np.arange(int(count.sum()))
        - np.repeat(np.cumsum(count) - count, count)
        + np.repeat(start, count)
    ]
    px, py = x[point], y[point]
    inside = (r[cand, 0] <= px) & (px <= r[cand, 2]) & (r[cand, 1] <= py) & (py <= r[cand, 3])
    return out + np.bincount(point[inside], minlength=len(xy))


def decimated_lines(
    points: np.ndarray,
    pairs: np.ndarray,
    bounds: tuple[float, float, float, float],
    shape: tuple[int, int],
) -> tuple[np.ndarray, np.ndarray]:
    """Line segments snapped to the texel centres of a raster, as many as it can show.

    Each end moves to the centre of its texel; segments that shrink to a point or
    repeat another are dropped. The result's size follows the raster (at most the
    texels the lines pass through, times four), not the number of segments given.

    Parameters
    ----------
    points : (V, 2) or (V, 3) float
    pairs : (k, 2) int
    bounds : (x0, x1, y0, y1)
    shape : (rows, columns)

    Returns
    -------
    points : (m, 2) float64
        Texel centres in the units of ``points``.
    pairs : (j, 2) int64

    Examples
    --------
    >>> pts = np.array([[0.1, 0.1], [0.2, 0.1], [1.6, 0.4]])
    >>> decimated_lines(pts, np.array([[0, 1], [1, 2]]), (0, 2, 0, 1), (1, 2))
    (array([[0.5, 0.5],
           [1.5, 0.5]]), array([[0, 1]]))
    """
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    if len(pairs) == 0:
        return np.zeros((0, 2)), np.zeros((0, 2), dtype=np.int64)
    rows, cols = int(shape[0]), int(shape[1])
    x0, x1, y0, y1 = (float(v) for v in bounds)
    sx = cols / max(x1 - x0, 1e-300)
    sy = rows / max(y1 - y0, 1e-300)
    p = np.asarray(points)
    i = np.clip(((p[:, 0] - x0) * sx).astype(np.int64), 0, cols - 1)
    j = np.clip(((p[:, 1] - y0) * sy).astype(np.int64), 0, rows - 1)
    cell = j * cols + i
    ends = np.sort(cell[pairs], axis=1)
    ends = ends[ends[:, 0] != ends[:, 1]]
    if len(ends) == 0:
        return np.zeros((0, 2)), np.zeros((0, 2), dtype=np.int64)
    ends = np.unique(ends[:, 0] * (rows * cols) + ends[:, 1])
    ends = np.column_stack([ends // (rows * cols), ends % (rows * cols)])
    used, inverse = np.unique(ends, return_inverse=True)
    xy = np.column_stack([x0 + (used % cols + 0.5) / sx, y0 + (used // cols + 0.5) / sy])
    return xy, inverse.reshape(-1, 2)

"""Area of a union of axis-aligned rectangles, for the paper mode's overlap ratio.

The plane is cut by a grid whose cells are no wider and no taller than the
smallest rectangle. A rectangle then never lies strictly inside a cell: in
every cell it reaches, it covers a *quadrant* of the cell, anchored at one of
the cell's four corners (lower-left, lower-right, upper-left, upper-right)::

    +-----------+        in a cell, at abscissa x, the rectangles covering x
    |UL   |  UR |        from the bottom (lower quadrants) cover [bottom, bottom + g],
    |-----+     |        those from the top cover [top - t, top]: the covered
    |     |-----|        length is min(cell height, g + t), with g (t) the
    |LL   |  LR |        longest bottom (top) quadrant reaching x
    +-----------+

Each family's longest reach along x is a running maximum over the quadrants
sorted by where they start (right-anchored) or end (left-anchored), so one
sort of all (cell, quadrant) pieces gives the exact area: O(P log P) for P
rectangles of comparable size (the paper's patches are all congruent: about
four pieces each). Rectangles of very different sizes would need many cells
each; those sets take the slab sweep (:func:`union_area_slabs`) instead.
"""

from __future__ import annotations

import math

import numpy as np

_CHUNK = 4_000_000  # (rectangle, slab) pairs handled at once by the slab sweep
#: Most (cell, rectangle) pieces per rectangle before the slab sweep is used instead.
_PIECES_PER_RECT = 64
#: Cells are at least this much smaller than the smallest rectangle, so none fits in one.
_SHRINK = 1.0 - 1e-9


def union_area(rects: np.ndarray) -> float:
    """Exact area of the union of axis-aligned rectangles.

    Parameters
    ----------
    rects : (P, 4) float64
        (x0, y0, x1, y1) with x0 < x1, y0 < y1.

    Returns
    -------
    float
        The area, to rounding (the pieces are summed in float64).

    Examples
    --------
    >>> union_area(np.array([[0.0, 0, 2, 2], [1, 1, 3, 3]]))
    7.0
    """
    rects = np.asarray(rects, dtype=np.float64).reshape(-1, 4)
    if len(rects) == 0:
        return 0.0
    area = _union_area_grid(rects)
    return union_area_slabs(rects) if area is None else area


def _grid(lo: np.ndarray, hi: np.ndarray) -> tuple[float, float] | None:
    """Start and size of grid cells along one axis: smaller than every interval [lo, hi].

    The size has an 8-bit mantissa and the start is a multiple of its last bit,
    so every grid line ``start + k size`` is exact in float64; None when the
    intervals are too small for their coordinates to keep that so.
    """
    smallest = float(np.minimum.reduce(hi - lo)) * _SHRINK
    if not (smallest > 0 and np.isfinite(smallest)):
        return None
    unit = math.ldexp(1.0, math.frexp(smallest)[1] - 8)  # size = 128..255 units
    size = math.floor(smallest / unit) * unit
    start = math.floor(float(np.minimum.reduce(lo)) / unit) * unit
    if max(abs(start), abs(float(np.maximum.reduce(hi)))) / unit > 2.0**50:
        return None
    return start, size


def _cells(lo: np.ndarray, hi: np.ndarray, start: float, size: float):
    """First and last grid cell index touched by each interval [lo, hi] (int64)."""
    first = np.floor((lo - start) / size).astype(np.int64)
    first -= start + first * size > lo  # the division rounded up across a line
    last = np.floor((hi - start) / size).astype(np.int64)
    last += start + (last + 1) * size < hi
    return first, last


def _ranks(values: np.ndarray) -> np.ndarray:
    """(N,) int64: position of each value in ascending order (ties in index order)."""
    return _order_and_ranks(values)[1]


def _order_and_ranks(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The stable ascending order of ``values`` and :func:`_ranks` (one sort for both).

    A stable sort: on coordinates of patches placed along a curve, which come in long
    ascending and descending runs, much faster than the default quicksort.
    """
    order = values.argsort(kind="stable")
    rank = np.empty(len(values), dtype=np.int64)
    rank[order] = np.arange(len(values))
    return order, rank


def _union_area_grid(rects: np.ndarray) -> float | None:
    """The quadrant sweep of the module docstring; None when it does not apply."""
    n = len(rects)
    x0, y0, x1, y1 = (np.ascontiguousarray(rects[:, k]) for k in range(4))
    grid_x, grid_y = _grid(x0, x1), _grid(y0, y1)
    if grid_x is None or grid_y is None:
        return None
    (gx0, cx), (gy0, cy) = grid_x, grid_y
    i_first, i_last = _cells(x0, x1, gx0, cx)
    j_first, j_last = _cells(y0, y1, gy0, cy)
    n_i = i_last - i_first + 1
    n_j = j_last - j_first + 1
    count = n_i * n_j
    total = int(np.add.reduce(count))
    if total > _PIECES_PER_RECT * n + 4096:
        return None

    # one piece per (rectangle, cell), rectangle by rectangle
    rect = np.arange(n).repeat(count)
    local = np.arange(total, dtype=np.int64) - (count.cumsum() - count).repeat(count)
    di, dj = np.divmod(local, n_j[rect])
    del local
    i = i_first[rect] + di
    j = j_first[rect] + dj
    del di, dj
    left, right = gx0 + i * cx, gx0 + (i + 1) * cx  # the cell's sides
    bottom, top = gy0 + j * cy, gy0 + (j + 1) * cy
    a = np.maximum(x0[rect], left)
    b = np.minimum(x1[rect], right)
    c = np.maximum(y0[rect], bottom)
    d = np.minimum(y1[rect], top)
    keep = (b > a) & (d > c)
    from_left = a <= left  # else it reaches the right side
    from_bottom = c <= bottom  # else it reaches the top
    any_of = np.logical_or.reduce
    if any_of(keep & ~from_left & (b < right)) or any_of(keep & ~from_bottom & (d < top)):
        return None  # a piece inside a cell: rounding beat the margin
    if not np.logical_and.reduce(keep):
        rect, i, j, a, b, c, d = (v[keep] for v in (rect, i, j, a, b, c, d))
        left, right, bottom, top = (v[keep] for v in (left, right, bottom, top))
        from_left, from_bottom = from_left[keep], from_bottom[keep]

    # Sort the pieces by cell, then by where they start (right-anchored: a) or end
    # (left-anchored: b), on exact integer ranks of the rectangles' coordinates.
    x_rank = _ranks(np.concatenate([x0, x1]))  # (2n,)
    n_x = 2 * n + 1  # rank 2n: the cell's right side
    event_rank = np.where(from_left, np.where(b < right, x_rank[n + rect], 2 * n), x_rank[rect])
    i_low, j_low = np.minimum.reduce(i), np.minimum.reduce(j)
    i -= i_low
    j -= j_low
    span_j = int(np.maximum.reduce(j)) + 1
    if (float(np.maximum.reduce(i)) + 1) * span_j * n_x < 2.0**62:
        # stable: the pieces come rectangle by rectangle, in runs a merge sort finds (ties,
        # full-width pieces' events at the cell's side, add nothing whatever their order)
        order = ((i * span_j + j) * n_x + event_rank).argsort(kind="stable")
    else:  # a sparse, very fine grid: sort on the three keys
        order = np.lexsort((event_rank, j, i))
    del event_rank
    i, j = i[order], j[order]
    new_cell = np.concatenate(([True], (i[1:] != i[:-1]) | (j[1:] != j[:-1])))
    event = np.where(from_left, b, a)[order]
    # the cells' sides again, from the sorted cell indices (the same products and sums:
    # cheaper than four gathers in the new order)
    i += i_low
    j += j_low
    left, right = gx0 + i * cx, gx0 + (i + 1) * cx
    bottom, top = gy0 + j * cy, gy0 + (j + 1) * cy
    del i, j
    rect, from_left, from_bottom = rect[order], from_left[order], from_bottom[order]
    c, d = c[order], d[order]
    height = top - bottom

    m = len(event)
    starts = np.flatnonzero(new_cell)
    seg = new_cell.cumsum() - 1  # (m,) cell ordinal
    ends = np.concatenate((starts[1:], [m]))  # one past each cell's last piece
    last = np.zeros(m, dtype=bool)
    last[ends - 1] = True

    # exact reach ranks: bottom pieces by top edge d (a cell's top: rank n + 1),
    # top pieces by lower edge c descending (a cell's bottom: rank n + 1); 0: none
    full = n + 1
    y1_order, y1_rank = _order_and_ranks(y1)
    y0_order, y0_rank = _order_and_ranks(y0)
    b_rank = np.where(d < top, y1_rank[rect] + 1, full)
    t_rank = np.where(c > bottom, n - y0_rank[rect], full)
    stride = np.int64(n + 2)
    offset = seg * stride

    reverse_offset = seg[-1] - seg[::-1]
    reverse_offset *= stride

    def running(rank: np.ndarray, mask: np.ndarray, backward: bool) -> np.ndarray:
        """Largest rank of the masked pieces so far in each cell (from the end if backward)."""
        key = np.where(mask, rank, 0)
        shift = offset
        if backward:
            key = key[::-1] + reverse_offset
            shift = reverse_offset
        else:
            key += shift
        np.maximum.accumulate(key, out=key)
        key -= shift
        return key[::-1] if backward else key

    # right-anchored pieces reach x once x passes their start: prefix, this piece included;
    # left-anchored pieces reach x until x passes their end: suffix, after this piece
    from_right = ~from_left
    rb = running(b_rank, from_right & from_bottom, backward=False)
    rt = running(t_rank, from_right & ~from_bottom, backward=False)
    lb_here = running(b_rank, from_left & from_bottom, backward=True)
    lt_here = running(t_rank, from_left & ~from_bottom, backward=True)
    lb = np.zeros(m, dtype=np.int64)
    lt = np.zeros(m, dtype=np.int64)
    lb[:-1] = np.where(last[:-1], 0, lb_here[1:])
    lt[:-1] = np.where(last[:-1], 0, lt_here[1:])

    # rank -> reach length in the piece's cell: rank 0 (none) reaches nothing and rank
    # n + 1 (full) the whole cell, by infinite sentinels clipped to [0, height]; inside
    # a cell every reach grows with its rank, so the longer of two reaches is the reach
    # of the larger rank
    y1_up = np.concatenate([[-np.inf], y1[y1_order], [np.inf]])  # by bottom-piece rank
    y0_down = np.concatenate([[np.inf], y0[y0_order][::-1], [-np.inf]])  # by top-piece rank

    def covered(b_rank_: np.ndarray, t_rank_: np.ndarray, at) -> np.ndarray:
        """Length of the cell's height covered by the bottom and the top family."""
        g = y1_up.take(b_rank_)
        g -= bottom[at]
        np.clip(g, 0.0, height[at], out=g)
        t = y0_down.take(t_rank_)
        np.subtract(top[at], t, out=t)
        np.clip(t, 0.0, height[at], out=t)
        g += t
        return np.minimum(height[at], g, out=g)

    # the stretch after each piece's event, up to the next event or the cell's right side
    nxt = np.empty(m)
    nxt[:-1] = event[1:]
    nxt[last] = right[last]
    nxt -= event
    everything = slice(None)
    nxt *= covered(np.maximum(rb, lb), np.maximum(rt, lt), everything)
    area = float(np.add.reduce(nxt))
    # from each cell's left side to its first event only left-anchored pieces reach
    f = starts
    first = covered(lb_here[f], lt_here[f], f)
    area += float(np.add.reduce((event[f] - left[f]) * first))
    return area


def union_area_slabs(rects: np.ndarray) -> float:
    """Exact area of the union of axis-aligned rectangles, slab by slab.

    The plane is cut into vertical slabs at every rectangle's x-edges; in each
    slab the covered length is the union of the active y-intervals. The cost
    grows with the number of (rectangle, slab) pairs, O(P²) for heavily
    overlapping rectangles; :func:`union_area` uses it only for rectangles of
    very different sizes.

    Parameters
    ----------
    rects : (P, 4) float64
        (x0, y0, x1, y1) with x0 < x1, y0 < y1.
    """
    rects = np.asarray(rects, dtype=np.float64).reshape(-1, 4)
    if len(rects) == 0:
        return 0.0
    xs = np.unique(rects[:, [0, 2]])
    width = np.diff(xs)
    first = np.searchsorted(xs, rects[:, 0])
    stop = np.searchsorted(xs, rects[:, 2])
    y0 = rects[:, 1] - rects[:, 1].min()
    y1 = rects[:, 3] - rects[:, 1].min()
    span = float(y1.max()) * 2 + 1.0
    total = 0.0
    per_slab = max(1, int(_CHUNK // max(1, len(rects))))
    for lo in range(0, len(width), per_slab):
        hi = min(lo + per_slab, len(width))
        a = np.maximum(first, lo)
        b = np.minimum(stop, hi)
        count = np.clip(b - a, 0, None)
        rect = np.repeat(np.arange(len(rects)), count)
        before_rect = np.repeat(np.cumsum(count) - count, count)
        slab = np.repeat(a, count) + (np.arange(len(rect)) - before_rect)
        order = np.lexsort((y0[rect], slab))
        rect, slab = rect[order], slab[order]
        # shift each slab into its own band so one running maximum serves all slabs
        offset = (slab - lo) * span
        bottom = y0[rect] + offset
        top = y1[rect] + offset
        reach = np.maximum.accumulate(top)
        before = np.concatenate([[-np.inf], reach[:-1]])
        covered = np.clip(top - np.maximum(bottom, before), 0.0, None)
        length = np.bincount(slab - lo, weights=covered, minlength=hi - lo)
        total += float(length @ width[lo:hi])
    return total

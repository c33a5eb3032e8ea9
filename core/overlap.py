"""Area of a union of axis-aligned rectangles, for the paper mode's overlap ratio."""

from __future__ import annotations

import numpy as np

_CHUNK = 4_000_000  # (rectangle, slab) pairs handled at once


def union_area(rects: np.ndarray) -> float:
    """Exact area of the union of axis-aligned rectangles.

    The plane is cut into vertical slabs at every rectangle's x-edges; in
    each slab the covered length is the union of the active y-intervals.

    Parameters
    ----------
    rects : (P, 4) float64
        (x0, y0, x1, y1) with x0 < x1, y0 < y1.

    Examples
    --------
    >>> union_area(np.array([[0.0, 0, 2, 2], [1, 1, 3, 3]]))
    7.0
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

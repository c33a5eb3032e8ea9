"""What every mesh the core returns must satisfy, checked before it is returned.

A violation is a bug in the core or a geometry it cannot mesh; either way the
mesh is refused with :class:`MeshInvariantError` (a ``ValueError``) naming the
parameters, instead of reaching a solver. The checks are vectorised and
blocked (no (T, 3, 2) temporary), so they cost a fraction of the build:

- every coordinate is finite;
- every triangle is counter-clockwise seen from +z (our structures are planar)
  and not flat: its area is at least ``FLAT`` times its longest edge squared;
- in conforming mode: no two vertices at the same point and no edge on three
  or more triangles (a watertight, manifold mesh).

The functions here are the general path over plain arrays; meshes of template
copies are checked faster by :mod:`barymesh.repeat` (same answers, see
``tests/test_core_chain_paths.py``), and :func:`barymesh.check.check_mesh` chooses.
"""

from __future__ import annotations

import numpy as np

from .topology import BLOCK

#: A triangle whose area is below this fraction of its longest edge squared is flat.
FLAT = 1e-12


class MeshInvariantError(ValueError):
    """A built mesh breaks an invariant; the message names the parameters."""


def inverted_or_flat(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Triangles that are clockwise seen from +z or flatter than ``FLAT``.

    Parameters
    ----------
    points : (V, 2 or 3) float64
    triangles : (T, 3) int

    Returns
    -------
    (K,) int
        Indices of the offending triangles, ascending.

    Examples
    --------
    >>> pts = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [2.0, 0.0]])
    >>> inverted_or_flat(pts, np.array([[0, 1, 2], [0, 2, 1], [0, 1, 3]])).tolist()
    [1, 2]
    """
    x = np.ascontiguousarray(points[:, 0])
    y = np.ascontiguousarray(points[:, 1])
    bad = []
    for lo in range(0, len(triangles), BLOCK):
        tri = triangles[lo : lo + BLOCK]
        hit = np.flatnonzero(flagged(x, y, *(tri[:, c] for c in range(3))))
        if len(hit):
            bad.append(hit + lo)
    return np.concatenate(bad) if bad else np.empty(0, dtype=np.intp)


def flagged(
    x: np.ndarray, y: np.ndarray, i: np.ndarray, j: np.ndarray, k: np.ndarray
) -> np.ndarray:
    """Mask of the triangles (corners at i, j, k of x, y) that are clockwise or flat.

    Parameters
    ----------
    x, y : float64 arrays
        Coordinates, gathered with ``take`` (any shape ``i``, ``j``, ``k`` index).
    i, j, k : int arrays
        The three corners of each triangle, indices into ``x`` and ``y``.
    """
    x0, y0 = x.take(i), y.take(i)
    ux = x.take(j)
    ux -= x0
    uy = y.take(j)
    uy -= y0
    vx = x.take(k)
    vx -= x0
    vy = y.take(k)
    vy -= y0
    twice_area = ux * vy
    twice_area -= uy * vx
    # first against 2 (|u|² + |v|²) >= the longest edge squared (a stricter test, fewer
    # operations); the few triangles it flags are measured exactly
    bound = ux * ux
    bound += uy * uy
    bound += vx * vx
    bound += vy * vy
    bound *= 4 * FLAT
    flagged = ~(twice_area >= bound)  # NaN counts as bad
    if flagged.any():
        f = np.flatnonzero(flagged)
        longest = np.maximum.reduce(
            [
                ux[f] ** 2 + uy[f] ** 2,
                vx[f] ** 2 + vy[f] ** 2,
                (ux[f] - vx[f]) ** 2 + (uy[f] - vy[f]) ** 2,
            ]
        )
        flagged[f] = ~(twice_area[f] >= 2 * FLAT * longest)
    return flagged


def duplicate_vertices(points: np.ndarray, vertices: np.ndarray | None = None) -> int:
    """Number of vertices at exactly the same (x, y) as another one.

    Parameters
    ----------
    points : (V, 2 or 3) float64
    vertices : (K,) int, optional
        Only look among these vertices (for example those on the patches' sides).

    Examples
    --------
    >>> pts = np.array([[0.0, 1.0], [-0.0, 1.0], [1.0, 0.0], [-1.0, -1.0], [1.0, 1.0]])
    >>> duplicate_vertices(pts), duplicate_vertices(pts, np.array([2, 3, 4]))
    (1, 0)
    """
    points = np.asarray(points)
    if vertices is None:
        index = None
        n = len(points)
    else:
        seen = np.zeros(len(points), dtype=bool)
        seen[vertices.ravel()] = True
        index = np.flatnonzero(seen)
        n = len(index)
    if n < 2:
        return 0
    # equal points have equal bits (+ 0.0 turns -0.0 into 0.0): one integer key per point,
    # sorted fast; only when two keys agree are the points compared exactly
    x, y = (_column(points, axis, index) for axis in (0, 1))
    key = _point_keys(x, y)
    key.sort()
    if not (key[1:] == key[:-1]).any():
        return 0
    order = np.lexsort((y, x))
    sx, sy = x[order], y[order]
    return int(((sx[1:] == sx[:-1]) & (sy[1:] == sy[:-1])).sum())


def _column(points: np.ndarray, axis: int, index: np.ndarray | None) -> np.ndarray:
    """(K,) float64 coordinate ``axis`` of the points ``index`` (all if None), + 0.0."""
    if index is None:
        column = np.ascontiguousarray(points[:, axis])
    else:  # gathered straight from the rows: no copy of the whole column
        flat = points.reshape(-1) if points.flags.c_contiguous else points.ravel()
        column = flat.take(index * points.shape[1] + axis)
    column += 0.0  # -0.0 becomes 0.0 (in place: a fresh array either way)
    return column


#: An odd 64-bit multiplier (the golden ratio's bits) spreading x over the key.
_MIX = np.uint64(0x9E3779B97F4A7C15)


def _point_keys(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """(K,) uint64 keys, equal for equal points (and rarely otherwise).

    x's bits times an odd constant plus y's bits with their halves swapped: a
    sum of x's and y's bits would give (x, y) and (−x, −y) (sign bits 2⁶³ apart
    in both) the same key, so every point-symmetric ring would fall through to
    the exact comparison.
    """
    xb = x.view(np.uint64)
    yb = y.view(np.uint64)
    key = xb * _MIX
    key += (yb << np.uint64(32)) | (yb >> np.uint64(32))
    return key

"""Edge grading: node positions that crowd toward the metal's outer edges.

At a metal edge the current along it and the charge across it grow like 1/√d (d the
distance to the edge), and a uniform mesh converges at first order. The graded meshes
keep the paper's topology (a patch's primary triangles are still cut into n² sub-triangles,
the counts and the RWG table keep their shape); only the nodes along each primary edge
move, and the points inside follow them.

Along one side of a patch the nodes are ``edge_nodes(n, start, end)``: clustered toward
an end that meets a metal edge, evenly spaced toward one that does not. Each end's layer
follows a power law, node k at ``a (k/n)**GRADING_POWER`` (so the first cell shrinks as
n⁻⁴, resolving the 1/√d singularity), and joins a core of cells ``CORE_SLOPE`` times the
uniform 1/n with a continuous slope::

    uniform, n = 8   |     |     |     |     |     |     |     |     |
    edge_nodes(8)    ||    |       |       |       |       |    ||     (both ends)
    edge_nodes(8, start=True, end=False): the first half of edge_nodes(16) stretched

Inside a patch the points follow the sides by transfinite (Coons) interpolation: on the
unit square, x(u, v) = (1 − v) B(u) + v T(u) and y(u, v) = (1 − u) L(v) + u R(v) from the
nodes of the bottom, top, left and right sides; with opposite sides alike it is the
tensor grid (B(u), L(v)). Two patches sharing a side share its nodes, whatever else they
are next to, so a graded assembly is as conforming as a uniform one.

:func:`outline_sides` decides, for patches that meet side to side (a patch, the pieces of
a cross or of a square ring, the pixels of a painted grid), which ends of each side to
cluster toward: those where a straight piece of the outline meets the side across it.

This module is plain numpy and sits below :mod:`barymesh.params`.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

#: Power of the end layers of :func:`edge_nodes`: the first of n cells is about 34 / n⁴
#: of the side (chosen by the convergence benchmark: powers 3 and 4 converge alike for
#: patches, 4 a little faster near resonances; ``benchmarks/convergence.py``).
GRADING_POWER = 4.0
#: Width of the core cells against the uniform 1 / n (the end layers take the rest).
CORE_SLOPE = 1.5
#: Where the end layer meets the core, as a fraction of half the side.
_JOIN = 0.5 * (1.0 - 1.0 / CORE_SLOPE) * GRADING_POWER / (GRADING_POWER - 1.0)
_LAYER = CORE_SLOPE / (GRADING_POWER * _JOIN ** (GRADING_POWER - 1.0))

#: Sides of a patch in :data:`barymesh.subdivision.SIDES` order (bottom A→B, right B→D,
#: top C→D, left A→C), each (cluster at its start, cluster at its end): every end graded.
ALL_ENDS = ((True, True),) * 4


def _half(t: np.ndarray) -> np.ndarray:
    """The graded map of [0, 1/2] onto itself: power layer, then a straight core."""
    layer = _LAYER * t**GRADING_POWER
    core = _LAYER * _JOIN**GRADING_POWER + CORE_SLOPE * (t - _JOIN)
    return np.where(t < _JOIN, layer, core)


@lru_cache(maxsize=512)
def _nodes(n: int, start: bool, end: bool) -> np.ndarray:
    k = np.arange(n + 1)
    t = k / n
    if start and end:
        # node k and node n − k from the same half-map, so that the nodes are symmetric
        mirrored = np.minimum(k, n - k) / n
        nodes = np.where(k <= n - k, _half(mirrored), 1.0 - _half(mirrored))
    elif start:
        nodes = 2.0 * _half(t / 2.0)
    elif end:
        nodes = 1.0 - 2.0 * _half((n - k) / n / 2.0)
    else:
        nodes = t
    nodes[0], nodes[-1] = 0.0, 1.0
    nodes.flags.writeable = False
    return nodes


def edge_nodes(n: int, start: bool = True, end: bool = True) -> np.ndarray:
    """(n + 1,) float64 nodes from 0 to 1 along a side, graded toward the ends asked for.

    Parameters
    ----------
    n : int
        Segments along the side (the patch's subdivisions), >= 1.
    start, end : bool
        Cluster toward 0, toward 1. Both: symmetric (node n − k is 1 − node k); neither:
        the uniform k / n; one: the first half of ``edge_nodes(2 n)`` stretched (or its
        mirror image).

    Returns
    -------
    (n + 1,) float64, read-only
        Increasing, exactly 0.0 first and 1.0 last.

    Examples
    --------
    >>> [round(float(x), 4) for x in edge_nodes(8)]
    [0.0, 0.0083, 0.125, 0.3125, 0.5, 0.6875, 0.875, 0.9917, 1.0]
    >>> [round(float(x), 4) for x in edge_nodes(4, start=True, end=False)]
    [0.0, 0.0167, 0.25, 0.625, 1.0]
    >>> edge_nodes(4, start=False, end=False).tolist()
    [0.0, 0.25, 0.5, 0.75, 1.0]
    """
    if n < 1:
        raise ValueError(f"n={n!r} must be >= 1")
    return _nodes(int(n), bool(start), bool(end))


def first_cell(n: int) -> float:
    """The narrowest cell of any :func:`edge_nodes` of n segments, as a fraction of the side.

    The one-sided layer is the finer (it is half of a grading of 2 n).

    >>> f"{first_cell(16):.3g}"
    '6.52e-05'
    """
    return float(min(np.diff(edge_nodes(n, True, False)).min(), np.diff(edge_nodes(n)).min()))


@lru_cache(maxsize=512)
def coons_uv(
    n: int, sides: tuple[tuple[bool, bool], ...] = ALL_ENDS
) -> tuple[np.ndarray, np.ndarray]:
    """(u, v) of the (n + 1)² grid points of a graded unit square, point (a, b) at b (n + 1) + a.

    Parameters
    ----------
    n : int
        Segments along each side.
    sides : tuple of four (bool, bool)
        Bottom, right, top and left side (:data:`barymesh.subdivision.SIDES` order, each
        running toward increasing u or v): cluster at its start, at its end.

    Returns
    -------
    u, v : ((n + 1)²,) float64, read-only
        With equal opposite sides the grid is the tensor product of their nodes,
        bit for bit; otherwise the transfinite interpolation of the four sides.
    """
    bottom, right, top, left = (edge_nodes(n, *s) for s in sides)
    t = np.arange(n + 1) / n
    if sides[0] == sides[2]:
        u = np.broadcast_to(bottom[None, :], (n + 1, n + 1))
    else:
        u = (1.0 - t)[:, None] * bottom[None, :] + t[:, None] * top[None, :]
    if sides[1] == sides[3]:
        v = np.broadcast_to(left[:, None], (n + 1, n + 1))
    else:
        v = (1.0 - t)[None, :] * left[:, None] + t[None, :] * right[:, None]
    # the corners and sides exactly, whatever the interpolation rounds to
    u = np.array(u)
    v = np.array(v)
    u[0, :], u[-1, :], u[:, 0], u[:, -1] = bottom, top, 0.0, 1.0
    v[:, 0], v[:, -1], v[0, :], v[-1, :] = left, right, 0.0, 1.0
    u, v = u.ravel(), v.ravel()
    u.flags.writeable = False
    v.flags.writeable = False
    return u, v


def graded_barycentric(bary: np.ndarray, n: int) -> np.ndarray:
    """(N, 2) barycentric (s, t) of a subdivided primary triangle, graded toward its 3 edges.

    Point (i, j, k) / n (i + j + k = n) goes to (g(i/n), g(j/n), g(k/n)) normalised to
    sum 1, with g = :func:`edge_nodes` (n): on each edge (one of i, j, k zero) that is the
    edge's graded nodes, so neighbouring primaries meet node to node.

    Parameters
    ----------
    bary : (N, 2) float64
        (s, t) = (i / n, j / n) of :func:`barymesh.subdivision.uniform_subdivision`.
    n : int

    Examples
    --------
    >>> from barymesh.subdivision import uniform_subdivision
    >>> g = graded_barycentric(uniform_subdivision(4)[0], 4)
    >>> [round(float(x), 4) for x in g[:5, 0]]
    [0.0, 0.125, 0.5, 0.875, 1.0]
    """
    nodes = edge_nodes(n)
    ij = np.rint(np.asarray(bary) * n).astype(np.intp)
    k = n - ij[:, 0] - ij[:, 1]
    g = np.stack([nodes[ij[:, 0]], nodes[ij[:, 1]], nodes[k]], axis=1)
    return g[:, :2] / g.sum(axis=1, keepdims=True)


def outline_sides(
    rects: np.ndarray, neighbours: np.ndarray | None = None, tolerance: float = 0.0
) -> np.ndarray:
    """Which ends of each side of axis-aligned rectangles to grade toward.

    The rectangles meet side to side (a side is either on the outline of their union or
    shared whole by two of them). An end of a side is graded when a side of the outline
    that runs across it ends there: the nodes along the side then crowd toward that
    piece of the outline, where the current is singular. A side along a straight
    stretch of outline is not graded along itself, and a side inside the metal is
    graded only toward the outline it meets.

    Parameters
    ----------
    rects : (P, 4) float64
        (x0, y0, x1, y1) of each rectangle, x0 < x1, y0 < y1.
    neighbours : (K, 4) float64, optional
        Rectangles of metal beyond these (copies in the neighbouring cells of a periodic
        array): their sides shared with ``rects`` are not outline.
    tolerance : float
        Coordinates closer than this are one (shared corners of rectangles placed
        with rounding); 0 compares exactly.

    Returns
    -------
    (P, 4, 2) bool
        For each rectangle's bottom, right, top and left side (each running toward
        increasing x or y): grade toward its start, toward its end.

    Examples
    --------
    >>> outline_sides(np.array([[0.0, 0.0, 1.0, 1.0]]))[0].all()  # a lone patch: every end
    np.True_
    >>> s = outline_sides(np.array([[0.0, 0, 1, 1], [1, 0, 2, 1]]))  # two side by side
    >>> s[0].tolist()  # bottom and top of the left one: graded at their left ends only
    [[True, False], [True, True], [True, False], [True, True]]
    """
    rects = np.asarray(rects, dtype=np.float64).reshape(-1, 4)
    extra = np.zeros((0, 4)) if neighbours is None else np.asarray(neighbours, np.float64)
    everything = np.concatenate([rects, extra.reshape(-1, 4)])
    if len(rects) == 0:
        return np.zeros((0, 4, 2), dtype=bool)
    # integer keys of the coordinates, equal within the tolerance
    values = np.unique(everything)
    if tolerance > 0:
        group = np.concatenate([[0], np.cumsum(np.diff(values) > tolerance)])
    else:
        group = np.arange(len(values))
    key = group[np.searchsorted(values, everything)]  # (Q, 4): x0, y0, x1, y1
    x0, y0, x1, y1 = key.T
    # sides as (fixed, a, b, orientation): horizontal at y = fixed from x = a to b (0),
    # vertical at x = fixed from y = a to b (1); SIDES order per rectangle
    fixed = np.stack([y0, x1, y1, x0], axis=1)
    lo = np.stack([x0, y0, x0, y0], axis=1)
    hi = np.stack([x1, y1, x1, y1], axis=1)
    vertical = np.broadcast_to(np.array([0, 1, 0, 1]), fixed.shape)
    sides = np.stack([vertical, fixed, lo, hi], axis=-1).reshape(-1, 4)
    _, inverse, counts = np.unique(sides, axis=0, return_inverse=True, return_counts=True)
    outline = (counts[inverse.ravel()] == 1).reshape(-1, 4)  # the neighbours' count too
    # the ends of outline sides: (x, y) keys with the orientation of the side there
    ends = []
    for k in range(4):
        on = np.flatnonzero(outline[:, k])
        is_vertical = k % 2
        for end in (lo, hi):
            if is_vertical:
                ends.append(np.stack([fixed[on, k], end[on, k], np.ones(len(on), int)], 1))
            else:
                ends.append(np.stack([end[on, k], fixed[on, k], np.zeros(len(on), int)], 1))
    marks = np.unique(np.concatenate(ends), axis=0) if ends else np.zeros((0, 3), int)
    width = int(key.max()) + 1
    code = (marks[:, 0] * width + marks[:, 1]) * 2 + marks[:, 2]

    def graded(x: np.ndarray, y: np.ndarray, across: int) -> np.ndarray:
        """Whether an outline side of orientation ``across`` ends at (x, y)."""
        return np.isin((x * width + y) * 2 + across, code)

    n = len(rects)
    out = np.zeros((n, 4, 2), dtype=bool)
    for k in range(4):
        f, a, b = fixed[:n, k], lo[:n, k], hi[:n, k]
        if k % 2:  # a vertical side (x = f): graded toward horizontal outline at its ends
            out[:, k, 0], out[:, k, 1] = graded(f, a, 0), graded(f, b, 0)
        else:  # a horizontal side (y = f): toward vertical outline
            out[:, k, 0], out[:, k, 1] = graded(a, f, 1), graded(b, f, 1)
    return out

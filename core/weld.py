"""The paper's metric constraint: vertices closer than a tolerance ε are one vertex.

Points are welded when their distance is at most ε, whatever their position
relative to any rounding grid (no coordinate snapping is involved), and points
farther apart than ε are never merged: a chain of near points whose ends are
farther than ε apart is refused with an error instead of being merged.
"""

from __future__ import annotations

import numpy as np

from .topology import INDEX


class NearPointChain(ValueError):
    """A group of points joined by the tolerance whose ends are farther apart than it.

    Attributes
    ----------
    tolerance : float
        The welding distance ε (mm).
    centre : tuple of float
        (x, y) mean of the group's points (mm).
    span : float
        Distance between the group's two farthest points (mm), > ``tolerance``.
    """

    def __init__(self, tolerance: float, centre: tuple[float, float], span: float) -> None:
        self.tolerance = tolerance
        self.centre = centre
        self.span = span
        super().__init__(
            f"{self.finding}; points farther apart than the tolerance are never merged: use a "
            "smaller tolerance"
        )

    @property
    def finding(self) -> str:
        """What was found, without the advice: where the chain is and how long."""
        x, y = self.centre
        return (
            f"tolerance={self.tolerance:.6g} mm joins a chain of near points near "
            f"({x:.6g}, {y:.6g}) whose ends are {self.span:.6g} mm apart"
        )


def merge_pairs(
    n_points: int,
    pairs: np.ndarray,
    coords: np.ndarray | None = None,
    tolerance: float | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Merge points joined (transitively) by ``pairs`` into one vertex each.

    Parameters
    ----------
    n_points : int
        Number of points before merging.
    pairs : (K, 2) int
        Pairs of point indices that are the same vertex.
    coords : (n_points, d) float, optional
        With ``tolerance``: check that every merged group has all its points
        within ``tolerance`` of each other, and raise ``ValueError`` if not.
    tolerance : float, optional

    Returns
    -------
    vertex_of_point : (n_points,) int
        New vertex id of every point, numbered in order of first appearance.
    representative : (V,) int
        The first point of every vertex (use it to take the coordinates).

    Examples
    --------
    >>> ids, rep = merge_pairs(5, np.array([[3, 1], [4, 3]]))
    >>> ids.tolist(), rep.tolist()
    ([0, 1, 2, 1, 1], [0, 1, 2])
    """
    pairs = np.asarray(pairs).reshape(-1, 2)
    if len(pairs) == 0:  # nothing merged: every point is its own vertex
        return np.arange(n_points, dtype=INDEX), np.arange(n_points, dtype=INDEX)
    label = np.arange(n_points, dtype=np.int64)
    if len(pairs):
        # scipy here, not at the top: ``import barymesh`` stays light
        import scipy.sparse as sp
        from scipy.sparse.csgraph import connected_components

        nodes, inverse = np.unique(pairs, return_inverse=True)
        inverse = inverse.reshape(-1, 2)
        graph = sp.coo_matrix(
            (np.ones(len(inverse), dtype=np.int8), (inverse[:, 0], inverse[:, 1])),
            shape=(len(nodes), len(nodes)),
        )
        n_comp, comp = connected_components(graph, directed=False)
        smallest = np.full(n_comp, np.iinfo(np.int64).max)
        np.minimum.at(smallest, comp, nodes)  # nodes ascending: smallest member first
        label[nodes] = smallest[comp]
        if coords is not None and tolerance is not None:
            _check_diameters(nodes, comp, coords, tolerance)
    representative = np.flatnonzero(label == np.arange(n_points))
    new_id = np.cumsum(label == np.arange(n_points)) - 1
    return new_id[label].astype(INDEX), representative.astype(INDEX)


def _check_diameters(nodes: np.ndarray, comp: np.ndarray, coords: np.ndarray, tol: float) -> None:
    """Raise if a merged group holds two points farther apart than ``tol``.

    In O(N) memory: a group's diameter lies between its widest projection on
    any direction and that width over cos(π / 2K) for K evenly spread
    directions; only groups whose bounds straddle ``tol`` (rare) are measured
    exactly, on their convex hull.
    """
    order = np.argsort(comp, kind="stable")
    comp_sorted = comp[order]
    pts = coords[nodes[order]]
    start = np.flatnonzero(np.r_[True, comp_sorted[1:] != comp_sorted[:-1]])
    ends = np.append(start, len(pts))
    lo = np.minimum.reduceat(pts, start, axis=0)
    hi = np.maximum.reduceat(pts, start, axis=0)
    # the box's longest side is a lower bound of the diameter, its diagonal an upper one
    side = (hi - lo).max(axis=1)
    chain = np.flatnonzero(side > tol)
    if len(chain) == 0:
        suspect = np.flatnonzero(np.linalg.norm(hi - lo, axis=1) > tol)
        if len(suspect) == 0:
            return
        sizes = ends[suspect + 1] - ends[suspect]
        first = np.repeat(ends[suspect] - np.cumsum(sizes) + sizes, sizes)
        sub = pts[first + np.arange(sizes.sum())]
        sub_start = np.cumsum(sizes) - sizes
        widest = np.zeros(len(suspect))
        for phi in np.linspace(0.0, np.pi, _DIRECTIONS, endpoint=False):
            proj = sub[:, 0] * np.cos(phi) + sub[:, 1] * np.sin(phi)
            width = np.maximum.reduceat(proj, sub_start) - np.minimum.reduceat(proj, sub_start)
            np.maximum(widest, width, out=widest)
        over = widest > tol
        unsure = ~over & (widest / np.cos(np.pi / (2 * _DIRECTIONS)) > tol)
        chain = suspect[over]
        for g in suspect[unsure]:  # rare: a diameter within 0.03 % of the tolerance
            if _diameter(pts[ends[g] : ends[g + 1]]) > tol:
                chain = np.append(chain, g)
                break
        if len(chain) == 0:
            return
    g = int(chain[0])
    group = pts[ends[g] : ends[g + 1]]
    centre = group.mean(axis=0)
    raise NearPointChain(tol, (float(centre[0]), float(centre[1])), _diameter(group))


#: Directions of the projections that bound a group's diameter (within 0.03 %).
_DIRECTIONS = 64


def _diameter(points: np.ndarray) -> float:
    """Largest distance between two of the (N, 2) points, in bounded memory."""
    if len(points) > 64:
        from scipy.spatial import ConvexHull, QhullError

        try:
            points = points[ConvexHull(points).vertices]
        except QhullError:  # collinear or coincident: the extreme points along the line
            d = points - points[0]
            axis = np.argmax(np.abs(d).max(axis=0))
            points = points[[np.argmin(d[:, axis]), np.argmax(d[:, axis])]]
    best = 0.0
    for lo in range(0, len(points), 1024):
        block = points[lo : lo + 1024]
        dx = block[:, None, 0] - points[None, :, 0]
        dy = block[:, None, 1] - points[None, :, 1]
        dist = np.hypot(dx, dy)
        best = max(best, float(dist.max()))
    return best


def weld_points(coords: np.ndarray, tolerance: float) -> tuple[np.ndarray, np.ndarray]:
    """Weld arbitrary points closer than ``tolerance`` (k-d tree, any layout).

    Parameters
    ----------
    coords : (N, d) float64
    tolerance : float

    Returns
    -------
    The ``(vertex_of_point, representative)`` pair of :func:`merge_pairs`.
    """
    from scipy.spatial import cKDTree

    coords = np.asarray(coords, dtype=np.float64)
    # an unbalanced tree builds about twice as fast and finds the same pairs
    tree = cKDTree(coords, balanced_tree=False, compact_nodes=False)
    pairs = tree.query_pairs(tolerance, output_type="ndarray")
    return merge_pairs(len(coords), pairs, coords, tolerance)


def weld_lattice_patches(
    origins: np.ndarray, step: tuple[float, float], segments: int, tolerance: float
) -> tuple[np.ndarray, np.ndarray]:
    """Weld the vertices of congruent axis-aligned patches sharing one lattice.

    Every patch holds the grid points ``origin + (a sx, b sy)`` for
    a, b in 0..n, stored at local index b (n + 1) + a. A point of patch j is
    within ε of a point of patch i exactly when the offset between their
    origins is within ε of a lattice vector (p sx, q sy) with |p|, |q| <= n;
    then all their overlapping grid points pair up at that same distance.
    Candidate patches are found by the fractional parts of their origins on
    the lattice (periodic axes of a k-d tree) together with their positions
    (two more axes: origins at most n steps apart), so the cost does not grow
    with how densely the patches overlap nor with how many patches share one
    lattice (a patch array).

    Parameters
    ----------
    origins : (P, 2) float64
        Lower-left corners.
    step : (sx, sy)
        Lattice spacing (patch size / n).
    segments : int
        n.
    tolerance : float
        ε, below half the smaller step.

    Returns
    -------
    The ``(vertex_of_point, representative)`` pair of :func:`merge_pairs`, over
    the P (n + 1)² patch-local points in patch order.
    """
    origins = np.asarray(origins, dtype=np.float64)
    n = segments
    per_patch = (n + 1) ** 2
    n_points = len(origins) * per_patch
    steps = np.asarray(step, dtype=np.float64)
    scaled = origins / steps
    frac = scaled - np.floor(scaled)
    frac[frac >= 1.0] = 0.0
    radius = tolerance / np.minimum.reduce(steps) * 1.000001
    cand = _lattice_candidates(origins, frac, n * steps + tolerance, radius)
    if len(cand) == 0:
        return merge_pairs(n_points, np.empty((0, 2), dtype=np.int64))
    i, j = cand[:, 0], cand[:, 1]
    offset = origins[j] - origins[i]
    pq = np.round(offset / steps).astype(np.int64)
    residual = np.linalg.norm(offset - pq * steps, axis=1)
    ok = (residual <= tolerance) & (np.abs(pq) <= n).all(axis=1)
    i, j, pq = i[ok], j[ok], pq[ok]
    if len(i) == 0:
        return merge_pairs(n_points, np.empty((0, 2), dtype=np.int64))
    # point (a, b) of patch j is point (a + p, b + q) of patch i
    a = np.tile(np.arange(n + 1), n + 1)
    b = np.repeat(np.arange(n + 1), n + 1)
    ai = a[None, :] + pq[:, :1]
    bi = b[None, :] + pq[:, 1:]
    inside = (ai >= 0) & (ai <= n) & (bi >= 0) & (bi <= n)
    rows, local = np.nonzero(inside)
    pi = i[rows] * per_patch + bi[rows, local] * (n + 1) + ai[rows, local]
    pj = j[rows] * per_patch + local
    pairs = np.stack([pi, pj], axis=1)
    coords = np.repeat(origins, per_patch, axis=0) + np.tile(
        np.stack([a * steps[0], b * steps[1]], axis=1), (len(origins), 1)
    )
    return merge_pairs(n_points, pairs, coords, tolerance)


def _lattice_candidates(
    origins: np.ndarray, frac: np.ndarray, reach: np.ndarray, radius: float
) -> np.ndarray:
    """(K, 2) pairs of patches whose origins may differ by a lattice vector (p, q), |p|, |q| <= n.

    Chebyshev neighbours in four coordinates: the two fractional lattice
    coordinates (periodic, within ``radius``) and the origins scaled so that
    ``reach`` (n steps + ε per axis) becomes ``radius`` (not periodic: the
    box is three times wider than the data).
    """
    if len(origins) < 2:
        return np.empty((0, 2), dtype=np.int64)
    scaled = (origins - np.minimum.reduce(origins, axis=0)) / reach * radius
    pairs = _window_candidates(frac, scaled, radius * 1.000001)
    if pairs is not None:
        return pairs
    from scipy.spatial import cKDTree

    span = float(scaled.max(initial=0.0))
    box = np.array([1.0 + 1e-300, 1.0 + 1e-300, 3 * span + 1.0, 3 * span + 1.0])
    # an unbalanced tree builds faster; the pairs found are the same
    tree = cKDTree(np.concatenate([frac, scaled], axis=1), boxsize=box, balanced_tree=False)
    return tree.query_pairs(radius * 1.000001, p=np.inf, output_type="ndarray")


def _window_candidates(frac: np.ndarray, scaled: np.ndarray, r: float) -> np.ndarray | None:
    """The pairs of :func:`_lattice_candidates` by sorting on the first lattice phase.

    Origins spread along a curve (a paper ring) have phases spread over [0, 1):
    after sorting, the points within r of each one (periodically) are a short
    window, and the windows' pairs are filtered on the other three coordinates.
    Much faster than a k-d tree there; returns None when the windows hold many
    pairs (patches sharing one lattice, as in a patch array), for the tree.
    """
    # the arrays' methods and ufuncs rather than numpy's Python wrappers (np.argsort,
    # np.repeat, ...): on a ring this runs first in a build, when those are not in cache
    n = len(frac)
    order = frac[:, 0].argsort(kind="stable")
    key = frac[order, 0]
    wrap = (key <= r).nonzero()[0]  # seen again one period on
    ext_key = np.concatenate([key, key[wrap] + 1.0])
    ext_point = np.concatenate([order, order[wrap]])
    stop = ext_key.searchsorted(key + r, side="right")
    count = np.maximum(stop - np.arange(1, n + 1), 0)  # the points after each, in reach
    total = int(np.add.reduce(count))
    if total > 4 * n + 1024:
        return None
    first = (np.arange(1, n + 1) - count.cumsum() + count).repeat(count)
    a = order.repeat(count)
    b = ext_point[first + np.arange(total)]
    dy = np.abs(frac[a, 1] - frac[b, 1])
    near = (np.minimum(dy, 1.0 - dy) <= r) & (a != b)
    near &= np.logical_and.reduce(np.abs(scaled[a] - scaled[b]) <= r, axis=1)
    if not np.logical_or.reduce(near):  # the usual answer on a ring: no patches share a lattice
        return np.empty((0, 2), dtype=np.int64)
    a, b = a[near], b[near]
    return np.stack([np.minimum(a, b), np.maximum(a, b)], axis=1).astype(np.int64)

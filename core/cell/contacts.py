"""How the parts of a cell meet: overlaps, hanging vertices and corner (pinch) contacts.

All tests are vectorised over candidate pairs found with k-d trees: a part's
triangles are compared only with the other part's triangles whose bounding
boxes overlap theirs (:func:`box_pairs`).
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from ..topology import BLOCK, EdgeTopology

#: Size classes of the broad phase: boxes within a factor 2 of each other share one.
_MAX_CLASSES = 24
#: Triangles of one size class queried at once (bounds the candidate pairs in memory).
_QUERY_CHUNK = 1 << 13


def _boxes(xy: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Bounding boxes of triangles: (T, 2) lower and upper corners."""
    corners = xy[triangles]
    return corners.min(axis=1), corners.max(axis=1)


def _size_classes(half: np.ndarray, smallest: float) -> np.ndarray:
    """(T,) int class of each box: ⌈log2(its largest half side / smallest)⌉, capped."""
    size = np.maximum(half.max(axis=1), smallest)
    return np.minimum(np.ceil(np.log2(size / smallest)), _MAX_CLASSES).astype(np.intp)


def box_pairs(
    lo_a: np.ndarray, hi_a: np.ndarray, lo_b: np.ndarray, hi_b: np.ndarray, depth: float = 0.0
) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """Pairs of axis-aligned boxes of two sets that overlap by more than ``depth``.

    The broad phase of :func:`overlapping_triangles`: the boxes are sorted into size
    classes (a factor 2 apart) and each class of ``a`` is matched with each class of
    ``b`` through a k-d tree of box centres in the max norm, whose radius is the two
    classes' largest half sides: every overlapping pair is found, and a small box is
    never compared with all boxes within the largest box's reach (what one radius for
    all did, quadratic on graded meshes). Time O((n + K) log n) for K overlapping
    pairs of similar sizes, memory bounded by the chunks.

    Parameters
    ----------
    lo_a, hi_a : (Ta, 2) float
    lo_b, hi_b : (Tb, 2) float
    depth : float
        Boxes must overlap by more than this along both axes (give or take 1e-12 of the
        largest coordinate: a superset of the pairs that overlap by more).

    Yields
    ------
    (K,) int, (K,) int
        Chunks of indices (box of a, box of b); every overlapping pair once.
    """
    if not len(lo_a) or not len(lo_b):
        return
    from scipy.spatial import cKDTree  # here: ``barymesh --help`` stays quick

    centre_a, half_a = (lo_a + hi_a) / 2, (hi_a - lo_a) / 2
    centre_b, half_b = (lo_b + hi_b) / 2, (hi_b - lo_b) / 2
    # rounding slack: a pair the separating-axis test (other arithmetic) calls overlapping
    # is never dropped here, even at exactly ``depth`` (found by the fuzz)
    scale = max(float(np.abs(lo_a).max()), float(np.abs(hi_a).max()))
    scale = max(scale, float(np.abs(lo_b).max()), float(np.abs(hi_b).max()), depth)
    slack = 1e-12 * scale
    smallest = max(float(min(half_a.max(axis=1).min(), half_b.max(axis=1).min())), 1e-300)
    class_a, class_b = _size_classes(half_a, smallest), _size_classes(half_b, smallest)
    groups_b = []
    for c in np.unique(class_b):
        members = np.flatnonzero(class_b == c)
        reach = float(half_b[members].max())
        groups_b.append((members, reach, cKDTree(centre_b[members])))
    for c in np.unique(class_a):
        members_a = np.flatnonzero(class_a == c)
        reach_a = float(half_a[members_a].max())
        for lo in range(0, len(members_a), _QUERY_CHUNK):
            chunk = members_a[lo : lo + _QUERY_CHUNK]
            tree_a = cKDTree(centre_a[chunk])
            for members_b, reach_b, tree_b in groups_b:
                found = tree_a.sparse_distance_matrix(
                    tree_b, reach_a + reach_b + slack, p=np.inf, output_type="ndarray"
                )
                i = chunk[found["i"]]
                j = members_b[found["j"]]
                keep = np.all(
                    (hi_a[i] + slack > lo_b[j] + depth) & (hi_b[j] + slack > lo_a[i] + depth),
                    axis=1,
                )
                if keep.any():
                    yield i[keep], j[keep]


def _separated(a: np.ndarray, b: np.ndarray, tolerance: float) -> np.ndarray:
    """(K,) bool: triangles a[k] and b[k] ((K, 3, 2) each) share no more than ``tolerance``.

    Separating-axis theorem over the six side normals: disjoint (or touching) when
    some normal separates their projections by at least ``-tolerance``.
    """
    sides = np.concatenate([np.roll(a, -1, axis=1) - a, np.roll(b, -1, axis=1) - b], axis=1)
    normals = np.stack([-sides[..., 1], sides[..., 0]], axis=-1)  # (K, 6, 2)
    normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
    pa = np.einsum("kad,kpd->kap", normals, a)  # (K, 6, 3) projections
    pb = np.einsum("kad,kpd->kap", normals, b)
    apart = (pa.max(-1) <= pb.min(-1) + tolerance) | (pb.max(-1) <= pa.min(-1) + tolerance)
    return apart.any(axis=1)


def overlapping_triangles(
    xy_a: np.ndarray,
    tri_a: np.ndarray,
    xy_b: np.ndarray,
    tri_b: np.ndarray,
    tolerance: float,
    limit: int | None = None,
) -> np.ndarray:
    """Pairs of triangles of two meshes whose interiors overlap by more than ``tolerance``.

    Two triangles are disjoint (or only touch) when some side's normal
    separates their projections by at least ``-tolerance`` (separating-axis
    theorem); otherwise they share area. Only pairs whose bounding boxes overlap
    by more than ``tolerance`` are tested (:func:`box_pairs`).

    Parameters
    ----------
    xy_a, xy_b : (Va, 2), (Vb, 2) float64
    tri_a, tri_b : (Ta, 3), (Tb, 3) int
    tolerance : float
        Depth (mm) below which triangles count as touching, not overlapping.
    limit : int, optional
        Stop once this many pairs are found (``1``: whether any overlap); default all.

    Returns
    -------
    (K, 2) int
        (triangle of a, triangle of b) for every overlapping pair, sorted; with
        ``limit``, the first ``limit`` found (in the broad phase's order).

    Examples
    --------
    >>> sq = np.array([[0, 0], [1, 0], [0, 1], [1, 1.0]]); t = np.array([[0, 1, 2], [1, 3, 2]])
    >>> len(overlapping_triangles(sq, t, sq + [1, 0], t, 1e-9))  # side by side
    0
    >>> overlapping_triangles(sq, t, sq + [0.5, 0], t, 1e-9).tolist()
    [[0, 0], [1, 0], [1, 1]]
    """
    found: list[np.ndarray] = []
    count = 0
    lo_a, hi_a = _boxes(xy_a, tri_a)
    lo_b, hi_b = _boxes(xy_b, tri_b)
    for i, j in box_pairs(lo_a, hi_a, lo_b, hi_b, tolerance):
        for start in range(0, len(i), BLOCK):
            ii, jj = i[start : start + BLOCK], j[start : start + BLOCK]
            hit = ~_separated(xy_a[tri_a[ii]], xy_b[tri_b[jj]], tolerance)
            found.append(np.stack([ii[hit], jj[hit]], axis=1).astype(np.int64))
            count += int(hit.sum())
            if limit is not None and count >= limit:
                return np.concatenate(found)[:limit]
    pairs = np.concatenate(found) if found else np.empty((0, 2), dtype=np.int64)
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]


def hanging_vertices(
    xy: np.ndarray, edges: np.ndarray, boundary: np.ndarray, tolerance: float
) -> np.ndarray:
    """Vertices lying inside a boundary edge they are not an end of (T-junctions).

    Parameters
    ----------
    xy : (V, 2) float64
    edges : (E, 2) int
    boundary : (B,) int
        Ids of the boundary edges to test.
    tolerance : float
        Distance (mm) within which a vertex is on an edge.

    Returns
    -------
    (H, 2) int
        (edge id, vertex id) pairs.
    """
    if len(boundary) == 0:
        return np.empty((0, 2), dtype=np.int64)
    ends = edges[boundary]
    p0, p1 = xy[ends[:, 0]], xy[ends[:, 1]]
    mid = (p0 + p1) / 2
    half = np.linalg.norm(p1 - p0, axis=1).max() / 2
    candidates = np.unique(ends)
    from scipy.spatial import cKDTree

    pairs = cKDTree(mid).sparse_distance_matrix(
        cKDTree(xy[candidates]), half + tolerance, output_type="ndarray"
    )
    e = pairs["i"].astype(np.int64)
    v = candidates[pairs["j"]].astype(np.int64)
    keep = (v != ends[e, 0]) & (v != ends[e, 1])
    e, v = e[keep], v[keep]
    d = p1[e] - p0[e]
    length2 = (d * d).sum(axis=1)
    t = ((xy[v] - p0[e]) * d).sum(axis=1) / length2
    foot = p0[e] + t[:, None] * d
    dist = np.linalg.norm(xy[v] - foot, axis=1)
    margin = tolerance / np.sqrt(length2)
    on = (dist <= tolerance) & (t > margin) & (t < 1 - margin)
    return np.stack([boundary[e[on]], v[on]], axis=1)


def pinch_vertices(topology: EdgeTopology, n_vertices: int) -> np.ndarray:
    """(K,) int vertices where two pieces of metal meet at a point (corner contacts).

    A vertex on the boundary of a conforming mesh has two boundary edges; one
    with four or more is where two fans of triangles touch at a single point.
    """
    ends = topology.edges[topology.valence == 1].ravel()
    return np.flatnonzero(np.bincount(ends, minlength=n_vertices) >= 4)

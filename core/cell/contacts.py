"""How the parts of a cell meet: overlaps, hanging vertices and corner (pinch) contacts.

All tests are vectorised over candidate pairs found with k-d trees: a part's
triangles are compared only with the other part's triangles whose
circumscribing discs reach them.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ..topology import BLOCK, EdgeTopology


def _discs(xy: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Centroids (T, 2) and the largest centroid-to-corner distance of triangles (T, 3)."""
    corners = xy[triangles]
    centre = corners.mean(axis=1)
    radius = np.linalg.norm(corners - centre[:, None], axis=-1).max(initial=0.0)
    return centre, radius


def overlapping_triangles(
    xy_a: np.ndarray,
    tri_a: np.ndarray,
    xy_b: np.ndarray,
    tri_b: np.ndarray,
    tolerance: float,
) -> np.ndarray:
    """Pairs of triangles of two meshes whose interiors overlap by more than ``tolerance``.

    Two triangles are disjoint (or only touch) when some side's normal
    separates their projections by at least ``-tolerance`` (separating-axis
    theorem); otherwise they share area.

    Parameters
    ----------
    xy_a, xy_b : (Va, 2), (Vb, 2) float64
    tri_a, tri_b : (Ta, 3), (Tb, 3) int
    tolerance : float
        Depth (mm) below which triangles count as touching, not overlapping.

    Returns
    -------
    (K, 2) int
        (triangle of a, triangle of b) for every overlapping pair.

    Examples
    --------
    >>> sq = np.array([[0, 0], [1, 0], [0, 1], [1, 1.0]]); t = np.array([[0, 1, 2], [1, 3, 2]])
    >>> len(overlapping_triangles(sq, t, sq + [1, 0], t, 1e-9))  # side by side
    0
    >>> len(overlapping_triangles(sq, t, sq + [0.5, 0], t, 1e-9)) > 0
    True
    """
    if len(tri_a) == 0 or len(tri_b) == 0:
        return np.empty((0, 2), dtype=np.int64)
    ca, ra = _discs(xy_a, tri_a)
    cb, rb = _discs(xy_b, tri_b)
    pairs = cKDTree(ca).sparse_distance_matrix(cKDTree(cb), ra + rb, output_type="ndarray")
    i = pairs["i"].astype(np.int64)
    j = pairs["j"].astype(np.int64)
    hits = []
    for lo in range(0, len(i), BLOCK):
        a = xy_a[tri_a[i[lo : lo + BLOCK]]]  # (K, 3, 2)
        b = xy_b[tri_b[j[lo : lo + BLOCK]]]
        sides = np.concatenate([np.roll(a, -1, axis=1) - a, np.roll(b, -1, axis=1) - b], axis=1)
        normals = np.stack([-sides[..., 1], sides[..., 0]], axis=-1)  # (K, 6, 2)
        normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
        pa = np.einsum("kad,kpd->kap", normals, a)  # (K, 6, 3) projections
        pb = np.einsum("kad,kpd->kap", normals, b)
        apart = (pa.max(-1) <= pb.min(-1) + tolerance) | (pb.max(-1) <= pa.min(-1) + tolerance)
        hit = ~apart.any(axis=1)
        hits.append(np.flatnonzero(hit) + lo)
    hit = np.concatenate(hits) if hits else np.empty(0, dtype=np.int64)
    return np.stack([i[hit], j[hit]], axis=1)


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

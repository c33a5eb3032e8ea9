"""Per-triangle and per-edge passes of repeated meshes, compiled by numba.

Imported by :func:`barymesh.repeat.compiled.kernels` only, on the first large mesh that
asks (``import barymesh`` and small builds never load numba). Each kernel is the loop of a
numpy function of :mod:`barymesh.repeat`, which stays the reference: the same
operations on the same operands in the same order, without ``fastmath`` (no reordered
sums, no fused multiply-adds, a division by 3 kept a division), so the results are
equal bit for bit (``tests/test_core_mesh_kernels.py``). What the loops save is the
numpy path's temporaries: every corner or end gathered into an array of its own, then
added, then copied into the interleaved output; here each output value is written once.
Compiled on first call and cached on disk (``cache=True``); ``make`` compiles them
(:func:`barymesh.repeat.compiled.warm_up`).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def centroids(
    x: np.ndarray,
    y: np.ndarray,
    z: np.ndarray,
    axes: np.ndarray,
    vertex_map: np.ndarray,
    unwelded: bool,
    nv: int,
    triangles: np.ndarray,
    out: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """(P Nt, 3) barycentres of :func:`barymesh.repeat.patch_centroids`, into ``out``.

    Corner k of triangle t of patch p is global vertex ``vertex_map[p, triangles[t, k]]``
    (``p nv + triangles[t, k]`` when ``unwelded``); coordinate a is added corner by
    corner, then divided by 3, where ``axes[a]``, else 0 (a column that is zero everywhere).
    """
    n_p = vertex_map.shape[0]
    nt = triangles.shape[0]
    for p in range(n_p):
        row = p * nt
        for t in range(nt):
            i0 = triangles[t, 0]
            i1 = triangles[t, 1]
            i2 = triangles[t, 2]
            if unwelded:
                b = p * nv
                i0 += b
                i1 += b
                i2 += b
            else:
                i0 = vertex_map[p, i0]
                i1 = vertex_map[p, i1]
                i2 = vertex_map[p, i2]
            out[row + t, 0] = (x[i0] + x[i1] + x[i2]) / 3.0 if axes[0] else 0.0
            out[row + t, 1] = (y[i0] + y[i1] + y[i2]) / 3.0 if axes[1] else 0.0
            out[row + t, 2] = (z[i0] + z[i1] + z[i2]) / 3.0 if axes[2] else 0.0


@njit(cache=True, nogil=True)
def copies_lengths(
    x: np.ndarray,
    y: np.ndarray,
    z: np.ndarray,
    axes: np.ndarray,
    n_patches: int,
    nv: int,
    start: np.ndarray,
    end: np.ndarray,
    out: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Lengths of :func:`barymesh.repeat.copies.copies_lengths`, into the (P K,) ``out``.

    Segment k of copy p joins vertices p nv + ``start[k]`` and p nv + ``end[k]``; the
    squared differences of the coordinates where ``axes`` are added from 0 in axis
    order, then the square root taken.
    """
    k = start.shape[0]
    for p in range(n_patches):
        b = p * nv
        row = p * k
        for s in range(k):
            i = b + start[s]
            j = b + end[s]
            total = 0.0
            if axes[0]:
                d = x[j] - x[i]
                total += d * d
            if axes[1]:
                d = y[j] - y[i]
                total += d * d
            if axes[2]:
                d = z[j] - z[i]
                total += d * d
            out[row + s] = np.sqrt(total)


@njit(cache=True, nogil=True)
def copy_slack(
    x: np.ndarray, y: np.ndarray, z: np.ndarray, n_columns: int, nv: int
) -> float:  # pragma: no cover - compiled
    """:func:`barymesh.repeat.copies.copy_slack` of the first ``n_columns`` of x, y, z.

    The largest |(patch p's coordinate of l − of its vertex 0) − the first patch's|
    (the numpy path's max and −min of those differences), plus twice the machine
    epsilon times the largest |coordinate|; NaN when any of them is NaN.
    """
    deviation = 0.0
    extent = 0.0
    undefined = False
    eps2 = 2.0 * np.finfo(np.float64).eps
    n_p = x.shape[0] // nv
    for c in range(n_columns):
        column = x if c == 0 else (y if c == 1 else z)
        for p in range(n_p):
            b = p * nv
            origin = column[b]
            for i in range(nv):
                value = column[b + i]
                rel = (value - origin) - (column[i] - column[0])
                if np.isnan(rel) or np.isnan(value):
                    undefined = True
                rel = abs(rel)
                if rel > deviation:
                    deviation = rel
                value = abs(value)
                if value > extent:
                    extent = value
    if undefined:
        return np.nan
    return deviation + eps2 * extent


@njit(cache=True, nogil=True)
def rect_points(
    u: np.ndarray,
    v: np.ndarray,
    rects: np.ndarray,
    points: np.ndarray,
    x: np.ndarray,
    y: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Template points (u, v) on the rectangles (x0, y0, wx, wy), written as a mesh's.

    Point l of patch p is x0 + u wx, y0 + v wy (the product rounded, then the sum, as
    :func:`barymesh.structures._rect_points`), into row p nv + l of ``points`` (z = 0)
    and of the columns ``x`` and ``y``.
    """
    nv = u.shape[0]
    for p in range(rects.shape[0]):
        x0 = rects[p, 0]
        y0 = rects[p, 1]
        wx = rects[p, 2]
        wy = rects[p, 3]
        b = p * nv
        for i in range(nv):
            px = u[i] * wx
            px += x0
            py = v[i] * wy
            py += y0
            points[b + i, 0] = px
            points[b + i, 1] = py
            points[b + i, 2] = 0.0
            x[b + i] = px
            y[b + i] = py

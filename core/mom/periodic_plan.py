"""The per-mesh plan of the periodic fill: its tables of triangle pairs, computed once.

:func:`fill_plan` lays out what :mod:`barymesh.mom.periodic_fill` reads at every
frequency: each pair's σ code, its reduced offset from the nearest node of G_reg's Taylor
grid, the distance 1/|c| and direction of the pairs whose G is expanded, the far-rule
points of the close pairs, the near and close pairs' list, the triangles' moments and the
single-precision RWG maps, all in units of a typical triangle's size.

It takes the cell's plain arrays (the free-space geometry, σ, the reduced offsets, the
pairs near across the sides and the RWG maps), not a
:class:`~barymesh.mom.periodic_geometry.PeriodicGeometry`: the geometry keeps the plan,
so the plan sits below it, and the geometry below the fill.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .geometry import MomGeometry

#: Pairs at least this many times the larger triangle's longest edge apart (centroid to
#: the nearest image's centroid) have G expanded like G_reg; closer ones take the far rule.
IMAGE_TAYLOR_FACTOR = 4.0
#: Grid nodes per cell length at which G_reg's Taylor coefficients are tabulated.
TAYLOR_NODES = 128


@dataclass(frozen=True, eq=False)
class FillPlan:
    """The frequency-independent data of the periodic fill; pairs as [source, observation].

    Lengths are in units of ``scale`` (a typical triangle's size), so that the single
    precision moments (areas, I, J and their products) stay far from float32's
    underflow on any mesh.

    Attributes
    ----------
    scale : float
        The unit of length (m).
    node : (T, T) int32
        Flat index (G × G grid) of the Taylor node nearest each pair's reduced centroid
        offset.
    offset : (2, T, T) float32
        That offset minus the node, x and y.
    distance : (T, T) float32
        |c|, c = c_o − c_s − ρ_σ the offset from the source image's centroid.
    inverse : (T, T) float32
        1/|c| on the distant pairs, 0 on the near and close ones (G is not expanded there).
    unit : (2, T, T) float32
        c/|c| on the distant pairs, x and y; 0 elsewhere.
    sigma_code : (T, T) int16
        Row of ``sigmas`` holding each pair's σ.
    sigmas : (S, 2) int
        The distinct σ.
    close_distance : (Q², K) float32
        Far-rule point distances |r − r' − ρ_σ| of the close pairs, one of each mirrored
        pair (observation o < source s, in ``special`` after the near ones), [a Q + b, pair].
    close_weights : (6, Q², K) float32
        The flat moments' point weights: moment i = Σ_p W[i, p] G_p.
    special : (M, 2) int
        (observation, source) of every near and close pair, sorted by observation: the
        near pairs of σ = 0, those across the cell's sides, the close pairs and their
        mirrors, permuted by ``special_order``.
    special_order : (M,) int
        Their order in the concatenation of those four lists.
    special_starts : (T + 1,) int
        Where each observation triangle's pairs start in ``special``.
    areas : (T,) float32
    second : (T, 2, 2) float32
    third : (T, 2, 2, 2) float32
    reach : float
        A bound on |r − r' − ρ_σ| over every point pair.
    maps : (N, 3T) csr float32
        The real RWG maps [C | D_x | D_y] of the unknowns (their T− halves across the
        cell's sides excluded), C in units of 1/``scale``.
    folded : (C, 3T) csr float32
        The T− halves of the C unknowns across the sides (``crossing_rows``).
    crossing_rows : (C,) int
    """

    scale: float
    node: np.ndarray
    offset: np.ndarray
    distance: np.ndarray
    inverse: np.ndarray
    unit: np.ndarray
    sigma_code: np.ndarray
    sigmas: np.ndarray
    close_distance: np.ndarray
    close_weights: np.ndarray
    special: np.ndarray
    special_order: np.ndarray
    special_starts: np.ndarray
    areas: np.ndarray
    second: np.ndarray
    third: np.ndarray
    reach: float
    maps: sp.csr_matrix
    folded: sp.csr_matrix
    crossing_rows: np.ndarray


def fill_plan(
    base: MomGeometry,
    lattice: np.ndarray,
    shift: np.ndarray,
    reduced: np.ndarray,
    cross: np.ndarray,
    maps: sp.csr_matrix,
    folded: sp.csr_matrix,
) -> FillPlan:
    """The :class:`FillPlan` of a cell.

    Parameters
    ----------
    base : MomGeometry
        The cell's free-space geometry (its near pairs are those of σ = 0).
    lattice : (2, 2) float
        Rows a1, a2 (m).
    shift : (T, T, 2) int8
        σ of each pair, [observation, source].
    reduced : (T, T, 2) float
        The reduced centroid offsets in lattice coordinates, [observation, source].
    cross : (K, 2) int
        The near pairs across the cell's sides (σ ≠ 0), (observation, source).
    maps, folded : (N, 3T) sparse float
        The RWG maps (see :class:`barymesh.mom.periodic_geometry.PeriodicGeometry`).
    """
    t = base.n_triangles
    single = np.float32
    sizes = base.sizes
    h = float(np.median(sizes))  # the unit of length of the plan
    # the reduced offsets [s, o], one contiguous plane per lattice coordinate
    u, v = (np.ascontiguousarray(reduced[..., c].T) for c in range(2))
    # G_reg's Taylor nodes
    step = 1.0 / TAYLOR_NODES
    half = TAYLOR_NODES // 2 + 2  # the grid spans [−e, e]², e = half · step, just over ½
    nu, nv = np.rint(u * TAYLOR_NODES), np.rint(v * TAYLOR_NODES)  # odd, like σ
    node = (nu + half) * (2 * half + 1)
    node += nv + half
    nu *= step
    nv *= step
    np.subtract(u, nu, out=nu)  # the offset from the node, lattice coordinates
    np.subtract(v, nv, out=nv)
    offset = np.empty((2, t, t), dtype=single)  # in units of h
    for c in range(2):  # elementwise: a threaded BLAS call stalls on a busy machine
        np.multiply(nu, lattice[0, c] / h, out=offset[c], casting="same_kind")
        offset[c] += nv * (lattice[1, c] / h)
    del nu, nv
    # the offset c from the source image's centroid, [s, o]
    cx = u * lattice[0, 0]
    cx += v * lattice[1, 0]
    cy = u * lattice[0, 1]
    cy += v * lattice[1, 1]
    del u, v
    distance = np.hypot(cx, cy)
    larger = np.maximum(sizes[:, None], sizes[None, :])
    larger *= IMAGE_TAYLOR_FACTOR
    near = np.zeros((t, t), dtype=bool)  # [s, o]
    near[base.near_pairs[:, 1], base.near_pairs[:, 0]] = True
    near[cross[:, 1], cross[:, 0]] = True
    expanded = distance >= larger
    expanded &= ~near
    del larger
    inverse = np.zeros((t, t))
    np.divide(1.0, distance, out=inverse, where=expanded)
    unit = np.empty((2, t, t), dtype=single)
    np.multiply(cx, inverse, out=unit[0], casting="same_kind")
    np.multiply(cy, inverse, out=unit[1], casting="same_kind")
    del cx, cy
    # σ as a small code per pair, [s, o]
    s0, s1 = (np.ascontiguousarray(shift[..., c].T, dtype=np.int32) for c in range(2))
    low = (int(s0.min()), int(s1.min()))
    span = int(s1.max()) - low[1] + 1
    s0 -= low[0]
    s0 *= span
    s0 += s1
    s0 -= low[1]
    flat = s0.ravel()
    del s1
    present = np.flatnonzero(np.bincount(flat))
    sigmas = np.stack([present // span + low[0], present % span + low[1]], axis=1)
    lookup = np.zeros(present[-1] + 1, dtype=np.int16)
    lookup[present] = np.arange(len(present))
    code = lookup[flat]
    # close pairs, one of each mirrored pair (observation o < source s), with their points
    obs, src = np.nonzero((~expanded & ~near).T & np.triu(np.ones((t, t), dtype=bool), 1))
    close = np.stack([obs, src], axis=1)
    far = base.far
    q = far.size
    moved = far.points[src, :, :2] + (shift[obs, src].astype(np.float64) @ lattice)[:, None, :]
    delta = far.points[obs, :, None, :2] - moved[:, None, :, :]  # (K, a, b, 2)
    close_distance = np.sqrt(np.einsum("kabc,kabc->kab", delta, delta)).reshape(-1, q * q).T
    w, rho = far.weights / h**2, far.rho[:, :, :2] / h
    left = [w[obs], w[obs] * rho[obs, :, 0], w[obs] * rho[obs, :, 1]]  # (K, a)
    right = [w[src], w[src] * rho[src, :, 0], w[src] * rho[src, :, 1]]  # (K, b)

    def weights(u: np.ndarray, v: np.ndarray) -> np.ndarray:
        return (u[:, :, None] * v[:, None, :]).reshape(-1, q * q).T.astype(single)

    close_weights = np.stack(
        [
            weights(left[0], right[0]),
            weights(left[1], right[0]),
            weights(left[2], right[0]),
            weights(left[0], right[1]),
            weights(left[0], right[2]),
            weights(left[1], right[1]) + weights(left[2], right[2]),
        ]
    )
    special = np.concatenate([base.near_pairs, cross, close, close[:, ::-1]])
    special_order = np.lexsort((special[:, 1], special[:, 0]))
    special = special[special_order]
    special_starts = np.searchsorted(special[:, 0], np.arange(t + 1))
    rule = base.near
    w_near, rho_near = rule.weights, rule.rho[:, :, :2]
    second = np.einsum("tq,tqi,tqj->tij", w_near, rho_near, rho_near)
    third = np.einsum("tq,tqi,tqj,tqk->tijk", w_near, rho_near, rho_near, rho_near)
    crossing_rows = np.flatnonzero(np.diff(folded.tocsr().indptr))
    column = np.concatenate([np.full(t, h), np.ones(2 * t)])  # C in 1/h: times h

    def scaled(matrix: sp.csr_matrix) -> sp.csr_matrix:
        return sp.csr_matrix(matrix @ sp.diags(column), dtype=single)

    return FillPlan(
        scale=h,
        node=node.astype(np.int32),
        offset=offset,
        distance=np.multiply(distance, 1.0 / h, dtype=single),
        inverse=np.multiply(inverse, h, dtype=single),
        unit=unit,
        sigma_code=code.reshape(t, t).astype(np.int16),
        sigmas=sigmas,
        close_distance=(close_distance / h).astype(single),
        close_weights=close_weights,
        special=special,
        special_order=special_order,
        special_starts=special_starts,
        areas=(base.areas / h**2).astype(single),
        second=(second / h**4).astype(single),
        third=(third / h**5).astype(single),
        reach=float(distance.max() + 2.0 * sizes.max()) / h,
        maps=scaled(maps),
        folded=scaled(folded.tocsr()[crossing_rows]),
        crossing_rows=crossing_rows,
    )

"""How the EFIE matrix of an infinite array is filled: a plan per mesh
(:mod:`barymesh.mom.periodic_plan`), a fill per frequency (here).

Each triangle pair (observation o, source s) is integrated against the image of s
nearest to o, shifted by ρ_σ (see :mod:`barymesh.mom.periodic`), with the periodic
Green's function split as G_p = G + G_reg there: G = e^(−jkR)/R of that image, G_reg
the smooth rest. With c the offset from that image's centroid to o's, the pairs fall
in three kinds by |c| against the larger triangle's longest edge h:

- **near** (|c| < 1.5 h, :data:`barymesh.mom.periodic_geometry.NEAR_FACTOR`): G by the
  free-space solver's closed-form 1/R and R parts plus the near rule on the rest;
- **close** (|c| < :data:`IMAGE_TAYLOR_FACTOR` h): G by the free-space far rule
  (every point with every point, one of each mirrored pair);
- **distant**, most pairs: G, like G_reg everywhere, by a second-order Taylor
  expansion about c, integrated exactly over both triangles through their areas A,
  second moments I = ∫ρρᵀ dS and third moments J = ∫ρρρ dS about their centroids
  (∫ρ dS = 0). The moments follow from the value, gradient and Hessian at T² points
  instead of the kernel at T²Q². The error is O((h/|c|)³) for G, against the far
  rule's O((h/|c|)²) in the first moments (its three points do not integrate J):
  from 4 h on, the matrix moves by 3e-5 of its norm against the far rule's (whose
  own error, against a degree-5 rule on both triangles, is 2.4e-4).

G_reg's value, gradient and Hessian are read from a grid of step
1/:data:`TAYLOR_NODES` in lattice coordinates (the expansion is taken about the
node nearest the reduced offset), tabulated per frequency from the Chebyshev
interpolant of G_reg through n² Ewald sums, n = :data:`CHEBYSHEV_NODES` or 8 + k |a|.

The expansion runs in single precision on split real and imaginary parts (its
coefficients are real), in blocks of :data:`TAYLOR_BLOCK` observation triangles that
stay in cache; each block's moments go at once through the sparse RWG maps into
the (3T, N) right factor R of Z = [C | D_x | D_y] R, one sparse product at the end.

That assembly is the reference; by default (numba installed) the pairs' expansion,
phases and RWG products run compiled instead, in double precision on both cores
(:mod:`barymesh.mom.compiled_periodic_fill`), on the same tables. ``double=True`` runs
this module's assembly in double precision, which the compiled one equals to rounding.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Callable
from functools import cache
from typing import TYPE_CHECKING, Any

import numpy as np
import scipy.sparse as sp
from numpy.polynomial import chebyshev
from scipy.linalg import blas

from .compiled_fill import resolve_backend
from .compiled_periodic_fill import Medium, compiled_periodic_matrix, kernels
from .near_series import near_moments_series
from .operator import ETA0, SINGLE_PRECISION_PHASE, near_moments
from .periodic_geometry import PeriodicGeometry
from .periodic_green import PeriodicGreen, reciprocal_vectors
from .periodic_plan import IMAGE_TAYLOR_FACTOR as IMAGE_TAYLOR_FACTOR
from .periodic_plan import TAYLOR_NODES as TAYLOR_NODES
from .periodic_plan import FillPlan as FillPlan
from .periodic_plan import fill_plan as fill_plan

if TYPE_CHECKING:
    from .periodic_layered import LayeredKernel

#: Floquet orders with |γ_pq| under this times the smallest reciprocal vector are taken
#: out of G_reg and integrated exactly (:func:`slow_orders`); from there to twice it, a
#: fraction going smoothly to 0, so that the matrix is smooth in frequency.
SLOW_ORDERS = 0.5
#: Fewest Chebyshev nodes per lattice direction through which G_reg is interpolated (per
#: frequency); more at high frequency: 8 + k |a| (the matrix moves by 4e-6 or less).
CHEBYSHEV_NODES = 12
#: Source-observation pairs per block of the Taylor pass (its ~20 temporaries stay in cache).
TAYLOR_BLOCK = 1 << 15
#: The six moments of a pair kept on a flat screen, as rows of
#: :data:`barymesh.mom.geometry.MOMENTS` (1, ρ_x, ρ_y, ρ'_x, ρ'_y, ρ·ρ').
FLAT_MOMENTS = (0, 1, 2, 4, 5, 7)
#: The flat moments of a pair's mirror (ρ and ρ' swap).
MIRRORED = (0, 3, 4, 1, 2, 5)
#: Z = Σ_a C_a S_ab C_bᵀ over the parts a, b of [C | D_x | D_y], with S_00 = k ∫∫ρ·ρ'G −
#: 4/k ∫∫G, S_0c = k ∫∫ρ_c G, S_c0 = k ∫∫ρ'_c G, S_cc = k ∫∫G: per part a, its (b, moment).
TERMS = (
    ((0, 5), (1, 1), (2, 2)),  # a = 0: C with S_00, D_x with S_0x, D_y with S_0y
    ((0, 3), (1, 0)),  # a = x: C with S_x0, D_x with S_xx
    ((0, 4), (2, 0)),  # a = y
)
#: The entries xx, xy, yy of a symmetric 2 × 2 matrix.
UPPER = ((0, 0), (0, 1), (1, 1))


@cache
def _chebyshev_maps(n: int, extent: float, step: float) -> tuple[np.ndarray, np.ndarray]:
    """Chebyshev nodes on [−extent, extent] and the (3, G, n) maps to a grid of ``step``."""
    x = np.cos(np.pi * (np.arange(n) + 0.5) / n)  # first kind, in [−1, 1]
    to_coefficients = np.linalg.inv(chebyshev.chebvander(x, n - 1))
    half = int(round(extent / step))
    grid = step * np.arange(-half, half + 1) / extent
    eye = np.eye(n)
    maps = np.stack(
        [
            chebyshev.chebvander(grid, n - 1 - d) @ chebyshev.chebder(eye, d, axis=0)
            if d
            else chebyshev.chebvander(grid, n - 1)
            for d in range(3)
        ]
    )
    maps = maps @ to_coefficients / extent ** np.arange(3)[:, None, None]
    return extent * x, maps


def slow_orders(green: PeriodicGreen, lattice: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The Floquet orders taken out of G_reg: (S, 2) κ_pq (rad/m) and (S,) c = w 2π/(A γ_pq).

    An order near its onset (γ_pq → 0) adds c e^(−jκ_pq·ρ) to G_p with c ~ 1/γ large:
    smooth, but with derivatives too large for the Taylor expansion. Every order with
    |γ_pq| under L = :data:`SLOW_ORDERS` times the smallest reciprocal vector (every
    propagating one, and the evanescent ones that nearly propagate) is integrated
    exactly instead, as a rank-3 term of Z (:func:`slow_order_terms`).

    Between L and 2L only the fraction w of the order is taken out, w falling from 1
    to 0 as a quintic smoothstep in |γ_pq|: the split is exact for any w (what is taken
    out of G_reg is added back), so w changes only which part carries the Taylor error,
    and the matrix stays smooth in frequency. A hard switch at L made |R| jump by up to
    1e-3 where an order crossed it, which rational fits of a sweep cannot follow.
    """
    b1, b2 = reciprocal_vectors(lattice[0], lattice[1])
    limit = SLOW_ORDERS * min(np.linalg.norm(b1), np.linalg.norm(b2))
    size = np.abs(green.gamma)
    keep = size < 2.0 * limit
    s = np.clip((2.0 * limit - size[keep]) / limit, 0.0, 1.0)  # empty when limit is 0
    weight = s**3 * (10.0 - 15.0 * s + 6.0 * s * s)
    return green.kappa[keep], weight * 2.0 * np.pi / (green.area * green.gamma[keep])


def slow_order_terms(
    pg: PeriodicGeometry,
    k: float,
    kt: np.ndarray,
    kappa: np.ndarray,
    c: np.ndarray,
    c_phi: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """(N, 3S) U and V with U Vᵀ the part of Z from G = Σ c e^(−jκ·(r − r')) (SI, Ω).

    The kernel is separable: with E0 = ∫ e^(−jκ·r) dS and E1 = ∫ ρ e^(−jκ·r) dS per
    triangle (the near rule), the testing functions' Fourier moments are P_c = C E1_c +
    D_c E0 and Q = C E0, the basis functions' the same with e^(+jκ·r'), and the term is
    jkη/4π c (Σ_c P_c P̃_cᵀ − 4/k² Q Q̃ᵀ). With ``c_phi`` (on layers), G_A's coefficients
    are ``c`` and G_Φ's ``c_phi``: jkη/4π (c Σ_c P_c P̃_cᵀ − 4/k² c_Φ Q Q̃ᵀ).
    """
    rule = pg.base.near
    t = pg.base.n_triangles
    basis, test = pg.basis_maps(kt)
    phase = np.exp(-1j * np.einsum("tqc,sc->tqs", rule.points[:, :, :2], kappa))  # (T, Q, S)
    e0 = np.einsum("tq,tqs->ts", rule.weights, phase)
    e1 = np.einsum("tq,tqc,tqs->tcs", rule.weights, rule.rho[:, :, :2], phase)

    def moments(maps: sp.csr_matrix, e0: np.ndarray, e1: np.ndarray) -> list[np.ndarray]:
        cm, dx, dy = (maps[:, i * t : (i + 1) * t] for i in range(3))
        return [cm @ e1[:, 0] + dx @ e0, cm @ e1[:, 1] + dy @ e0, cm @ e0]

    p = moments(test, e0, e1)
    q = moments(basis, np.conj(e0), np.conj(e1))
    scale = 1j * k * ETA0 / (4.0 * np.pi) * c
    scale_phi = scale if c_phi is None else 1j * k * ETA0 / (4.0 * np.pi) * c_phi
    u = np.concatenate([p[0] * scale, p[1] * scale, p[2] * (scale_phi * (-4.0 / (k * k)))], axis=1)
    v = np.concatenate(q, axis=1)
    return u, v


def regular_tables(
    lattice: np.ndarray,
    green: PeriodicGreen,
    kappa: np.ndarray | None = None,
    c: np.ndarray | None = None,
) -> np.ndarray:
    """(12, G²) float32: G_reg and its x, y, xx, xy, yy derivatives on the grid, re and im.

    Rows 2d and 2d + 1 are the real and imaginary parts of derivative d. With ``kappa``
    and ``c``, the orders Σ c e^(−jκ·ρ) are taken out of G_reg first (:func:`slow_orders`).
    """
    step = 1.0 / TAYLOR_NODES
    reach = float(np.linalg.norm(lattice, axis=1).max())
    n = max(CHEBYSHEV_NODES, math.ceil(8 + abs(green.k) * reach))
    u, maps = _chebyshev_maps(n, (TAYLOR_NODES // 2 + 2) * step, step)
    points = np.stack(np.meshgrid(u, u, indexing="ij"), axis=-1).reshape(-1, 2) @ lattice
    values = green.regular(points)
    if kappa is not None and c is not None and len(c):
        values = values - np.exp(-1j * (points @ kappa.T)) @ c
    # tiny products, by einsum (a threaded BLAS call of this size stalls on a busy
    # machine), on the real and imaginary parts side by side: the maps are real, and a
    # real einsum is several times faster than a complex one
    pairs = np.ascontiguousarray(values).view(np.float64).reshape(n, n, 2)
    v0, v1, v2 = np.einsum("ijc,dkj->dikc", pairs, maps)  # (n, G, 2) each
    b0, b1, b2 = maps

    def product(b: np.ndarray, v: np.ndarray) -> np.ndarray:  # b (G, n) real @ v (n, G) complex
        return np.einsum("ij,jkc->ikc", b, v).view(np.complex128)[..., 0]

    g, gu, gv = (product(b, v) for b, v in ((b0, v0), (b1, v0), (b0, v1)))
    guu, guv, gvv = (product(b, v) for b, v in ((b2, v0), (b1, v1), (b0, v2)))
    m = np.linalg.inv(lattice)  # ∇_x = M ∇_u, H_x = M H_u Mᵀ
    out = np.empty((6,) + g.shape, dtype=np.complex128)
    out[0] = g
    for axis in range(2):
        out[1 + axis] = m[axis, 0] * gu + m[axis, 1] * gv
    for i, (a, b) in enumerate(UPPER):
        out[3 + i] = (
            m[a, 0] * m[b, 0] * guu
            + (m[a, 0] * m[b, 1] + m[a, 1] * m[b, 0]) * guv
            + m[a, 1] * m[b, 1] * gvv
        )
    flat = out.reshape(6, -1)
    return np.stack([flat.real, flat.imag], axis=1).reshape(12, -1).astype(np.float32)


def _phase(distance: np.ndarray, k: float, max_phase: float, double: bool = False) -> np.ndarray:
    """k R in float32, reduced to [−π, π] in double precision first when it can be large
    (with ``double``, k R in double precision, unreduced: the reference fill's)."""
    if double:
        return k * distance.astype(np.float64)
    if max_phase <= SINGLE_PRECISION_PHASE:
        return np.multiply(distance, np.float32(k), dtype=np.float32)
    x = k * distance.astype(np.float64)
    x -= (2.0 * np.pi) * np.rint(x * (0.5 / np.pi))
    return x.astype(np.float32)


def cross_moments(pg: PeriodicGeometry, k: complex) -> np.ndarray:
    """(K, 8) moments of G over the near pairs across the cell's sides (closed-form 1/R, R)."""
    rule = pg.base.near
    obs, src = pg.cross[:, 0], pg.cross[:, 1]
    dist = pg.cross_distances
    x = k * dist
    with np.errstate(divide="ignore", invalid="ignore"):
        smooth = (np.cos(x) - 1.0 + 0.5 * x * x - 1j * np.sin(x)) / dist
    smooth[dist == 0.0] = -1j * k
    w_o, w_s = rule.weights[obs], rule.weights[src]
    rho_o, rho_s = rule.rho[obs], rule.rho[src]  # ρ' is the same for the shifted source
    h0 = np.einsum("kab,kb->ka", smooth, w_s)
    h1 = np.einsum("kab,kb,kbc->kac", smooth, w_s, rho_s)
    out = np.empty((len(obs), 8), dtype=np.complex128)
    out[:, 0] = np.einsum("ka,ka->k", w_o, h0)
    out[:, 1:4] = np.einsum("ka,kac,ka->kc", w_o, rho_o, h0)
    out[:, 4:7] = np.einsum("ka,kac->kc", w_o, h1)
    out[:, 7] = np.einsum("ka,kac,kac->k", w_o, rho_o, h1)
    return out + pg.cross_static_inv_r - (0.5 * k * k) * pg.cross_static_r


def special_moments(
    pg: PeriodicGeometry,
    k: complex,
    charge_only: bool = False,
    double: bool = False,
    compiled: bool = False,
) -> np.ndarray:
    """(6, 2, M) float32 flat moments of G over the near and close pairs, re and im.

    ``k`` may be complex (Im k < 0, a lossy medium); with ``charge_only`` only the first
    moment, ∫∫ 1, is returned ((1, 2, M)), as the layered fill's scalar potential needs.

    In the order of ``pg.plan.special``: the near pairs by the free-space solver's
    closed forms, those across the cell's sides likewise against the shifted source,
    the close pairs by the far rule (their mirrors with ρ and ρ' swapped). In units of
    the plan's ``scale`` h: G times h, areas over h², so the six moments over h³, h⁴,
    h⁴, h⁴, h⁴ and h⁵.

    With ``double`` the close pairs' kernel and sums are taken in double precision and
    the result is float64 (the reference of the compiled fill); with ``compiled`` the
    same double-precision sums come from the compiled loop
    :func:`~barymesh.mom.periodic_fill_kernels.close_moments`, written straight into
    the plan's order (no einsum, no gather).
    """
    plan = pg.plan
    h = plan.scale
    count = 1 if charge_only else 6
    near = _near_special(pg, k, count, single=not (double or compiled))  # (count, K)
    if compiled:
        return _compiled_special(plan, k, near, count)
    real: Any = np.float64 if double else np.float32
    kh = float(np.real(k)) * h
    x = _phase(plan.close_distance, kh, kh * plan.reach, double)
    distance = plan.close_distance.astype(real)
    inverse = np.divide(real(1.0), distance, dtype=real)
    if np.imag(k):  # a lossy medium (the layered fill): e^(Im k R) on the close pairs
        inverse *= np.exp(real(np.imag(k) * h) * distance)
    kernel = np.stack([np.cos(x) * inverse, -np.sin(x) * inverse])  # (2, Q², K)
    weights = plan.close_weights[:count].astype(real)
    close = np.einsum("ipk,rpk->irk", weights, kernel).reshape(2 * count, -1)
    values = np.empty((count, 2, len(plan.special)), dtype=real)
    n_near, n_close = near.shape[1], close.shape[1]
    values[:, 0, :n_near] = near.real
    values[:, 1, :n_near] = near.imag
    flat = values.reshape(2 * count, -1)
    flat[:, n_near : n_near + n_close] = close
    flat[:, n_near + n_close :] = close[_mirrored_rows(count)]
    return np.take(flat, plan.special_order, axis=1).reshape(count, 2, -1)


def _near_special(pg: PeriodicGeometry, k: complex, count: int, single: bool) -> np.ndarray:
    """(count, K) complex moments of the near pairs and those across the sides (units of h)."""
    h = pg.plan.scale
    own = near_moments_series(pg.base, k)  # the smooth kernel's power series, when it applies
    if own is None:
        own = near_moments(pg.base, k, single=single)
    closed = [own[:, FLAT_MOMENTS]]
    if len(pg.cross):
        closed.append(cross_moments(pg, k)[:, FLAT_MOMENTS])
    near = np.concatenate(closed).T / (h ** np.array([3, 4, 4, 4, 4, 5]))[:, None]  # (6, K)
    return near[:count]


def _mirrored_rows(count: int) -> np.ndarray:
    """Rows (re, im per moment) of a close pair's moments that its mirror takes, in order."""
    return np.array([[2 * i, 2 * i + 1] for i in MIRRORED[:count]], dtype=np.intp).ravel()


_POSITIONS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _special_positions(plan: FillPlan) -> np.ndarray:
    """(M,) column of ``plan.special`` that each near, close and mirrored pair lands in."""
    if plan not in _POSITIONS:
        where = np.empty(len(plan.special_order), dtype=np.intp)
        where[plan.special_order] = np.arange(len(where))
        _POSITIONS[plan] = where
    return _POSITIONS[plan]


def _compiled_special(plan: FillPlan, k: complex, near: np.ndarray, count: int) -> np.ndarray:
    """:func:`special_moments` with ``compiled``: (count, 2, M) float64."""
    where = _special_positions(plan)
    n_near, n_close = near.shape[1], plan.close_distance.shape[1]
    out = np.empty((2 * count, len(where)))
    out[0::2, where[:n_near]] = near.real
    out[1::2, where[:n_near]] = near.imag
    kernels().close_moments(
        plan.close_distance,
        plan.close_weights[:count],
        float(np.real(k)) * plan.scale,
        float(np.imag(k)) * plan.scale,
        where[n_near : n_near + n_close],
        where[n_near + n_close :],
        _mirrored_rows(count),
        out,
    )
    return out.reshape(count, 2, -1)


def _taylor_moments(
    plan: FillPlan,
    tables: np.ndarray,
    k: complex,
    max_phase: float,
    lo: int,
    hi: int,
    charge_only: bool = False,
    double: bool = False,
) -> np.ndarray:
    """(6, 2, T, B) float32 flat moments of G + G_reg's expansions, observers lo..hi.

    With ``double``, the same formulas in double precision on the same single-precision
    plan and tables: the reference of the compiled fill
    (:mod:`barymesh.mom.periodic_fill_kernels`), which computes them so.

    ``k`` may be complex (a lossy medium, Im k < 0: the layered fill's averaged media);
    with ``charge_only`` only the first moment, ∫∫ 1, is returned ((1, 2, T, B)): what
    the scalar potential needs.

    With the expansion about c (G) or about the grid node n (G_reg, e = c − n the
    remainder), both written about c as f + ∇f·w + ½ wᵀHw with w = ρ − ρ'::

        ∫∫ 1      = A A' f + ½ (A' tr HI + A tr HI')
        ∫∫ ρ      = A' (I ∇f + ½ J:H)
        ∫∫ ρ'     = A (−I' ∇f + ½ J':H)
        ∫∫ ρ·ρ'   = −tr(I H I')

    f = g + ∇g·e + ½ eᵀHe, ∇f = ∇g + He for G_reg from the node's g, ∇g, H; G's terms are
    zero on the near and close pairs (``plan.inverse`` is 0 there).
    """
    t, b = plan.node.shape[0], hi - lo
    real: Any = np.float64 if double else np.float32  # the numpy type of the arithmetic
    # a row of 12 per pair (one cache line), then planes
    rows = np.take(tables, plan.node[:, lo:hi], axis=0)  # (T, B, 12)
    planes = np.ascontiguousarray(rows.transpose(2, 0, 1), dtype=real)
    g, gx, gy, hxx, hxy, hyy = planes.reshape(6, 2, t, b)
    ex, ey = (plan.offset[c][:, lo:hi].astype(real) for c in range(2))
    tmp = np.empty_like(g)

    def mac(acc: np.ndarray, a: np.ndarray, w: np.ndarray | float) -> None:  # acc += a w
        np.multiply(a, w, out=tmp)
        acc += tmp

    # G_reg about c: f = g + ½ (∇g + ∇f)·e, ∇f = ∇g + He
    dx = hxx * ex
    dx += gx
    mac(dx, hxy, ey)
    dy = hyy * ey
    dy += gy
    mac(dy, hxy, ex)
    value = gx + dx
    value *= ex
    np.add(gy, dy, out=tmp)
    tmp *= ey
    value += tmp
    value *= 0.5
    value += g
    # G = e^(−jkR)/R about c: G' = −(1/R + jk) G, G'' = (2/R² − k² + 2jk/R) G, and
    # ∇G = G' ĉ, H = (G'' − G'/R) ĉĉᵀ + (G'/R) I
    inv = plan.inverse[:, lo:hi].astype(real)
    distance = plan.distance[:, lo:hi].astype(real)
    kr, ki = float(np.real(k)), float(np.imag(k))
    x = _phase(distance, kr, max_phase, double)
    kk = real(kr)
    gr = np.cos(x)
    gr *= inv
    gi = np.sin(x)
    gi *= inv
    np.negative(gi, out=gi)
    if ki:  # e^(−jkR) = e^(−j Re k R) e^(Im k R): a lossy medium's decay
        decay = np.exp(real(ki) * distance)
        gr *= decay
        gi *= decay
        shifted = inv - real(ki)  # 1/R + jk = (1/R − Im k) + j Re k
    else:
        shifted = inv
    g1 = np.empty_like(g)  # G'
    np.multiply(gi, kk, out=g1[0])
    g1[0] -= shifted * gr
    np.multiply(gr, kk, out=g1[1])
    g1[1] += shifted * gi
    np.negative(g1[1], out=g1[1])
    a2 = inv * inv
    a2 *= 2.0
    if ki:  # 2/R² − k² + 2jk/R: real part 2/R² − Re k² − 2 Im k/R, imaginary 2 Re k (1/R − Im k)
        a2 -= real(kr * kr - ki * ki)
        a2 -= inv * real(2.0 * ki)
        b2 = shifted * real(2.0 * kr)
    else:
        a2 -= kk * kk
        b2 = inv * (2.0 * kk)
    p = np.empty_like(g)  # G'' − G'/R
    np.multiply(a2, gr, out=p[0])
    p[0] -= b2 * gi
    np.multiply(a2, gi, out=p[1])
    p[1] += b2 * gr
    q = g1 * inv  # G'/R
    p -= q
    value[0] += gr
    value[1] += gi
    ux, uy = (plan.unit[c][:, lo:hi].astype(real) for c in range(2))
    if not charge_only:
        mac(dx, g1, ux)
        mac(dy, g1, uy)
    hxx += q
    hyy += q
    uu = ux * ux
    mac(hxx, p, uu)
    np.multiply(ux, uy, out=uu)
    mac(hxy, p, uu)
    np.multiply(uy, uy, out=uu)
    mac(hyy, p, uu)

    areas, second, third = (a.astype(real) for a in (plan.areas, plan.second, plan.third))
    a_s, a_o = areas[:, None], areas[lo:hi]
    i_s, i_o = second[:, None], second[lo:hi]  # (T, 1, 2, 2), (B, 2, 2)
    j_s, j_o = third[:, None], third[lo:hi]
    out = np.empty((1 if charge_only else 6, 2, t, b), dtype=real)

    def hessian(acc: np.ndarray, wxx, wxy, wyy) -> None:  # acc += H:w (wxy both halves)
        mac(acc, hxx, wxx)
        mac(acc, hxy, wxy)
        mac(acc, hyy, wyy)

    # ∫∫ 1 = A A' f + ½ A' tr HI + ½ A tr HI'
    value *= a_o
    hessian(value, *(0.5 * i_o[:, p, q] * (1 + (p != q)) for p, q in UPPER))
    value *= a_s
    acc = out[0]
    np.multiply(hxx, 0.5 * i_s[..., 0, 0], out=acc)
    mac(acc, hxy, i_s[..., 0, 1])
    mac(acc, hyy, 0.5 * i_s[..., 1, 1])
    acc *= a_o
    acc += value
    if charge_only:
        return out
    for c in range(2):
        # A' (I ∇f + ½ J:H), then A (−I' ∇f + ½ J':H)
        acc = out[1 + c]
        np.multiply(dx, i_o[:, c, 0], out=acc)
        mac(acc, dy, i_o[:, c, 1])
        hessian(acc, *(0.5 * j_o[:, c, p, q] * (1 + (p != q)) for p, q in UPPER))
        acc *= a_s
        acc = out[3 + c]
        np.multiply(dx, -i_s[..., c, 0], out=acc)
        mac(acc, dy, -i_s[..., c, 1])
        hessian(acc, *(0.5 * j_s[..., c, p, q] * (1 + (p != q)) for p, q in UPPER))
        acc *= a_o
    # −tr(I H I') = −Σ_kl H_kl C_kl, C_kl = Σ_i I_ik I'_li (outer products of the two sides)
    i_s = i_s[:, 0]

    def outer(p: int, q: int) -> np.ndarray:
        return -(np.outer(i_s[:, q, 0], i_o[:, 0, p]) + np.outer(i_s[:, q, 1], i_o[:, 1, p]))

    out[5] = 0.0
    hessian(out[5], outer(0, 0), outer(0, 1) + outer(1, 0), outer(1, 1))
    return out


def _sigma_phases(pg: PeriodicGeometry, kt: np.ndarray) -> np.ndarray | None:
    """(S,) complex e^(−j k_t·ρ_σ) of each distinct σ; None when all are 1."""
    plan = pg.plan
    if not np.any(kt) or not np.any(plan.sigmas):
        return None
    rho = plan.sigmas.astype(np.float64) @ pg.lattice
    return np.exp(-1j * (rho @ kt))


def _block_phases(pg: PeriodicGeometry, kt: np.ndarray, double: bool = False) -> np.ndarray | None:
    """(2, S) float32 e^(−j k_t·ρ_σ) of each distinct σ, re and im; None when all are 1
    (float64 with ``double``)."""
    phase = _sigma_phases(pg, kt)
    if phase is None:
        return None
    return np.stack([phase.real, phase.imag]).astype(np.float64 if double else np.float32)


def _unknown_phase(pg: PeriodicGeometry, kt: np.ndarray) -> np.ndarray:
    """(C,) complex e^(−j k_t·a) of the T− halves across the sides (``plan.crossing_rows``)."""
    return np.exp(-1j * (pg.crossing[pg.plan.crossing_rows] @ kt))


def fill(
    pg: PeriodicGeometry,
    k: float,
    kt: np.ndarray,
    layered: LayeredKernel | None = None,
    backend: str | None = None,
    double: bool = False,
) -> np.ndarray:
    """The (N, N) complex128 EFIE matrix of the array at real ``k`` and Floquet phase ``kt``.

    See :func:`barymesh.mom.periodic.periodic_impedance_matrix`, which checks the input.
    With ``layered`` (:func:`barymesh.mom.periodic_layered.layered_kernel`), the sheet lies
    on dielectric layers: G_A and G_Φ are the homogeneous limits μ̃ G_p(k_A) and
    G_p(k_Φ)/ε̄, each integrated as G_p is in vacuum, plus their spectral rest in the
    Taylor tables, plus the exact harmonics.

    ``backend`` picks the assembly of the pairs' expansions (as
    :func:`barymesh.mom.operator.impedance_matrix` does): "numba" the compiled one
    (:mod:`barymesh.mom.compiled_periodic_fill`, double precision), "numpy" this module's
    (single precision, or double with ``double``: the compiled one's reference); by
    default the environment variable ``BARYMESH_FILL``, else numba when installed.
    """
    compiled = resolve_backend(backend) == "numba"
    if layered is not None:
        return _fill_layered(pg, k, kt, layered, compiled, double)
    plan = pg.plan
    h = plan.scale  # every length below in units of h: G and its derivatives times h, h², h³
    green = PeriodicGreen(
        tuple(pg.lattice[0]), tuple(pg.lattice[1]), k, (float(kt[0]), float(kt[1]))
    )
    slow_kappa, slow_c = slow_orders(green, pg.lattice)
    tables = _scaled_tables(regular_tables(pg.lattice, green, slow_kappa, slow_c), h)
    special = special_moments(pg, k, double=double, compiled=compiled)  # (6, 2, M)
    kh = k * h
    max_phase = kh * plan.reach
    if compiled:
        z = compiled_periodic_matrix(
            plan,
            pg.n_unknowns,
            _unknown_phase(pg, kt),
            Medium(tables.astype(np.float64), kh, special),
            _all_phases(pg, kt),
            4.0 / (kh * kh),
            _factor(k, h),
        )
    else:
        real: Any = np.float64 if double else np.float32  # the numpy type of the arithmetic
        phases = _block_phases(pg, kt, double)
        scale = real(4.0 / (kh * kh))

        def block_moments(lo: int, hi: int) -> np.ndarray:
            m = _taylor_moments(plan, tables, kh, max_phase, lo, hi, double=double)
            _add_special(plan, m, special, lo, hi)
            _apply_phases(plan, m, phases, lo, hi)
            m[5] -= scale * m[0]  # ρ·ρ' − 4/k² part of S_00 (over k)
            return m

        z = _assemble(pg, k, kt, block_moments, double)
    if len(slow_c):  # the orders taken out of G_reg, exactly
        u, v = slow_order_terms(pg, k, kt, slow_kappa, slow_c)
        # z += u vᵀ in place, as zᵀ (Fortran order) += v uᵀ: no N² temporary
        blas.zgemm(1.0, v, u, beta=1.0, c=z.T, trans_b=1, overwrite_c=1)
    return z


def _all_phases(pg: PeriodicGeometry, kt: np.ndarray) -> np.ndarray:
    """(S,) complex e^(−j k_t·ρ_σ), ones when there is no phase (the compiled loops')."""
    phase = _sigma_phases(pg, kt)
    return np.ones(len(pg.plan.sigmas), dtype=np.complex128) if phase is None else phase


def _factor(k: float, h: float) -> complex:
    """jkη/4π h³: Z in ohms from the moments in units of h (C/h S/k C/h)."""
    return complex(1j * k * ETA0 / (4.0 * np.pi) * h**3)


def _add_special(plan: FillPlan, m: np.ndarray, special: np.ndarray, lo: int, hi: int) -> None:
    """Add the near and close pairs' moments of the block's observers to ``m`` in place."""
    first, last = plan.special_starts[lo], plan.special_starts[hi]
    obs, src = plan.special[first:last, 0] - lo, plan.special[first:last, 1]
    m[:, :, src, obs] += special[:, :, first:last]


def _apply_phases(
    plan: FillPlan, m: np.ndarray, phases: np.ndarray | None, lo: int, hi: int
) -> None:
    """Multiply each pair's moments by its image's Floquet phase e^(−j k_t·ρ_σ), in place."""
    if phases is None:
        return
    code = plan.sigma_code[:, lo:hi]
    pr, pi = phases[0][code], phases[1][code]
    re = m[:, 0] * pr
    re -= m[:, 1] * pi
    m[:, 1] *= pr
    m[:, 1] += m[:, 0] * pi
    m[:, 0] = re


def _assemble(
    pg: PeriodicGeometry,
    k: float,
    kt: np.ndarray,
    block_moments: Callable[[int, int], np.ndarray],
    double: bool = False,
) -> np.ndarray:
    """Z from each block's (6, 2, T, B) moments, as C S Cᵀ through the RWG maps (SI, Ω)."""
    plan = pg.plan
    t, n = pg.base.n_triangles, pg.n_unknowns
    h = plan.scale
    real: Any = np.float64 if double else np.float32  # the numpy type of the arithmetic
    maps = plan.maps.astype(real)
    crossing = plan.crossing_rows
    unknown_phase = _unknown_phase(pg, kt)
    ph = [part.astype(real)[:, None] for part in (unknown_phase.real, unknown_phase.imag)]
    parts = [maps[:, c * t : (c + 1) * t] for c in range(3)]
    folded_all = plan.folded.astype(real)
    folded = [folded_all[:, c * t : (c + 1) * t] for c in range(3)]
    right = np.zeros((3 * t, 2 * n), dtype=real)  # R, re | im
    block = max(1, min(t, TAYLOR_BLOCK // max(1, t)))
    for lo in range(0, t, block):
        hi = min(t, lo + block)
        m = block_moments(lo, hi)
        for a, pairs in enumerate(TERMS):
            # R_a = Σ_b S_abᵀ C_bᵀ on the block's rows: (C_b S_ab)ᵀ, re and im
            re = sum(parts[b] @ m[i, 0] for b, i in pairs)
            im = sum(parts[b] @ m[i, 1] for b, i in pairs)
            if len(crossing):  # the T− halves across the sides carry e^(−j k_t·a)
                fr = sum(folded[b] @ m[i, 0] for b, i in pairs)
                fi = sum(folded[b] @ m[i, 1] for b, i in pairs)
                re[crossing] += ph[0] * fr - ph[1] * fi
                im[crossing] += ph[0] * fi + ph[1] * fr
            right[a * t + lo : a * t + hi, :n] = re.T
            right[a * t + lo : a * t + hi, n:] = im.T
    product = maps @ right  # (N, 2N)
    z = np.empty((n, n), dtype=np.complex128)
    z.real = product[:, :n]
    z.imag = product[:, n:]
    if len(crossing):  # the testing halves across the sides carry e^(+j k_t·a)
        extra = folded_all @ right
        z[crossing] += np.conj(unknown_phase)[:, None] * (extra[:, :n] + 1j * extra[:, n:])
    z *= _factor(k, h)  # C/h S/k C/h in SI: h³ times the scaled sum
    return z


def _scaled_tables(tables: np.ndarray, h: float) -> np.ndarray:
    """(12, G²) tables in SI → (G², 12) in units of h (G times h, ∇G h², H h³), in place."""
    tables *= (h ** np.repeat([1, 2, 2, 3, 3, 3], 2))[:, None].astype(np.float32)
    return np.ascontiguousarray(tables.T)  # (G², 12)


def _times(m: np.ndarray, c: complex) -> None:
    """Multiply (…, 2, T, B) re/im moments by the complex ``c`` in place."""
    real = m.dtype.type
    if c.imag == 0.0:
        m *= real(c.real)
        return
    re = m[..., 0, :, :] * real(c.real)
    re -= m[..., 1, :, :] * real(c.imag)
    m[..., 1, :, :] *= real(c.real)
    m[..., 1, :, :] += m[..., 0, :, :] * real(c.imag)
    m[..., 0, :, :] = re


def _split(values: np.ndarray) -> np.ndarray:
    """(6, G, G) complex → (12, G²) float32, rows re, im per derivative (as the tables)."""
    flat = values.reshape(6, -1)
    return np.stack([flat.real, flat.imag], axis=1).reshape(12, -1).astype(np.float32)


def _fill_layered(
    pg: PeriodicGeometry,
    k: float,
    kt: np.ndarray,
    layered: LayeredKernel,
    compiled: bool = False,
    double: bool = False,
) -> np.ndarray:
    """:func:`fill` on layers: G_A = μ̃ G_p(k_A) + rest, G_Φ = G_p(k_Φ)/ε̄ + rest, + exact."""
    plan = pg.plan
    h = plan.scale
    kt2 = (float(kt[0]), float(kt[1]))
    a1, a2 = tuple(pg.lattice[0]), tuple(pg.lattice[1])
    medium = layered.medium
    green_a = PeriodicGreen(a1, a2, medium.k_a, kt2)
    green_phi = PeriodicGreen(a1, a2, medium.k_phi, kt2)
    kappa = layered.exact_kappa
    step = 1.0 / TAYLOR_NODES
    half = TAYLOR_NODES // 2 + 2
    grid = step * np.arange(-half, half + 1)
    tables_a = _scaled_tables(
        regular_tables(pg.lattice, green_a, kappa, layered.taken_a)
        + _split(layered.rest_tables(grid, "a")),
        h,
    )
    tables_phi = _scaled_tables(
        regular_tables(pg.lattice, green_phi, kappa, layered.taken_phi)
        + _split(layered.rest_tables(grid, "phi")),
        h,
    )
    special_a = special_moments(pg, medium.k_a, double=double, compiled=compiled)
    special_phi = special_moments(
        pg, medium.k_phi, charge_only=True, double=double, compiled=compiled
    )
    k_ah, k_phih = medium.k_a * h, medium.k_phi * h
    if compiled:
        z = compiled_periodic_matrix(
            plan,
            pg.n_unknowns,
            _unknown_phase(pg, kt),
            Medium(tables_a.astype(np.float64), k_ah, special_a),
            _all_phases(pg, kt),
            4.0 / (k * h) ** 2,
            _factor(k, h),
            scalar=Medium(tables_phi.astype(np.float64), k_phih, special_phi),
            mu=complex(medium.mu),
            inv_eps=complex(1.0 / medium.eps),
        )
    else:
        phases = _block_phases(pg, kt, double)
        scale = (np.float64 if double else np.float32)(4.0 / (k * h) ** 2)

        def block_moments(lo: int, hi: int) -> np.ndarray:
            m = _taylor_moments(plan, tables_a, k_ah, abs(k_ah) * plan.reach, lo, hi, double=double)
            _add_special(plan, m, special_a, lo, hi)
            _apply_phases(plan, m, phases, lo, hi)
            _times(m, complex(medium.mu))
            charge = _taylor_moments(
                plan,
                tables_phi,
                k_phih,
                abs(k_phih) * plan.reach,
                lo,
                hi,
                charge_only=True,
                double=double,
            )
            _add_special(plan, charge, special_phi, lo, hi)
            _apply_phases(plan, charge, phases, lo, hi)
            _times(charge, 1.0 / medium.eps)
            m[5] -= scale * charge[0]  # ρ·ρ' G_A − 4/k0² G_Φ
            return m

        z = _assemble(pg, k, kt, block_moments, double)
    if len(kappa):
        u, v = slow_order_terms(pg, k, kt, kappa, layered.exact_a, layered.exact_phi)
        blas.zgemm(1.0, v, u, beta=1.0, c=z.T, trans_b=1, overwrite_c=1)
    return z

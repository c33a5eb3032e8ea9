"""The EFIE impedance matrix of RWG functions with Galerkin testing.

Perfectly conducting surfaces in free space, time convention e^(jωt)::

    Z_mn = jωμ/4π ∫∫ f_m·f_n G dS dS' − j/(4πωε) ∫∫ ∇·f_m ∇'·f_n G dS dS'
         = jη/4π [ k ∫∫ f_m·f_n G − (1/k) ∫∫ ∇·f_m ∇'·f_n G ],   G = e^(−jkR)/R

so that Z I = V with V_m = ∫ f_m·E_inc dS. Triangle pairs are integrated
as eight moments (see :mod:`barymesh.mom.geometry`): far pairs with the far
rule on both triangles (every point with every point), near pairs with
the near rule on the smooth remainder

    G − 1/R + k²R/2 = (cos kR − 1 + (kR)²/2 − j sin kR) / R

plus the cached static moments of 1/R and R (closed form inside).
The matrix is filled in blocks of observation triangles, so no (T, T)
table of moments is ever held whole.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..constants import ETA0, SPEED_OF_LIGHT
from .compiled_fill import compiled_impedance_matrix, resolve_backend
from .geometry import MomGeometry, far_point_distances

#: Complex numbers held by one block of the far-pair kernel.
BLOCK_ENTRIES = 1 << 21
#: Fewest blocks of observation triangles per fill.
MIN_BLOCKS = 8


def wavenumber(frequency: float) -> float:
    """k = 2π f / c (rad/m) for a frequency in Hz."""
    return 2.0 * np.pi * float(frequency) / SPEED_OF_LIGHT


def active_axes(geom: MomGeometry) -> tuple[int, ...]:
    """Coordinates along which the mesh extends (z is dropped for a flat mesh in z = 0)."""
    span = np.ptp(geom.vertices, axis=0)
    return tuple(int(c) for c in range(3) if span[c] > 0 or np.any(geom.vertices[:, c]))


def near_moments(geom: MomGeometry, k: complex, single: bool = False) -> np.ndarray:
    """(K, 8) complex moments of G over the near pairs, at wavenumber ``k``.

    ``k`` may be complex, Im k < 0 (a lossy medium; ``single`` is then ignored).

    The smooth kernel is evaluated on one of each mirrored pair (a, b), (b, a)
    only: with L = [w, w ρ] on each triangle, the 4 × 4 moments of (b, a) are
    the transpose of those of (a, b).

    With ``single``, the kernel's sines are taken in single precision (several times
    faster): its error is then about 1e-7 of the whole G (kR ≤ 1 on a near pair),
    though more of the smooth part alone, whose real part is (kR)⁴/24R for small kR.
    """
    upper = geom.near_upper
    obs, src = geom.near_pairs[upper, 0], geom.near_pairs[upper, 1]
    dist = geom.near_distances
    if np.imag(k):  # a lossy medium (the layered periodic fill): the kernel as it is
        with np.errstate(divide="ignore", invalid="ignore"):
            smooth = (np.exp(-1j * k * dist) - 1.0 + 0.5 * (k * dist) ** 2) / dist
    else:
        x = k * dist
        if single:
            x = x.astype(np.float32)
        smooth = np.empty(dist.shape, dtype=np.complex128)
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / dist
            half = np.sin(0.5 * x)
            smooth.real = (0.5 * x * x - 2.0 * half * half) * inv
            smooth.imag = -np.sin(x) * inv
    at_zero = dist == 0.0
    smooth[at_zero] = -1j * k
    w = geom.near.weights[:, :, None]
    frame = np.concatenate([w, w * geom.near.rho], axis=2)  # (T, Qn, 4): w, w ρ
    m4 = np.matmul(frame[obs].transpose(0, 2, 1), smooth @ frame[src].astype(np.complex128))
    return near_moments_from_half(geom, m4, k)


def near_moments_from_half(geom: MomGeometry, m4: np.ndarray, k: complex) -> np.ndarray:
    """(K, 8) complex moments of G over the near pairs from the smooth kernel's moments.

    ``m4`` is (H, 4, 4) complex: the frame [w, w ρ] moments of the smooth kernel over the
    pairs of ``geom.near_upper`` (one of each mirrored pair); the mirrors take their
    transposes, and the closed-form 1/R and R parts are added.
    """
    m4 = m4[geom.near_half]  # (K, 4, 4)
    mirrored = geom.near_mirrored
    m4[mirrored] = m4[mirrored].transpose(0, 2, 1)
    out = np.empty((len(m4), 8), dtype=np.complex128)
    out[:, 0] = m4[:, 0, 0]
    out[:, 1:4] = m4[:, 1:, 0]
    out[:, 4:7] = m4[:, 0, 1:]
    out[:, 7] = m4[:, 1, 1] + m4[:, 2, 2] + m4[:, 3, 3]
    out += geom.static_inv_r
    out -= (0.5 * k * k) * geom.static_r
    return out


#: Largest phase k·R computed straight in single precision (error below 50 × 6e-8 rad).
SINGLE_PRECISION_PHASE = 50.0


def far_kernel(
    dist: np.ndarray, k: float, max_phase: float | None = None, double: bool = False
) -> np.ndarray:
    """e^(−jkR)/R for far pairs, with the phase's cosine and sine in single precision.

    When k R can exceed :data:`SINGLE_PRECISION_PHASE` (``max_phase``, default
    from ``dist``), the phase is first reduced to [−π, π] in double precision;
    either way the error is below 1e-7 of |G| or so, far under the far rule's
    own error (about 1e-3). Single-precision cos and sin are vectorised and
    about ten times faster, and they are most of the fill time.

    With ``double``, the kernel is computed in double precision throughout: the
    reference the compiled fill (:mod:`barymesh.mom.compiled_fill`) is tested against.
    """
    if double:
        x = k * dist
        with np.errstate(divide="ignore"):
            return (np.cos(x) - 1j * np.sin(x)) / dist
    if max_phase is None:
        max_phase = k * float(dist.max()) if dist.size else 0.0
    if max_phase <= SINGLE_PRECISION_PHASE:
        x32 = np.multiply(dist, np.float32(k), dtype=np.float32)
    else:
        x = k * dist
        x -= (2.0 * np.pi) * np.rint(x * (0.5 / np.pi))
        x32 = x.astype(np.float32)
        del x
    inv = np.divide(1.0, dist)
    kernel = np.empty(dist.shape, dtype=np.complex128)
    np.multiply(np.cos(x32), inv, out=kernel.real)
    np.negative(inv, out=inv)
    np.multiply(np.sin(x32), inv, out=kernel.imag)
    return kernel


def far_moments(
    geom: MomGeometry,
    k: float,
    lo: int,
    hi: int,
    axes: tuple[int, ...],
    src_lo: int = 0,
    double: bool = False,
) -> np.ndarray:
    """(8, T − src_lo, hi − lo) complex far-rule moments of G, source triangle first.

    Source triangles src_lo..T against observation triangles lo..hi; entry
    ``[i, s, o]`` is moment i (:data:`~barymesh.mom.geometry.MOMENTS`) of the pair
    (observation lo + o, source src_lo + s). The kernel is laid out source
    point by observation point, so the contraction over the source points is
    one batched real matrix product per source triangle (its weights w and
    w ρ' against the real and imaginary parts of the kernel). ``double``: see
    :func:`far_kernel`.
    """
    far = geom.far
    q = far.size
    ts = geom.n_triangles - src_lo
    tb = hi - lo
    if geom.far_distances is not None:  # symmetric: the rows may be the sources
        dist = geom.far_distances[src_lo * q :, lo * q : hi * q]
    else:
        dist = far_point_distances(far, src_lo, geom.n_triangles, lo, hi)
    span = np.ptp(geom.vertices, axis=0)
    kernel = far_kernel(dist, k, k * float(np.linalg.norm(span)), double)
    kernel = kernel.reshape(ts, q, tb * q)
    # source side: (Ts, 1 + len(axes), Qf) weights w, w ρ'_c against (Ts, Qf, 2 Tb Qf) reals
    w = far.weights[src_lo:, None, :]
    src_weights = np.concatenate([w] + [w * far.rho[src_lo:, None, :, c] for c in axes], axis=1)
    h = np.matmul(src_weights, kernel.view(np.float64)).view(np.complex128)
    del kernel
    h = h.reshape(ts, 1 + len(axes), tb, q)
    out = np.zeros((8, ts, tb), dtype=np.complex128)
    w_obs = far.weights[lo:hi]
    rho_obs = far.rho[lo:hi]
    h0 = h[:, 0]
    out[0] = np.einsum("tpa,pa->tp", h0, w_obs)
    for i, c in enumerate(axes):
        hc = h[:, 1 + i]
        wrho = w_obs * rho_obs[:, :, c]
        out[1 + c] = np.einsum("tpa,pa->tp", h0, wrho)
        out[4 + c] = np.einsum("tpa,pa->tp", hc, w_obs)
        out[7] += np.einsum("tpa,pa->tp", hc, wrho)
    return out


def _contribution(m, k, axes, left, right) -> np.ndarray:
    """Part of Z from moments ``m`` (8, Ts, Tb) and the stacked sparse maps of a block.

    With A, D_c the coefficient and offset maps (:class:`FillBlock`), a pair's
    Galerkin terms are A·(k ∫∫ρ·ρ'G − 4/k ∫∫G)·Aᵀ + Σ_c [D_c·k∫∫ρ'_c G·Aᵀ +
    A·k∫∫ρ_c G·D_cᵀ + D_c·k∫∫G·D_cᵀ] (observation on the left). Stacking
    ``right`` = [A | D_x | D_y ...] (Nr, (1+a) Ts) and ``left`` likewise on the
    block's triangles, the (R, Nr) part of Z = left · (right · S)ᵀ for one dense (1+a) × (1+a)
    block matrix S of moments: two sparse products instead of ten.
    """
    ts, tb = m.shape[1:]
    size = 1 + len(axes)
    blocks = np.zeros((size, ts, size, tb), dtype=np.complex128)
    blocks[0, :, 0] = k * m[7] - (4.0 / k) * m[0]
    for i, c in enumerate(axes, start=1):
        blocks[i, :, 0] = k * m[1 + c]
        blocks[0, :, i] = k * m[4 + c]
        blocks[i, :, i] = k * m[0]
    w = right @ blocks.reshape(size * ts, size * tb)  # (Nr, (1+a) Tb)
    return left @ w.T


@dataclass(frozen=True, eq=False)
class FillBlock:
    """One block of observation triangles lo..hi and its sparse maps, reused every fill.

    ``touched`` are the unknowns living on the block; ``left`` their coefficient
    and offset maps restricted to the block, side by side, (R, (1+a) Tb) with a
    the number of active axes (it is also the right factor of the block against
    itself); ``after_rows`` the unknowns living on triangles hi..T and ``after``
    their maps there, (Na, (1+a) Ts).
    """

    lo: int
    hi: int
    touched: np.ndarray
    left: sp.csr_matrix
    after_rows: np.ndarray
    after: sp.csr_matrix | None


_BLOCKS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def fill_blocks(geom: MomGeometry) -> list[FillBlock]:
    """The observation blocks of a fill (cached per geometry: a sweep slices once)."""
    if geom in _BLOCKS:
        return _BLOCKS[geom]
    t = geom.n_triangles
    maps = [geom.coef_matrix.tocsc()] + [geom.offset_matrices[c].tocsc() for c in active_axes(geom)]
    # at least MIN_BLOCKS blocks, so that the mirrored half is most of the work
    block = max(1, min(BLOCK_ENTRIES // max(1, t * geom.far.size**2), -(-t // MIN_BLOCKS)))
    out = []
    for lo in range(0, t, block):
        hi = min(t, lo + block)
        touched = np.unique(maps[0][:, lo:hi].indices)
        if len(touched) == 0:
            continue
        after_rows = np.unique(maps[0][:, hi:].indices)
        after = None
        if len(after_rows):
            after = sp.hstack([m[:, hi:][after_rows] for m in maps], "csr")
        left = sp.hstack([m[:, lo:hi][touched] for m in maps], "csr")
        out.append(FillBlock(lo, hi, touched, left, after_rows, after))
    _BLOCKS[geom] = out
    return out


def impedance_matrix(
    geom: MomGeometry, k: float, backend: str | None = None, double: bool = False
) -> np.ndarray:
    """The (N, N) complex EFIE matrix at wavenumber ``k`` (rad/m).

    Two fills compute it: the compiled one (``barymesh.mom.compiled_fill``,
    multi-threaded, double precision), when numba is installed, and the numpy one
    (``numpy_impedance_matrix`` here), the reference. They agree to 1e-12 of the
    largest entry (the numpy one with ``double``; by default its far kernel is in
    single precision, about 1e-7 of |G|, far under the far rule's own error).

    Parameters
    ----------
    geom : MomGeometry
    k : float
        Free-space wavenumber, > 0.
    backend : {"numba", "numpy"}, optional
        Which fill; by default the environment variable ``BARYMESH_FILL``, else numba
        when it is installed.
    double : bool
        The numpy fill's far kernel in double precision (the compiled fill always is).

    Returns
    -------
    (N, N) complex128
        Z in ohms; Z I = V with V in volts (V_m = ∫ f_m·E_inc, E in V/m).
    """
    k = float(k)
    if not np.isfinite(k) or k <= 0:
        raise ValueError(f"wavenumber k={k} is invalid; expected a positive number")
    if resolve_backend(backend) == "numba":
        return compiled_impedance_matrix(geom, k, near_moments(geom, k))
    return numpy_impedance_matrix(geom, k, double)


def numpy_impedance_matrix(geom: MomGeometry, k: float, double: bool = False) -> np.ndarray:
    """The EFIE matrix by the numpy fill (:func:`impedance_matrix` checks ``k``).

    Blocks of observation triangles are integrated against themselves and
    the triangles after them only; the pairs before them are the transposes
    of pairs already done (the Galerkin integrals are symmetric, swapping
    the moments of ρ and ρ'): half the kernel work. Only near pairs inside
    one block are integrated both ways; their static parts are computed once
    per mirrored pair, so Z is symmetric to rounding. ``double``: the far kernel
    in double precision (:func:`far_kernel`).
    """
    axes = active_axes(geom)
    t = geom.n_triangles
    n = geom.n_unknowns
    near = near_moments(geom, k)
    starts = np.searchsorted(geom.near_pairs[:, 0], np.arange(t + 1))
    z = np.zeros((n, n), dtype=np.complex128)
    for blk in fill_blocks(geom):
        lo, hi = blk.lo, blk.hi
        m = far_moments(geom, k, lo, hi, axes, src_lo=lo, double=double)
        span = slice(starts[lo], starts[hi])
        keep = geom.near_pairs[span, 1] >= lo
        rows = geom.near_pairs[span, 0][keep] - lo
        cols = geom.near_pairs[span, 1][keep] - lo
        m[:, cols, rows] = near[span][keep].T
        width = hi - lo
        own = np.ix_(blk.touched, blk.touched)
        z[own] += _contribution(m[:, :width], k, axes, blk.left, blk.left)
        if blk.after is not None:
            upper = _contribution(m[:, width:], k, axes, blk.left, blk.after)
            z[np.ix_(blk.touched, blk.after_rows)] += upper
            z[np.ix_(blk.after_rows, blk.touched)] += upper.T  # the mirrored pairs
    z *= 1j * ETA0 / (4.0 * np.pi)
    return z


def gram_matrix(geom: MomGeometry) -> sp.csr_matrix:
    """(N, N) sparse G_mn = ∫ f_m·f_n dS: the RWG Gram matrix (m²·A⁻² units of f²).

    Per triangle, f = C ρ + D with ρ measured from its centroid, so ∫ f_m·f_n =
    C_m C_n ∫ |ρ|² + D_m·D_n A (the cross terms vanish: ∫ ρ dS = 0); the near rule
    (degree 5) is exact for the quadratic ∫ |ρ|². A sheet impedance Z_s adds Z_s G to Z.
    """
    rule = geom.near
    second = np.einsum("tq,tqc,tqc->t", rule.weights, rule.rho, rule.rho)
    gram = geom.coef_matrix @ sp.diags(second) @ geom.coef_matrix.T
    area = sp.diags(geom.areas)
    for offsets in geom.offset_matrices:
        gram = gram + offsets @ area @ offsets.T
    return sp.csr_matrix(gram)

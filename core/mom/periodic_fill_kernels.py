"""The periodic fill's loops, compiled by numba (imported by :mod:`.compiled_periodic_fill`).

Like :mod:`barymesh.mom.fill_kernels`, this module imports numba at its top, so nothing
imports it until a periodic fill asks for it, and every function is cached on disk
(``cache=True``). The kernels compute in double precision, ``fastmath`` off, on the
plan's single-precision tables (read, not recomputed): they agree with the numpy path
of :mod:`barymesh.mom.periodic_fill` run in double precision (``double=True``) to
rounding, the tests hold them to 1e-12 of the largest entry.

Two kernels per block of observation triangles lo..hi:

- :func:`right_block` computes, per observation triangle (one per thread), the six flat
  moments of G + G_reg against every source (the Taylor expansion of
  ``periodic_fill._taylor_moments``, plus the near and close pairs' moments, times the
  image's Floquet phase), and adds them through the source triangle's RWG
  coefficients into its rows of the block's right factor R (Z = [C | D_x | D_y] R);
- :func:`rows_block` adds R's rows into the rows of Z of the unknowns living on the
  block's triangles, one row of Z per thread (no two threads write one row).

and, once per frequency, :func:`close_moments`: the close pairs' far-rule moments (the
numpy path's einsum) in double precision, in the plan's order.

The numpy path writes the moments of a block as (6, 2, T, B) planes and multiplies by
sparse maps; here no pair's moments leave the registers and a core's cache.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from .fill_kernels import sincos

#: Observation triangles per job of :func:`right_block`: the plan's [source, observation]
#: tables are read 16 observers (64 bytes of float32, a cache line) at a time.
OBSERVER_CHUNK = 16


@njit(cache=True)
def taylor_row(
    tab: np.ndarray,
    inp: np.ndarray,
    src: np.ndarray,
    kr: float,
    ki: float,
    count: int,
    charge_only: bool,
    out: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """One source's flat moments of G + G_reg's expansions against ``count`` observers.

    The formulas and their order are those of ``periodic_fill._taylor_moments`` (see its
    docstring), written out on real and imaginary parts, the pair's Floquet phase
    applied at the end. Per observer c: ``tab[:, c]`` (12,) G_reg's value, gradient and
    Hessian at the pair's node (re, im per derivative); ``inp[:, c]`` (19,) the offset
    from the node (x, y), |c|, 1/|c| (0 on near and close pairs, where G's terms vanish),
    ĉ (x, y), the phase (re, im) and the observer's :func:`right_block` ``moments`` row;
    ``src`` the source's row; k = kr + j ki in units of the plan's scale. ``out[:, c]``
    gets the six moments' re and im (12 rows), or with ``charge_only`` ∫∫ 1's (2 rows).

    The inputs are gathered by the caller into these small double-precision rows first,
    which also widens the plan's single-precision values before any arithmetic (in numba
    a float32 times a float32 stays float32: ĉ_x² so rounded put 3e-11 of max |Z| between
    the paths). A loop of arithmetic only over contiguous rows ran 1.5 times faster than
    the same formulas reading the plan and the table in place.
    """
    a_s, s00, s01, s10, s11 = src[0], src[1], src[2], src[3], src[4]
    for c in range(count):
        t0, t1, t2, t3 = tab[0, c], tab[1, c], tab[2, c], tab[3, c]
        t4, t5, t6, t7 = tab[4, c], tab[5, c], tab[6, c], tab[7, c]
        t8, t9, t10, t11 = tab[8, c], tab[9, c], tab[10, c], tab[11, c]
        ex, ey, dist, inv = inp[0, c], inp[1, c], inp[2, c], inp[3, c]
        ux, uy, phr, phi = inp[4, c], inp[5, c], inp[6, c], inp[7, c]
        a_o, o00, o01, o10, o11 = inp[8, c], inp[9, c], inp[10, c], inp[11, c], inp[12, c]
        dxr = t6 * ex + t2 + t8 * ey
        dxi = t7 * ex + t3 + t9 * ey
        dyr = t10 * ey + t4 + t8 * ex
        dyi = t11 * ey + t5 + t9 * ex
        vr = ((t2 + dxr) * ex + (t4 + dyr) * ey) * 0.5 + t0
        vi = ((t3 + dxi) * ex + (t5 + dyi) * ey) * 0.5 + t1
        # G = e^(−jkR)/R about c
        sn, cs = sincos(kr * dist)
        gr = cs * inv
        gi = -(sn * inv)
        if ki != 0.0:
            decay = np.exp(ki * dist)
            gr *= decay
            gi *= decay
            shifted = inv - ki
            a2 = 2.0 * inv * inv - (kr * kr - ki * ki) - inv * (2.0 * ki)
            b2 = shifted * (2.0 * kr)
        else:
            shifted = inv
            a2 = 2.0 * inv * inv - kr * kr
            b2 = inv * (2.0 * kr)
        g1r = gi * kr - shifted * gr
        g1i = -(gr * kr + shifted * gi)
        qr = g1r * inv
        qi = g1i * inv
        pr = (a2 * gr - b2 * gi) - qr
        pi = (a2 * gi + b2 * gr) - qi
        vr += gr
        vi += gi
        uu, uv, vv = ux * ux, ux * uy, uy * uy
        hxxr = t6 + (qr + pr * uu)
        hxxi = t7 + (qi + pi * uu)
        hxyr = t8 + pr * uv
        hxyi = t9 + pi * uv
        hyyr = t10 + (qr + pr * vv)
        hyyi = t11 + (qi + pi * vv)
        # ∫∫ 1
        w0, w1, w2 = 0.5 * o00, o01, 0.5 * o11
        vr = (vr * a_o + (hxxr * w0 + hxyr * w1 + hyyr * w2)) * a_s
        vi = (vi * a_o + (hxxi * w0 + hxyi * w1 + hyyi * w2)) * a_s
        w0, w1, w2 = 0.5 * s00, s01, 0.5 * s11
        m0r = (hxxr * w0 + hxyr * w1 + hyyr * w2) * a_o + vr
        m0i = (hxxi * w0 + hxyi * w1 + hyyi * w2) * a_o + vi
        out[0, c] = m0r * phr - m0i * phi
        out[1, c] = m0i * phr + m0r * phi
        if charge_only:
            continue
        dxr += g1r * ux
        dxi += g1i * ux
        dyr += g1r * uy
        dyi += g1i * uy
        # ∫∫ ρ_x, ∫∫ ρ_y: A' (I ∇f + ½ J:H)
        w0, w1, w2 = 0.5 * inp[13, c], inp[14, c], 0.5 * inp[15, c]
        m1r = ((dxr * o00 + dyr * o01) + (hxxr * w0 + hxyr * w1 + hyyr * w2)) * a_s
        m1i = ((dxi * o00 + dyi * o01) + (hxxi * w0 + hxyi * w1 + hyyi * w2)) * a_s
        w0, w1, w2 = 0.5 * inp[16, c], inp[17, c], 0.5 * inp[18, c]
        m2r = ((dxr * o10 + dyr * o11) + (hxxr * w0 + hxyr * w1 + hyyr * w2)) * a_s
        m2i = ((dxi * o10 + dyi * o11) + (hxxi * w0 + hxyi * w1 + hyyi * w2)) * a_s
        # ∫∫ ρ'_x, ∫∫ ρ'_y: A (−I' ∇f + ½ J':H)
        w0, w1, w2 = 0.5 * src[5], src[6], 0.5 * src[7]
        m3r = ((dxr * -s00 + dyr * -s01) + (hxxr * w0 + hxyr * w1 + hyyr * w2)) * a_o
        m3i = ((dxi * -s00 + dyi * -s01) + (hxxi * w0 + hxyi * w1 + hyyi * w2)) * a_o
        w0, w1, w2 = 0.5 * src[8], src[9], 0.5 * src[10]
        m4r = ((dxr * -s10 + dyr * -s11) + (hxxr * w0 + hxyr * w1 + hyyr * w2)) * a_o
        m4i = ((dxi * -s10 + dyi * -s11) + (hxxi * w0 + hxyi * w1 + hyyi * w2)) * a_o
        # ∫∫ ρ·ρ' = −tr(I H I') = −Σ_pq H_pq Σ_i I_qi I'_ip
        c00 = -(s00 * o00 + s01 * o10)
        c01 = -(s10 * o00 + s11 * o10)
        c10 = -(s00 * o01 + s01 * o11)
        c11 = -(s10 * o01 + s11 * o11)
        w1 = c01 + c10
        m5r = hxxr * c00 + hxyr * w1 + hyyr * c11
        m5i = hxxi * c00 + hxyi * w1 + hyyi * c11
        out[2, c] = m1r * phr - m1i * phi
        out[3, c] = m1i * phr + m1r * phi
        out[4, c] = m2r * phr - m2i * phi
        out[5, c] = m2i * phr + m2r * phi
        out[6, c] = m3r * phr - m3i * phi
        out[7, c] = m3i * phr + m3r * phi
        out[8, c] = m4r * phr - m4i * phi
        out[9, c] = m4i * phr + m4r * phi
        out[10, c] = m5r * phr - m5i * phi
        out[11, c] = m5i * phr + m5r * phi


@njit(parallel=True, cache=True)
def right_block(
    node: np.ndarray,
    offset: np.ndarray,
    distance: np.ndarray,
    inverse: np.ndarray,
    unit: np.ndarray,
    sigma_code: np.ndarray,
    moments: np.ndarray,
    special: np.ndarray,
    special_starts: np.ndarray,
    tables_a: np.ndarray,
    k_a: complex,
    special_a: np.ndarray,
    layered: bool,
    tables_phi: np.ndarray,
    k_phi: complex,
    special_phi: np.ndarray,
    mu: complex,
    inv_eps: complex,
    phases: np.ndarray,
    scale: float,
    src_starts: np.ndarray,
    src_unknown: np.ndarray,
    src_coef: np.ndarray,
    src_phase: np.ndarray,
    factor: complex,
    lo: int,
    hi: int,
    out: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """The rows of R of observation triangles lo..hi, written to ``out`` (3, hi − lo, N).

    Plan arrays as in :class:`~barymesh.mom.periodic_plan.FillPlan` ([source,
    observation]); ``moments`` (T, 11) each triangle's A, I_00, I_01, I_10, I_11,
    J_000, J_001, J_011, J_100, J_101, J_111 in double precision; ``tables_a`` (G², 12)
    G_reg's Taylor table at ``k_a`` (units of the plan's scale), ``special_a`` (6, 2, M)
    the near and close pairs' moments. With ``layered``, the charge moment comes from
    ``tables_phi`` at ``k_phi`` and ``special_phi`` (1, 2, M), and the moments are μ̃ G_A
    and G_Φ/ε̄. ``phases``
    (S,) complex: e^(−j k_t·ρ_σ) per σ code. ``src_*``: each source triangle's unknowns
    (CSR by triangle) with their [C, D_x, D_y] coefficients and Floquet phase. Every
    entry is multiplied by ``factor`` (jkη/4π h³ in the vacuum fill).

    One job is :data:`OBSERVER_CHUNK` observers: for each source, the loop over them
    reads the plan's rows in order and writes the moments to the job's (12, T, C)
    scratch; then, per observer, the near and close pairs are added and every pair's
    moments go through the source's RWG coefficients into R.
    """
    t = moments.shape[0]
    width = hi - lo
    chunks = (width + OBSERVER_CHUNK - 1) // OBSERVER_CHUNK
    kar, kai = k_a.real, k_a.imag
    kpr, kpi = k_phi.real, k_phi.imag
    for chunk in prange(chunks):
        first = lo + chunk * OBSERVER_CHUNK
        last = min(hi, first + OBSERVER_CHUNK)
        m = np.empty((12, t, OBSERVER_CHUNK))
        charge = np.empty((2, t, OBSERVER_CHUNK))
        inp = np.empty((19, OBSERVER_CHUNK))
        tab = np.empty((12, OBSERVER_CHUNK))
        tab_phi = np.empty((12, OBSERVER_CHUNK))
        count = last - first
        for o in range(first, last):
            out[:, o - lo, :] = 0.0  # the job's own rows of R, zeroed where they are used
            for j in range(11):
                inp[8 + j, o - first] = moments[o, j]
        # sources outside, observers inside: the plan's [s, o] rows are read in order
        for s in range(t):
            for o in range(first, last):
                c = o - first
                r = node[s, o]
                for j in range(12):
                    tab[j, c] = tables_a[r, j]
                if layered:
                    for j in range(12):
                        tab_phi[j, c] = tables_phi[r, j]
                ph = phases[sigma_code[s, o]]
                inp[0, c] = offset[0, s, o]
                inp[1, c] = offset[1, s, o]
                inp[2, c] = distance[s, o]
                inp[3, c] = inverse[s, o]
                inp[4, c] = unit[0, s, o]
                inp[5, c] = unit[1, s, o]
                inp[6, c] = ph.real
                inp[7, c] = ph.imag
            taylor_row(tab, inp, moments[s], kar, kai, count, False, m[:, s, :])
            if layered:
                taylor_row(tab_phi, inp, moments[s], kpr, kpi, count, True, charge[:, s, :])
        for o in range(first, last):
            c = o - first
            for idx in range(special_starts[o], special_starts[o + 1]):
                s = special[idx, 1]
                ph = phases[sigma_code[s, o]]
                pr, pi = ph.real, ph.imag
                for i in range(6):
                    re, im = np.float64(special_a[i, 0, idx]), np.float64(special_a[i, 1, idx])
                    m[2 * i, s, c] += re * pr - im * pi
                    m[2 * i + 1, s, c] += im * pr + re * pi
                if layered:
                    re, im = np.float64(special_phi[0, 0, idx]), np.float64(special_phi[0, 1, idx])
                    charge[0, s, c] += re * pr - im * pi
                    charge[1, s, c] += im * pr + re * pi
            row = o - lo
            for s in range(t):
                f0 = complex(m[0, s, c], m[1, s, c])
                f1 = complex(m[2, s, c], m[3, s, c])
                f2 = complex(m[4, s, c], m[5, s, c])
                f3 = complex(m[6, s, c], m[7, s, c])
                f4 = complex(m[8, s, c], m[9, s, c])
                f5 = complex(m[10, s, c], m[11, s, c])
                if layered:
                    f0, f1, f2, f3, f4, f5 = f0 * mu, f1 * mu, f2 * mu, f3 * mu, f4 * mu, f5 * mu
                    q = complex(charge[0, s, c], charge[1, s, c]) * inv_eps
                else:
                    q = f0
                s00 = factor * (f5 - scale * q)
                s0x, s0y = factor * f1, factor * f2
                sx0, sy0, sxx = factor * f3, factor * f4, factor * f0
                for slot in range(src_starts[s], src_starts[s + 1]):
                    n = src_unknown[slot]
                    c0, c1, c2 = src_coef[slot, 0], src_coef[slot, 1], src_coef[slot, 2]
                    r0 = c0 * s00 + c1 * s0x + c2 * s0y
                    r1 = c0 * sx0 + c1 * sxx
                    r2 = c0 * sy0 + c2 * sxx
                    w = src_phase[slot]
                    if w.real != 1.0 or w.imag != 0.0:  # a T− half across the sides
                        r0, r1, r2 = r0 * w, r1 * w, r2 * w
                    out[0, row, n] += r0
                    out[1, row, n] += r1
                    out[2, row, n] += r2


@njit(parallel=True, cache=True)
def rows_block(
    rows: np.ndarray,
    tst_starts: np.ndarray,
    tst_triangle: np.ndarray,
    tst_coef: np.ndarray,
    tst_phase: np.ndarray,
    lo: int,
    hi: int,
    right: np.ndarray,
    z: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Z[m] += Σ (testing coefficient) R[triangle] over the block's triangles of each m.

    ``rows`` are the unknowns with a triangle in lo..hi; ``tst_*`` each unknown's
    triangles (CSR by unknown) with their [C, D_x, D_y] coefficients and the complex
    conjugate of their Floquet phase; ``right`` (3, hi − lo, N) from :func:`right_block`.
    """
    n = z.shape[1]
    for i in prange(len(rows)):
        m = rows[i]
        for slot in range(tst_starts[m], tst_starts[m + 1]):
            o = tst_triangle[slot]
            if o < lo or o >= hi:
                continue
            ph = tst_phase[slot]
            w0 = tst_coef[slot, 0] * ph
            w1 = tst_coef[slot, 1] * ph
            w2 = tst_coef[slot, 2] * ph
            r = o - lo
            for col in range(n):
                z[m, col] += w0 * right[0, r, col] + w1 * right[1, r, col] + w2 * right[2, r, col]


#: Close pairs per job of :func:`close_moments` (their 12 sums stay in L1 cache).
CLOSE_CHUNK = 256


@njit(parallel=True, cache=True)
def close_moments(
    distance: np.ndarray,
    weights: np.ndarray,
    kr: float,
    ki: float,
    position: np.ndarray,
    mirror_position: np.ndarray,
    mirrored: np.ndarray,
    out: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """The close pairs' flat moments of e^(−jkR)/R by the far rule, written into ``out``.

    ``distance`` (Q², K) float32 R between the rule's points of each close pair,
    ``weights`` (count, Q², K) float32 the rule's weights times the moments' factors
    (the plan's ``close_distance`` and ``close_weights``); k = ``kr`` + j ``ki`` in units
    of the plan's scale (``ki`` ≤ 0, a lossy medium). The sums are those of
    ``periodic_fill.special_moments`` (an einsum there) in double precision; pair j's
    (2 count,) re/im rows go to column ``position[j]`` of ``out`` (2 count, M) float64 and,
    rows permuted by ``mirrored``, to column ``mirror_position[j]``: its mirror, ρ and ρ'
    swapped.
    """
    q2, pairs = distance.shape
    count = weights.shape[0]
    rows = 2 * count
    chunks = (pairs + CLOSE_CHUNK - 1) // CLOSE_CHUNK
    for chunk in prange(chunks):
        first = chunk * CLOSE_CHUNK
        width = min(pairs, first + CLOSE_CHUNK) - first
        acc = np.zeros((rows, CLOSE_CHUNK))
        re = np.empty(CLOSE_CHUNK)
        im = np.empty(CLOSE_CHUNK)
        for p in range(q2):
            # the kernel at point pair p of every pair of the chunk, then the sums: two
            # loops over the chunk that the compiler vectorises
            for j in range(width):
                d = np.float64(distance[p, first + j])
                inverse = 1.0 / d
                if ki != 0.0:
                    inverse *= np.exp(ki * d)
                s, c = sincos(kr * d)
                re[j] = c * inverse
                im[j] = -s * inverse
            for i in range(count):
                for j in range(width):
                    w = np.float64(weights[i, p, first + j])
                    acc[2 * i, j] += w * re[j]
                    acc[2 * i + 1, j] += w * im[j]
        for j in range(width):
            a, b = position[first + j], mirror_position[first + j]
            for r in range(rows):
                out[r, a] = acc[r, j]
                out[r, b] = acc[mirrored[r], j]

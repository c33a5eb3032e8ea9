"""The periodic fill's loops, compiled by numba (imported by :mod:`.compiled_periodic_fill`).

Like :mod:`barymesh.mom.fill_kernels`, this module imports numba at its top, so nothing
imports it until a periodic fill asks for it, and every function is cached on disk
(``cache=True``). The kernels compute in double precision, ``fastmath`` off, on the
plan's single-precision tables (read, not recomputed): they agree with the numpy path
of :mod:`barymesh.mom.periodic_fill` run in double precision (``double=True``) to
rounding, the tests hold them to 1e-12 of the largest entry.

Two kernels per block of observation triangles lo..hi:

- :func:`right_block` computes, per chunk of observation triangles (one chunk per thread), the
  six flat moments of G + G_reg against every source (the Taylor expansion of
  ``periodic_fill._taylor_moments``, plus the near and close pairs' moments, times the
  image's Floquet phase), and sums them through the RWG coefficients of each unknown's
  source triangles into its rows of the block's right factor R (Z = [C | D_x | D_y] R);
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
#: Rows of :func:`taylor_row`'s scratch, one per quantity, each OBSERVER_CHUNK observers
#: wide: the table's 12 values and e^(Im k R) from ``TAB``, the pair's 8 (offset x, y,
#: |c|, 1/|c|, ĉ x, y, phase re, im) from ``PAIR``, the observer's 11 moments from
#: ``OBS``, the 12 results from ``OUT``.
TAB, PAIR, OBS, OUT, ROWS = 0, 13, 21, 32, 44


@njit(cache=True)
def taylor_row(
    buf: np.ndarray,
    src: np.ndarray,
    kr: float,
    ki: float,
    count: int,
    charge_only: bool,
) -> None:  # pragma: no cover - compiled
    """One source's flat moments of G + G_reg's expansions against ``count`` observers.

    The formulas and their order are those of ``periodic_fill._taylor_moments`` (see its
    docstring), written out on real and imaginary parts, the pair's Floquet phase
    applied at the end. ``buf`` is the caller's scratch of :data:`ROWS` rows of
    :data:`OBSERVER_CHUNK` (observer c at column c): from row ``TAB``, G_reg's value,
    gradient and Hessian at the pair's node (re, im per derivative, 12 rows; row 12 is
    this function's); from ``PAIR`` the offset from the node (x, y), |c|, 1/|c| (0 on
    near and close pairs, where G's terms vanish), ĉ (x, y), the phase (re, im); from
    ``OBS`` the observer's :func:`right_block` ``moments`` row. ``src`` is the source's
    row; k = kr + j ki in units of the plan's scale. The rows from ``OUT`` get the six
    moments' re and im (12 rows), or with ``charge_only`` ∫∫ 1's (2 rows).

    The inputs are gathered by the caller into these double-precision rows first, which
    also widens the plan's single-precision values before any arithmetic (in numba a
    float32 times a float32 stays float32: ĉ_x² so rounded put 3e-11 of max |Z| between
    the paths). All rows in one array at constant distances is what lets the compiler
    vectorise the loop (8 observers a step): with separate input and output arrays it
    would have to rule out their overlap at run time, for too many pairs of rows, and
    ran the loop one observer at a time, 1.4 times slower for the whole kernel.
    """
    w = OBSERVER_CHUNK
    a_s, s00, s01, s10, s11 = src[0], src[1], src[2], src[3], src[4]
    j0, j1, j2 = 0.5 * src[5], src[6], 0.5 * src[7]  # hoisted: the loop reads buf only
    j3, j4, j5 = 0.5 * src[8], src[9], 0.5 * src[10]
    if ki != 0.0:
        for c in range(count):
            buf[(TAB + 12) * w + c] = np.exp(ki * buf[(PAIR + 2) * w + c])
    else:
        for c in range(count):
            buf[(TAB + 12) * w + c] = 1.0
    for c in range(count):
        i, j, k = TAB * w + c, PAIR * w + c, OBS * w + c
        t0, t1, t2, t3 = buf[i], buf[i + w], buf[i + 2 * w], buf[i + 3 * w]
        t4, t5, t6, t7 = buf[i + 4 * w], buf[i + 5 * w], buf[i + 6 * w], buf[i + 7 * w]
        t8, t9, t10, t11 = buf[i + 8 * w], buf[i + 9 * w], buf[i + 10 * w], buf[i + 11 * w]
        ex, ey, dist, inv = buf[j], buf[j + w], buf[j + 2 * w], buf[j + 3 * w]
        ux, uy, phr, phi = buf[j + 4 * w], buf[j + 5 * w], buf[j + 6 * w], buf[j + 7 * w]
        a_o, o00, o01 = buf[k], buf[k + w], buf[k + 2 * w]
        o10, o11 = buf[k + 3 * w], buf[k + 4 * w]
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
        decay = buf[i + 12 * w]  # e^(Im k R); 1 without loss, which changes no product
        gr *= decay
        gi *= decay
        shifted = inv - ki
        a2 = 2.0 * inv * inv - (kr * kr - ki * ki) - inv * (2.0 * ki)
        b2 = shifted * (2.0 * kr)
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
        buf[OUT * w + c] = m0r * phr - m0i * phi
        buf[(OUT + 1) * w + c] = m0i * phr + m0r * phi
        if charge_only:
            continue
        dxr += g1r * ux
        dxi += g1i * ux
        dyr += g1r * uy
        dyi += g1i * uy
        # ∫∫ ρ_x, ∫∫ ρ_y: A' (I ∇f + ½ J:H)
        w0, w1, w2 = 0.5 * buf[k + 5 * w], buf[k + 6 * w], 0.5 * buf[k + 7 * w]
        m1r = ((dxr * o00 + dyr * o01) + (hxxr * w0 + hxyr * w1 + hyyr * w2)) * a_s
        m1i = ((dxi * o00 + dyi * o01) + (hxxi * w0 + hxyi * w1 + hyyi * w2)) * a_s
        w0, w1, w2 = 0.5 * buf[k + 8 * w], buf[k + 9 * w], 0.5 * buf[k + 10 * w]
        m2r = ((dxr * o10 + dyr * o11) + (hxxr * w0 + hxyr * w1 + hyyr * w2)) * a_s
        m2i = ((dxi * o10 + dyi * o11) + (hxxi * w0 + hxyi * w1 + hyyi * w2)) * a_s
        # ∫∫ ρ'_x, ∫∫ ρ'_y: A (−I' ∇f + ½ J':H)
        w0, w1, w2 = j0, j1, j2
        m3r = ((dxr * -s00 + dyr * -s01) + (hxxr * w0 + hxyr * w1 + hyyr * w2)) * a_o
        m3i = ((dxi * -s00 + dyi * -s01) + (hxxi * w0 + hxyi * w1 + hyyi * w2)) * a_o
        w0, w1, w2 = j3, j4, j5
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
        buf[(OUT + 2) * w + c] = m1r * phr - m1i * phi
        buf[(OUT + 3) * w + c] = m1i * phr + m1r * phi
        buf[(OUT + 4) * w + c] = m2r * phr - m2i * phi
        buf[(OUT + 5) * w + c] = m2i * phr + m2r * phi
        buf[(OUT + 6) * w + c] = m3r * phr - m3i * phi
        buf[(OUT + 7) * w + c] = m3i * phr + m3r * phi
        buf[(OUT + 8) * w + c] = m4r * phr - m4i * phi
        buf[(OUT + 9) * w + c] = m4i * phr + m4r * phi
        buf[(OUT + 10) * w + c] = m5r * phr - m5i * phi
        buf[(OUT + 11) * w + c] = m5i * phr + m5r * phi


@njit(parallel=True, cache=True)
def right_block(
    pair: np.ndarray,
    pair_code: np.ndarray,
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
    slot_starts: np.ndarray,
    slot_source: np.ndarray,
    slot_coef: np.ndarray,
    slot_phase: np.ndarray,
    factor: complex,
    lo: int,
    hi: int,
    out: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """The rows of R of observation triangles lo..hi, written to ``out`` (3, hi − lo, N).

    ``pair`` and ``pair_code``: the plan's per-pair arrays by chunk of
    :data:`OBSERVER_CHUNK` observers (:class:`~barymesh.mom.compiled_periodic_fill.PairRows`:
    offset x, y, distance, inverse, unit x, y; node and σ code), ``sigma_code`` the
    plan's [source, observation] σ codes (read for the near and close pairs);
    ``moments`` (T, 11) each triangle's A, I_00, I_01, I_10, I_11, J_000, J_001, J_011,
    J_100, J_101, J_111 in double precision; ``tables_a`` (G², 12) G_reg's Taylor table
    at ``k_a`` (units of the plan's scale), ``special_a`` (6, 2, M) the near and close
    pairs' moments. With ``layered``, the charge moment comes from ``tables_phi`` at
    ``k_phi`` and ``special_phi`` (1, 2, M), and the moments are μ̃ G_A and G_Φ/ε̄.
    ``phases`` (S,) complex: e^(−j k_t·ρ_σ) per σ code. ``slot_*``: each unknown's source
    triangles (CSR by unknown, triangles ascending) with their [C, D_x, D_y] coefficients
    and Floquet phase. Every entry is multiplied by ``factor`` (jkη/4π h³ in the vacuum
    fill).

    One job is the block's part of one chunk of :data:`OBSERVER_CHUNK` observers (chunks
    counted from triangle 0, so that each job's pair rows are contiguous): for each
    source, the loop over them reads the chunk's rows in order, :func:`taylor_row` their
    moments into the job's
    (T, 12, C) scratch; the near and close pairs are added, each pair's moments turned
    into its six blocks of S in place (on real and imaginary rows, a loop over the
    observers that the compiler vectorises), and each entry of R is then written once,
    unknown by unknown, as the sum over the unknown's sources in ascending order: the
    sums and their order are those of adding every source's products into R in turn,
    without the scattered read-modify-writes (a third of the kernel's time before).
    """
    t = moments.shape[0]
    chunks = (hi - 1) // OBSERVER_CHUNK - lo // OBSERVER_CHUNK + 1
    kar, kai = k_a.real, k_a.imag
    kpr, kpi = k_phi.real, k_phi.imag
    mur, mui = mu.real, mu.imag
    ier, iei = inv_eps.real, inv_eps.imag
    fcr, fci = factor.real, factor.imag
    w = OBSERVER_CHUNK
    g0 = lo // w
    for chunk in prange(chunks):
        g = g0 + chunk
        first = max(lo, g * w)
        count = min(hi, g * w + w) - first
        off = first - g * w
        m = np.empty((t, 12, w))
        charge = np.empty((t, 2, w))
        buf = np.empty(ROWS * w)
        buf_phi = np.empty(ROWS * w)
        for c in range(count):
            for j in range(11):
                buf[(OBS + j) * w + c] = moments[first + c, j]
                buf_phi[(OBS + j) * w + c] = moments[first + c, j]
        # sources outside, observers inside: the chunk's [s] rows are read in order
        for s in range(t):
            rows = pair[g, s]
            codes = pair_code[g, s]
            for c in range(count):
                r = codes[0, off + c]
                for j in range(12):
                    buf[(TAB + j) * w + c] = tables_a[r, j]
                if layered:
                    for j in range(12):
                        buf_phi[(TAB + j) * w + c] = tables_phi[r, j]
                ph = phases[codes[1, off + c]]
                for j in range(6):
                    buf[(PAIR + j) * w + c] = rows[j, off + c]
                buf[(PAIR + 6) * w + c] = ph.real
                buf[(PAIR + 7) * w + c] = ph.imag
            taylor_row(buf, moments[s], kar, kai, count, False)
            for j in range(12):
                for c in range(count):
                    m[s, j, c] = buf[(OUT + j) * w + c]
            if layered:
                for j in range(PAIR, OBS):
                    for c in range(count):
                        buf_phi[j * w + c] = buf[j * w + c]
                taylor_row(buf_phi, moments[s], kpr, kpi, count, True)
                for j in range(2):
                    for c in range(count):
                        charge[s, j, c] = buf_phi[(OUT + j) * w + c]
        for o in range(first, first + count):
            c = o - first
            for idx in range(special_starts[o], special_starts[o + 1]):
                s = special[idx, 1]
                ph = phases[sigma_code[s, o]]
                pr, pi = ph.real, ph.imag
                for i in range(6):
                    re, im = np.float64(special_a[i, 0, idx]), np.float64(special_a[i, 1, idx])
                    m[s, 2 * i, c] += re * pr - im * pi
                    m[s, 2 * i + 1, c] += im * pr + re * pi
                if layered:
                    re, im = np.float64(special_phi[0, 0, idx]), np.float64(special_phi[0, 1, idx])
                    charge[s, 0, c] += re * pr - im * pi
                    charge[s, 1, c] += im * pr + re * pi
        # each pair's six moments to the six blocks of S, in place, split re/im
        for s in range(t):
            ms = m[s]
            if layered:
                for i in range(6):
                    for c in range(count):
                        fr, fi = ms[2 * i, c], ms[2 * i + 1, c]
                        ms[2 * i, c] = fr * mur - fi * mui
                        ms[2 * i + 1, c] = fr * mui + fi * mur
                cs = charge[s]
                for c in range(count):
                    cr, ci = cs[0, c], cs[1, c]
                    cs[0, c] = cr * ier - ci * iei
                    cs[1, c] = cr * iei + ci * ier
                qs = cs
            else:
                qs = ms  # the charge moment is ∫∫ 1's, row 0 (read before it is scaled)
            for c in range(count):
                f0r, f0i = ms[0, c], ms[1, c]
                qr, qi = qs[0, c], qs[1, c]
                dr = ms[10, c] - scale * qr
                di = ms[11, c] - scale * qi
                ms[10, c] = fcr * dr - fci * di  # S_00
                ms[11, c] = fcr * di + fci * dr
                ms[0, c] = fcr * f0r - fci * f0i  # S_xx = S_yy
                ms[1, c] = fcr * f0i + fci * f0r
            for i in range(1, 5):
                for c in range(count):
                    fr, fi = ms[2 * i, c], ms[2 * i + 1, c]
                    ms[2 * i, c] = fcr * fr - fci * fi
                    ms[2 * i + 1, c] = fcr * fi + fci * fr
        # R's rows, unknown by unknown: each written once, from its slots' sources
        acc = np.empty((6, w))
        for n in range(slot_starts.shape[0] - 1):
            acc[:, :] = 0.0
            for slot in range(slot_starts[n], slot_starts[n + 1]):
                ms = m[slot_source[slot]]
                c0, c1, c2 = slot_coef[slot, 0], slot_coef[slot, 1], slot_coef[slot, 2]
                wr, wi = slot_phase[slot].real, slot_phase[slot].imag
                if wr != 1.0 or wi != 0.0:  # a T− half across the sides
                    for c in range(count):
                        r0r = (c0 * ms[10, c] + c1 * ms[2, c]) + c2 * ms[4, c]
                        r0i = (c0 * ms[11, c] + c1 * ms[3, c]) + c2 * ms[5, c]
                        r1r = c0 * ms[6, c] + c1 * ms[0, c]
                        r1i = c0 * ms[7, c] + c1 * ms[1, c]
                        r2r = c0 * ms[8, c] + c2 * ms[0, c]
                        r2i = c0 * ms[9, c] + c2 * ms[1, c]
                        acc[0, c] += r0r * wr - r0i * wi
                        acc[1, c] += r0r * wi + r0i * wr
                        acc[2, c] += r1r * wr - r1i * wi
                        acc[3, c] += r1r * wi + r1i * wr
                        acc[4, c] += r2r * wr - r2i * wi
                        acc[5, c] += r2r * wi + r2i * wr
                else:
                    for c in range(count):
                        acc[0, c] += (c0 * ms[10, c] + c1 * ms[2, c]) + c2 * ms[4, c]
                        acc[1, c] += (c0 * ms[11, c] + c1 * ms[3, c]) + c2 * ms[5, c]
                        acc[2, c] += c0 * ms[6, c] + c1 * ms[0, c]
                        acc[3, c] += c0 * ms[7, c] + c1 * ms[1, c]
                        acc[4, c] += c0 * ms[8, c] + c2 * ms[0, c]
                        acc[5, c] += c0 * ms[9, c] + c2 * ms[1, c]
            for c in range(count):
                row = first + c - lo
                out[0, row, n] = complex(acc[0, c], acc[1, c])
                out[1, row, n] = complex(acc[2, c], acc[3, c])
                out[2, row, n] = complex(acc[4, c], acc[5, c])


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
        inverse = np.empty(CLOSE_CHUNK)
        for p in range(q2):
            # the kernel at point pair p of every pair of the chunk, then the sums: loops
            # over the chunk that the compiler vectorises (without loss, all of them)
            if ki != 0.0:  # a lossy medium: e^(Im k R), a call, in a loop of its own
                for j in range(width):
                    d = np.float64(distance[p, first + j])
                    inverse[j] = 1.0 / d * np.exp(ki * d)
            else:
                for j in range(width):
                    inverse[j] = 1.0 / np.float64(distance[p, first + j])
            for j in range(width):  # with no call in it: 15% off the whole kernel
                s, c = sincos(kr * np.float64(distance[p, first + j]))
                re[j] = c * inverse[j]
                im[j] = -s * inverse[j]
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

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


@njit(cache=True, inline="always")
def taylor_pair(
    row: np.ndarray,
    ex: float,
    ey: float,
    dist: float,
    inv: float,
    ux: float,
    uy: float,
    kr: float,
    ki: float,
    a_s: float,
    a_o: float,
    i_s: np.ndarray,
    i_o: np.ndarray,
    j_s: np.ndarray,
    j_o: np.ndarray,
    out: np.ndarray,
    charge_only: bool,
) -> None:  # pragma: no cover - compiled
    """One pair's flat moments of G + G_reg's expansions into ``out`` (6,) complex.

    The formulas and their order are those of ``periodic_fill._taylor_moments``
    (see its docstring), on complex numbers instead of split planes: ``row`` (12,) is
    G_reg's value, gradient and Hessian at the pair's node (re, im per derivative),
    (ex, ey) the offset from the node, ``inv`` 1/|c| (0 on near and close pairs, where
    G's terms vanish), (ux, uy) ĉ, k = kr + j ki in units of the plan's scale. The
    caller widens the plan's single-precision values to double first: in numba a float32
    times a float32 stays float32 (ĉ_x² so rounded put 3e-11 of max |Z| between the
    paths).
    """
    g = complex(row[0], row[1])
    gx = complex(row[2], row[3])
    gy = complex(row[4], row[5])
    hxx = complex(row[6], row[7])
    hxy = complex(row[8], row[9])
    hyy = complex(row[10], row[11])
    dx = hxx * ex + gx + hxy * ey
    dy = hyy * ey + gy + hxy * ex
    value = ((gx + dx) * ex + (gy + dy) * ey) * 0.5 + g
    # G = e^(−jkR)/R about c
    s, c = sincos(kr * dist)
    gr = c * inv
    gi = -(s * inv)
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
    g1 = complex(gi * kr - shifted * gr, -(gr * kr + shifted * gi))
    q = g1 * inv
    p = complex(a2 * gr - b2 * gi, a2 * gi + b2 * gr) - q
    value += complex(gr, gi)
    if not charge_only:
        dx += g1 * ux
        dy += g1 * uy
    hxx += q + p * (ux * ux)
    hxy += p * (ux * uy)
    hyy += q + p * (uy * uy)
    value *= a_o
    value += hxx * (0.5 * i_o[0, 0]) + hxy * i_o[0, 1] + hyy * (0.5 * i_o[1, 1])
    value *= a_s
    acc = hxx * (0.5 * i_s[0, 0]) + hxy * i_s[0, 1] + hyy * (0.5 * i_s[1, 1])
    out[0] = acc * a_o + value
    if charge_only:
        return
    for c in range(2):
        acc = dx * i_o[c, 0] + dy * i_o[c, 1]
        acc += hxx * (0.5 * j_o[c, 0, 0]) + hxy * j_o[c, 0, 1] + hyy * (0.5 * j_o[c, 1, 1])
        out[1 + c] = acc * a_s
        acc = dx * -i_s[c, 0] + dy * -i_s[c, 1]
        acc += hxx * (0.5 * j_s[c, 0, 0]) + hxy * j_s[c, 0, 1] + hyy * (0.5 * j_s[c, 1, 1])
        out[3 + c] = acc * a_o
    # −tr(I H I') = −Σ_pq H_pq Σ_i I_qi I'_ip
    o00 = -(i_s[0, 0] * i_o[0, 0] + i_s[0, 1] * i_o[1, 0])
    o01 = -(i_s[1, 0] * i_o[0, 0] + i_s[1, 1] * i_o[1, 0])
    o10 = -(i_s[0, 0] * i_o[0, 1] + i_s[0, 1] * i_o[1, 1])
    o11 = -(i_s[1, 0] * i_o[0, 1] + i_s[1, 1] * i_o[1, 1])
    out[5] = hxx * o00 + hxy * (o01 + o10) + hyy * o11


@njit(parallel=True, cache=True)
def right_block(
    node: np.ndarray,
    offset: np.ndarray,
    distance: np.ndarray,
    inverse: np.ndarray,
    unit: np.ndarray,
    sigma_code: np.ndarray,
    areas: np.ndarray,
    second: np.ndarray,
    third: np.ndarray,
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
    """The rows of R of observation triangles lo..hi, added to ``out`` (3, hi − lo, N).

    Plan arrays as in :class:`~barymesh.mom.periodic_plan.FillPlan` ([source,
    observation]), ``areas``, ``second`` and ``third`` in double precision;
    ``tables_a`` (G², 12) G_reg's Taylor table at ``k_a`` (units of the plan's
    scale), ``special_a`` (6, 2, M) the near and close pairs' moments. With
    ``layered``, the charge moment comes from ``tables_phi`` at ``k_phi`` and
    ``special_phi`` (1, 2, M), and the moments are μ̃ G_A and G_Φ/ε̄. ``phases`` (S,)
    complex: e^(−j k_t·ρ_σ) per σ code. ``src_*``: each source triangle's unknowns
    (CSR by triangle) with their [C, D_x, D_y] coefficients and Floquet phase. Every
    entry is multiplied by ``factor`` (jkη/4π h³ in the vacuum fill).
    """
    t = areas.shape[0]
    width = hi - lo
    chunks = (width + OBSERVER_CHUNK - 1) // OBSERVER_CHUNK
    for chunk in prange(chunks):
        first = lo + chunk * OBSERVER_CHUNK
        last = min(hi, first + OBSERVER_CHUNK)
        m = np.empty((last - first, 6, t), dtype=np.complex128)
        charge = np.empty((last - first, t), dtype=np.complex128)
        pair = np.empty(6, dtype=np.complex128)
        # sources outside, observers inside: the plan's [s, o] rows are read in order
        for s in range(t):
            a_s, i_s, j_s = areas[s], second[s], third[s]
            for o in range(first, last):
                taylor_pair(
                    tables_a[node[s, o]],
                    np.float64(offset[0, s, o]),
                    np.float64(offset[1, s, o]),
                    np.float64(distance[s, o]),
                    np.float64(inverse[s, o]),
                    np.float64(unit[0, s, o]),
                    np.float64(unit[1, s, o]),
                    k_a.real,
                    k_a.imag,
                    a_s,
                    areas[o],
                    i_s,
                    second[o],
                    j_s,
                    third[o],
                    pair,
                    False,
                )
                ph = phases[sigma_code[s, o]]
                for i in range(6):
                    m[o - first, i, s] = pair[i] * ph
                if layered:
                    taylor_pair(
                        tables_phi[node[s, o]],
                        np.float64(offset[0, s, o]),
                        np.float64(offset[1, s, o]),
                        np.float64(distance[s, o]),
                        np.float64(inverse[s, o]),
                        np.float64(unit[0, s, o]),
                        np.float64(unit[1, s, o]),
                        k_phi.real,
                        k_phi.imag,
                        a_s,
                        areas[o],
                        i_s,
                        second[o],
                        j_s,
                        third[o],
                        pair,
                        True,
                    )
                    charge[o - first, s] = pair[0] * ph
        for o in range(first, last):
            mo, co = m[o - first], charge[o - first]
            for idx in range(special_starts[o], special_starts[o + 1]):
                s = special[idx, 1]
                ph = phases[sigma_code[s, o]]
                for i in range(6):
                    value = complex(np.float64(special_a[i, 0, idx]), special_a[i, 1, idx])
                    mo[i, s] += value * ph
                if layered:
                    value = complex(np.float64(special_phi[0, 0, idx]), special_phi[0, 1, idx])
                    co[s] += value * ph
            row = o - lo
            for s in range(t):
                if layered:
                    for i in range(6):
                        mo[i, s] *= mu
                    q = co[s] * inv_eps
                else:
                    q = mo[0, s]
                s00 = mo[5, s] - scale * q
                for slot in range(src_starts[s], src_starts[s + 1]):
                    n = src_unknown[slot]
                    c0, c1, c2 = src_coef[slot, 0], src_coef[slot, 1], src_coef[slot, 2]
                    w = factor * src_phase[slot]
                    out[0, row, n] += w * (c0 * s00 + c1 * mo[1, s] + c2 * mo[2, s])
                    out[1, row, n] += w * (c0 * mo[3, s] + c1 * mo[0, s])
                    out[2, row, n] += w * (c0 * mo[4, s] + c2 * mo[0, s])


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

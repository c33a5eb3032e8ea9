"""The free-space fill's loops, compiled by numba (imported by :mod:`.compiled_fill` only).

This module imports numba at its top, so nothing imports it until a fill asks for it
(``import barymesh`` stays light). Every function is compiled on its first call and
cached on disk (``cache=True``): later processes load the machine code in a fraction of
a second instead of compiling it again (see :func:`barymesh.mom.compiled_fill.warm_up`).

The kernels run in double precision throughout, with ``fastmath`` off: the results
agree with the numpy path's double-precision formulas to rounding (the tests hold them
to 1e-12 of the largest entry). The phase's sine and cosine are written out here as
polynomials (fdlibm's kernels after a three-part reduction by π/2) rather than called
from the C library, so that the compiler can vectorise the loop over source triangles:
a call to ``sin`` stops that.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

# 2/π and π/2 in three parts (fdlibm's pio2_1, pio2_2, pio2_3): n·pio2_1 and n·pio2_2
# are exact for the n of any phase the solver meets, so r = x − n π/2 keeps full precision.
_TWO_OVER_PI = 6.36619772367581382433e-01
_PIO2_1 = 1.57079632673412561417e00
_PIO2_2 = 6.07710050630396597660e-11
_PIO2_3 = 2.02226624871116645580e-21
# fdlibm's __kernel_sin and __kernel_cos on [−π/4, π/4]
_S1 = -1.66666666666666324348e-01
_S2 = 8.33333333332248946124e-03
_S3 = -1.98412698298579493134e-04
_S4 = 2.75573137070700676789e-06
_S5 = -2.50507602534068634195e-08
_S6 = 1.58969099521155010221e-10
_C1 = 4.16666666666666019037e-02
_C2 = -1.38888888888741095749e-03
_C3 = 2.48015872894767294178e-05
_C4 = -2.75573143513906633035e-07
_C5 = 2.08757232129817482790e-09
_C6 = -1.13596475577881948265e-11

#: Source triangles per job of :func:`far_block` (its 16 output rows stay in L1 cache).
SOURCE_CHUNK = 128


@njit(cache=True, inline="always")
def sincos(x: float) -> tuple[float, float]:  # pragma: no cover - compiled
    """sin x and cos x for x ≥ 0, to about an ulp, without a branch or a call."""
    n = np.floor(x * _TWO_OVER_PI + 0.5)
    r = x - n * _PIO2_1
    r = r - n * _PIO2_2
    r = r - n * _PIO2_3
    z = r * r
    s = r + r * z * (_S1 + z * (_S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))))
    c = 1.0 - 0.5 * z + z * z * (_C1 + z * (_C2 + z * (_C3 + z * (_C4 + z * (_C5 + z * _C6)))))
    quadrant = np.int64(n) & 3
    odd = (quadrant & 1) == 1
    sign_s = 1.0 - (quadrant & 2)  # + in quadrants 0, 1
    sign_c = 1.0 - ((quadrant + 1) & 2)  # + in quadrants 0, 3
    sin_x = sign_s * (c if odd else s)
    cos_x = sign_c * (s if odd else c)
    return sin_x, cos_x


@njit(cache=True)
def sincos_array(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # pragma: no cover
    """:func:`sincos` over an array (for the tests, against numpy's sin and cos)."""
    s = np.empty_like(x)
    c = np.empty_like(x)
    for i in range(x.size):
        s[i], c[i] = sincos(x[i])
    return s, c


@njit(parallel=True, cache=True)
def far_block(
    px: np.ndarray,
    py: np.ndarray,
    pz: np.ndarray,
    w: np.ndarray,
    rx: np.ndarray,
    ry: np.ndarray,
    rz: np.ndarray,
    k: float,
    lo: int,
    hi: int,
    out: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Far-rule moments of G of observation triangles lo..hi against sources lo..T.

    ``px`` … ``rz`` are (Q, T): the far rule's points, weights and ρ, one row per point
    of the rule (so that a row runs over triangles, the loop the compiler vectorises).
    ``out`` is (16, hi − lo, T − lo) float64, overwritten: rows 2i and 2i + 1 are the
    real and imaginary parts of moment i (:data:`barymesh.mom.geometry.MOMENTS`) of the
    pair (observation lo + o, source lo + s) at ``[:, o, s]``. Coincident points (a
    triangle against itself) take R = 1, as the numpy path does: such pairs are near
    ones, overwritten afterwards.

    One job is one observation triangle against :data:`SOURCE_CHUNK` sources. Per pair
    of points, the kernel goes into a row of the job's own scratch (a loop of loads and
    arithmetic only, which the compiler vectorises four wide), then into 8 rows summed
    over the source points, which go into the 16 moments once per observation point; a
    single loop doing it all was not vectorised (its 16 output rows and 7 inputs are too
    many possible aliases to check) and ran 2.5 times slower.
    """
    q, t = w.shape
    tb = hi - lo
    ts = t - lo
    chunks = (ts + SOURCE_CHUNK - 1) // SOURCE_CHUNK
    for job in prange(tb * chunks):
        o = job // chunks
        first = lo + (job % chunks) * SOURCE_CHUNK
        n = min(t, first + SOURCE_CHUNK) - first
        p = lo + o
        acc = np.zeros((16, SOURCE_CHUNK))
        g = np.empty((2, SOURCE_CHUNK))
        h = np.empty((8, SOURCE_CHUNK))  # Σ_b w' G and Σ_b w' ρ' G, re and im
        for a in range(q):
            xa, ya, za = px[a, p], py[a, p], pz[a, p]
            wa = w[a, p]
            ax, ay, az = rx[a, p], ry[a, p], rz[a, p]
            h[:, :n] = 0.0
            for b in range(q):
                sx = px[b, first : first + n]
                sy = py[b, first : first + n]
                sz = pz[b, first : first + n]
                sw = w[b, first : first + n]
                for j in range(n):
                    dx = xa - sx[j]
                    dy = ya - sy[j]
                    dz = za - sz[j]
                    r = np.sqrt(dx * dx + dy * dy + dz * dz)
                    r = r if r > 0.0 else 1.0
                    sin_x, cos_x = sincos(k * r)
                    scale = sw[j] / r
                    g[0, j] = cos_x * scale
                    g[1, j] = -sin_x * scale
                bx = rx[b, first : first + n]
                by = ry[b, first : first + n]
                bz = rz[b, first : first + n]
                for j in range(n):
                    gr = g[0, j]
                    gi = g[1, j]
                    h[0, j] += gr
                    h[1, j] += gi
                    h[2, j] += gr * bx[j]
                    h[3, j] += gi * bx[j]
                    h[4, j] += gr * by[j]
                    h[5, j] += gi * by[j]
                    h[6, j] += gr * bz[j]
                    h[7, j] += gi * bz[j]
            # the observation point's weight and ρ, once per point
            for j in range(n):
                h0r = wa * h[0, j]
                h0i = wa * h[1, j]
                hxr = wa * h[2, j]
                hxi = wa * h[3, j]
                hyr = wa * h[4, j]
                hyi = wa * h[5, j]
                hzr = wa * h[6, j]
                hzi = wa * h[7, j]
                acc[0, j] += h0r
                acc[1, j] += h0i
                acc[2, j] += h0r * ax
                acc[3, j] += h0i * ax
                acc[4, j] += h0r * ay
                acc[5, j] += h0i * ay
                acc[6, j] += h0r * az
                acc[7, j] += h0i * az
                acc[8, j] += hxr
                acc[9, j] += hxi
                acc[10, j] += hyr
                acc[11, j] += hyi
                acc[12, j] += hzr
                acc[13, j] += hzi
                acc[14, j] += ax * hxr + ay * hyr + az * hzr
                acc[15, j] += ax * hxi + ay * hyi + az * hzi
        offset = first - lo
        for i in range(16):
            for j in range(n):
                out[i, o, offset + j] = acc[i, j]


@njit(parallel=True, cache=True)
def assemble_block(
    m: np.ndarray,
    lo: int,
    hi: int,
    rows: np.ndarray,
    rwg_triangles: np.ndarray,
    rwg_coef: np.ndarray,
    rwg_offset: np.ndarray,
    tri_unknowns: np.ndarray,
    tri_coef: np.ndarray,
    tri_offset: np.ndarray,
    k: float,
    z: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Add one block's moments ``m`` (16, hi − lo, T − lo) into the rows ``rows`` of Z.

    Per triangle, f_m = c_m (ρ + d_m); a pair of triangles adds to Z_mn (over jη/4π)

        c_m c_n (k ∫∫ρ·ρ'G − 4/k ∫∫G) + k c_n b_m·∫∫ρ'G + k c_m b_n·∫∫ρG + k b_m·b_n ∫∫G

    with b = c d (the offset maps' entries). Each row is one job, so no two threads
    write the same entry. Pairs of two triangles of the block count half: the pair
    (s, p) is in the block too, and Z + Zᵀ (:func:`symmetrize`) adds it back; pairs
    with the source after the block count whole, for the same reason.

    ``rwg_coef`` (N, 2) and ``rwg_offset`` (N, 2, 3) are c and b of each unknown on its
    two triangles ``rwg_triangles`` (N, 2); ``tri_unknowns`` (T, U), ``tri_coef`` (T, U)
    and ``tri_offset`` (T, U, 3) the same per triangle (−1 pads the unknowns).
    """
    ts = m.shape[2]
    width = tri_unknowns.shape[1]
    charge = 4.0 / k
    for i in prange(len(rows)):
        row = rows[i]
        z_row = z[row]
        # per source triangle, α = c_m (k M7 − 4/k M0) + k b_m·M_ρ' and β = k (c_m M_ρ +
        # b_m M0), re and im (a vectorised loop), then Z_mn += c_n α + b_n·β per unknown n
        buf = np.empty((8, ts))
        for side in range(2):
            p = rwg_triangles[row, side]
            if p < lo or p >= hi:
                continue
            o = p - lo
            cm = rwg_coef[row, side]
            bx, by, bz = (
                rwg_offset[row, side, 0],
                rwg_offset[row, side, 1],
                rwg_offset[row, side, 2],
            )
            kc = k * cm
            for j in range(ts):
                half = 0.5 if lo + j < hi else 1.0
                m0r, m0i = m[0, o, j], m[1, o, j]
                buf[0, j] = half * (
                    cm * (k * m[14, o, j] - charge * m0r)
                    + k * (bx * m[8, o, j] + by * m[10, o, j] + bz * m[12, o, j])
                )
                buf[1, j] = half * (
                    cm * (k * m[15, o, j] - charge * m0i)
                    + k * (bx * m[9, o, j] + by * m[11, o, j] + bz * m[13, o, j])
                )
                buf[2, j] = half * (kc * m[2, o, j] + k * bx * m0r)
                buf[3, j] = half * (kc * m[3, o, j] + k * bx * m0i)
                buf[4, j] = half * (kc * m[4, o, j] + k * by * m0r)
                buf[5, j] = half * (kc * m[5, o, j] + k * by * m0i)
                buf[6, j] = half * (kc * m[6, o, j] + k * bz * m0r)
                buf[7, j] = half * (kc * m[7, o, j] + k * bz * m0i)
            for j in range(ts):
                s = lo + j
                ar, ai = buf[0, j], buf[1, j]
                xr, xi = buf[2, j], buf[3, j]
                yr, yi = buf[4, j], buf[5, j]
                wr, wi = buf[6, j], buf[7, j]
                for u in range(width):
                    col = tri_unknowns[s, u]
                    if col < 0:
                        break
                    cn = tri_coef[s, u]
                    ox, oy, oz = tri_offset[s, u, 0], tri_offset[s, u, 1], tri_offset[s, u, 2]
                    z_row[col] += complex(
                        cn * ar + ox * xr + oy * yr + oz * wr,
                        cn * ai + ox * xi + oy * yi + oz * wi,
                    )


@njit(parallel=True, cache=True)
def symmetrize(z: np.ndarray, scale: complex, tile: int) -> None:  # pragma: no cover
    """z ← scale (z + zᵀ) in place, tile by tile (a tile and its mirror per job)."""
    n = z.shape[0]
    tiles = (n + tile - 1) // tile
    for job in prange(tiles * (tiles + 1) // 2):
        # job → (ti, tj) with tj ≤ ti, row by row of the lower triangle of tiles
        ti = np.int64((np.sqrt(8.0 * job + 1.0) - 1.0) / 2.0)
        while ti * (ti + 1) // 2 > job:
            ti -= 1
        while (ti + 1) * (ti + 2) // 2 <= job:
            ti += 1
        tj = job - ti * (ti + 1) // 2
        r0, r1 = ti * tile, min(n, (ti + 1) * tile)
        c0, c1 = tj * tile, min(n, (tj + 1) * tile)
        for r in range(r0, r1):
            for c in range(c0, min(c1, r + 1)):
                v = scale * (z[r, c] + z[c, r])
                z[r, c] = v
                z[c, r] = v

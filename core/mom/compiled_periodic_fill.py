"""The periodic EFIE matrix assembled by compiled, multi-threaded loops (numba).

The fast path beside the numpy assembly of :mod:`barymesh.mom.periodic_fill`, which stays
the reference: the tests hold the two to 1e-12 of the largest entry, the numpy path run
in double precision (``double=True``; by default it computes the Taylor expansion, the
phases and the RWG products in single precision, about 1e-7 of the entries). What is
shared is the per-frequency tables of G_reg (its Taylor table, the exact Floquet
orders), the near pairs' closed forms and the plan; what is compiled is the part that
grows as T² and N² (the expansion of every pair, its Floquet phase, and the products
with the RWG maps) and the close pairs' far-rule moments, taken in double precision
(:mod:`barymesh.mom.periodic_fill_kernels`).

Each block of observation triangles fills its (3, B, N) rows of the right factor R
(16 observers per thread, reading the plan's per-pair arrays from a copy laid out chunk of
observers by chunk, :class:`PairRows`), then adds them into the rows of Z of the unknowns on those
triangles (one row per thread): no sparse product, no (6, 2, T, B) planes in memory,
and R never held whole, so that the memory beside Z stays one block's 8 MB.

Like :mod:`barymesh.mom.compiled_fill`, whose lock and thread count it shares (one
compiled fill at a time per process), it imports numba on the first fill; the kernels
are cached on disk, and :func:`warm_up` (which ``make`` runs) compiles them ahead.
"""

from __future__ import annotations

import logging
import time
import weakref
from dataclasses import dataclass
from types import ModuleType

import numpy as np
import scipy.sparse as sp

from . import compiled_fill
from .periodic_plan import FillPlan

log = logging.getLogger(__name__)

#: Bytes of one block of R (3 rows of N complex per observation triangle).
BLOCK_BYTES = 8 << 20

_KERNELS: ModuleType | None = None


def kernels() -> ModuleType:
    """The periodic kernels' module, imported on first use (numba and the free-space
    kernels with it, whose sine and cosine it uses)."""
    global _KERNELS
    if _KERNELS is None:
        compiled_fill.kernels()  # sets the OpenMP wait policy before numba loads
        from . import periodic_fill_kernels

        _KERNELS = periodic_fill_kernels
    return _KERNELS


def is_cached() -> bool:
    """Whether the periodic kernels were compiled and cached before (by file name)."""
    names = ("right_block", "rows_block", "close_moments")
    return all(
        any(
            any(folder.glob(f"periodic_fill_kernels.{name}-*.nbi"))
            for folder in compiled_fill.cache_folders()
        )
        for name in names
    )


@dataclass(frozen=True, eq=False)
class Slots:
    """Each unknown's triangles with its coefficients, as the compiled loops read them.

    One slot is one (unknown, triangle) pair of the RWG maps [C | D_x | D_y]; the T−
    halves across the cell's sides (the plan's ``folded`` rows) are slots of their own,
    carrying their unknown's Floquet phase.

    Attributes
    ----------
    unknown : (K,) intp
    triangle : (K,) intp
    coef : (K, 3) float64
        C, D_x, D_y of the slot (the plan's scaled single-precision maps).
    crossing : (K,) intp
        Row of ``plan.crossing_rows`` whose phase the slot carries, −1 for none.
    by_source : (K,) intp
        The slots sorted by unknown, then triangle (the order in which
        :func:`~barymesh.mom.periodic_fill_kernels.right_block` sums them).
    by_unknown : (K,) intp
        The slots sorted by unknown; ``unknown_starts`` (N + 1,) where each begins.
    """

    unknown: np.ndarray
    triangle: np.ndarray
    coef: np.ndarray
    crossing: np.ndarray
    by_source: np.ndarray
    by_unknown: np.ndarray
    unknown_starts: np.ndarray


_SLOTS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _entries(matrix: sp.csr_matrix, t: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(row, triangle, (., 3) coefficients) of each distinct (row, triangle) of ``matrix``."""
    coo = sp.coo_matrix(matrix)
    key = coo.row.astype(np.int64) * t + coo.col % t
    unique, where = np.unique(key, return_inverse=True)
    coef = np.zeros((len(unique), 3))
    np.add.at(coef, (where, coo.col // t), coo.data.astype(np.float64))
    return (unique // t).astype(np.intp), (unique % t).astype(np.intp), coef


def slots(plan: FillPlan, n: int, t: int) -> Slots:
    """The :class:`Slots` of ``plan`` (cached per plan: a sweep builds them once)."""
    if plan in _SLOTS:
        return _SLOTS[plan]
    rows, tri, coef = _entries(plan.maps, t)
    f_rows, f_tri, f_coef = _entries(plan.folded, t)
    unknown = np.concatenate([rows, np.asarray(plan.crossing_rows, dtype=np.intp)[f_rows]])
    triangle = np.concatenate([tri, f_tri])
    crossing = np.concatenate([np.full(len(rows), -1, dtype=np.intp), f_rows])
    by_source = np.lexsort((triangle, unknown))  # stable: a crossing half after its own
    by_unknown = np.argsort(unknown, kind="stable")
    out = Slots(
        unknown=unknown,
        triangle=triangle,
        coef=np.concatenate([coef, f_coef]),
        crossing=crossing,
        by_source=by_source,
        by_unknown=by_unknown,
        unknown_starts=np.searchsorted(unknown[by_unknown], np.arange(n + 1)),
    )
    _SLOTS[plan] = out
    return out


@dataclass(frozen=True, eq=False)
class PairRows:
    """The plan's per-pair arrays as :func:`~barymesh.mom.periodic_fill_kernels.right_block`
    reads them: observer chunk by chunk, so that one source's rows for a chunk of
    :data:`~barymesh.mom.periodic_fill_kernels.OBSERVER_CHUNK` observers are contiguous.

    Attributes
    ----------
    values : (G, T, 6, W) float32
        Offset from the node (x, y), distance, inverse distance, unit vector (x, y) of
        the pair [s, o] at [o // W, s, :, o % W] (the plan's, copied; 0 past T).
    codes : (G, T, 2, W) int32
        The Taylor node and σ code of the pair, same places.
    """

    values: np.ndarray
    codes: np.ndarray


_PAIRS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def has_pair_rows(plan: FillPlan) -> bool:
    """Whether :func:`pair_rows` of ``plan`` is made (and kept) already."""
    return plan in _PAIRS


def pair_rows(plan: FillPlan) -> PairRows:
    """The :class:`PairRows` of ``plan`` (cached per plan: a sweep builds them once).

    A copy of the plan's per-pair arrays (32 bytes per pair, counted in
    :data:`~barymesh.mom.periodic_checks.GEOMETRY_BYTES_PER_T2`): read in the plan's
    [source, observation] order, one source's 16 observers were 8 rows 2.9 KB apart at
    1,042 unknowns, and the pair loop waited on memory for a third of its gathering;
    here they are 512 contiguous bytes, the next source's right after.
    """
    if plan in _PAIRS:
        return _PAIRS[plan]
    w = kernels().OBSERVER_CHUNK
    t = plan.node.shape[0]
    g = (t + w - 1) // w
    values = np.zeros((g, t, 6, w), dtype=np.float32)
    codes = np.zeros((g, t, 2, w), dtype=np.int32)
    planes = (plan.offset[0], plan.offset[1], plan.distance, plan.inverse, *plan.unit)
    for j, plane in enumerate(planes):
        padded = np.zeros((t, g * w), dtype=np.float32)
        padded[:, :t] = plane
        values[:, :, j, :] = padded.reshape(t, g, w).transpose(1, 0, 2)
    for j, plane in enumerate((plan.node, plan.sigma_code)):
        padded = np.zeros((t, g * w), dtype=np.int32)
        padded[:, :t] = plane
        codes[:, :, j, :] = padded.reshape(t, g, w).transpose(1, 0, 2)
    out = PairRows(values=values, codes=codes)
    _PAIRS[plan] = out
    return out


def triangle_moments(plan: FillPlan) -> np.ndarray:
    """(T, 11) float64 A, I_00, I_01, I_10, I_11, J_000, J_001, J_011, J_100, J_101, J_111
    of each triangle (the plan's, widened): what a pair's expansion reads of its two."""
    third = plan.third
    return np.column_stack(
        [
            plan.areas,
            plan.second.reshape(-1, 4),
            third[:, 0, 0, 0],
            third[:, 0, 0, 1],
            third[:, 0, 1, 1],
            third[:, 1, 0, 0],
            third[:, 1, 0, 1],
            third[:, 1, 1, 1],
        ]
    ).astype(np.float64)


@dataclass(frozen=True)
class Medium:
    """What the compiled loops need of one Green's function's per-frequency tables.

    Attributes
    ----------
    tables : (G², 12) float64
        G_reg's Taylor table in units of the plan's scale.
    k : complex
        The wavenumber times the plan's scale.
    special : (6, 2, M) or (1, 2, M) float64
        The near and close pairs' moments (``periodic_fill.special_moments`` with
        ``compiled``).
    """

    tables: np.ndarray
    k: complex
    special: np.ndarray


def compiled_periodic_matrix(
    plan: FillPlan,
    n: int,
    unknown_phase: np.ndarray,
    vector: Medium,
    phases: np.ndarray,
    scale: float,
    factor: complex,
    scalar: Medium | None = None,
    mu: complex = 1.0,
    inv_eps: complex = 1.0,
) -> np.ndarray:
    """:func:`_compiled_periodic_matrix`, one compiled fill at a time (``FILL_LOCK``)."""
    with compiled_fill.FILL_LOCK:
        return _compiled_periodic_matrix(
            plan, n, unknown_phase, vector, phases, scale, factor, scalar, mu, inv_eps
        )


def _compiled_periodic_matrix(
    plan: FillPlan,
    n: int,
    unknown_phase: np.ndarray,
    vector: Medium,
    phases: np.ndarray,
    scale: float,
    factor: complex,
    scalar: Medium | None,
    mu: complex,
    inv_eps: complex,
) -> np.ndarray:
    """The (N, N) periodic EFIE matrix without its exact Floquet orders (SI, Ω).

    Parameters
    ----------
    plan : FillPlan
    n : int
        Number of unknowns.
    unknown_phase : (C,) complex
        e^(−j k_t·a) of the unknowns across the cell's sides (``plan.crossing_rows``).
    vector : Medium
        G_A's tables (in vacuum, G_p's; the charge moment from them too).
    phases : (S,) complex
        e^(−j k_t·ρ_σ) of each σ code of the plan.
    scale : float
        4/(k h)², the charge term's weight against ρ·ρ'.
    factor : complex
        jkη/4π h³: Z in ohms from the scaled moments.
    scalar : Medium, optional
        G_Φ's tables on layers (its ``special`` the charge moment only).
    mu, inv_eps : complex
        μ̃ and 1/ε̄ of the layered kernel's homogeneous limits.
    """
    if _KERNELS is None:
        warm_up()  # the cache's warning, if it has to compile
    kern = kernels()
    compiled_fill.use_fill_threads()
    t = plan.areas.shape[0]
    table = slots(plan, n, t)
    pairs = pair_rows(plan)
    in_phase = np.ones(len(table.unknown), dtype=np.complex128)
    crossed = table.crossing >= 0
    in_phase[crossed] = unknown_phase[table.crossing[crossed]]
    by_s, by_u = table.by_source, table.by_unknown
    moments = triangle_moments(plan)
    layered = scalar is not None
    phi = scalar if scalar is not None else vector
    z = np.zeros((n, n), dtype=np.complex128)
    block = max(4, min(t, BLOCK_BYTES // (48 * max(1, n))))
    scratch = np.empty(3 * block * n, dtype=np.complex128)
    tst_triangle = table.triangle[by_u]
    for lo in range(0, t, block):
        hi = min(t, lo + block)
        right = scratch[: 3 * (hi - lo) * n].reshape(3, hi - lo, n)  # zeroed by the kernel
        kern.right_block(
            pairs.values,
            pairs.codes,
            plan.sigma_code,
            moments,
            plan.special,
            plan.special_starts,
            vector.tables,
            complex(vector.k),
            vector.special,
            layered,
            phi.tables,
            complex(phi.k),
            phi.special,
            complex(mu),
            complex(inv_eps),
            phases,
            float(scale),
            table.unknown_starts,
            table.triangle[by_s],
            table.coef[by_s],
            in_phase[by_s],
            complex(factor),
            lo,
            hi,
            right,
        )
        inside = (tst_triangle >= lo) & (tst_triangle < hi)
        rows = np.unique(table.unknown[by_u][inside])
        kern.rows_block(
            rows,
            table.unknown_starts,
            tst_triangle,
            table.coef[by_u],
            np.conj(in_phase[by_u]),
            lo,
            hi,
            right,
            z,
        )
    return z


def warm_up() -> float:
    """Compile (or load from the cache) the free-space and periodic kernels; the seconds.

    The periodic kernels take about as long as the free-space ones to compile, once per
    installation (``make`` runs this); a fill that finds no cache logs a warning first.
    """
    start = time.perf_counter()
    compiled_fill.warm_up()
    if not is_cached():
        log.warning(
            "compiling the periodic solver's fill kernels with numba: once per "
            "installation, about 15-25 s; later runs load them from the cache"
        )
    kern = kernels()
    t, n = 2, 2
    f32 = np.float32
    w = kern.OBSERVER_CHUNK
    tables = np.zeros((1, 12))
    special = np.zeros((6, 2, 1))
    right = np.zeros((3, t, n), dtype=np.complex128)
    starts = np.array([0, 1, 2], dtype=np.intp)
    unknowns = np.array([0, 1], dtype=np.intp)
    coef = np.ones((2, 3))
    ones = np.ones(2, dtype=np.complex128)
    for layered in (False, True):
        kern.right_block(
            np.zeros((1, t, 6, w), dtype=f32),
            np.zeros((1, t, 2, w), dtype=np.int32),
            np.zeros((t, t), dtype=np.int16),
            np.ones((t, 11)),
            np.zeros((1, 2), dtype=np.intp),
            np.array([0, 1, 1], dtype=np.intp),
            tables,
            1.0 + 0j,
            special,
            layered,
            tables,
            1.0 + 0j,
            special[:1],
            1.0 + 0j,
            1.0 + 0j,
            ones[:1],
            1.0,
            starts,
            unknowns,
            coef,
            ones,
            1.0 + 0j,
            0,
            t,
            right,
        )
    kern.rows_block(
        unknowns, starts, unknowns, coef, ones, 0, t, right, np.zeros((n, n), dtype=np.complex128)
    )
    for count in (6, 1):  # the vector potential's moments, the charge's alone
        kern.close_moments(
            np.ones((1, 1), dtype=f32),
            np.ones((count, 1, 1), dtype=f32),
            1.0,
            -0.5,
            np.zeros(1, dtype=np.intp),
            np.ones(1, dtype=np.intp),
            np.arange(2 * count, dtype=np.intp),
            np.zeros((2 * count, 2)),
        )
    return time.perf_counter() - start

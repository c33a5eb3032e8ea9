"""The free-space EFIE matrix filled by compiled, multi-threaded loops (numba).

The fast path beside :func:`barymesh.mom.operator.impedance_matrix`'s numpy fill, which
stays the reference: the tests hold the two to 1e-12 of the largest entry (the numpy
path with its far kernel in double precision). Same moments, same near pairs, same
symmetry; what changes is how the far pairs are integrated and assembled:

- :func:`~barymesh.mom.fill_kernels.far_block` computes the eight far-rule moments of a
  block of observation triangles against every source triangle after the block's first,
  from the quadrature points directly (no (T Q, T Q) table of distances or kernel), on
  every core, the loop over source triangles vectorised;
- the near pairs' moments (numpy, :func:`~barymesh.mom.operator.near_moments`, in double
  precision) overwrite theirs;
- :func:`~barymesh.mom.fill_kernels.assemble_block` adds each pair's moments straight
  into the rows of Z of the unknowns living on the block's triangles (one row per
  thread), instead of two sparse products and a scatter;
- Z is filled for source triangles from the block on only (each pair once, pairs inside
  a block at half weight), and :func:`~barymesh.mom.fill_kernels.symmetrize` makes it
  Z + Zᵀ at the end: the Galerkin matrix of a reciprocal operator is symmetric.

numba is imported on the first fill only (:func:`kernels`); its compiled code is cached
on disk, so that only the first fill on a machine pays the compilation (about 16 s here,
with a warning logged first; :func:`warm_up` does it ahead of time, and ``make`` runs it).
"""

from __future__ import annotations

import importlib.util
import logging
import os
import threading
import time
import weakref
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

import numpy as np

from ..constants import ETA0
from .geometry import MomGeometry

log = logging.getLogger(__name__)

#: The environment variable that picks the fill: "numpy" for the reference path,
#: "numba" (or unset) for the compiled one when numba is installed.
BACKEND_VARIABLE = "BARYMESH_FILL"
#: The backends :func:`resolve_backend` accepts.
BACKENDS = ("numba", "numpy")
#: Bytes of one block's moments (16 float64 per triangle pair): small enough to stay in
#: the processor's last-level cache between the kernel that writes them and the
#: assembly that reads them.
BLOCK_BYTES = 8 << 20
#: Rows and columns of a tile of :func:`~barymesh.mom.fill_kernels.symmetrize`.
SYMMETRIZE_TILE = 64

_KERNELS: ModuleType | None = None
#: One compiled fill at a time per process. numba's parallel loops run on one thread pool;
#: its workqueue layer (numba's fallback where neither OpenMP nor TBB loads) aborts the
#: process when two threads launch into it at once, which the window's solve and array
#: panels, or a study's threads, would do. A second fill waits for the first, each still
#: on every core.
FILL_LOCK = threading.Lock()


def numba_available() -> bool:
    """Whether numba can be imported (without importing it)."""
    try:
        return importlib.util.find_spec("numba") is not None
    except (ImportError, ValueError):  # a module set to None in sys.modules: blocked
        return False


def resolve_backend(backend: str | None) -> str:
    """The fill to run: ``backend``, else :data:`BACKEND_VARIABLE`, else numba if installed.

    Raises
    ------
    ValueError
        If ``backend`` (or the variable) names no backend, or asks for numba where it
        is not installed.
    """
    chosen = backend if backend is not None else os.environ.get(BACKEND_VARIABLE) or None
    if chosen is None:
        return "numba" if numba_available() else "numpy"
    if chosen not in BACKENDS:
        where = "backend" if backend is not None else BACKEND_VARIABLE
        raise ValueError(f"{where}={chosen!r} is not a fill backend; expected one of {BACKENDS}")
    if chosen == "numba" and not numba_available():
        raise ValueError("backend='numba' asks for numba, which is not installed")
    return chosen


def kernels() -> ModuleType:
    """The compiled kernels' module, imported on first use (numba with it)."""
    global _KERNELS
    if _KERNELS is None:
        start = time.perf_counter()
        # OpenMP threads that wait at the end of a parallel loop sleep instead of spinning
        # (unless the user chose): on a shared 2-core machine a spinning thread takes the
        # core the other one needs, and the 9,976-unknown fill took 20 s against 12 s
        os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
        from . import fill_kernels

        _KERNELS = fill_kernels
        log.debug("numba and the fill kernels imported in %.2f s", time.perf_counter() - start)
    return _KERNELS


def fill_threads(cores: int) -> int:
    """Threads of the compiled fill: ``cores`` (numba's), fewer when OMP_NUM_THREADS says so.

    numba reads NUMBA_NUM_THREADS only (its ``cores`` here); process pools that give each
    worker one thread set OMP_NUM_THREADS=1 and the like (Dask's nanny does, for
    ``barymesh study``), and two fills of two threads each on two cores run slower than two
    of one: the threads wait for each other at every block.
    """
    if os.environ.get("NUMBA_NUM_THREADS"):
        return cores
    try:
        limit = int(os.environ.get("OMP_NUM_THREADS", ""))
    except ValueError:
        return cores
    return max(1, min(cores, limit))


def use_fill_threads() -> None:
    """Give this thread's compiled loops :func:`fill_threads` threads (numba imported).

    numba's thread count is per calling thread: set at each fill, so that a solve in a
    worker thread has it too.
    """
    import numba  # imported by the kernels' module already

    cores = numba.config.NUMBA_NUM_THREADS  # type: ignore[attr-defined]  # set at import
    numba.set_num_threads(fill_threads(cores))


def cache_folders() -> list[Path]:
    """Where numba may keep the compiled kernels: NUMBA_CACHE_DIR, else beside this module."""
    folders = [Path(__file__).resolve().parent / "__pycache__"]
    if os.environ.get("NUMBA_CACHE_DIR"):
        # numba mirrors the module's folder under it
        root = Path(os.environ["NUMBA_CACHE_DIR"])
        folders = [root / p.relative_to(p.anchor) for p in folders] + folders
    return folders


def is_cached() -> bool:
    """Whether the fill's kernels were compiled and cached before (by file name; a cache
    made stale by a changed source is found here, then recompiled by numba silently)."""
    names = ("far_block", "assemble_block", "symmetrize")
    return all(
        any(any(folder.glob(f"fill_kernels.{name}-*.nbi")) for folder in cache_folders())
        for name in names
    )


def warm_up() -> float:
    """Compile (or load from the cache) the kernels on a tiny problem; the seconds it took.

    The first compiled fill on a machine compiles the kernels, about 15 s of CPU (their
    machine code is then cached on disk, and later processes load it in well under a
    second). ``make`` runs this once after installing, so that no solve pays for it; a
    fill that finds no cache logs a warning before it compiles.
    """
    start = time.perf_counter()
    if not is_cached():
        log.warning(
            "compiling the solver's fill kernels with numba: once per installation, about "
            "15-25 s; later runs load them from the cache"
        )
    kern = kernels()
    columns = [np.ascontiguousarray(np.arange(6.0).reshape(1, 6) * (c + 1)) for c in range(7)]
    m = np.zeros((16, 2, 6))
    kern.far_block(*columns, 1.0, 0, 2, m)
    rwg_triangles = np.array([[0, 1], [1, 2]], dtype=np.intp)
    rows = np.flatnonzero(np.ones(2, dtype=bool))
    tri_unknowns = np.array([[0], [0], [1], [-1], [-1], [-1]], dtype=np.intp)
    z = np.zeros((2, 2), dtype=np.complex128)
    kern.assemble_block(
        m,
        0,
        2,
        rows,
        rwg_triangles,
        np.ones((2, 2)),
        np.zeros((2, 2, 3)),
        tri_unknowns,
        np.ones((6, 1)),
        np.zeros((6, 1, 3)),
        1.0,
        z,
    )
    kern.symmetrize(z, 1j, SYMMETRIZE_TILE)
    return time.perf_counter() - start


@dataclass(frozen=True, eq=False)
class CompiledTables:
    """The per-mesh arrays the compiled fill reads, in the layouts its loops want.

    Attributes
    ----------
    points : tuple of seven (Q, T) float64
        The far rule's x, y, z, weights and ρ_x, ρ_y, ρ_z, one row per point of the rule.
    rwg_coef : (N, 2) float64
        c = ± l / 2A of each unknown on its triangles T+, T−.
    rwg_offset : (N, 2, 3) float64
        b = c (c_p − v_free) of each unknown on its two triangles.
    tri_unknowns : (T, U) intp
        The unknowns living on each triangle, −1 after the last (U is 3 on a manifold).
    tri_coef : (T, U) float64
    tri_offset : (T, U, 3) float64
    """

    points: tuple[np.ndarray, ...]
    rwg_coef: np.ndarray
    rwg_offset: np.ndarray
    tri_unknowns: np.ndarray
    tri_coef: np.ndarray
    tri_offset: np.ndarray


_TABLES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def compiled_tables(geom: MomGeometry) -> CompiledTables:
    """The :class:`CompiledTables` of ``geom`` (cached per geometry: a sweep builds them once)."""
    if geom in _TABLES:
        return _TABLES[geom]
    far = geom.far
    points = tuple(
        np.ascontiguousarray(a.T)
        for a in (
            far.points[:, :, 0],
            far.points[:, :, 1],
            far.points[:, :, 2],
            far.weights,
            far.rho[:, :, 0],
            far.rho[:, :, 1],
            far.rho[:, :, 2],
        )
    )
    tri = geom.rwg_triangles
    n = geom.n_unknowns
    rows = np.arange(n)
    coef = geom.coef_matrix.tocsr()
    rwg_coef = np.stack([np.asarray(coef[rows, tri[:, s]]).ravel() for s in range(2)], axis=1)
    rwg_offset = np.stack(
        [
            np.stack(
                [
                    np.asarray(geom.offset_matrices[c].tocsr()[rows, tri[:, s]]).ravel()
                    for c in range(3)
                ],
                axis=1,
            )
            for s in range(2)
        ],
        axis=1,
    )
    # per triangle, its unknowns in order (a triangle of a junction may carry more than 3)
    flat_tri = tri.ravel()
    order = np.argsort(flat_tri, kind="stable")
    counts = np.bincount(flat_tri, minlength=geom.n_triangles)
    width = max(1, int(counts.max()) if len(counts) else 1)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    slot = np.arange(len(order)) - np.repeat(starts, counts)
    t_sorted = flat_tri[order]
    tri_unknowns = np.full((geom.n_triangles, width), -1, dtype=np.intp)
    tri_coef = np.zeros((geom.n_triangles, width))
    tri_offset = np.zeros((geom.n_triangles, width, 3))
    tri_unknowns[t_sorted, slot] = order // 2
    tri_coef[t_sorted, slot] = rwg_coef.ravel()[order]
    tri_offset[t_sorted, slot] = rwg_offset.reshape(-1, 3)[order]
    out = CompiledTables(points, rwg_coef, rwg_offset, tri_unknowns, tri_coef, tri_offset)
    _TABLES[geom] = out
    return out


def block_size(n_triangles: int) -> int:
    """Observation triangles per block: :data:`BLOCK_BYTES` of moments, at least 4."""
    return max(4, BLOCK_BYTES // (128 * max(1, n_triangles)))


def compiled_impedance_matrix(geom: MomGeometry, k: float, near: np.ndarray) -> np.ndarray:
    """:func:`_compiled_impedance_matrix`, one fill at a time (:data:`FILL_LOCK`)."""
    with FILL_LOCK:
        return _compiled_impedance_matrix(geom, k, near)


def _compiled_impedance_matrix(geom: MomGeometry, k: float, near: np.ndarray) -> np.ndarray:
    """The (N, N) complex EFIE matrix by the compiled loops (see the module's text).

    Parameters
    ----------
    geom : MomGeometry
    k : float
        Free-space wavenumber (rad/m), > 0 (checked by the caller).
    near : (K, 8) complex
        The moments of the near pairs ``geom.near_pairs``
        (:func:`~barymesh.mom.operator.near_moments`).

    Returns
    -------
    (N, N) complex128
        Z in ohms, as :func:`~barymesh.mom.operator.impedance_matrix`.
    """
    if _KERNELS is None:
        warm_up()  # the cache's warning, if it has to compile
    kern = kernels()
    use_fill_threads()
    tables = compiled_tables(geom)
    t = geom.n_triangles
    n = geom.n_unknowns
    z = np.zeros((n, n), dtype=np.complex128)
    pairs = geom.near_pairs
    starts = np.searchsorted(pairs[:, 0], np.arange(t + 1))
    near_split = np.empty((16, len(near)))
    near_split[0::2] = near.real.T
    near_split[1::2] = near.imag.T
    block = block_size(t)
    scratch = np.empty(16 * block * t)
    rwg_tri = geom.rwg_triangles
    for lo in range(0, t, block):
        hi = min(t, lo + block)
        m = scratch[: 16 * (hi - lo) * (t - lo)].reshape(16, hi - lo, t - lo)
        kern.far_block(*tables.points, float(k), lo, hi, m)
        span = slice(starts[lo], starts[hi])
        keep = pairs[span, 1] >= lo
        obs = pairs[span, 0][keep] - lo
        src = pairs[span, 1][keep] - lo
        m[:, obs, src] = near_split[:, span][:, keep]
        rows = np.flatnonzero(((rwg_tri >= lo) & (rwg_tri < hi)).any(axis=1))
        kern.assemble_block(
            m,
            lo,
            hi,
            rows,
            rwg_tri,
            tables.rwg_coef,
            tables.rwg_offset,
            tables.tri_unknowns,
            tables.tri_coef,
            tables.tri_offset,
            float(k),
            z,
        )
    scale = complex(1j * ETA0 / (4.0 * np.pi))
    kern.symmetrize(z, scale, SYMMETRIZE_TILE)
    _restore_self_asymmetry(z, geom, tables, k, near, scale)
    return z


def _restore_self_asymmetry(
    z: np.ndarray,
    geom: MomGeometry,
    tables: CompiledTables,
    k: float,
    near: np.ndarray,
    scale: complex,
) -> None:
    """Give back the self pairs' antisymmetric part that Z + Zᵀ averaged away, in place.

    A triangle against itself is the one pair whose moments are not mirror images:
    its static part integrates ρ by the rule and ρ' in closed form, so ∫∫ρG and ∫∫ρ'G
    differ by the rule's error. The numpy fill keeps that difference; here the
    symmetrisation halved it into both Z_mn and Z_nm. With v_mn the self pair's term of
    Z_mn (:func:`~barymesh.mom.fill_kernels.assemble_block`), Z_mn gets ½ (v_mn − v_nm)
    = ½ k (c_n b_m − c_m b_n)·(∫∫ρ'G − ∫∫ρG) back, so the two fills agree to rounding.
    """
    pairs = geom.near_pairs
    own = np.flatnonzero(pairs[:, 0] == pairs[:, 1])
    tri = pairs[own, 0]
    diff = near[own, 4:7] - near[own, 1:4]  # (T, 3) complex
    unknowns = tables.tri_unknowns[tri]
    coef = tables.tri_coef[tri]
    offset = tables.tri_offset[tri]
    width = unknowns.shape[1]
    for u in range(width):
        for v in range(width):
            if u == v:
                continue
            ok = (unknowns[:, u] >= 0) & (unknowns[:, v] >= 0)
            cross = coef[:, v, None] * offset[:, u] - coef[:, u, None] * offset[:, v]
            value = (0.5 * k) * scale * np.einsum("tc,tc->t", cross[ok], diff[ok])
            np.add.at(z, (unknowns[ok, u], unknowns[ok, v]), value)

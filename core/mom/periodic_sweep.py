"""Frequency sweeps of an infinite array: point by point, or by adaptive rational fits.

:func:`periodic_sweep` solves the array of a unit cell (:func:`~barymesh.mom.periodic_solve`)
at the frequencies asked for, or, with ``interpolate=True`` (the default), at a few of them
chosen greedily, and reports the rest from rational fits of the Floquet coefficients (AAA,
Nakatsukasa, Sète & Trefethen 2018, :class:`scipy.interpolate.AAA`).

The coefficients are analytic in frequency except where a Floquet order (p, q) starts to
propagate (a grating lobe, or Wood-Rayleigh anomaly, at |κ_pq| = k): there they have a
square-root branch point. So the band is cut at every onset, each piece is fitted on its
own, and each piece has a sample just above or just below the onset
(:data:`ONSET_OFFSET`, relative).

In each piece, the reflection coefficients of the (0, 0) order (its T is δ + R on a
zero-thickness screen) are fitted on all samples, and, for the error estimate, three
times more (:data:`FOLDS`), each time leaving out every third sample but the piece's two
ends (sorted by frequency: the first fit leaves out samples 1, 4, 7, ..., the second 2,
5, 8, ..., the third 3, 6, 9, ...). The estimated error at a requested frequency is the
largest difference between the fit on all samples and any of those three; the next sample
goes where that estimate is largest over the whole band, until it is below ``tolerance``
everywhere. The left-out fits use two thirds of the samples, so the estimate is
pessimistic for the fit on all of them, which is the one reported. (Against fits on
halves, the even- and odd-numbered samples, it takes 10 to 20 % fewer solves for the same
tolerance; against point-by-point solves of eight cells and angles, the reported curves
stay within 0.6 times the tolerance: ``benchmarks/sweep_accuracy.py``.)

Each sample's matrix is filled in the calling thread and factorised in a worker thread
(:class:`_Samples`), so the next sample is filled beside the last one's LU; the next
sample is then chosen before the last one's result is in (:data:`OVERLAP_MARGIN`).
"""

from __future__ import annotations

import contextlib
import logging
import math
import os
import warnings
from collections import deque
from collections.abc import Callable, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from scipy.interpolate import AAA
from scipy.signal import find_peaks

from ..mesh import TriMesh
from .compiled_periodic_fill import has_pair_rows
from .excitation import PlaneWave
from .floquet import (
    grating_lobe_onsets,
    incidence_direction,
    merged_onsets,
    order_onsets,
    te_tm_polarizations,
)
from .operator import wavenumber
from .periodic import (
    FilledSystem,
    blas_threads,
    check_stack,
    fill_system,
    one_blas_thread,
    solve_system,
)
from .periodic_caveats import onset_resonance_warning
from .periodic_checks import as_lattice, check_green_terms, check_periodic_memory
from .periodic_geometry import lattice_metres, periodic_geometry
from .periodic_green import reciprocal_vectors
from .periodic_sweep_result import PeriodicSweep
from .solve import SolveCancelled, check_frequencies, check_sheet_impedance, memory_allowance
from .stack import Stack

log = logging.getLogger(__name__)

#: Relative distance of the samples placed just below and just above a grating-lobe onset
#: (closer, the solver's own power balance degrades: 6e-4 at 1e-4, 1.5e-3 at 1e-5 above
#: the (1, ±1) onset of an 8 mm patch array at 30°).
ONSET_OFFSET = 1e-4
#: Samples a piece of the band starts with (both ends included).
INITIAL_SAMPLES = 5
#: Folds of the error estimate: each fit leaves out every FOLDS-th inner sample.
FOLDS = 3
#: Smallest prominence of a peak or dip of |R_co| reported as a resonance.
RESONANCE_PROMINENCE = 0.05
#: Fill each frequency while the last one's LU runs in a worker thread (:class:`_Samples`).
OVERLAP = True
#: While a sample is being solved, the next is chosen only where the estimated error is
#: at least this many times the tolerance (else after that sample). Replayed on stored
#: solves of ``benchmarks/sweep_accuracy.py``'s eight cells and the 1,452-triangle slot:
#: 5 % more solves than one after another, against 10 % at 1.
OVERLAP_MARGIN = 3.0
#: Bytes per N² that a second matrix in flight adds: Z (complex128) and its
#: single-precision LU, beside the next frequency's fill.
OVERLAP_BYTES_PER_N2 = 24.0

__all__ = [
    "ONSET_OFFSET",
    "PeriodicSweep",
    "grating_lobe_onsets",
    "periodic_sweep",
    "te_tm_polarizations",
]


def _fit(x: np.ndarray, values: np.ndarray, clean_up: bool = True) -> list[AAA]:
    """One AAA fit per column of ``values`` (S, M) at points ``x`` (S,).

    ``clean_up``: remove Froissart doublets (spurious pole-zero pairs) from the fits, as
    AAA does by default; the error estimate's fits skip it (half their time; a doublet
    left there can only raise the estimate, so it costs a sample, never accuracy).
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return [AAA(x, values[:, m], clean_up=clean_up) for m in range(values.shape[1])]


def _evaluate(fits: list[AAA], x: np.ndarray) -> np.ndarray:
    out = np.stack([np.asarray(r(x), dtype=np.complex128) for r in fits], axis=1)
    return np.where(np.isfinite(out), out, np.inf)  # a pole on the grid: a huge error


@dataclass
class _Piece:
    """One piece of the band between grating-lobe onsets (mutable, private to the sweep)."""

    lo: float  # ends of the piece (Hz): band edges, or onsets ± ONSET_OFFSET
    hi: float
    grid: np.ndarray  # indices of the requested frequencies in it
    n_orders: int  # orders propagating in it: the first n_orders of the sweep's
    samples: dict  # frequency -> (R, T), each (n_orders, 2, K)
    branch_lo: float | None = None  # the onset at its lower end (a branch point), if any
    branch_hi: float | None = None
    error: np.ndarray = field(default_factory=lambda: np.zeros(0))  # (len(grid),)
    gain: np.ndarray | None = None  # (len(grid),) max(1, |b|) of T = a δ + b R on layers
    stale: bool = True  # samples were added since ``error`` was estimated

    def scale(self, f: np.ndarray) -> np.ndarray:
        """The fit's variable x in [−1, 1]: analytic in x at an onset's square-root branch.

        Near an onset f0 a coefficient is A(f) + B(f) sqrt(|f − f0|) with A, B analytic,
        so it is analytic in s = sqrt(|f − f0|): x is linear in s at a piece with one
        onset end, and in t, f = a + (b − a) sin² t, at one between two onsets.
        """
        f = np.asarray(f, dtype=np.float64)
        a = self.lo if self.branch_lo is None else self.branch_lo
        b = self.hi if self.branch_hi is None else self.branch_hi
        width = max(b - a, 1.0)
        u = np.clip((f - a) / width, 0.0, 1.0)
        if self.branch_lo is not None and self.branch_hi is not None:
            return 4.0 / np.pi * np.arcsin(np.sqrt(u)) - 1.0
        if self.branch_lo is not None:
            return 2.0 * np.sqrt(u) - 1.0
        if self.branch_hi is not None:
            return 1.0 - 2.0 * np.sqrt(1.0 - u)
        return 2.0 * u - 1.0

    def unscale(self, x: np.ndarray) -> np.ndarray:
        """Frequency (Hz, complex for poles) of the fit's variable x (inverse of scale)."""
        x = np.asarray(x, dtype=np.complex128)
        a = self.lo if self.branch_lo is None else self.branch_lo
        b = self.hi if self.branch_hi is None else self.branch_hi
        width = max(b - a, 1.0)
        if self.branch_lo is not None and self.branch_hi is not None:
            u = np.sin(np.pi / 4.0 * (x + 1.0)) ** 2
        elif self.branch_lo is not None:
            u = ((x + 1.0) / 2.0) ** 2
        elif self.branch_hi is not None:
            u = 1.0 - ((1.0 - x) / 2.0) ** 2
        else:
            u = (x + 1.0) / 2.0
        return a + width * u

    def arrays(self) -> tuple[np.ndarray, np.ndarray]:
        x = np.array(sorted(self.samples))
        v = np.stack(
            [np.concatenate([r.ravel(), t.ravel()]) for r, t in (self.samples[f] for f in x)]
        )
        return x, v


def _headline(piece: _Piece, k: int) -> np.ndarray:
    """Columns of the (0, 0) order's R among a piece's flattened values (TE, TM per wave).

    Its T needs no fit of its own: E_tan is continuous across a zero-thickness screen
    (perfect or a sheet impedance), so T_00 = δ + R_00 component by component in vacuum,
    to rounding, and T = a δ + b R on layers (:func:`barymesh.mom.stack.transmission_map`):
    a fit of R is as good for T, but for the factor |b| (``_Piece.gain``).
    """
    return np.arange(2 * k)


def _refit(piece: _Piece, frequencies: np.ndarray, k: int) -> None:
    grid_f = frequencies[piece.grid]
    solved = np.isin(grid_f, list(piece.samples))
    if len(piece.samples) < 3:  # no fit yet (none at all while the first ones are solved)
        piece.error = np.where(solved, 0.0, np.inf)
        return
    x, v = piece.arrays()
    cols = _headline(piece, k)
    xs, vh = piece.scale(x), v[:, cols]
    xg = piece.scale(grid_f)
    full = _evaluate(_fit(xs, vh, clean_up=False), xg)
    interior = np.arange(1, len(x) - 1)
    diff = np.zeros(len(grid_f))
    for fold in range(min(FOLDS, len(interior))):
        keep = np.ones(len(x), dtype=bool)
        keep[interior[fold::FOLDS]] = False
        other = _evaluate(_fit(xs[keep], vh[keep], clean_up=False), xg)
        with np.errstate(invalid="ignore"):
            diff = np.maximum(diff, np.nan_to_num(np.abs(full - other), nan=np.inf).max(axis=1))
    if piece.gain is not None:  # on layers T's error is R's times |b|
        diff = diff * piece.gain
    piece.error = np.where(solved, 0.0, diff)


def _usable_cores() -> int:
    """The CPUs this process may run on (its affinity where the OS tells it)."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1


class _Samples:
    """The sweep's solves, each frequency's fill beside the last frequency's LU.

    :meth:`start` fills the EFIE in the calling thread and hands its LU, refinement and
    Floquet amplitudes to one worker thread, so that the caller can choose and fill the
    next frequency meanwhile (both on one BLAS thread: two cores busy, not four threads
    on two). Without a second core, or without the memory for a second matrix
    (:data:`OVERLAP_BYTES_PER_N2`), every solve finishes in :meth:`start`.
    """

    def __init__(
        self,
        mesh: TriMesh,
        waves: list[PlaneWave],
        lattice: Any,
        zs: complex,
        orders: np.ndarray,
        memory_limit: float | None,
        stack: Stack | None = None,
    ) -> None:
        self.pg = periodic_geometry(mesh, lattice, memory_limit=memory_limit)
        t, n = self.pg.base.n_triangles, self.pg.n_unknowns
        need = check_periodic_memory(
            t, n, memory_limit, geometry=False, pair_copy=not has_pair_rows(self.pg.plan)
        )
        allowed, _ = memory_allowance(memory_limit)
        self.overlapping = (
            OVERLAP
            and _usable_cores() >= 2
            and need + OVERLAP_BYTES_PER_N2 * float(n) ** 2 <= allowed
        )
        self.waves, self.zs, self.orders, self.stack = waves, zs, orders, stack
        self.warnings: dict[str, str] = {}  # one per kind, the first met
        self.direction = np.asarray(waves[0].direction, dtype=np.float64)[:2]
        self._pool: ThreadPoolExecutor | None = None
        self._stack = contextlib.ExitStack()

    def __enter__(self) -> _Samples:
        if self.overlapping:
            self._stack.enter_context(one_blas_thread())
            self._pool = ThreadPoolExecutor(1, "barymesh-sweep")
            self._stack.callback(self._pool.shutdown, wait=True, cancel_futures=True)
        return self

    def __exit__(self, *exc: object) -> None:
        self._stack.close()

    def start(self, frequency: float, n_orders: int) -> Future:
        """A future of R and T (n_orders, 2, K) of the first ``n_orders`` orders per wave."""
        kt = wavenumber(frequency) * self.direction
        if self._pool is not None:
            system = fill_system(self.pg, frequency, kt, self.zs, self.stack)
            return self._pool.submit(self._finish, system, n_orders)
        done: Future = Future()
        with blas_threads(self.pg.n_unknowns):
            system = fill_system(self.pg, frequency, kt, self.zs, self.stack)
            done.set_result(self._finish(system, n_orders))
        return done

    def _finish(self, system: FilledSystem, n_orders: int) -> tuple[np.ndarray, np.ndarray]:
        k = len(self.waves)
        r = np.zeros((n_orders, 2, k), dtype=np.complex128)
        t = np.zeros((n_orders, 2, k), dtype=np.complex128)
        expected = self.orders[:n_orders].tolist()
        index = {tuple(o): i for i, o in enumerate(expected)}
        # the waves share k_t (one direction): one LU, a right-hand side each
        for j, s in enumerate(solve_system(system, self.waves)):
            for text in s.warnings:  # the samples next to onsets are there on purpose
                kind = text.split(":")[0]
                if kind != "near an onset":
                    self.warnings.setdefault(kind, text)
            rows = np.array([index.get(tuple(o), -1) for o in s.orders.tolist()])
            if np.any(rows < 0) or len(rows) != n_orders:
                raise RuntimeError(
                    f"at {system.frequency:.9g} Hz the solver's propagating orders "
                    f"{s.orders.tolist()} differ from the expected {expected}"
                )
            r[rows, :, j] = s.reflection
            t[rows, :, j] = s.transmission
        return r, t


def _uncovered(piece: _Piece, grid_f: np.ndarray, flying: list[float]) -> np.ndarray:
    """The piece's error estimate, 0 where a sample still being solved is the nearest one.

    The next sample is chosen while the last one is solved; the grid points nearer (in
    the fit's variable) to that one than to any solved sample are left to it.
    """
    if not flying:
        return piece.error
    xg = piece.scale(grid_f)
    solved = piece.scale(np.array(sorted(piece.samples)))
    near_solved = np.min(np.abs(xg[:, None] - solved[None, :]), axis=1, initial=np.inf)
    near_flying = np.min(np.abs(xg[:, None] - piece.scale(np.array(flying))[None, :]), axis=1)
    return np.where(near_flying <= near_solved, 0.0, piece.error)


def _next_sample(
    pieces: list[_Piece],
    frequencies: np.ndarray,
    k: int,
    flying: list[tuple[_Piece, float]],
    tolerance: float,
) -> tuple[_Piece, float] | None:
    """The requested frequency of largest estimated error, or None when all are below
    ``tolerance``; grid points left to the samples being solved (``flying``) excluded."""
    worst, best = 0.0, None
    for piece in pieces:
        if piece.stale:
            _refit(piece, frequencies, k)
            piece.stale = False
        if not len(piece.grid):
            continue
        grid_f = frequencies[piece.grid]
        error = _uncovered(piece, grid_f, [f for p, f in flying if p is piece])
        i = int(np.argmax(error))
        if best is None or error[i] > worst:
            worst, best = float(error[i]), (piece, float(grid_f[i]))
    return best if worst >= tolerance else None


def periodic_sweep(
    mesh: TriMesh,
    frequencies: Sequence[float] | np.ndarray,
    incidence: PlaneWave | None = None,
    *,
    interpolate: bool = True,
    polarizations: str = "both",
    lattice: Any = None,
    sheet_impedance: complex = 0.0,
    tolerance: float = 1e-3,
    max_samples: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    cancel: Callable[[], bool] | None = None,
    memory_limit: float | None = None,
    stack: Stack | None = None,
) -> PeriodicSweep:
    """Reflection and transmission of the infinite array of ``mesh`` over frequency.

    Parameters
    ----------
    mesh : TriMesh
        One cell of the screen (mm), flat in z = 0, carrying a lattice (a unit cell),
        or with ``lattice=``.
    frequencies : (F,) float
        Hz, strictly increasing.
    incidence : PlaneWave, optional
        The incident wave at every frequency; default normal incidence from above,
        E along x.
    interpolate : bool
        True: solve at greedily chosen samples and fit the rest (see the module's
        docstring); False: solve at every frequency.
    polarizations : {"both", "incident"}
        "both" solves TE and TM incidence from the incidence's direction (the full
        2 × 2 of every order, needed by :meth:`PeriodicSweep.to_touchstone`; the
        incidence's own polarisation is their combination); "incident" solves the
        incidence's polarisation alone (half the work).
    lattice : Lattice, optional
        Default: the mesh's own.
    sheet_impedance : complex
        Z_s of the screen (Ω per square), as for :func:`~barymesh.mom.periodic_solve`.
    tolerance : float
        Target absolute error of the (0, 0) coefficients (``interpolate=True``).
    max_samples : int, optional
        Most frequencies solved with ``interpolate=True`` (default: as many as asked
        for, plus two per onset); when reached first, the sweep stops and says so in
        the log, and :attr:`PeriodicSweep.error_estimate` shows where it is uncertain.
        The two ends of every piece between onsets are solved whatever the limit.
    progress : callable, optional
        ``progress(done, total)`` after each frequency solved; ``total`` is the number
        of frequencies with ``interpolate=False`` and ``max_samples`` otherwise (the
        last call reports ``done == total``).
    cancel : callable, optional
        Checked before each frequency; when it returns True the sweep stops with
        :class:`~barymesh.mom.SolveCancelled`.
    memory_limit : float, optional
        A cap in bytes (in addition to the memory available now): a cell whose solve
        would need more raises :class:`~barymesh.mom.ProblemTooLarge` before anything
        is allocated (:func:`~barymesh.mom.periodic.check_periodic_memory`).
    stack : Stack, optional
        Dielectric layers and a ground plane, as for :func:`~barymesh.mom.periodic_solve`.
        The band is still cut at the vacuum's onsets only: inside a layer of finite
        thickness an order's onset is no branch point.

    Returns
    -------
    PeriodicSweep

    Raises
    ------
    ProblemTooLarge
        The cell would not fit in memory (checked before the first solve).
    ValueError
        Bad frequencies, no lattice, metal across the cell boundary without matching
        periodic edges (from :func:`~barymesh.mom.periodic_geometry`), a
        frequency at a grating-lobe onset with ``interpolate=False``.
    """
    freqs = check_frequencies(frequencies)
    wave, direction = _checked_incidence(incidence, polarizations)
    zs = check_sheet_impedance(sheet_impedance)
    stack = _checked_stack(stack, direction)
    tolerance = _checked_tolerance(tolerance)
    lattice, vectors = _checked_cell(mesh, lattice, freqs, direction, memory_limit)
    fields, waves, incident_te_tm, incident_components = _incident_fields(
        wave, direction, polarizations
    )
    kk = len(waves)
    orders, onsets = order_onsets(vectors, direction, float(freqs[-1]))
    inside = merged_onsets(onsets[(onsets > freqs[0]) & (onsets < freqs[-1])])
    max_samples = _checked_max_samples(max_samples, len(freqs), inside)
    total = len(freqs) if not interpolate else max_samples
    pieces = _pieces(freqs, inside, onsets, orders, stack, vectors, direction)
    queue = _first_samples(pieces, freqs, interpolate)
    with _Samples(mesh, waves, lattice, zs, orders, memory_limit, stack) as samples:
        done, budget_hit = _solve_samples(
            samples,
            pieces,
            queue,
            freqs,
            kk,
            interpolate=interpolate,
            tolerance=tolerance,
            max_samples=max_samples,
            total=total,
            progress=progress,
            cancel=cancel,
        )
    _final_errors(pieces, freqs, kk, interpolate)
    if interpolate:
        _report_end(pieces, budget_hit, max_samples, tolerance, progress, done, total)
    refl, trans, error, sampled, co_fits = _curves(
        pieces, freqs, orders, kk, stack, vectors, direction, incident_te_tm, incident_components
    )
    result = PeriodicSweep(
        frequencies=freqs,
        incidence=wave,
        polarizations=fields,
        incident_te_tm=incident_te_tm,
        orders=orders,
        onsets=onsets,
        order_reflection=refl,
        order_transmission=trans,
        lattice=vectors,
        sampled=np.array(sorted(sampled)),
        error_estimate=error,
        interpolated=bool(interpolate),
        sheet_impedance=zs,
        resonances=np.zeros(0),
        resonance_kinds=(),
        quality_factors=np.zeros(0),
        mesh=mesh,
        lattice_source=lattice,
        stack=stack,
    )
    return _with_resonances(result, co_fits, tuple(samples.warnings.values()))


# -- the sweep's steps, in the order periodic_sweep takes them ---------------------------


def _checked_incidence(incidence: PlaneWave | None, polarizations: str) -> tuple:
    """The incident wave (default: normal incidence from above) and its direction (3,).

    Checked before anything is built: a wrong type, a wave along the screen or an unknown
    ``polarizations`` is refused by name.
    """
    wave = PlaneWave() if incidence is None else incidence
    if not isinstance(wave, PlaneWave):
        raise TypeError(f"incidence must be a PlaneWave, got {type(wave).__name__}")
    direction = incidence_direction(wave)
    if polarizations not in ("both", "incident"):
        raise ValueError(f"polarizations={polarizations!r}; expected 'both' or 'incident'")
    return wave, direction


def _checked_stack(stack: Any, direction: np.ndarray) -> Stack | None:
    """The stack as the solver takes it; a grounded one must be lit from above, the side
    without the ground plane."""
    stack = check_stack(stack)
    if stack is not None and stack.ground and direction[2] > 0:
        raise ValueError(
            "the incident wave comes from below, where the ground plane is: a grounded "
            "stack is lit from above (direction_z < 0)"
        )
    return stack


def _checked_tolerance(tolerance: Any) -> float:
    """``tolerance`` as a positive float: the greedy sampling stops below it."""
    tolerance = float(tolerance)
    if not (np.isfinite(tolerance) and tolerance > 0):
        raise ValueError(f"tolerance={tolerance!r}; expected a positive number")
    return tolerance


def _checked_cell(
    mesh: Any,
    lattice: Any,
    frequencies: np.ndarray,
    direction: np.ndarray,
    memory_limit: float | None,
) -> tuple[Any, np.ndarray]:
    """The lattice as given (a Lattice or None) and its vectors (2, 2) in metres.

    Every check of the cell (boundary, size, memory) runs here, before the first solve, so
    that a sweep that cannot run fails at once and not after minutes of solves; the lattice
    sums' at the top of the band. The geometry it builds is cached for the solves.
    """
    if not isinstance(mesh, TriMesh):
        raise TypeError(f"mesh must be a TriMesh, got {type(mesh).__name__}")
    lattice = as_lattice(lattice)
    vectors = lattice_metres(mesh, lattice)
    check_green_terms(
        vectors, float(frequencies[-1]), direction, memory_limit, float(frequencies[0])
    )
    periodic_geometry(mesh, lattice, memory_limit=memory_limit)
    return lattice, vectors


def _incident_fields(wave: PlaneWave, direction: np.ndarray, polarizations: str) -> tuple:
    """What is solved at each frequency: (fields (K, 3), waves (K,), the incidence's TE/TM
    components (2,), and each wave's TE/TM components flattened (2 K,), as R[0] is).

    "both" solves TE and TM from the incidence's direction (K = 2), so that every order's
    full 2 × 2 is known; "incident" the incidence alone (K = 1).
    """
    basis = te_tm_polarizations(direction)
    pol = np.asarray(wave.polarization)
    incident_te_tm = basis @ pol
    if polarizations == "both":
        fields = basis
        waves = [PlaneWave(direction, e, wave.amplitude) for e in basis]
    else:
        fields = np.real_if_close(pol)[None, :]
        waves = [wave]
    incident_components = (basis @ fields.T).ravel()  # (2, K): TE/TM of each wave, as R[0]
    return fields, waves, incident_te_tm, incident_components


def _checked_max_samples(max_samples: int | None, n_frequencies: int, inside: np.ndarray) -> int:
    """The most frequencies solved: by default as many as asked for, plus two per onset
    inside the band (the samples on either side of it)."""
    if max_samples is None:
        max_samples = n_frequencies + 2 * len(inside)
    max_samples = int(max_samples)
    if max_samples < 1:
        raise ValueError(f"max_samples={max_samples!r}; expected a positive number")
    return max_samples


def _pieces(
    freqs: np.ndarray,
    inside: np.ndarray,
    onsets: np.ndarray,
    orders: np.ndarray,
    stack: Stack | None,
    vectors: np.ndarray,
    direction: np.ndarray,
) -> list[_Piece]:
    """The band cut at every onset ``inside`` it, each piece fitted on its own.

    The coefficients have a square-root branch point at an onset, so a piece ends
    :data:`ONSET_OFFSET` short of it and its fit's variable is made analytic there
    (:meth:`_Piece.scale`); a requested frequency at an onset belongs to the lower piece.
    On layers T's error is R's times |b| (T = a δ + b R): each piece keeps that factor.
    """
    edges = np.concatenate([[freqs[0]], inside, [freqs[-1]]])
    which = np.clip(np.searchsorted(inside, freqs, side="left"), 0, len(inside))
    pieces = []
    for i in range(len(edges) - 1):
        lo = edges[i] * (1 + ONSET_OFFSET) if i > 0 else edges[i]
        hi = edges[i + 1] * (1 - ONSET_OFFSET) if i < len(edges) - 2 else edges[i + 1]
        n_orders = int(np.count_nonzero(onsets < 0.5 * (edges[i] + edges[i + 1])))
        piece = _Piece(lo, hi, np.flatnonzero(which == i), n_orders, {})
        piece.branch_lo = float(edges[i]) if i > 0 else None
        piece.branch_hi = float(edges[i + 1]) if i < len(edges) - 2 else None
        if stack is not None:  # T's error is R's times |b| (T = a δ + b R)
            _, b = _transmission_maps(
                stack, vectors, direction, freqs[piece.grid], orders[:n_orders]
            )
            piece.gain = np.maximum(1.0, np.abs(b[:, 0]).max(axis=1)) if len(b) else None
        pieces.append(piece)
    return pieces


def _first_samples(
    pieces: list[_Piece], freqs: np.ndarray, interpolate: bool
) -> list[tuple[_Piece, float, bool]]:
    """What to solve first, as a stack popped from the end: (piece, frequency, always).

    Point by point, every requested frequency. Interpolating, each piece's two ends
    (``always``: solved whatever ``max_samples``, a fit needs them) and a few evenly spread
    requested frequencies (:data:`INITIAL_SAMPLES` in all), so that every piece has a fit
    and an error estimate before the greedy choice starts.
    """
    queue: list[tuple[_Piece, float, bool]] = []
    for piece in pieces:
        grid_f = freqs[piece.grid]
        if not interpolate:
            queue += [(piece, float(f), True) for f in grid_f]
            continue
        starts = [piece.lo, piece.hi]
        inner = grid_f[(grid_f > piece.lo) & (grid_f < piece.hi)]
        if len(inner):
            pick = np.unique(np.linspace(0, len(inner) - 1, INITIAL_SAMPLES)[1:-1].round())
            starts += list(inner[pick.astype(int)])
        ordered = sorted(set(starts), key=lambda f: f not in (piece.lo, piece.hi))
        queue += [(piece, float(f), j < 2) for j, f in enumerate(ordered)]
    queue.reverse()  # popped from the end
    return queue


def _solve_samples(
    samples: _Samples,
    pieces: list[_Piece],
    queue: list[tuple[_Piece, float, bool]],
    freqs: np.ndarray,
    kk: int,
    *,
    interpolate: bool,
    tolerance: float,
    max_samples: int,
    total: int,
    progress: Callable[[int, int], None] | None,
    cancel: Callable[[], bool] | None,
) -> tuple[int, bool]:
    """Solve the ``queue``, then (interpolating) the greedy samples, into ``pieces``.

    The next sample is chosen where the estimated error is largest (:func:`_next_sample`)
    until it is below ``tolerance`` everywhere or ``max_samples`` are solved. With a
    worker thread one sample is in flight while the next is chosen and filled, and the
    next is chosen beside it only where the estimate is :data:`OVERLAP_MARGIN` times the
    tolerance. Returns (frequencies solved, whether ``max_samples`` stopped the sweep).
    """
    done = started = 0
    budget_hit = False
    flying: deque[tuple[_Piece, float, Future]] = deque()
    depth = 1 if samples.overlapping else 0  # samples solved while the next is chosen
    while True:
        if cancel is not None and cancel():  # before the next choice (a refit) too
            raise SolveCancelled(f"the sweep was cancelled after {done} frequencies")
        nxt = None
        while queue and nxt is None:
            piece, f, always = queue.pop()
            if always or started < max_samples:
                nxt = piece, f
            else:
                budget_hit = True
        if nxt is None and interpolate and not budget_hit:
            # beside a sample being solved, only where the estimate is well above the
            # tolerance: near it, that sample's result may well be enough
            margin = OVERLAP_MARGIN if flying else 1.0
            busy = [(p, f) for p, f, _ in flying]
            nxt = _next_sample(pieces, freqs, kk, busy, margin * tolerance)
            if nxt is not None and started >= max_samples:
                nxt = None
                budget_hit = not flying
        if nxt is not None:
            piece, f = nxt
            flying.append((piece, f, samples.start(f, piece.n_orders)))
            started += 1
            if len(flying) <= depth:
                continue
        elif not flying:
            break
        piece, f, future = flying.popleft()
        piece.samples[f] = future.result()
        piece.stale = True
        done += 1
        if progress is not None:
            progress(done, total)
    return done, budget_hit


def _final_errors(pieces: list[_Piece], freqs: np.ndarray, kk: int, interpolate: bool) -> None:
    """Each piece's error estimate for the samples it ended with (0 point by point: every
    requested frequency was solved)."""
    for piece in pieces:
        if not interpolate:
            piece.error = np.zeros(len(piece.grid))
        elif piece.stale:
            _refit(piece, freqs, kk)


def _report_end(
    pieces: list[_Piece],
    budget_hit: bool,
    max_samples: int,
    tolerance: float,
    progress: Callable[[int, int], None] | None,
    done: int,
    total: int,
) -> None:
    """An interpolating sweep's last word: in the log when ``max_samples`` stopped it above
    the tolerance, and ``progress(done, done)`` when it needed fewer than ``total``, so that
    a progress bar ends full."""
    if budget_hit:
        log.warning(
            "the interpolating sweep stopped at max_samples=%d with an estimated error "
            "of %.3g (tolerance %.3g)",
            max_samples,
            max(p.error.max() if len(p.error) else 0.0 for p in pieces),
            tolerance,
        )
    if progress is not None and done < total:
        progress(done, done)


def _curves(
    pieces: list[_Piece],
    freqs: np.ndarray,
    orders: np.ndarray,
    kk: int,
    stack: Stack | None,
    vectors: np.ndarray,
    direction: np.ndarray,
    incident_te_tm: np.ndarray,
    incident_components: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[float], list[tuple[_Piece, AAA | None]]]:
    """The (F, P, 2, K) reflection and transmission: solved values where solved, the fits
    elsewhere, NaN where an order is evanescent; with the (F,) error estimate, the
    frequencies solved and each piece's fit of R_co (for the resonances).

    R alone is fitted: E_tan is continuous across the screen, so in vacuum every order's T
    is its R, plus the incident wave's TE/TM components for (0, 0) (the solver's too); on
    layers T = a δ + b R, order by order (:func:`barymesh.mom.stack.transmission_map`).
    """
    nf = len(freqs)
    n_all = len(orders)
    refl = np.full((nf, n_all, 2, kk), np.nan, dtype=np.complex128)
    trans = np.full((nf, n_all, 2, kk), np.nan, dtype=np.complex128)
    error = np.zeros(nf)
    sampled: list[float] = []
    co_fits: list[tuple[_Piece, AAA | None]] = []
    for piece in pieces:
        if not piece.samples:  # point by point, no requested frequency between two onsets
            continue
        x, v = piece.arrays()
        sampled += list(x)
        n = piece.n_orders * 2 * kk
        grid_f = freqs[piece.grid]
        if len(x) >= 2:  # R alone is fitted (see above)
            fitted_r = _evaluate(_fit(piece.scale(x), v[:, :n]), piece.scale(grid_f))
        else:
            fitted_r = np.repeat(v[:, :n], len(grid_f), axis=0)
        if stack is None:
            fitted_t = fitted_r.copy()
            fitted_t[:, : 2 * kk] += incident_components
        else:
            shape = (len(grid_f), piece.n_orders, 2, kk)
            a, b = _transmission_maps(stack, vectors, direction, grid_f, orders[: piece.n_orders])
            fitted_t = b[..., None] * fitted_r.reshape(shape)
            fitted_t[:, 0] += a[:, 0, :, None] * incident_components.reshape(2, kk)
            fitted_t = fitted_t.reshape(len(grid_f), -1)
        values = np.concatenate([fitted_r, fitted_t], axis=1)
        for j, f in enumerate(grid_f):  # exact values where solved
            if float(f) in piece.samples:
                r, t = piece.samples[float(f)]
                values[j] = np.concatenate([r.ravel(), t.ravel()])
        shape = (len(grid_f), piece.n_orders, 2, kk)
        refl[piece.grid, : piece.n_orders] = values[:, :n].reshape(shape)
        trans[piece.grid, : piece.n_orders] = values[:, n:].reshape(shape)
        error[piece.grid] = piece.error
        co = _co_series(v[:, : 2 * kk].reshape(-1, 2, kk), incident_te_tm, kk)
        co_fits.append((piece, _fit(piece.scale(x), co[:, None])[0] if len(x) >= 3 else None))
    return refl, trans, error, sampled, co_fits


def _with_resonances(
    result: PeriodicSweep, co_fits: list[tuple[_Piece, AAA | None]], notes: tuple[str, ...]
) -> PeriodicSweep:
    """``result`` with its resonances (peaks and dips of |R_co|, refined on the fits, with
    Q) and its warnings: the solves' ``notes``, and a resonance next to an onset."""
    freqs = result.frequencies
    found, kinds, q = _resonances(result, co_fits)
    if len(found):
        r_co, t_co = result.co_polar()
        at = np.clip(np.searchsorted(freqs, found), 0, len(freqs) - 1)
        notes += onset_resonance_warning(
            found, kinds, result.grating_lobe_onsets, np.abs(r_co[at]), np.abs(t_co[at])
        )
    return replace(
        result, resonances=found, resonance_kinds=kinds, quality_factors=q, warnings=notes
    )


def _transmission_maps(
    stack: Stack,
    vectors: np.ndarray,
    direction: np.ndarray,
    frequencies: np.ndarray,
    orders: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """(a, b), each (F, P, 2): T = a δ + b R of ``orders`` at each frequency (stack.py)."""
    from .stack import transmission_map

    recip = np.array(reciprocal_vectors(vectors[0], vectors[1]))
    g = orders @ recip  # (P, 2)
    f_count, p_count = len(frequencies), len(orders)
    a = np.zeros((f_count, p_count, 2), dtype=np.complex128)
    b = np.zeros((f_count, p_count, 2), dtype=np.complex128)
    for i, f in enumerate(frequencies):
        k = wavenumber(float(f))
        kappa = k * direction[:2] + g
        a[i], b[i] = transmission_map(
            stack, k, np.einsum("ij,ij->i", kappa, kappa), from_above=bool(direction[2] < 0)
        )
    return a, b


def _co_series(r00: np.ndarray, c: np.ndarray, k: int) -> np.ndarray:
    """(S,) R_co of the (0, 0) order from its (S, 2, K) samples."""
    response = r00 @ c if k == 2 else r00[..., 0]
    return response @ np.conj(c)


def _resonances(sweep: PeriodicSweep, co_fits: list) -> tuple[np.ndarray, tuple, np.ndarray]:
    """Peaks and dips of |R_co| on the sweep's curve, refined on the fits, with Q.

    Over a ground plane nothing is transmitted and |R| is 1 but for loss: only its dips
    (absorption) are resonances; its peaks would be noise.
    """
    f = sweep.frequencies
    r = np.abs(sweep.co_polar()[0])
    if len(f) < 3 or not np.all(np.isfinite(r)):
        return np.zeros(0), (), np.zeros(0)
    found, kinds, qs = [], [], []
    onsets = sweep.grating_lobe_onsets
    step = np.min(np.diff(f))
    shapes = [("peak", r), ("dip", -r)]
    if sweep.stack is not None and sweep.stack.ground:
        shapes = shapes[1:]
    for kind, y in shapes:
        idx, _ = find_peaks(y, prominence=RESONANCE_PROMINENCE)
        for i in idx:
            if len(onsets) and np.min(np.abs(onsets - f[i])) < 1.5 * max(step, f[i] - f[i - 1]):
                continue  # the kink of an onset, not a resonance
            piece, fit = next(((p, a) for p, a in co_fits if i in p.grid), (None, None))
            fi, q = float(f[i]), math.nan
            if fit is not None and piece is not None:
                local = np.linspace(f[i - 1], f[i + 1], 41)
                local = local[(local >= piece.lo) & (local <= piece.hi)]
                values = np.abs(np.asarray(fit(piece.scale(local))))
                if np.all(np.isfinite(values)) and len(local):
                    fi = float(local[np.argmax(values) if kind == "peak" else np.argmin(values)])
                # a pole that makes a feature: the height |residue / Im x_p| of its term on
                # the real axis at least a resonance's prominence (not a Froissart doublet)
                xp, res = np.asarray(fit.poles()), np.asarray(fit.residues())
                with np.errstate(divide="ignore", invalid="ignore"):
                    height = np.abs(res) / np.abs(xp.imag)
                poles = piece.unscale(xp[(xp.imag != 0) & (height >= RESONANCE_PROMINENCE)])
                if len(poles):
                    nearest = poles[np.argmin(np.abs(poles - fi))]
                    if abs(nearest.real - fi) < 0.5 * fi:
                        q = float(nearest.real / (2.0 * abs(nearest.imag)))
            found.append(fi)
            kinds.append(kind)
            qs.append(q)
    order = np.argsort(found)
    return (
        np.array(found)[order],
        tuple(kinds[j] for j in order),
        np.array(qs)[order],
    )

"""The numbers behind the Solve dock's "Infinite array" tab (numpy only, no Qt).

:func:`sweep_array` is the one adapter between the tab and the periodic solver:
:func:`barymesh.mom.periodic_sweep` over the band (interpolating, AAA, from
:data:`INTERPOLATE_POINTS` frequencies on; below, point by point with
:func:`barymesh.mom.periodic_solve`, where a fit would cost more solves than it saves),
reduced to what the tab plots (the co-polar (0, 0)
reflection and transmission), the grating-lobe onsets with the orders that start there,
the onsets of orders guided inside a dielectric layer (:func:`guided_onsets`: not grating
lobes, they carry no power out), the resonances and the solver's warnings. With a
:class:`barymesh.mom.Stack` in the inputs the sheet lies on layers and perhaps a ground
plane; R and T are then referred to the stack's faces (:attr:`ArraySweep.reference_planes`).
It stops before its next solve when ``cancel()`` says so.

:func:`orders_rows` turns one :class:`barymesh.mom.PeriodicSolution` into the rows of the
tab's table of propagating Floquet orders.

The frequencies are solved in a child process (:func:`solver_process`, one for the whole
program, started on the first sweep), not in the calling worker thread: a thread shares
the GIL with the GUI thread, and every draw the window made meanwhile (the curve, the
cell's preview, the 3D view) took twice as long, up to a third of a second on a loaded
machine. The mesh and the inputs go to the child, an :class:`ArraySweep` comes back;
cancel and progress cross through two shared integers (:class:`_Shared`).
"""

from __future__ import annotations

import atexit
import itertools
import math
import multiprocessing
import threading
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from barymesh import TriMesh
from barymesh.constants import SPEED_OF_LIGHT

#: Polarisations offered, and the angle ``PlaneWave.from_angles`` turns E by from θ̂:
#: TE has E along φ̂ (perpendicular to the plane of incidence), TM along θ̂.
POLARIZATIONS = {"TE": 90.0, "TM": 0.0}
#: Metres per mesh unit (meshes and lattices are in mm).
METRES = 1e-3
#: Bands of at least this many frequencies are swept by rational interpolation (21 cost
#: 27 solves on a ring cell with three grating-lobe onsets in the band: no saving).
INTERPOLATE_POINTS = 41
#: Over a ground plane a dip of |R| is listed as a resonance only below 1 minus this.
DIP_DEPTH = 0.01
#: Floquet orders |p|, |q| <= this are searched for grating-lobe onsets.
ORDER_RANGE = 4


@dataclass(frozen=True)
class ArrayInputs:
    """What the tab's fields say: the band, the angle, the polarisation and Z_s.

    Attributes
    ----------
    frequencies : (F,) float
        Hz, increasing.
    theta, phi : float
        Direction the wave comes from (degrees): θ from the normal, φ from x.
    polarization : str
        ``"TE"`` or ``"TM"``.
    sheet_impedance : complex
        Ω per square (0: a perfect conductor).
    stack : barymesh.mom.Stack or None
        The layers around the sheet and the ground plane (None: the sheet in vacuum).
    """

    frequencies: tuple[float, ...]
    theta: float
    phi: float
    polarization: str
    sheet_impedance: complex = 0j
    stack: Any = None

    def incidence(self) -> Any:
        """The incident :class:`barymesh.mom.PlaneWave` (unit amplitude)."""
        from barymesh.mom import PlaneWave

        return PlaneWave.from_angles(self.theta, self.phi, POLARIZATIONS[self.polarization])


@dataclass(frozen=True, eq=False)
class ArraySweep:
    """The co-polar (0, 0) coefficients of an infinite array over a band.

    Attributes
    ----------
    frequencies : (F,) float
        Hz.
    reflection, transmission : (F,) complex
        Co-polar R and T of the (0, 0) order (T includes the incident wave).
    grating_lobe_onsets : tuple of (float, tuple of (int, int))
        Onset frequencies (Hz) inside the band, each with the orders (p, q) that begin
        to propagate there.
    resonances : (K,) float
        Frequencies (Hz) of the resonances (peaks and dips of |R|).
    inputs : ArrayInputs
    sampled : (S,) float
        The frequencies solved (Hz); the others come from the rational fit.
    error_estimate : (F,) float
        The fit's estimated absolute error (0 where solved).
    warnings : tuple of str
        When the curve should not be trusted as it is, one sentence per kind ("kind:
        text", :mod:`barymesh.mom.periodic_caveats`).
    guided_onsets : tuple of (float, tuple of (int, int), tuple of int)
        Onsets inside the band of orders guided inside a layer (:func:`guided_onsets`).
    zero_phase : (Z,) float
        Over a ground plane: the frequencies (Hz) where ∠R crosses 0 at the top face,
        the in-phase reflection of a high-impedance surface (:func:`zero_phase_frequencies`).
    """

    frequencies: np.ndarray
    reflection: np.ndarray
    transmission: np.ndarray
    grating_lobe_onsets: tuple[tuple[float, tuple[tuple[int, int], ...]], ...]
    resonances: np.ndarray
    inputs: ArrayInputs
    sampled: np.ndarray = field(default_factory=lambda: np.zeros(0))
    error_estimate: np.ndarray = field(default_factory=lambda: np.zeros(0))
    warnings: tuple[str, ...] = ()
    guided_onsets: tuple[tuple[float, tuple[tuple[int, int], ...], tuple[int, ...]], ...] = ()
    zero_phase: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def interpolated(self) -> bool:
        """Whether some frequencies come from the fit, not from a solve."""
        return len(self.sampled) < len(self.frequencies)

    @property
    def stack(self) -> Any:
        """The inputs' :class:`barymesh.mom.Stack` (None: the sheet in vacuum)."""
        return self.inputs.stack

    def equivalent_circuit(self) -> Any:
        """The Foster LC of the sheet fitted to this curve's R
        (:func:`barymesh.mom.circuit.equivalent_circuit`, as
        ``PeriodicSweep.equivalent_circuit``): below the first grating-lobe or guided
        onset; ValueError (one sentence) when no circuit fits."""
        from barymesh.mom.circuit import equivalent_circuit

        onsets = [hz for hz, _ in self.grating_lobe_onsets]
        onsets += [hz for hz, _, _ in self.guided_onsets]
        return equivalent_circuit(
            self.frequencies,
            self.reflection,
            self.inputs.stack,
            self.inputs.incidence(),
            onsets=onsets,
        )

    @property
    def reference_planes(self) -> tuple[float, float]:
        """Heights (mm) over the sheet of the planes R and T are referred to (the wave
        comes from above: the stack's top and bottom faces; (0, 0) in vacuum)."""
        stack = self.inputs.stack
        return (0.0, 0.0) if stack is None else stack.reference_planes


def lattice_vectors(mesh: TriMesh) -> np.ndarray:
    """(2, 2) float lattice vectors a1, a2 (rows, metres) of a unit cell's mesh.

    Raises ValueError (one line) when the mesh carries no lattice.
    """
    lattice = getattr(mesh, "lattice", None)
    if lattice is None:
        raise ValueError(
            "The mesh on screen has no lattice: open a unit cell (Cell ▸ Cell presets) "
            "to solve its infinite array"
        )
    return np.array([lattice.a1, lattice.a2], dtype=np.float64) * METRES


def grating_lobe_onsets(
    vectors: np.ndarray,
    theta: float,
    phi: float,
    band: tuple[float, float],
    index: float = 1.0,
) -> tuple[tuple[float, tuple[tuple[int, int], ...]], ...]:
    """Frequencies in ``band`` (Hz) at which a Floquet order (p, q) ≠ (0, 0) starts to
    propagate, for a wave from (θ, φ) (degrees, in vacuum) on the lattice ``vectors``
    ((2, 2), m), in vacuum or (``index`` = sqrt(εr μr)) inside a layer.

    Order (p, q) has κ = k u + p b1 + q b2 (u = the incident direction's transverse part);
    it propagates once |κ| <= n k, so its onset solves
    (n² − |u|²) k² − 2 (u·G) k − |G|² = 0.

    >>> a = np.eye(2) * 0.012  # a 12 mm square lattice
    >>> [(round(f / 1e9, 3), orders) for f, orders in grating_lobe_onsets(a, 0, 0, (1e9, 26e9))]
    [(24.983, ((-1, 0), (0, -1), (0, 1), (1, 0)))]
    """
    recip = 2.0 * np.pi * np.linalg.inv(np.asarray(vectors, dtype=np.float64)).T  # rows b1, b2
    t, f = math.radians(theta), math.radians(phi)
    u = -math.sin(t) * np.array([math.cos(f), math.sin(f)])
    # every order whose onset can lie in the band: |G| <= n k (1 + |u|) at the band's top
    radius = index * (1.0 + math.hypot(*u)) * 2.0 * np.pi * band[1] / SPEED_OF_LIGHT
    span = np.ceil(radius * np.linalg.norm(np.linalg.inv(recip), axis=0)).astype(int)
    span = np.maximum(span, ORDER_RANGE)
    pq = np.stack(
        np.meshgrid(
            np.arange(-span[0], span[0] + 1), np.arange(-span[1], span[1] + 1), indexing="ij"
        ),
        axis=-1,
    ).reshape(-1, 2)
    pq = pq[np.any(pq != 0, axis=1)]
    g = pq @ recip  # (M, 2)
    ug = g @ u
    gg = np.einsum("ij,ij->i", g, g)
    a = index * index - u @ u
    k = (ug + np.sqrt(ug * ug + a * gg)) / a
    hz = k * SPEED_OF_LIGHT / (2.0 * np.pi)
    inside = (hz >= band[0]) & (hz <= band[1])
    hz, pq = hz[inside], pq[inside]
    out: list[tuple[float, tuple[tuple[int, int], ...]]] = []
    for i in np.argsort(hz, kind="stable"):
        order = (int(pq[i, 0]), int(pq[i, 1]))
        if out and abs(hz[i] - out[-1][0]) <= 1e-9 * hz[i]:
            out[-1] = (out[-1][0], tuple(sorted((*out[-1][1], order))))
        else:
            out.append((float(hz[i]), (order,)))
    return tuple(out)


def guided_onsets(
    vectors: np.ndarray, theta: float, phi: float, band: tuple[float, float], stack: Any
) -> tuple[tuple[float, tuple[tuple[int, int], ...], tuple[int, ...]], ...]:
    """Onsets in ``band`` (Hz) of Floquet orders that propagate inside a layer of
    ``stack`` but not (yet) in vacuum: (frequency, orders, layers) by frequency, the
    layers as indices into ``stack.layers`` (top first).

    Above such an onset the order is guided inside the stack: it carries no power out
    and is no grating lobe, but the sheet's response changes there (a kink or a
    resonance of the slab). Layers of zero thickness or of index 1 have none.

    >>> from barymesh.mom import Layer, Stack
    >>> slab = Stack(below=(Layer(1.575, 2.2),), ground=True)
    >>> a = np.eye(2) * 0.012  # 12 mm: at normal incidence c / (P sqrt(2.2)) = 16.84 GHz
    >>> [(round(f / 1e9, 2), o, i) for f, o, i in guided_onsets(a, 0, 0, (5e9, 20e9), slab)]
    [(16.84, ((-1, 0), (0, -1), (0, 1), (1, 0)), (0,))]
    """
    if stack is None:
        return ()
    # an order reaches n k before k: each onset in a layer is below the order's in vacuum
    found: dict[float, tuple[set[tuple[int, int]], set[int]]] = {}
    for i, layer in enumerate(stack.layers):
        index = math.sqrt(layer.eps_r * layer.mu_r)
        if layer.thickness <= 0 or index <= 1.0:
            continue
        for hz, orders in grating_lobe_onsets(vectors, theta, phi, band, index):
            key = next((f for f in found if abs(f - hz) <= 1e-9 * hz), hz)
            entry = found.setdefault(key, (set(), set()))
            entry[0].update(orders)
            entry[1].add(i)
    return tuple(
        (hz, tuple(sorted(orders)), tuple(sorted(layers)))
        for hz, (orders, layers) in sorted(found.items())
    )


def resonance_frequencies(frequencies: np.ndarray, magnitude: np.ndarray) -> np.ndarray:
    """(K,) frequencies of the interior maxima of ``magnitude`` (parabola through each
    maximum and its two neighbours).

    >>> f = np.array([1.0, 2.0, 3.0, 4.0])
    >>> resonance_frequencies(f, np.array([0.1, 0.5, 0.5, 0.1])).tolist()
    [2.5]
    """
    f, m = np.asarray(frequencies, dtype=float), np.asarray(magnitude, dtype=float)
    if len(f) < 3:
        return np.zeros(0)
    i = np.flatnonzero((m[1:-1] >= m[:-2]) & (m[1:-1] > m[2:])) + 1
    y0, y1, y2 = m[i - 1], m[i], m[i + 1]
    denom = y0 - 2.0 * y1 + y2
    shift = np.where(np.abs(denom) > 0, 0.5 * (y0 - y2) / np.where(denom == 0, 1, denom), 0.0)
    step = np.where(shift >= 0, f[np.minimum(i + 1, len(f) - 1)] - f[i], f[i] - f[i - 1])
    return f[i] + np.clip(shift, -0.5, 0.5) * step


def zero_phase_frequencies(frequencies: np.ndarray, reflection: np.ndarray) -> np.ndarray:
    """(Z,) frequencies where the phase of ``reflection`` crosses 0 (linear between two
    samples; a jump through ±180° is no crossing).

    >>> f = np.array([1.0, 2.0, 3.0, 4.0])
    >>> zero_phase_frequencies(f, np.exp(1j * np.radians([90, 30, -30, -170]))).tolist()
    [2.5]
    """
    f = np.asarray(frequencies, dtype=float)
    ph = np.angle(np.asarray(reflection))
    a, b = ph[:-1], ph[1:]
    crossing = (((a <= 0) & (b > 0)) | ((a >= 0) & (b < 0))) & (np.abs(b - a) < np.pi)
    i = np.flatnonzero(crossing)
    return f[i] + (f[i + 1] - f[i]) * a[i] / (a[i] - b[i])


def reflector_resonances(
    frequencies: np.ndarray, reflection: np.ndarray, candidates: np.ndarray
) -> np.ndarray:
    """The ``candidates`` (Hz) that are dips of |R| at least :data:`DIP_DEPTH` deep.

    Over a ground plane every watt comes back (|R| = 1 without loss): a peak of |R| is
    no resonance there, and a dip is one only where the layers or the sheet absorb.
    """
    f = np.asarray(frequencies, dtype=float)
    candidates = np.asarray(candidates, dtype=float)
    if not len(candidates):
        return candidates
    magnitude = np.interp(candidates, f, np.abs(reflection))
    return candidates[magnitude <= 1.0 - DIP_DEPTH]


def solve_point(mesh: TriMesh, hz: float, inputs: ArrayInputs) -> Any:
    """:func:`barymesh.mom.periodic_solve` of ``mesh`` at ``hz`` with the tab's inputs."""
    from barymesh.mom import periodic_solve

    return periodic_solve(
        mesh, hz, inputs.incidence(), sheet_impedance=inputs.sheet_impedance, stack=inputs.stack
    )


class _Shared:
    """Two integers the parent and the child process both see: the highest job number
    cancelled, and the solves done by the running job (its progress)."""

    def __init__(self, context: Any) -> None:
        self.cancelled = context.Value("q", 0, lock=False)
        self.done = context.Value("q", 0, lock=False)


_PROCESS: ProcessPoolExecutor | None = None
_SHARED: _Shared | None = None
_PROCESS_LOCK = threading.Lock()
_JOBS = itertools.count(1)
#: Child side: the shared integers (from the initializer: they are inherited, not sent).
_CHILD: list[Any] = [None]


def _child_start(shared: _Shared) -> None:
    _CHILD[0] = shared


def solver_process() -> tuple[ProcessPoolExecutor, _Shared]:
    """The one child process the sweeps solve in (spawned: a process running Qt threads
    is never forked) and its shared integers; shut down when the program ends."""
    global _PROCESS, _SHARED
    with _PROCESS_LOCK:
        if _PROCESS is None:
            context = multiprocessing.get_context("spawn")
            _SHARED = _Shared(context)
            _PROCESS = ProcessPoolExecutor(
                max_workers=1, mp_context=context, initializer=_child_start, initargs=(_SHARED,)
            )
            atexit.register(_PROCESS.shutdown, wait=False, cancel_futures=True)
        assert _SHARED is not None  # made with the process
        return _PROCESS, _SHARED


def _forget_process(executor: ProcessPoolExecutor) -> None:
    """A child that died is replaced by a new one at the next sweep."""
    global _PROCESS
    with _PROCESS_LOCK:
        if _PROCESS is executor:
            _PROCESS = None


def _run_in_child(job: int, function: Callable[..., Any], args: tuple[Any, ...]) -> Any:
    shared = _CHILD[0]
    shared.done.value = 0

    def progress(done: int, _total: int) -> None:
        shared.done.value = done

    return function(*args, progress, lambda: shared.cancelled.value >= job)


def in_solver_process(
    function: Callable[..., Any],
    args: tuple[Any, ...],
    total: int,
    progress: Callable[[int, int], None] | None = None,
    cancel: Callable[[], bool] | None = None,
    meanwhile: Callable[[], None] | None = None,
) -> Any:
    """``function(*args, progress, cancel)`` in :func:`solver_process`, waited for here.

    ``function`` is a module-level function (the child imports it by name) that calls
    ``progress(done, total)`` as it goes and stops when ``cancel()`` turns true; here
    ``progress(done, total)`` is called when its count moves, and ``cancel()`` is polled
    every 50 ms and passed on. The Infinite array's sweeps and the Reflection phase tab's
    curves both solve there, one job after the other. ``meanwhile()`` is called here once
    the job is handed over, while the child works (a figure drawn meanwhile).
    """
    executor, shared = solver_process()
    job = next(_JOBS)
    future = executor.submit(_run_in_child, job, function, args)
    if meanwhile is not None:
        meanwhile()
    seen = -1
    while True:
        try:
            return future.result(timeout=0.05)
        except TimeoutError:
            pass
        except BrokenProcessPool:
            _forget_process(executor)
            raise RuntimeError("the solver's process ended unexpectedly; run again") from None
        if cancel is not None and cancel():
            shared.cancelled.value = max(shared.cancelled.value, job)
        done = int(shared.done.value)
        if progress is not None and done != seen:
            seen = done
            progress(min(done, total), total)


def _sweep(
    mesh: TriMesh,
    inputs: ArrayInputs,
    progress: Callable[[int, int], None] | None,
    cancel: Callable[[], bool] | None,
) -> ArraySweep:
    from barymesh.mom import SolveCancelled, periodic_sweep

    freqs = np.asarray(inputs.frequencies, dtype=np.float64)
    band = (float(freqs[0]), float(freqs[-1]))
    vectors = lattice_vectors(mesh)
    onsets = grating_lobe_onsets(vectors, inputs.theta, inputs.phi, band)
    guided = guided_onsets(vectors, inputs.theta, inputs.phi, band, inputs.stack)
    grounded = inputs.stack is not None and inputs.stack.ground
    if len(freqs) < INTERPOLATE_POINTS:
        # point by point here: periodic_sweep(interpolate=False) refuses a band with an
        # onset-to-onset piece that holds no requested frequency ("need at least one
        # array to stack"), and a short band costs fewer solves than a fit would
        r = np.empty(len(freqs), dtype=complex)
        t = np.empty(len(freqs), dtype=complex)
        notes: dict[str, str] = {}  # one warning per kind, the first met
        for i, hz in enumerate(freqs):
            if cancel is not None and cancel():
                raise SolveCancelled(f"the array sweep was cancelled after {i} of {len(freqs)}")
            solution = solve_point(mesh, float(hz), inputs)
            r[i], t[i] = solution.co_polar()
            for text in solution.warnings:
                notes.setdefault(text.split(":")[0], text)
            if progress is not None:
                progress(i + 1, len(freqs))
        resonances = resonance_frequencies(freqs, np.abs(r))
        if grounded:  # the dips, where something absorbs
            resonances = reflector_resonances(freqs, r, resonance_frequencies(freqs, -np.abs(r)))
        return ArraySweep(
            freqs,
            r,
            t,
            onsets,
            resonances,
            inputs,
            freqs.copy(),
            np.zeros(len(freqs)),
            tuple(notes.values()),
            guided,
            zero_phase_frequencies(freqs, r) if grounded else np.zeros(0),
        )
    sweep = periodic_sweep(
        mesh,
        freqs,
        inputs.incidence(),
        interpolate=True,
        polarizations="incident",
        sheet_impedance=inputs.sheet_impedance,
        progress=progress,
        cancel=cancel,
        stack=inputs.stack,
    )
    r, t = sweep.co_polar()
    resonances = np.asarray(sweep.resonances, dtype=float)
    if grounded:
        dips = [
            f for f, kind in zip(resonances, sweep.resonance_kinds, strict=True) if kind == "dip"
        ]
        resonances = reflector_resonances(freqs, r, np.asarray(dips, dtype=float))
    return ArraySweep(
        frequencies=freqs,
        reflection=np.asarray(r),
        transmission=np.asarray(t),
        grating_lobe_onsets=onsets,
        resonances=resonances,
        inputs=inputs,
        sampled=np.asarray(sweep.sampled, dtype=float),
        error_estimate=np.asarray(sweep.error_estimate, dtype=float),
        warnings=tuple(sweep.warnings),
        guided_onsets=guided,
        zero_phase=zero_phase_frequencies(freqs, r) if grounded else np.zeros(0),
    )


def array_unknowns(mesh: TriMesh) -> int:
    """The periodic solver's unknowns of a cell's ``mesh``: its interior RWG functions and
    the pairs of boundary edges matched across the cell's sides."""
    from barymesh.cell.periodic import periodic_pairs

    pairs = periodic_pairs(mesh, mesh.lattice, mesh.tolerance)
    return len(mesh.rwg) + (len(pairs.edges) if pairs.matched else 0)


def check_array_memory(mesh: TriMesh) -> None:
    """Raise ``barymesh.mom.ProblemTooLarge`` when the array of ``mesh`` would not fit in
    memory (:func:`barymesh.mom.check_periodic_memory`), from its triangles and unknowns
    (:func:`array_unknowns`): in the worker thread, in a second, rather than after the
    solver process has built the cell's geometry."""
    from barymesh.mom import check_periodic_memory

    check_periodic_memory(mesh.n_triangles, array_unknowns(mesh))


def sweep_array(
    mesh: TriMesh,
    inputs: ArrayInputs,
    progress: Callable[[int, int], None] | None = None,
    cancel: Callable[[], bool] | None = None,
    in_process: bool = True,
) -> ArraySweep:
    """The co-polar (0, 0) R and T of ``mesh``'s infinite array over ``inputs``' band.

    The sweep runs in :func:`solver_process` (``in_process=False``: here); ``progress``
    is called with (solves done, frequencies) while it runs. Raises
    ``barymesh.mom.SolveCancelled`` when ``cancel()`` turns true (seen before the next
    solve), or ValueError naming what is wrong with the cell.
    """
    lattice_vectors(mesh)  # no lattice: say so here, before a process is started
    check_array_memory(mesh)  # too large: say so here, before the process builds tables
    if not in_process:
        return _sweep(mesh, inputs, progress, cancel)
    return in_solver_process(_sweep, (mesh, inputs), len(inputs.frequencies), progress, cancel)


@dataclass(frozen=True)
class OrderRow:
    """One propagating Floquet order of a solution: its amplitudes, power and direction.

    ``reflected`` and ``transmitted`` are the TE and TM amplitudes' norm (units of the
    incident field); ``power_r``/``power_t`` their power over the incident power;
    ``theta``/``phi`` (degrees) the direction the reflected wave leaves in (the
    transmitted one leaves at the same angles below the screen).
    """

    p: int
    q: int
    reflected: float
    transmitted: float
    power_r: float
    power_t: float
    theta: float
    phi: float


def orders_rows(solution: Any) -> list[OrderRow]:
    """The table rows of every propagating order of a ``PeriodicSolution``, (0, 0) first."""
    power_r, power_t = solution.power_fractions
    kappa = np.asarray(solution.kappa, dtype=float)
    k = np.sqrt(np.einsum("ij,ij->i", kappa, kappa) + np.real(solution.beta) ** 2)
    theta = np.degrees(np.arcsin(np.clip(np.hypot(kappa[:, 0], kappa[:, 1]) / k, 0.0, 1.0)))
    phi = np.degrees(np.arctan2(kappa[:, 1], kappa[:, 0]))
    phi = np.where(theta < 1e-9, 0.0, phi)
    r = np.linalg.norm(np.abs(solution.reflection), axis=1)
    t = np.linalg.norm(np.abs(solution.transmission), axis=1)
    return [
        OrderRow(
            int(solution.orders[i, 0]),
            int(solution.orders[i, 1]),
            float(r[i]),
            float(t[i]),
            float(power_r[i]),
            float(power_t[i]),
            float(theta[i]),
            float(phi[i]) + 0.0,
        )
        for i in range(len(solution.orders))
    ]

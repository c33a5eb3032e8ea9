"""The EFIE of an infinite array: a flat PEC screen repeated on a 2D lattice.

A plane wave of transverse wavevector k_t falls on the array; the currents in
cell (m, n) are those of cell (0, 0) times e^(−j k_t·ρ_mn) (Floquet). The EFIE on
one cell is the free-space one with G replaced by the periodic Green's function
G_p of :mod:`barymesh.mom.periodic_green`::

    Z_mn = jη/4π ∫∫ [k f_m·f_n − (1/k) ∇·f_m ∇'·f_n] G_p(r − r') dS dS'

Each triangle pair (o, s) is integrated against the image of s nearest to o,
shifted by ρ_σ (σ from rounding the lattice coordinates of c_o − c_s), using
G_p(r − r') = e^(−j k_t·ρ_σ) G_p(r − r' − ρ_σ), and G_p = G + G_reg there: G =
e^(−jkR)/R of that one image, G_reg smooth over the reduced cell. How each part is
integrated, and fast, is :mod:`barymesh.mom.periodic_fill`.

The scattered field is a sum of Floquet orders (p, q) of wavevectors
(κ_pq, ±β_pq) above and below the screen, each an amplitude
E_pq = −kη / (2 A β_pq) · J̃(κ_pq)_⊥ with J̃(κ) = ∫_cell J e^(+jκ·ρ) dS.

Polarisations: TE is ẑ × κ̂ (for κ = 0, the incident plane's φ̂); TM completes
the wave's triad with a tangential part that is the same above and below
(TM = TE × k̂ for waves going down, −TE × k̂ for waves going up). With this
convention the co-polar (0, 0) coefficients of a zero-thickness screen obey
T = 1 + R, and power balance reads Σ (|R|² + |T|²) β_pq / β_00 = 1 over the
propagating orders.

Below this module: the cell's frequency-independent data,
:mod:`barymesh.mom.periodic_geometry`; the fill, :mod:`barymesh.mom.periodic_fill`; the
orders, their onsets and their TE/TM basis, :mod:`barymesh.mom.floquet`.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from functools import cache
from typing import Any

import numpy as np
import scipy.sparse as sp
from threadpoolctl import ThreadpoolController

from ..mesh import TriMesh
from .compiled_periodic_fill import has_pair_rows
from .excitation import PlaneWave
from .floquet import harmonics
from .operator import ETA0, wavenumber
from .periodic_caveats import periodic_warnings
from .periodic_checks import (
    GEOMETRY_BYTES_PER_T2,
    GEOMETRY_PEAK_BYTES_PER_T2,
    PERIODIC_FIXED_BYTES,
    SOLVE_BYTES_PER_N2,
    as_lattice,
    check_green_terms,
    check_periodic_memory,
    periodic_memory_needed,
)
from .periodic_fill import fill
from .periodic_geometry import (
    MAX_TRIANGLE,
    NEAR_FACTOR,
    PeriodicGeometry,
    cell_current,
    lattice_metres,
    periodic_geometry,
)
from .periodic_layered import layer_orders, layered_kernel, sheet_field
from .solve import check_sheet_impedance, dense_solve
from .stack import Stack, background, lit_side_loss, side, vacuum_admittance

#: What this module defines, and what it re-exports from the modules it was split into:
#: the geometry (:mod:`barymesh.mom.periodic_geometry`) and its memory model
#: (:mod:`barymesh.mom.periodic_checks`).
__all__ = [
    "GEOMETRY_BYTES_PER_T2",
    "GEOMETRY_PEAK_BYTES_PER_T2",
    "MAX_TRIANGLE",
    "NEAR_FACTOR",
    "PERIODIC_FIXED_BYTES",
    "SERIAL_BLAS_UNKNOWNS",
    "SOLVE_BYTES_PER_N2",
    "FilledSystem",
    "PeriodicGeometry",
    "PeriodicSolution",
    "blas_threads",
    "check_periodic_memory",
    "check_stack",
    "fill_system",
    "gram_matrix",
    "lattice_metres",
    "one_blas_thread",
    "periodic_geometry",
    "periodic_impedance_matrix",
    "periodic_memory_needed",
    "periodic_solve",
    "periodic_solve_many",
    "solve_system",
]

#: Largest solve (unknowns) run with one BLAS thread (:func:`blas_threads`): on a shared
#: 2-core machine the threaded LU of 1,680 unknowns took 0.41-0.55 s, one thread 0.24 s.
SERIAL_BLAS_UNKNOWNS = 2000


def periodic_impedance_matrix(
    pg: PeriodicGeometry,
    k: complex,
    kt: tuple[float, float] | np.ndarray = (0.0, 0.0),
    stack: Stack | None = None,
    backend: str | None = None,
    double: bool = False,
) -> np.ndarray:
    """The (N, N) complex EFIE matrix of the array at wavenumber ``k``, Floquet phase ``kt``.

    ``kt`` is the incident wave's transverse wavevector (rad/m). Reciprocity:
    Z(k_t)ᵀ = Z(−k_t). ``k`` is the vacuum's; ``stack`` (:class:`~barymesh.mom.stack.Stack`)
    puts the sheet on layers (None, or a stack with no layer and no ground: in vacuum).
    ``backend`` ("numba", "numpy", or None: ``BARYMESH_FILL``, else numba when installed)
    and ``double`` (the numpy path in double precision, the compiled one's reference)
    pick the assembly, as in :func:`barymesh.mom.operator.impedance_matrix`.
    """
    if complex(k).imag != 0:
        raise ValueError(f"k={k!r}: the periodic fill takes a real wavenumber (lossless medium)")
    kt = np.asarray(kt, dtype=np.float64)
    k = float(np.real(k))
    if stack is None or stack.is_free_standing:
        return fill(pg, k, kt, backend=backend, double=double)
    return fill(pg, k, kt, layered_kernel(stack, pg.lattice, k, kt), backend, double)


@dataclass(frozen=True, eq=False)
class PeriodicSolution:
    """Currents and Floquet amplitudes of an infinite array at one frequency and incidence.

    Attributes
    ----------
    geometry : PeriodicGeometry
    frequency : float
        Hz.
    incidence : PlaneWave
    coefficients : (N,) complex
        RWG currents of cell (0, 0) (A).
    orders : (P, 2) int
        Floquet orders (p, q), the propagating ones: (0, 0) first.
    kappa : (P, 2) float
        Their transverse wavevectors (rad/m).
    beta : (P,) float
        Their normal wavenumbers (rad/m).
    reflection, transmission : (P, 2) complex
        Amplitudes of each order's TE and TM fields on the incident side and the far
        side, in units of the incident amplitude (transmission includes the incident
        wave in the (0, 0) order).
    incident_te_tm : (2,) complex
        The incident field's TE and TM components (unit amplitude).
    condition_number, residual : float
        Of the solve (see :func:`barymesh.mom.solve.dense_solve`).
    sheet_impedance : complex
        Z_s of the screen (Ω per square).
    absorption : float
        Power dissipated in the sheet and in the layers over the incident power through
        the cell (:attr:`sheet_absorption` + :attr:`layer_absorption`).
    stack : Stack or None
        The layers around the sheet (None: free-standing in vacuum).
    sheet_absorption, layer_absorption : float
        The two parts of :attr:`absorption`: in the sheet impedance, in the layers' loss.
    layer_orders : (L, 2) int
        Floquet orders (p, q) that propagate in some layer of the stack but not in vacuum:
        guided inside the stack, they carry no power out (not grating lobes).
    warnings : tuple of str
        When the result should not be trusted as it is (see :mod:`barymesh.mom.caveats`).
    """

    geometry: PeriodicGeometry
    frequency: float
    incidence: PlaneWave
    coefficients: np.ndarray
    orders: np.ndarray
    kappa: np.ndarray
    beta: np.ndarray
    reflection: np.ndarray
    transmission: np.ndarray
    incident_te_tm: np.ndarray
    condition_number: float
    residual: float
    sheet_impedance: complex = 0j
    absorption: float = 0.0
    stack: Stack | None = None
    sheet_absorption: float = 0.0
    layer_absorption: float = 0.0
    layer_orders: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), dtype=int))
    warnings: tuple[str, ...] = ()

    @property
    def reference_planes(self) -> tuple[float, float]:
        """Heights (mm) over the sheet of the planes R and T are referred to.

        (the face the wave falls on, the far face): the stack's top and bottom faces
        for a wave from above, the other way round from below; (0, 0) free-standing.
        A reflection phase means nothing without its reference plane.
        """
        if self.stack is None:
            return (0.0, 0.0)
        top, bottom = self.stack.reference_planes
        return (top, bottom) if np.asarray(self.incidence.direction)[2] < 0 else (bottom, top)

    @property
    def power_fractions(self) -> tuple[np.ndarray, np.ndarray]:
        """(P,) reflected and transmitted power of each order over the incident power."""
        weight = self.beta / self.beta[0]
        return (
            weight * (np.abs(self.reflection) ** 2).sum(axis=1),
            weight * (np.abs(self.transmission) ** 2).sum(axis=1),
        )

    @property
    def power_balance(self) -> float:
        """Reflected, transmitted and absorbed power over the incident power: 1.

        The absorbed part is that of a sheet impedance (zero on a perfect conductor).
        """
        r, t = self.power_fractions
        return float(r.sum() + t.sum() + self.absorption)

    def co_polar(self) -> tuple[complex, complex]:
        """(R, T) of the (0, 0) order along the incident polarisation."""
        p = self.incident_te_tm
        return complex(self.reflection[0] @ np.conj(p)), complex(self.transmission[0] @ np.conj(p))

    @property
    def current_density(self) -> np.ndarray:
        """(T, 3) complex J (A/m) at the centroids of cell (0, 0)."""
        t = self.geometry.base.n_triangles
        kt = self.kappa[0]
        return cell_current(self.geometry, kt, self.coefficients, np.zeros((t, 1, 3)))[:, 0]


def periodic_solve(
    mesh: TriMesh,
    frequency: float,
    incidence: PlaneWave | None = None,
    *,
    lattice: Any = None,
    sheet_impedance: complex = 0.0,
    memory_limit: float | None = None,
    stack: Stack | None = None,
) -> PeriodicSolution:
    """Reflection and transmission of the infinite array of ``mesh`` at one frequency.

    Parameters
    ----------
    mesh : TriMesh
        One cell of the screen (mm), flat in z = 0, its metal inside the cell.
    frequency : float
        Hz.
    incidence : PlaneWave, optional
        Default: normal incidence from above, E along x.
    lattice : Lattice, optional
        The array's lattice (mm); default the mesh's own (a unit cell's).
    sheet_impedance : complex
        Surface impedance Z_s of the screen (Ω per square, Re Z_s >= 0): the boundary
        condition E_tan = Z_s J adds Z_s times the Gram matrix to the EFIE. 0 is a
        perfect conductor; a resistive or lossy sheet absorbs
        (:attr:`PeriodicSolution.absorption`).
    memory_limit : float, optional
        A cap in bytes (in addition to the memory available now); a cell that would
        need more raises :class:`~barymesh.mom.ProblemTooLarge` before allocating
        (:func:`check_periodic_memory`).
    stack : Stack, optional
        Dielectric layers above and below the sheet and a ground plane
        (:class:`~barymesh.mom.stack.Stack`); R is then referred to the stack's top face
        and T to its bottom face (:attr:`PeriodicSolution.reference_planes`). None: the
        sheet in vacuum.

    Returns
    -------
    PeriodicSolution

    See Also
    --------
    periodic_solve_many : several incidences at one frequency, one matrix per k_t.
    """
    wave = PlaneWave() if incidence is None else incidence
    if not isinstance(wave, PlaneWave):
        raise TypeError(f"incidence must be a PlaneWave, got {type(wave).__name__}")
    return periodic_solve_many(
        mesh,
        frequency,
        [wave],
        lattice=lattice,
        sheet_impedance=sheet_impedance,
        memory_limit=memory_limit,
        stack=stack,
    )[0]


def periodic_solve_many(
    mesh: TriMesh,
    frequency: float,
    incidences: Sequence[PlaneWave],
    *,
    lattice: Any = None,
    sheet_impedance: complex = 0.0,
    memory_limit: float | None = None,
    stack: Stack | None = None,
) -> tuple[PeriodicSolution, ...]:
    """:func:`periodic_solve` for several incident waves at one frequency.

    The impedance matrix depends on the incidence only through its transverse
    wavevector k_t = k (d_x, d_y): waves that share it (TE and TM from one direction,
    or the same direction's mirror from below) share one fill and one LU, solved
    with one right-hand side per wave (:func:`~barymesh.mom.solve.dense_solve`). Each
    distinct k_t is filled and factorised once.

    Parameters
    ----------
    mesh : TriMesh
        One cell of the screen (mm), as for :func:`periodic_solve`.
    frequency : float
        Hz.
    incidences : sequence of PlaneWave
        At least one.
    lattice : Lattice, optional
        Default: the mesh's own.
    sheet_impedance : complex
        Ω per square, as for :func:`periodic_solve`.
    memory_limit : float, optional
        Bytes, as for :func:`periodic_solve`.
    stack : Stack, optional
        The layers, as for :func:`periodic_solve`.

    Returns
    -------
    tuple of PeriodicSolution
        One per incidence, in their order; each equals :func:`periodic_solve` of that
        wave (to the refinement's floor, ~1e-15 relative).
    """
    frequency = float(frequency)
    if not (np.isfinite(frequency) and frequency > 0):
        raise ValueError(f"frequency={frequency!r} is invalid; expected a positive number (Hz)")
    if isinstance(incidences, PlaneWave):
        raise TypeError(
            "incidences must be a sequence of PlaneWave; for one wave use periodic_solve"
        )
    waves = list(incidences)
    if not waves:
        raise ValueError("incidences is empty; expected at least one PlaneWave")
    for i, wave in enumerate(waves):
        if not isinstance(wave, PlaneWave):
            raise TypeError(f"incidences[{i}] must be a PlaneWave, got {type(wave).__name__}")
        if abs(np.asarray(wave.direction)[2]) < 1e-9:
            raise ValueError(
                f"incidences[{i}] travels along the screen (direction_z = 0)"
                if len(waves) > 1
                else "the incident wave travels along the screen (direction_z = 0)"
            )
    zs = check_sheet_impedance(sheet_impedance)
    stack = check_stack(stack)
    if stack is not None and stack.ground:
        for i, wave in enumerate(waves):
            if np.asarray(wave.direction)[2] > 0:
                raise ValueError(
                    f"incidences[{i}] comes from below, where the ground plane is: "
                    "a grounded stack is lit from above (direction_z < 0)"
                )
    lattice = as_lattice(lattice)
    for wave in waves:  # the lattice sums' terms and memory, before the geometry is built
        check_green_terms(lattice_metres(mesh, lattice), frequency, wave.direction, memory_limit)
    pg = periodic_geometry(mesh, lattice, memory_limit=memory_limit)
    check_periodic_memory(
        pg.base.n_triangles,
        pg.n_unknowns,
        memory_limit,
        geometry=False,
        pair_copy=not has_pair_rows(pg.plan),
    )
    k = wavenumber(frequency)
    groups: dict[tuple[float, float], list[int]] = {}
    for i, wave in enumerate(waves):
        d = np.asarray(wave.direction)
        groups.setdefault((float(k * d[0]), float(k * d[1])), []).append(i)
    out: list[PeriodicSolution | None] = [None] * len(waves)
    for kt, members in groups.items():
        with blas_threads(pg.n_unknowns):
            system = fill_system(pg, frequency, kt, zs, stack)
            solved = solve_system(system, [waves[i] for i in members])
        for i, s in zip(members, solved, strict=True):
            out[i] = s
    return tuple(out)  # type: ignore[arg-type]  # every slot filled


@cache
def _blas_controller() -> ThreadpoolController:
    return ThreadpoolController()


def blas_threads(n: int) -> contextlib.AbstractContextManager:
    """One BLAS thread for a solve of up to :data:`SERIAL_BLAS_UNKNOWNS` unknowns.

    Measured on this 2-core machine under a load of about 4: with two OpenBLAS threads
    the fill's small products and the LU of 936 unknowns stall (LU 0.28-0.40 s against
    0.06 s on one thread; a 32-triangle cell's whole solve 0.16 s against 0.02 s).
    """
    if n > SERIAL_BLAS_UNKNOWNS:
        return contextlib.nullcontext()
    return one_blas_thread()


def one_blas_thread() -> contextlib.AbstractContextManager:
    """Every BLAS library of the process on one thread, while the context lasts."""
    return _blas_controller().limit(limits=1, user_api="blas")


@dataclass(frozen=True, eq=False)
class FilledSystem:
    """The EFIE of an array at one frequency and k_t, filled, not yet solved.

    The two halves of a solve (:func:`fill_system`, :func:`solve_system`), so that a
    sweep can fill the next frequency while the last one is factorised.

    Attributes
    ----------
    geometry : PeriodicGeometry
    frequency : float
        Hz.
    kt : (2,) float
        The transverse wavevector (rad/m).
    matrix : (N, N) complex128
        Z, plus Z_s times the Gram matrix (read only).
    gram : (N, N) sparse or None
        The Gram matrix, when Z_s ≠ 0.
    sheet_impedance : complex
        Ω per square.
    stack : Stack or None
        The layers (None: vacuum).
    """

    geometry: PeriodicGeometry
    frequency: float
    kt: tuple[float, float]
    matrix: np.ndarray
    gram: sp.csr_matrix | None
    sheet_impedance: complex
    stack: Stack | None = None


def check_stack(stack: Any) -> Stack | None:
    """``stack`` as the solver takes it: None for the sheet in vacuum, else a Stack."""
    if stack is None:
        return None
    if not isinstance(stack, Stack):
        raise TypeError(f"stack must be a barymesh.mom.Stack (or None), got {type(stack).__name__}")
    return None if stack.is_free_standing else stack


def fill_system(
    pg: PeriodicGeometry,
    frequency: float,
    kt: Sequence[float] | np.ndarray,
    sheet_impedance: complex = 0.0,
    stack: Stack | None = None,
) -> FilledSystem:
    """The filled EFIE of ``pg`` at ``frequency`` (Hz) and Floquet phase ``kt`` (rad/m)."""
    key = (float(kt[0]), float(kt[1]))
    k = wavenumber(frequency)
    stack = check_stack(stack)
    z = periodic_impedance_matrix(pg, k, key, stack)
    gram = None
    if sheet_impedance != 0:
        gram = gram_matrix(pg, np.asarray(key))
        z += sheet_impedance * gram.toarray()
    return FilledSystem(pg, float(frequency), key, z, gram, complex(sheet_impedance), stack)


def solve_system(system: FilledSystem, waves: Sequence[PlaneWave]) -> list[PeriodicSolution]:
    """The solutions for ``waves``, which share the system's k_t: one LU, K right-hand sides.

    The LU is of a single-precision copy of ``system.matrix``; the refinement's residuals
    use the matrix itself, which is left as it is.
    """
    pg, frequency, kt = system.geometry, system.frequency, system.kt
    zs, gram, z, stack = system.sheet_impedance, system.gram, system.matrix, system.stack
    k = wavenumber(frequency)
    rule = pg.base.near
    _, test = pg.basis_maps(np.asarray(kt))
    columns = []
    for wave in waves:
        e = (
            wave.field(rule.points, k)
            if stack is None
            else sheet_field(stack, k, wave, rule.points)
        )
        e0 = np.einsum("tq,tqc->tc", rule.weights, e)
        e1 = np.einsum("tq,tqc->t", rule.weights, rule.rho * e)
        columns.append(test @ np.concatenate([e1, e0[:, 0], e0[:, 1]]))
    if len(columns) == 1:  # one right-hand side: the 1-D solve, as before
        current, cond, residual = dense_solve(z, columns[0])
        currents, residuals = current[:, None], np.array([residual])
    else:
        currents, cond, many = dense_solve(z, np.stack(columns, axis=1))
        residuals = np.asarray(many)
    solutions = []
    for j, wave in enumerate(waves):
        current = np.ascontiguousarray(currents[:, j])
        if stack is None:
            solution = _floquet_amplitudes(
                pg, frequency, wave, k, kt, current, cond, float(residuals[j])
            )
        dissipated = 0.0
        if gram is not None:
            # ½ Re(Z_s) ∫ |J|² over the cell
            dissipated = 0.5 * zs.real * float(np.real(np.vdot(current, gram @ current)))
        if stack is not None:
            given = 0.0
            if stack.lossy:
                given = 0.5 * float(np.real(np.vdot(current, z @ current))) - dissipated
            solution = _layered_amplitudes(
                pg, frequency, wave, k, kt, current, cond, float(residuals[j]), stack, given
            )
        # against the incident power through the cell
        d = np.asarray(wave.direction)
        incident = wave.amplitude**2 / (2.0 * ETA0) * pg.area * abs(float(d[2]))
        absorbed = dissipated / incident
        solutions.append(
            replace(
                solution,
                sheet_impedance=zs,
                sheet_absorption=absorbed,
                absorption=absorbed + solution.layer_absorption,
                warnings=periodic_warnings(pg, stack, frequency, d, cond),
            )
        )
    return solutions


def gram_matrix(pg: PeriodicGeometry, kt: np.ndarray) -> sp.csr_matrix:
    """(N, N) sparse G_mn = ∫ f_m*·f_n dS over cell (0, 0): the RWG Gram matrix.

    Per triangle, f = C ρ + D with ρ measured from its centroid, so ∫ f_m·f_n =
    C_m C_n ∫ |ρ|² + D_m·D_n A (the cross terms vanish: ∫ ρ dS = 0). Testing halves
    carry the conjugate Floquet phase, as in the impedance matrix.
    """
    base = pg.base
    rule = base.near
    second = np.einsum("tq,tqc,tqc->t", rule.weights, rule.rho, rule.rho)  # ∫ |ρ|² dS
    weights = np.concatenate([second, base.areas, base.areas])
    basis, test = pg.basis_maps(kt)
    return (test @ sp.diags(weights) @ basis.T).tocsr()


def _floquet_amplitudes(pg, frequency, wave, k, kt, current, cond, residual) -> PeriodicSolution:
    h = harmonics(pg, wave, k, kt, current)
    orders, kappa, beta, jt = h.orders, h.kappa, h.beta, h.jt
    te, tm_up, tm_down = h.te, h.tm_up, h.tm_down
    d = np.asarray(wave.direction)
    scale = -k * ETA0 / (2.0 * pg.area * beta)  # E_pq = scale · J̃_⊥
    up = scale[:, None] * np.stack(
        [np.einsum("pc,pc->p", jt, te), np.einsum("pc,pc->p", jt, tm_up)], axis=1
    )
    down = scale[:, None] * np.stack(
        [np.einsum("pc,pc->p", jt, te), np.einsum("pc,pc->p", jt, tm_down)], axis=1
    )
    pol = np.asarray(wave.polarization) * wave.amplitude
    going_down = d[2] < 0
    tm_inc = tm_down[0] if going_down else tm_up[0]
    incident = np.array([pol @ te[0], pol @ tm_inc]) / wave.amplitude
    reflected, transmitted = (up, down) if going_down else (down, up)
    transmitted = transmitted / wave.amplitude
    transmitted[0] += incident
    return PeriodicSolution(
        geometry=pg,
        frequency=frequency,
        incidence=wave,
        coefficients=current,
        orders=orders,
        kappa=kappa,
        beta=beta,
        reflection=reflected / wave.amplitude,
        transmission=transmitted,
        incident_te_tm=incident,
        condition_number=cond,
        residual=residual,
    )


def _layered_amplitudes(
    pg, frequency, wave, k, kt, current, cond, residual, stack: Stack, power_given: float = 0.0
) -> PeriodicSolution:
    """:func:`_floquet_amplitudes` on layers: each order's sheet voltage through the line.

    The sheet current's harmonic J̃(κ) drives the line of each order: the tangential
    field at the sheet is V = −η0 J̃ / (A (y_up + y_down)) (TE along ẑ × κ̂, TM along κ̂),
    carried to the stack's faces by the sides' transfers; the background (the stack lit
    without the sheet) adds to the (0, 0) order.

    ``power_given`` is ½ Re(I^H Z I) less the sheet impedance's loss (W per cell): with
    lossy layers, the power the currents lose in them is that less what they radiate.
    """
    h = harmonics(pg, wave, k, kt, current)
    orders, kappa, beta, jt, phi = h.orders, h.kappa, h.beta, h.jt, h.phi
    te, tm_up, tm_down = h.te, h.tm_up, h.tm_down
    d = np.asarray(wave.direction)
    kappa2 = np.einsum("ij,ij->i", kappa, kappa)
    norm = np.sqrt(kappa2)
    plane = np.array([math.cos(phi), math.sin(phi), 0.0])
    safe = np.where(norm > 1e-9 * k, norm, 1.0)[:, None]
    along = np.where(
        norm[:, None] > 1e-9 * k,
        np.concatenate([kappa / safe, np.zeros((len(kappa), 1))], 1),
        plane,
    )
    up = side(tuple(reversed(stack.above)), False, kappa2, k)
    down = side(stack.below, stack.ground, kappa2, k)
    drive = np.stack([np.einsum("pc,pc->p", jt, te), np.einsum("pc,pc->p", jt, along)], axis=1)
    sheet = -ETA0 / pg.area * drive / (up.admittance + down.admittance)  # (P, 2) V at the sheet
    # full amplitudes at the faces: TE is tangential; TM's tangential part is along κ̂
    tm_up_t = np.einsum("pc,pc->p", tm_up, along)
    tm_down_t = np.einsum("pc,pc->p", tm_down, along)
    at_top = sheet * up.transfer / np.stack([np.ones(len(kappa)), tm_up_t], axis=1)
    at_bottom = sheet * down.transfer / np.stack([np.ones(len(kappa)), tm_down_t], axis=1)
    pol = np.asarray(wave.polarization) * wave.amplitude
    going_down = d[2] < 0
    tm_inc = tm_down[0] if going_down else tm_up[0]
    incident = np.array([pol @ te[0], pol @ tm_inc]) / wave.amplitude
    line = background(stack, k, float(np.hypot(kt[0], kt[1])), from_above=bool(going_down))
    reflected, transmitted = (at_top, at_bottom) if going_down else (at_bottom, at_top)
    reflected = reflected / wave.amplitude
    transmitted = transmitted / wave.amplitude
    reflected[0] += line.reflection * incident
    transmitted[0] += line.transmission * incident
    absorbed = 0.0
    if stack.lossy:
        v_inc = (
            wave.amplitude * incident * np.array([1.0, (tm_down_t if going_down else tm_up_t)[0]])
        )
        lit_side, far_side = (up, down) if going_down else (down, up)
        lost = _layers_loss(
            stack, bool(going_down), k, kappa2, sheet, line.sheet * v_inc, v_inc, lit_side, far_side
        )
        given = power_given / (pg.area / ETA0)  # W per m², over 1/η0
        absorbed = (given + lost) / (0.5 * wave.amplitude**2 * abs(float(d[2])))
    return PeriodicSolution(
        geometry=pg,
        frequency=frequency,
        incidence=wave,
        coefficients=current,
        orders=orders,
        kappa=kappa,
        beta=beta,
        reflection=reflected,
        transmission=transmitted,
        incident_te_tm=incident,
        condition_number=cond,
        residual=residual,
        stack=stack,
        layer_orders=layer_orders(stack, pg.lattice, k, np.asarray(kt)),
        layer_absorption=absorbed,
        absorption=absorbed,
    )


def _layers_loss(
    stack: Stack,
    from_above: bool,
    k: float,
    kappa2: np.ndarray,
    sheet: np.ndarray,
    background_field: np.ndarray,
    incoming: np.ndarray,
    lit: Any,
    far: Any,
) -> float:
    """What to add to ½ Re(I^H Z I) (per m², over 1/η0) for the power lost in the layers.

    ½ Re(I^H Z I) is what the currents give the fields: radiated into the propagating
    orders, or lost in the layers under their own field. So take off what ``sheet`` (the
    currents' voltages at the sheet, (P, 2), propagating orders) radiates through the two
    sides, and add what the stack's own field ``background_field`` (the (0, 0) order's
    voltages at the sheet; ``incoming`` on the lit face) adds to the (0, 0) order's loss.
    """
    y0 = vacuum_admittance(kappa2, k).real

    def outward_loss(v: np.ndarray, line: Any) -> float:  # into the side, less out of it
        return 0.5 * float(
            np.sum(
                np.abs(v) ** 2 * (line.admittance[0].real - np.abs(line.transfer[0]) ** 2 * y0[0])
            )
        )

    radiated = 0.5 * float(
        np.sum(np.abs(sheet) ** 2 * (np.abs(lit.transfer) ** 2 + np.abs(far.transfer) ** 2) * y0)
    )
    own, both = sheet[0], sheet[0] + background_field
    extra = outward_loss(both, far) - outward_loss(own, far)
    lit_layers = stack.sides(from_above)[0]
    if any(layer.lossy for layer in lit_layers):
        extra += lit_side_loss(lit_layers, float(kappa2[0]), k, both, incoming)
        extra -= outward_loss(own, lit)
    return extra - radiated

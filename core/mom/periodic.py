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
"""

from __future__ import annotations

import contextlib
import math
import weakref
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from functools import cache, cached_property
from typing import Any

import numpy as np
import scipy.sparse as sp
from threadpoolctl import ThreadpoolController

from ..mesh import TriMesh
from .excitation import PlaneWave
from .geometry import (
    METRES_PER_MESH_UNIT,
    MIRROR_MOMENTS,
    SIZE_TIE,
    MomGeometry,
    close_pairs,
    mom_geometry,
    static_moments,
)
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
from .periodic_green import PeriodicGreen
from .periodic_layered import layer_orders, layered_kernel, sheet_field
from .periodic_plan import FillPlan, fill_plan
from .solve import (
    check_sheet_impedance,
    dense_solve,
)
from .stack import Stack, background, lit_side_loss, side, vacuum_admittance

#: What this module defines, and what it re-exports from the modules it was split into
#: (the geometry's memory model lives in :mod:`barymesh.mom.periodic_checks`).
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

#: Near triples: centroids closer than this many times the larger triangle's longest edge.
NEAR_FACTOR = 1.5
#: Largest triangle, as a fraction of the cell's smallest height.
MAX_TRIANGLE = 0.2
#: Largest solve (unknowns) run with one BLAS thread (:func:`blas_threads`): on a shared
#: 2-core machine the threaded LU of 1,680 unknowns took 0.41-0.55 s, one thread 0.24 s.
SERIAL_BLAS_UNKNOWNS = 2000


def lattice_metres(mesh: TriMesh, lattice: Any) -> np.ndarray:
    """The lattice vectors (2, 2) in metres: ``lattice``'s, or else the mesh's own."""
    lat = lattice if lattice is not None else getattr(mesh, "lattice", None)
    if lat is None:
        raise ValueError(
            "the mesh carries no lattice: an infinite array needs a unit cell "
            "(mesh a cell, or pass lattice=Lattice(...))"
        )
    vectors = np.array([lat.a1, lat.a2], dtype=np.float64) * METRES_PER_MESH_UNIT
    return vectors


@dataclass(frozen=True, eq=False)
class PeriodicGeometry:
    """The frequency-independent part of an infinite-array solve (metres).

    Attributes
    ----------
    base : MomGeometry
        The mesh's free-space geometry (rules, its interior RWG maps, its near pairs:
        those of the periodic fill whose nearest image is the triangle itself).
    lattice : (2, 2) float
        Rows a1, a2 (m).
    maps : (N, 3T) sparse float
        The RWG functions of cell (0, 0) as [C | D_x | D_y] (see
        :mod:`barymesh.mom.geometry`): the interior ones, then one per pair of matching
        edges on opposite sides of the cell, whose T+ lies inside the cell at the minus
        side and whose T− is the triangle at the plus side, seen from the next cell.
        ``maps`` holds every half but those T−, which are in ``folded``.
    folded : (N, 3T) sparse float
        The T− halves of the unknowns across the cell's sides, at their place in cell
        (0, 0); they carry the Floquet phase e^(−j k_t·a) of the lattice vector a they
        are moved by (``crossing``).
    crossing : (N, 2) float
        That lattice vector (m), zero for the interior unknowns.
    shift : (T, T, 2) int8
        σ of each pair (observation, source): the source image used; σ(s, o) = −σ(o, s).
    cross : (K, 2) int
        (observation, source) pairs whose image σ ≠ 0 touches the observation triangle
        (near across the cell's sides), sorted by observation.
    cross_static_inv_r, cross_static_r : (K, 8) float
        The eight moments of 1/R and R over those pairs (near rule outside, closed form
        inside), against the shifted source.
    cross_distances : (K, Qn, Qn) float
        |r − r' − ρ_σ| between their near rule's points.
    plan : FillPlan
        How the matrix is filled (:mod:`barymesh.mom.periodic_fill`).
    """

    base: MomGeometry
    lattice: np.ndarray
    maps: sp.csr_matrix
    folded: sp.csr_matrix
    crossing: np.ndarray
    shift: np.ndarray
    cross: np.ndarray
    cross_static_inv_r: np.ndarray
    cross_static_r: np.ndarray
    cross_distances: np.ndarray
    plan: FillPlan

    @property
    def area(self) -> float:
        return float(abs(np.linalg.det(self.lattice)))

    @property
    def n_unknowns(self) -> int:
        return self.maps.shape[0]

    @property
    def n_crossing(self) -> int:
        """Unknowns across the cell's sides."""
        return int(np.count_nonzero(np.any(self.crossing != 0, axis=1)))

    @cached_property
    def near(self) -> np.ndarray:
        """(K, 2) int: every near (observation, source) pair, sorted by observation."""
        pairs = np.concatenate([self.base.near_pairs, self.cross])
        return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]

    def basis_maps(self, kt: np.ndarray) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """The (N, 3T) complex maps of the basis functions and of the testing functions.

        Basis halves moved by a carry e^(−j k_t·a), testing halves its conjugate. The last
        k_t's pair is kept: a solve asks for it three times (the right-hand side, the
        orders taken out of G_reg, the current). Read only.
        """
        kt = np.asarray(kt, dtype=np.float64)
        key = (float(kt[0]), float(kt[1]))
        last = self.__dict__.get("_last_basis_maps")
        if last is not None and last[0] == key:
            return last[1]
        phase = np.exp(-1j * (self.crossing @ kt))
        basis = self.maps + sp.diags(phase) @ self.folded
        test = self.maps + sp.diags(np.conj(phase)) @ self.folded
        maps = (basis.tocsr(), test.tocsr())
        self.__dict__["_last_basis_maps"] = (key, maps)  # a frozen dataclass: not setattr
        return maps


def _shift_vectors(shift: np.ndarray, lattice: np.ndarray) -> np.ndarray:
    """ρ_σ = σ_1 a1 + σ_2 a2 (..., 2), elementwise so that ρ_(−σ) = −ρ_σ bit for bit."""
    s = shift.astype(np.float64)
    return s[..., :1] * lattice[0] + s[..., 1:] * lattice[1]


def _rwg_maps(
    mesh: TriMesh, base: MomGeometry, lattice: Any, vectors: np.ndarray
) -> tuple[sp.csr_matrix, sp.csr_matrix, np.ndarray]:
    """[C | D_x | D_y] of the interior unknowns and of those across the cell's sides."""
    from ..cell.periodic import periodic_pairs

    lat = lattice if lattice is not None else mesh.lattice
    pairs = periodic_pairs(mesh, lat, mesh.tolerance)
    if not pairs.matched:
        raise ValueError(
            f"{len(pairs.unmatched_edges)} boundary edge(s) of the metal lie on a side of the "
            "cell with no matching edge on the opposite side: the metal crosses the cell "
            "boundary, but its mesh is not periodic there (mesh the cell with a lattice)"
        )
    t = base.n_triangles
    interior = [base.coef_matrix] + list(base.offset_matrices[:2])
    n_int = base.n_unknowns
    topo = mesh.topology
    minus, plus = pairs.edges[:, 0], pairs.edges[:, 1]
    m = len(minus)
    points = base.vertices
    rows: list[np.ndarray] = []
    cols: list[np.ndarray] = []
    values: list[np.ndarray] = []
    rows_b: list[np.ndarray] = []
    cols_b: list[np.ndarray] = []
    values_b: list[np.ndarray] = []
    if m:
        ends = topo.edges[minus]
        length = np.linalg.norm(points[ends[:, 0]] - points[ends[:, 1]], axis=1)
        for side, (edge, sign) in enumerate(((minus, 1.0), (plus, -1.0))):
            tri = topo.edge_triangles[edge, 0]
            corners = base.triangles[tri]
            on_edge = (corners[:, :, None] == topo.edges[edge][:, None, :]).any(axis=2)
            free = corners[np.arange(m), np.argmin(on_edge, axis=1)]
            coef = sign * length / (2.0 * base.areas[tri])
            offset = base.centroids[tri] - points[free]
            row = n_int + np.arange(m)
            for c, value in enumerate((coef, coef * offset[:, 0], coef * offset[:, 1])):
                (rows_b if side else rows).append(row)
                (cols_b if side else cols).append(tri + c * t)
                (values_b if side else values).append(value)
    n = n_int + m
    head = sp.vstack([sp.hstack(interior, "csr"), sp.csr_matrix((m, 3 * t))], "csr")

    def matrix(r: list, c: list, v: list) -> sp.csr_matrix:
        if not r:
            return sp.csr_matrix((n, 3 * t))
        return sp.csr_matrix(
            (np.concatenate(v), (np.concatenate(r), np.concatenate(c))), shape=(n, 3 * t)
        )

    crossing = np.zeros((n, 2))
    crossing[n_int:] = vectors[pairs.edge_shift] if m else 0.0
    return (head + matrix(rows, cols, values)).tocsr(), matrix(rows_b, cols_b, values_b), crossing


_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def periodic_geometry(
    mesh: TriMesh, lattice: Any = None, *, memory_limit: float | None = None
) -> PeriodicGeometry:
    """The frequency-independent data of the array of ``mesh`` on ``lattice`` (or its own).

    Cached per mesh and lattice: a sweep over frequency or angle computes it once.

    Parameters
    ----------
    mesh : TriMesh
        One cell of the screen (mm).
    lattice : Lattice, optional
        Default: the mesh's own.
    memory_limit : float, optional
        A cap in bytes for building it and one solve beside it
        (:func:`check_periodic_memory`, checked before the T² tables are allocated).

    Raises
    ------
    ProblemTooLarge
        When the geometry and a solve would not fit in memory.
    ValueError
        A mesh off z = 0, triangles too large for the cell, metal across the cell's
        sides without matching periodic edges.
    """
    lattice = as_lattice(lattice)  # a Lattice, or two vectors in mm
    vectors = lattice_metres(mesh, lattice)
    key = tuple(vectors.ravel())
    per_mesh = _CACHE.setdefault(mesh, {})
    if key not in per_mesh:
        per_mesh.clear()  # one lattice per mesh at a time; keeps memory bounded
        per_mesh[key] = _periodic_geometry(mesh, lattice, vectors, memory_limit)
    return per_mesh[key]


def _periodic_geometry(
    mesh: TriMesh, lattice: Any, vectors: np.ndarray, memory_limit: float | None
) -> PeriodicGeometry:
    # before the geometry (a minute for a large cell): the memory of the unknowns (the
    # interior ones and the pairs across the sides, counted cheaply)
    from ..cell.periodic import periodic_pairs

    lat = lattice if lattice is not None else mesh.lattice
    pairs = periodic_pairs(mesh, lat, mesh.tolerance)
    check_periodic_memory(mesh.n_triangles, len(mesh.rwg) + len(pairs.edges), memory_limit)
    base = mom_geometry(mesh, near_factor=NEAR_FACTOR)  # its near pairs: those of σ = 0
    if np.any(base.vertices[:, 2] != 0.0):
        raise ValueError("the periodic solver takes flat screens only: the mesh is not in z = 0")
    heights = abs(np.linalg.det(vectors)) / np.linalg.norm(vectors, axis=1)
    if base.sizes.max() > MAX_TRIANGLE * heights.min():
        raise ValueError(
            f"triangles of up to {base.sizes.max() * 1e3:.4g} mm are too large for a cell of "
            f"height {heights.min() * 1e3:.4g} mm; refine the mesh (at most "
            f"{MAX_TRIANGLE:g} of the cell's height)"
        )
    maps, folded, crossing = _rwg_maps(mesh, base, lattice, vectors)
    check_periodic_memory(base.n_triangles, maps.shape[0], memory_limit)
    centroids = base.centroids[:, :2]
    lat = centroids @ np.linalg.inv(vectors)  # lattice coordinates of the centroids
    frac = lat[:, None, :] - lat[None, :, :]  # (T, T, 2), antisymmetric bit for bit
    shift = np.rint(frac)  # rint is odd (ties to even), so σ(s, o) = −σ(o, s)
    frac -= shift  # the reduced centroid offsets, in [−½, ½]²
    shift = shift.astype(np.int8)
    cross = _cross_pairs(base, vectors, shift)
    obs, src = cross[:, 0], cross[:, 1]
    offset = _shift_vectors(shift[obs, src], vectors)  # (K, 2)
    offset3 = np.concatenate([offset, np.zeros((len(offset), 1))], axis=1)
    static = _cross_static_moments(base, obs, src, offset3)
    rule = base.near
    d = rule.points[obs][:, :, None, :] - (rule.points[src] + offset3[:, None, :])[:, None]
    cross_distances = np.sqrt(np.einsum("kabc,kabc->kab", d, d))
    return PeriodicGeometry(
        base=base,
        lattice=vectors,
        maps=maps,
        folded=folded,
        crossing=crossing,
        shift=shift,
        cross=cross,
        cross_static_inv_r=static[0],
        cross_static_r=static[1],
        cross_distances=cross_distances,
        plan=fill_plan(base, vectors, shift, frac, cross, maps, folded),
    )


def _cross_static_moments(
    base: MomGeometry, obs: np.ndarray, src: np.ndarray, offset3: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The free-space solver's closed-form 1/R and R moments of the pairs near through an
    image, against the shifted sources; on one of each mirrored pair (o, s + a) and
    (s, o − a), the one with the smaller triangle under the rule, as for the pairs in the
    cell (:func:`barymesh.mom.geometry._mirrored_static_moments`): the other is its
    mirror, and Z(0) is symmetric across the cell's sides too."""
    n = base.n_triangles
    key = obs * n + src  # ascending: the pairs are sorted
    want = src * n + obs
    partner = np.minimum(np.searchsorted(key, want), max(len(key) - 1, 0))
    paired = (key[partner] == want) if len(key) else np.zeros(0, dtype=bool)
    sizes = base.sizes
    tie = np.abs(sizes[obs] - sizes[src]) <= SIZE_TIE * np.maximum(sizes[obs], sizes[src])
    smaller = (~tie & (sizes[obs] < sizes[src])) | (tie & (obs < src))
    computed = ~paired | smaller
    rows = np.flatnonzero(computed)
    corners = base.vertices[base.triangles]
    inv_r, r1 = static_moments(
        base.near,
        corners[src[rows]] + offset3[rows, None, :],
        base.centroids[src[rows]] + offset3[rows],
        obs[rows],
        np.arange(len(rows)),
    )
    where = np.full(len(obs), -1, dtype=np.intp)
    where[rows] = np.arange(len(rows))
    mirrors = np.flatnonzero(~computed)
    out = []
    for m in (inv_r, r1):
        full = np.empty((len(obs), 8))
        full[rows] = m
        full[mirrors] = m[where[partner[mirrors]]][:, MIRROR_MOMENTS]
        out.append(full)
    return out[0], out[1]


def _cross_pairs(base: MomGeometry, vectors: np.ndarray, shift: np.ndarray) -> np.ndarray:
    """(K, 2) pairs (o, s) near through an image σ ≠ 0, sorted (the σ = 0 ones: ``base``)."""
    centroids = base.centroids[:, :2]
    sizes = base.sizes
    low, high = shift.reshape(-1, 2).min(axis=0), shift.reshape(-1, 2).max(axis=0)
    found = []
    for s1 in range(int(low[0]), int(high[0]) + 1):
        for s2 in range(int(low[1]), int(high[1]) + 1):
            if s1 == 0 and s2 == 0:
                continue
            image = centroids + s1 * vectors[0] + s2 * vectors[1]
            hits = close_pairs(centroids, image, sizes, sizes, NEAR_FACTOR)
            o, s = hits[:, 0], hits[:, 1]
            keep = np.all(shift[o, s] == (s1, s2), axis=1)
            found.append(hits[keep])
    pairs = np.concatenate(found) if found else np.zeros((0, 2), dtype=np.intp)
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]


def periodic_impedance_matrix(
    pg: PeriodicGeometry,
    k: complex,
    kt: tuple[float, float] | np.ndarray = (0.0, 0.0),
    stack: Stack | None = None,
) -> np.ndarray:
    """The (N, N) complex EFIE matrix of the array at wavenumber ``k``, Floquet phase ``kt``.

    ``kt`` is the incident wave's transverse wavevector (rad/m). Reciprocity:
    Z(k_t)ᵀ = Z(−k_t). ``k`` is the vacuum's; ``stack`` (:class:`~barymesh.mom.stack.Stack`)
    puts the sheet on layers (None, or a stack with no layer and no ground: in vacuum).
    """
    if complex(k).imag != 0:
        raise ValueError(f"k={k!r}: the periodic fill takes a real wavenumber (lossless medium)")
    kt = np.asarray(kt, dtype=np.float64)
    k = float(np.real(k))
    if stack is None or stack.is_free_standing:
        return fill(pg, k, kt)
    return fill(pg, k, kt, layered_kernel(stack, pg.lattice, k, kt))


def _floquet_basis(kappa: np.ndarray, beta: np.ndarray, k: float, phi: float) -> tuple:
    """Unit TE and TM vectors (P, 3) of the waves going up and down of each order."""
    norm = np.linalg.norm(kappa, axis=1)
    plane = np.array([math.cos(phi), math.sin(phi)])  # the incidence plane, for κ = 0
    safe = np.where(norm > 1e-9 * k, norm, 1.0)[:, None]
    along = np.where(norm[:, None] > 1e-9 * k, kappa / safe, plane)
    # along is κ̂ (or the incidence plane's direction for κ = 0); TE = ẑ × κ̂
    te = np.stack([-along[:, 1], along[:, 0], np.zeros(len(along))], axis=1)
    kz = np.real_if_close(beta)
    up = np.concatenate([kappa, kz[:, None]], axis=1) / k
    down = np.concatenate([kappa, -kz[:, None]], axis=1) / k
    tm_down = np.cross(te, down)
    tm_up = -np.cross(te, up)
    return te, tm_up, tm_down


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
        return _current(self.geometry, kt, self.coefficients, np.zeros((t, 1, 3)))[:, 0]


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
    check_periodic_memory(pg.base.n_triangles, pg.n_unknowns, memory_limit, geometry=False)
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


def _current(pg: PeriodicGeometry, kt: np.ndarray, current: np.ndarray, rho: np.ndarray):
    """(T, Q, 3) J of cell (0, 0) at points ρ (T, Q, 3) from their triangles' centroids."""
    t = pg.base.n_triangles
    basis, _ = pg.basis_maps(kt)
    linear = basis.T @ current  # (3T,): C, D_x, D_y per triangle
    alpha = linear[:t]
    beta = np.stack([linear[t : 2 * t], linear[2 * t :], np.zeros(t)], axis=1)
    return alpha[:, None, None] * rho + beta[:, None, :]


@dataclass(frozen=True, eq=False)
class _Harmonics:
    """The propagating Floquet orders of a solve, (0, 0) first, and the currents' J̃ there."""

    orders: np.ndarray  # (P, 2) int
    kappa: np.ndarray  # (P, 2) rad/m
    beta: np.ndarray  # (P,) rad/m
    jt: np.ndarray  # (P, 3) complex J̃(κ_pq) = ∫ J e^(+jκ·ρ) dS over the cell
    te: np.ndarray  # (P, 3) unit TE, and TM going up and down
    tm_up: np.ndarray
    tm_down: np.ndarray
    phi: float  # the incidence plane's azimuth (rad)


def _harmonics(pg, wave, k, kt, current) -> _Harmonics:
    green = PeriodicGreen(tuple(pg.lattice[0]), tuple(pg.lattice[1]), k, kt)
    prop = green.propagating()
    orders, kappa = green.orders[prop], green.kappa[prop]
    first = np.flatnonzero(np.all(orders == 0, axis=1))
    order = np.concatenate([first, np.setdiff1d(np.arange(len(orders)), first)])
    orders, kappa = orders[order], kappa[order]
    beta = np.sqrt(k * k - np.einsum("ij,ij->i", kappa, kappa))
    rule = pg.base.near
    j = _current(pg, kt, current, rule.rho)  # (T, Q, 3)
    phase = np.exp(1j * (rule.points[:, :, :2] @ kappa.T))  # (T, Q, P)
    jt = np.einsum("tq,tqc,tqp->pc", rule.weights, j, phase)  # J̃(κ_pq), (P, 3)
    d = np.asarray(wave.direction)
    phi = math.atan2(d[1], d[0]) if np.hypot(d[0], d[1]) > 1e-12 else 0.0
    te, tm_up, tm_down = _floquet_basis(kappa, beta, k, phi)
    return _Harmonics(orders, kappa, beta, jt, te, tm_up, tm_down, phi)


def _floquet_amplitudes(pg, frequency, wave, k, kt, current, cond, residual) -> PeriodicSolution:
    h = _harmonics(pg, wave, k, kt, current)
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
    h = _harmonics(pg, wave, k, kt, current)
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

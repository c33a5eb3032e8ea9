"""The EFIE kernel of an infinite array on dielectric layers: what the fill needs per frequency.

A sheet at z = 0 between the layers of a :class:`~barymesh.mom.stack.Stack` (vacuum
half-spaces outside, perhaps a ground plane) radiates, in each Floquet harmonic κ, into
a transmission line per polarisation (:mod:`barymesh.mom.stack`). With Z_TE and Z_TM
the impedances the sheet sees (the two sides in parallel, Z = η0 / (y_up + y_down)),
the mixed-potential EFIE keeps the free-space solver's form::

    Z_mn = jη0 k0/4π ∫∫ [f_m·f_n G_A − (1/k0²) ∇·f_m ∇'·f_n G_Φ] dS dS'

    G_A = (2π/A) Σ_κ a(κ) e^(−jκ·(ρ − ρ')),    a = 2 Z_TE / (jη0 k0)
    G_Φ = (2π/A) Σ_κ φ(κ) e^(−jκ·(ρ − ρ')),    φ = 2 k0 (Z_TE − Z_TM) / (jη0 |κ|²)

In vacuum a = φ = 1/γ, γ = sqrt(|κ|² − k0²): G_A = G_Φ = G_p, the Ewald sum of
:mod:`barymesh.mom.periodic_green`. On layers the sums converge slowly: a and φ fall
like 1/|κ| for large |κ|. Following the theory documentation of PSSFSS (P. Simon,
chapters 4-5), the large-|κ| limit is taken out: it is that of two half-spaces, the
media on either side of the sheet (ε1, μ1 above, ε2, μ2 below), and it is the
homogeneous-medium form of an averaged medium to O(|κ|⁻⁵)::

    a ≈ μ̃ / γ_A,      μ̃ = 2 μ1 μ2 / (μ1 + μ2),  k_A² = k0² ε̄ μ̃,  ε̄ = (ε1 + ε2)/2
    φ ≈ 1 / (ε̄ γ_Φ),  k_Φ² = 2 k0² [ε̄ μ̃ − (ε1 μ1 + ε2 μ2)/2 + ε1 ε2 (μ1 + μ2) / (2 (ε1 + ε2))]

(k_Φ² = 2 k0² ε1 ε2 / (ε1 + ε2) when μ = 1: the harmonic mean, where G_A takes the
arithmetic one). Each of μ̃ G_p(k_A) and G_p(k_Φ)/ε̄ is an array Green's function of a
homogeneous medium, which the free-space fill integrates as it does in vacuum (its
singular image in closed form, the Ewald rest by Taylor tables). What is left,

    Δ_A = a − μ̃/γ_A,   Δ_Φ = φ − 1/(ε̄ γ_Φ),

falls like |κ|⁻⁵ from the half-spaces' mismatch and like e^(−2|κ| d) from the layers
(d their thicknesses): it is summed spectrally at the Taylor tables' Chebyshev nodes.
The harmonics that propagate in some medium of the stack, or nearly (|κ| up to the
largest wavenumber of the stack, blended out over a Floquet spacing, and every
harmonic near the onset of the vacuum's or either averaged medium's), carry the
surface-wave poles and branch points of a and φ: they are taken out of every table and
integrated exactly with the true a and φ (:func:`exact_orders`).

Convergence: :func:`remainder_extent` chooses how far the spectral sum of the rest
goes (until its terms fall below :data:`REMAINDER_TOLERANCE` of the leading 1/|κ|) and
reports the terms it kept; ``benchmarks/layered.py`` shows each part converge.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .periodic_green import lattice_points, reciprocal_vectors
from .stack import Layer, Stack, side

#: The rest Δ is summed until |Δ(κ)| |κ| falls below this on a whole ring of harmonics.
REMAINDER_TOLERANCE = 1e-7
#: The rest is resolved at the Chebyshev nodes only where |Δ(κ)| |κ| exceeds this.
RESOLVED_TOLERANCE = 1e-6
#: Most harmonics the spectral rest may take (a layer far thinner than the cell needs many).
MAX_REMAINDER_ORDERS = 400_000
#: Exactly integrated harmonics are weighted out of the tables over this many times the
#: smallest reciprocal vector (as the vacuum fill's slow orders).
BLEND = 0.5
#: |κ| below this times k0 counts as κ = 0 in φ (its 0/0 limit, taken at this |κ|).
SMALL_KAPPA = 1e-3


def _smoothstep(s: np.ndarray) -> np.ndarray:
    s = np.clip(s, 0.0, 1.0)
    return s**3 * (10.0 - 15.0 * s + 6.0 * s * s)


def _adjacent(layers: tuple[Layer, ...]) -> tuple[complex, float]:
    """(ε, μ) of the first layer of non-zero thickness (outward), or the vacuum's."""
    for layer in layers:
        if layer.thickness > 0:
            return layer.epsilon, layer.mu_r
    return 1.0 + 0j, 1.0


@dataclass(frozen=True, eq=False)
class Extraction:
    """The two homogeneous media whose array Green's functions carry the singularity.

    Attributes
    ----------
    k_a, k_phi : complex
        Their wavenumbers (rad/m): complex (Im k < 0) when a medium at the sheet is lossy,
        so that the rest falls like |κ|⁻⁵ with loss too.
    mu : float
        μ̃, the amplitude of G_A's limit.
    eps : complex
        ε̄, G_Φ's limit is G_p(k_Φ) / ε̄.
    """

    k_a: complex
    k_phi: complex
    mu: float
    eps: complex


def _wavenumber(k2: complex) -> complex | None:
    """sqrt(k²) with Re k > 0 and Im k <= 0 (a passive medium), or None."""
    k = complex(np.sqrt(complex(k2)))
    if k.real < 0:
        k = -k
    if not (k.real > 0 and k.imag <= 1e-12 * k.real):
        return None
    return complex(k.real, min(k.imag, 0.0)) if k.imag < 0 else k.real  # real: the vacuum's path


def extraction(stack: Stack, k0: float) -> Extraction:
    """The large-|κ| limit of the stack's kernel at vacuum wavenumber ``k0`` (rad/m)."""
    e1, m1 = _adjacent(tuple(reversed(stack.above)))
    e2, m2 = _adjacent(stack.below)
    mu = 2.0 * m1 * m2 / (m1 + m2)
    eps = 0.5 * (e1 + e2)
    k_a = _wavenumber(k0 * k0 * eps * mu)
    d = eps * mu - 0.5 * (e1 * m1 + e2 * m2) + e1 * e2 * (m1 + m2) / (2.0 * (e1 + e2))
    k_phi = _wavenumber(2.0 * k0 * k0 * d)
    if k_a is None:  # cannot happen with passive media; keep the real part
        k_a = k0 * math.sqrt(eps.real * mu)
    if k_phi is None:  # only with unusual permeabilities: a slower rest, still exact
        k_phi = k_a
    return Extraction(k_a, k_phi, mu, complex(eps))


def sheet_coefficients(
    stack: Stack, kappa2: np.ndarray, k0: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(a, φ, y_up, y_down) of each harmonic of |κ|² ``kappa2`` (see the module's docstring).

    ``y_up`` and ``y_down`` are (..., 2) TE and TM admittances over 1/η0, seen from the
    sheet; a and φ are (...) complex, in the units of 1/γ (rad/m)⁻¹.
    """
    kappa2 = np.asarray(kappa2, dtype=np.float64)
    up = side(tuple(reversed(stack.above)), False, kappa2, k0)
    down = side(stack.below, stack.ground, kappa2, k0)
    total = up.admittance + down.admittance
    z_te = 1.0 / total[..., 0]
    a = 2.0 * z_te / (1j * k0)
    floor = (SMALL_KAPPA * k0) ** 2
    if np.any(kappa2 < floor):
        # φ's 0/0 at κ = 0: its limit, from the same line at a tiny |κ|
        lifted = np.maximum(kappa2, floor)
        up0 = side(tuple(reversed(stack.above)), False, lifted, k0)
        down0 = side(stack.below, stack.ground, lifted, k0)
        total0 = up0.admittance + down0.admittance
        phi = 2.0 * k0 * (1.0 / total0[..., 0] - 1.0 / total0[..., 1]) / (1j * lifted)
    else:
        phi = 2.0 * k0 * (z_te - 1.0 / total[..., 1]) / (1j * kappa2)
    return a, phi, up.admittance, down.admittance


def orders_within(
    lattice: np.ndarray, kt: np.ndarray, radius: float
) -> tuple[np.ndarray, np.ndarray]:
    """(M, 2) orders (p, q) and their κ = k_t + p b1 + q b2 with |κ| <= radius."""
    recip = np.array(reciprocal_vectors(lattice[0], lattice[1]))
    return lattice_points(recip, radius, centre=np.asarray(kt, dtype=np.float64))


@dataclass(frozen=True, eq=False)
class LayeredKernel:
    """Everything the fill needs of a stack at one frequency and Floquet phase.

    Attributes
    ----------
    k0 : float
        Vacuum wavenumber (rad/m).
    medium : Extraction
        The homogeneous limits G_A ≈ μ̃ G_p(k_A), G_Φ ≈ G_p(k_Φ)/ε̄.
    exact_kappa : (S, 2) float
        The harmonics integrated exactly (rad/m).
    exact_weight : (S,) float
        The fraction w of each taken out of the tables (1 inside, blended to 0).
    exact_a, exact_phi : (S,) complex
        w 2π/A times the true a and φ: the exact terms' coefficients.
    taken_a, taken_phi : (S,) complex
        w 2π/(A γ_A) and w 2π/(A γ_Φ): what comes out of the Ewald tables of G_p(k_A)
        and G_p(k_Φ) (without the amplitudes μ̃ and 1/ε̄).
    rest_orders : (M, 2) int
        The harmonics of the spectral rest, in a box of (p, q).
    rest_a, rest_phi : (M,) complex
        2π/A (1 − w) Δ_A / μ̃ and 2π/A (1 − w) Δ_Φ ε̄: the rest, in the units of the
        tables of G_p(k_A) and G_p(k_Φ).
    rest_harmonics : int
        Largest |p|, |q| of the rest that the Chebyshev nodes must resolve.
    rest_ring : float
        |Δ| |κ| on the last ring summed (the truncation, relative to the leading term).
    """

    k0: float
    medium: Extraction
    exact_kappa: np.ndarray
    exact_weight: np.ndarray
    exact_a: np.ndarray
    exact_phi: np.ndarray
    taken_a: np.ndarray
    taken_phi: np.ndarray
    rest_orders: np.ndarray
    rest_a: np.ndarray
    rest_phi: np.ndarray
    rest_harmonics: int
    rest_ring: float
    kt: tuple[float, float] = (0.0, 0.0)
    lattice: np.ndarray | None = None

    def rest_tables(self, grid: np.ndarray, which: str) -> np.ndarray:
        """(6, G, G) complex: the rest and its x, y, xx, xy, yy derivatives, exactly.

        At ρ = u_i a1 + u_j a2 for ``grid`` u (G,) in lattice units, from its harmonics
        (a finite Fourier sum, separable in p and q): no interpolation.
        """
        c = self.rest_a if which == "a" else self.rest_phi
        n = len(grid)
        out = np.zeros((6, n, n), dtype=np.complex128)
        if not len(c):
            return out
        assert self.lattice is not None
        lattice = self.lattice
        recip = np.array(reciprocal_vectors(lattice[0], lattice[1]))
        kt = np.asarray(self.kt)
        p, q = self.rest_orders[:, 0], self.rest_orders[:, 1]
        p0, q0 = int(p.min()), int(q.min())
        shape = (int(p.max()) - p0 + 1, int(q.max()) - q0 + 1)
        kappa = self.rest_orders @ recip + kt  # (M, 2)
        eu = np.exp(-2j * np.pi * np.outer(grid, np.arange(p0, p0 + shape[0])))
        ev = np.exp(-2j * np.pi * np.outer(grid, np.arange(q0, q0 + shape[1])))
        carrier = np.exp(-1j * np.add.outer(grid * (lattice[0] @ kt), grid * (lattice[1] @ kt)))
        kx, ky = kappa[:, 0], kappa[:, 1]
        # ∂/∂x e^(−jκ·ρ) = −jκ_x e^(−jκ·ρ)
        factors = (1.0, -1j * kx, -1j * ky, -kx * kx, -kx * ky, -ky * ky)
        for d, factor in enumerate(factors):
            box = np.zeros(shape, dtype=np.complex128)
            np.add.at(box, (p - p0, q - q0), c * factor)
            out[d] = carrier * (eu @ box @ ev.T)
        return out


def exact_weights(
    kappa: np.ndarray, k0: float, medium: Extraction, stack: Stack, limit: float
) -> np.ndarray:
    """w of each harmonic κ (M, 2): 1 where it is integrated exactly, blended to 0.

    Near the onset of the vacuum's and either averaged medium's harmonics (|γ| < 2L,
    as the vacuum fill's slow orders), and wherever a layer's medium could carry it
    (|κ| up to that medium's largest wavenumber, blended out over L).
    """
    size = np.hypot(kappa[:, 0], kappa[:, 1])
    w = np.zeros(len(kappa))
    for k in (k0, medium.k_a, medium.k_phi):
        gamma = np.sqrt(np.abs(size * size - k * k))  # |γ| of that medium
        w = np.maximum(w, _smoothstep((2.0 * limit - gamma) / limit))
    dense = [
        k0 * math.sqrt(abs(layer.epsilon) * layer.mu_r)
        for layer in stack.layers
        if layer.thickness > 0 and not layer.is_vacuum
    ]
    if dense:
        top = max(dense + [abs(medium.k_a), abs(medium.k_phi)])
        w = np.maximum(w, _smoothstep((top + limit - size) / limit))
    return w


def layered_kernel(stack: Stack, lattice: np.ndarray, k0: float, kt: np.ndarray) -> LayeredKernel:
    """The :class:`LayeredKernel` of ``stack`` on ``lattice`` (m) at ``k0``, ``kt``."""
    lattice = np.asarray(lattice, dtype=np.float64)
    kt = np.asarray(kt, dtype=np.float64)
    area = abs(float(np.linalg.det(lattice)))
    b1, b2 = reciprocal_vectors(lattice[0], lattice[1])
    b_min = float(min(np.linalg.norm(b1), np.linalg.norm(b2)))
    limit = BLEND * b_min
    medium = extraction(stack, k0)
    scale = 2.0 * np.pi / area
    k_top = max(
        [k0, abs(medium.k_a), abs(medium.k_phi)]
        + [k0 * math.sqrt(abs(layer.epsilon) * layer.mu_r) for layer in stack.layers]
    )
    # the exact harmonics
    reach = math.sqrt(k_top * k_top + 4.0 * limit * limit) + limit
    orders, kappa = orders_within(lattice, kt, reach)
    w = exact_weights(kappa, k0, medium, stack, limit)
    keep = w > 0
    orders, kappa, w = orders[keep], kappa[keep], w[keep]
    kappa2 = np.einsum("ij,ij->i", kappa, kappa)
    a, phi, _, _ = sheet_coefficients(stack, kappa2, k0)
    gamma_a = np.sqrt(kappa2 - medium.k_a**2 + 0j)
    gamma_phi = np.sqrt(kappa2 - medium.k_phi**2 + 0j)
    exact = dict(
        exact_kappa=kappa,
        exact_weight=w,
        exact_a=w * scale * a,
        exact_phi=w * scale * phi,
        taken_a=w * scale / gamma_a,
        taken_phi=w * scale / gamma_phi,
    )
    rest_orders, rest_a, rest_phi, harmonics, ring = _rest(
        stack, lattice, k0, kt, medium, limit, k_top, scale
    )
    return LayeredKernel(
        k0=float(k0),
        medium=medium,
        rest_orders=rest_orders,
        rest_a=rest_a,
        rest_phi=rest_phi,
        rest_harmonics=harmonics,
        rest_ring=ring,
        kt=(float(kt[0]), float(kt[1])),
        lattice=lattice,
        **exact,
    )


def _rest(
    stack: Stack,
    lattice: np.ndarray,
    k0: float,
    kt: np.ndarray,
    medium: Extraction,
    limit: float,
    k_top: float,
    scale: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, int, float]:
    """The spectral rest: orders, its two coefficient sets, harmonics to resolve, truncation."""
    radius = 4.0 * k_top + 8.0 * limit
    while True:
        orders, kappa = orders_within(lattice, kt, radius)
        if len(orders) > MAX_REMAINDER_ORDERS:
            raise ValueError(
                f"the layers' rest needs over {MAX_REMAINDER_ORDERS:,} Floquet harmonics "
                f"(|κ| up to {radius:.4g} rad/m): a layer is far thinner than the cell "
                f"({np.linalg.norm(lattice, axis=1).max() * 1e3:.4g} mm); merge it with its "
                "neighbour or thicken it"
            )
        kappa2 = np.einsum("ij,ij->i", kappa, kappa)
        size = np.sqrt(kappa2)
        w = exact_weights(kappa, k0, medium, stack, limit)
        a, phi, _, _ = sheet_coefficients(stack, kappa2, k0)
        with np.errstate(divide="ignore", invalid="ignore"):
            delta_a = a - medium.mu / np.sqrt(kappa2 - medium.k_a**2 + 0j)
            delta_phi = phi - 1.0 / (medium.eps * np.sqrt(kappa2 - medium.k_phi**2 + 0j))
        delta_a = np.where(w < 1.0, delta_a, 0.0)
        delta_phi = np.where(w < 1.0, delta_phi, 0.0)
        size_rel = np.maximum(np.abs(delta_a), np.abs(delta_phi * medium.eps)) * size
        ring = size > radius - 1.5 * limit / BLEND
        worst = float(size_rel[ring].max()) if np.any(ring) else 0.0
        if worst < REMAINDER_TOLERANCE:
            break
        radius *= 1.5
    resolved = size_rel > RESOLVED_TOLERANCE
    harmonics = int(np.abs(orders[resolved]).max()) if np.any(resolved) else 0
    keep = (size_rel > 0.01 * REMAINDER_TOLERANCE) & (w < 1.0)
    one_minus = (1.0 - w)[keep]
    rest_a = scale * one_minus * delta_a[keep] / medium.mu
    rest_phi = scale * one_minus * delta_phi[keep] * medium.eps
    return orders[keep], rest_a, rest_phi, harmonics, worst


def te_tm_basis(direction: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(TE, TM, in-plane unit) vectors of a wave travelling along ``direction`` (3,).

    The convention of :mod:`barymesh.mom.periodic`: TE = ẑ × κ̂ (κ̂ = x̂ at normal
    incidence), TM = TE × d̂ going down, −TE × d̂ going up.
    """
    d = np.asarray(direction, dtype=np.float64)
    d = d / np.linalg.norm(d)
    norm = math.hypot(d[0], d[1])
    phi = math.atan2(d[1], d[0]) if norm > 1e-12 else 0.0
    along = np.array([math.cos(phi), math.sin(phi), 0.0])
    te = np.array([-along[1], along[0], 0.0])
    tm = np.cross(te, d) if d[2] < 0 else -np.cross(te, d)
    return te, tm, along


def sheet_field(stack: Stack, k0: float, wave, points: np.ndarray) -> np.ndarray:
    """(..., 3) complex tangential E (V/m) at ``points`` (..., 3, m) of the sheet, lit by
    ``wave`` through the stack (without the sheet's currents).

    The wave's amplitude and phase are those at the face it falls on, at ρ = 0.
    """
    from .stack import background

    d = np.asarray(wave.direction, dtype=np.float64)
    te, tm, _ = te_tm_basis(d)
    pol = np.asarray(wave.polarization)
    c_te, c_tm = pol @ te, pol @ tm
    line = background(stack, k0, k0 * math.hypot(d[0], d[1]), from_above=bool(d[2] < 0))
    tm_t = tm.copy()
    tm_t[2] = 0.0
    field = line.sheet[0] * c_te * te + line.sheet[1] * c_tm * tm_t
    phase = np.exp(-1j * k0 * (np.asarray(points)[..., :2] @ d[:2]))
    return wave.amplitude * phase[..., None] * field


def layer_orders(stack: Stack, lattice: np.ndarray, k0: float, kt: np.ndarray) -> np.ndarray:
    """(L, 2) orders (p, q) that propagate in some layer of non-zero thickness but not in
    vacuum, sorted by |κ|."""
    ks = [k0 * math.sqrt(layer.eps_r * layer.mu_r) for layer in stack.layers if layer.thickness > 0]
    top = max(ks, default=0.0)
    if top <= k0:
        return np.zeros((0, 2), dtype=int)
    orders, kappa = orders_within(lattice, np.asarray(kt, dtype=np.float64), top)
    size = np.hypot(kappa[:, 0], kappa[:, 1])
    keep = size >= k0
    order = np.argsort(size[keep], kind="stable")
    return orders[keep][order]

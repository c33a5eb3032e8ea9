"""The free-space Green's function of a doubly periodic array, by Ewald summation.

A source repeated on a 2D lattice ``ρ_mn = m a1 + n a2`` in the plane z = 0, with
the Floquet (Bloch) phase of an incident plane wave of transverse wavevector
``k_t``, radiates (time convention e^(jωt), the free-space solver's G = e^(−jkR)/R)::

    G_p(ρ, z) = Σ_mn e^(−j k_t·ρ_mn) e^(−jk R_mn) / R_mn,   R_mn = |(ρ − ρ_mn, z)|

The sum converges slowly (not at all on a lossless medium). Ewald's splitting
(Jordan, Richter & Sheng, IEEE Trans. Antennas Propag. 34(3), 1986) writes it as
two sums that both converge like a Gaussian, with a splitting parameter E::

    G_p = G_spatial + G_spectral

    G_spatial  = Σ_mn e^(−j k_t·ρ_mn) / (2 R_mn)
                 [e^(−jkR_mn) erfc(R_mn E − jk/2E) + e^(+jkR_mn) erfc(R_mn E + jk/2E)]

    G_spectral = (π/A) Σ_pq e^(−j κ_pq·ρ) / γ_pq
                 [e^(+γ_pq z) erfc(γ_pq/2E + zE) + e^(−γ_pq z) erfc(γ_pq/2E − zE)]

with A the cell area, κ_pq = k_t + p b1 + q b2 the Floquet wavevectors
(b_i · a_j = 2π δ_ij) and γ_pq = sqrt(|κ_pq|² − k²), Re γ ≥ 0 (γ = +j β for a
propagating order, so that e^(−γ|z|) is an outgoing wave). The sum is the same
for every E > 0; E sets how the work splits between the two sums. Following
Kustepeli & Martin (IEEE Microw. Guided Wave Lett. 10(5), 2000), E is
``sqrt(π/A)`` (equal work in both sums) unless the frequency is high, where
E ≥ k/(2H) keeps the factor e^((k/2E)²) of the spatial terms below e^(H²), so
that the result keeps its digits.

Each sum is truncated where its terms' bound falls below ``tolerance`` times the
leading term, so the number of terms is bounded at every frequency and angle:
about ``(ln 1/tolerance)/π + 1`` rings of images and as many of Floquet orders,
plus the propagating orders (their number grows as (k a)², as it must).

The solver integrates the singular part of G_p, the (0, 0) image e^(−jkR)/R, as
the free-space solver does, and the smooth rest by plain quadrature:
:meth:`PeriodicGreen.regular` is G_p minus that image, finite at R = 0.

>>> import numpy as np
>>> g = PeriodicGreen(a1=(0.01, 0.0), a2=(0.0, 0.01), k=2 * np.pi / 0.03)
>>> rho = np.array([[0.002, 0.003]])
>>> h = PeriodicGreen((0.01, 0), (0, 0.01), 2 * np.pi / 0.03, splitting=4 * g.splitting)
>>> bool(abs(g(rho) - h(rho)) < 1e-10 * abs(g(rho)))
True
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.special import erfc, erfcx

#: Default relative truncation tolerance of both sums.
TOLERANCE = 1e-12
#: Kustepeli and Martin's bound H: the spatial terms' growth factor e^((k/2E)²) stays below e^(H²).
GROWTH_BOUND = 3.0
#: Below this R E, the regular (0, 0) term is its limit at R = 0 (the error is O((R E)²)).
SMALL_RE = 1e-5
#: Rounding error of one term.
EPSILON = 1e-16
#: Points evaluated per block (each holds one complex number per image or order).
BLOCK_POINTS = 4096


def reciprocal_vectors(a1: np.ndarray, a2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """b1, b2 with b_i · a_j = 2π δ_ij, for lattice vectors a1, a2 (shape (2,)).

    >>> b1, b2 = reciprocal_vectors(np.array([2.0, 0.0]), np.array([1.0, 1.0]))
    >>> np.round(np.array([b1 @ [2, 0], b1 @ [1, 1], b2 @ [2, 0], b2 @ [1, 1]]) / np.pi, 12)
    array([2., 0., 0., 2.])
    """
    lattice = np.array([a1, a2], dtype=np.float64)  # rows a1, a2
    recip = 2.0 * np.pi * np.linalg.inv(lattice).T  # rows b1, b2
    return recip[0], recip[1]


def default_splitting(area: float, k: complex, growth_bound: float = GROWTH_BOUND) -> float:
    """Kustepeli and Martin's splitting parameter: max(sqrt(π/A), |k| / 2H) (1/m)."""
    return max(math.sqrt(math.pi / area), abs(k) / (2.0 * growth_bound))


def lattice_points(
    basis: np.ndarray, radius: float, centre: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Integer pairs (m, n) and points m b0 + n b1 (+ centre) within ``radius`` of 0.

    ``basis`` is (2, 2), rows b0 and b1. The pairs are found in the bounding box
    of the disc in lattice coordinates, then filtered.
    """
    centre = np.zeros(2) if centre is None else centre
    inverse = np.linalg.inv(basis)  # coordinates c with c @ basis = point
    # |c_i| <= radius * |column i of the inverse| bounds the disc in lattice coordinates
    reach = (radius + np.linalg.norm(centre)) * np.linalg.norm(inverse, axis=0)
    m = np.arange(-math.ceil(reach[0]), math.ceil(reach[0]) + 1)
    n = np.arange(-math.ceil(reach[1]), math.ceil(reach[1]) + 1)
    pairs = np.stack(np.meshgrid(m, n, indexing="ij"), axis=-1).reshape(-1, 2)
    points = pairs @ basis + centre
    keep = np.einsum("ij,ij->i", points, points) <= radius * radius
    return pairs[keep], points[keep]


@dataclass(frozen=True)
class PeriodicGreen:
    """G_p of a 2D lattice at one wavenumber and transverse wavevector.

    Parameters
    ----------
    a1, a2 : (2,) float
        Lattice vectors (m), not parallel.
    k : complex
        Wavenumber (rad/m); a lossy medium has Im k < 0.
    kt : (2,) float, optional
        Transverse wavevector of the Floquet phase (rad/m): k (sin θ cos φ, sin θ sin φ)
        for a plane wave from (θ, φ). Zero at normal incidence.
    splitting : float, optional
        Ewald's E (1/m); :func:`default_splitting` by default. Any E > 0 gives the same
        G_p to within ``tolerance``.
    tolerance : float
        Relative truncation error of each sum.
    reach : float, optional
        Largest in-plane |ρ| to be evaluated (m) before reduction into the central cell;
        only sets how many images the spatial sum keeps. The points given are reduced
        into the cell anyway (G_p is quasi-periodic), so the default, the cell's
        diameter, fits every difference of two points of one cell.

    Attributes
    ----------
    images : (M, 2) int
        Lattice indices (m, n) of the spatial sum.
    orders : (P, 2) int
        Floquet orders (p, q) of the spectral sum.
    kappa : (P, 2) float
        Their transverse wavevectors κ_pq (rad/m).
    gamma : (P,) complex
        sqrt(|κ_pq|² − k²) with Re γ ≥ 0; imaginary for a propagating order.
    """

    a1: tuple[float, float]
    a2: tuple[float, float]
    k: complex
    kt: tuple[float, float] = (0.0, 0.0)
    splitting: float | None = None
    tolerance: float = TOLERANCE
    reach: float | None = None
    images: np.ndarray = field(init=False, repr=False)
    orders: np.ndarray = field(init=False, repr=False)
    kappa: np.ndarray = field(init=False, repr=False)
    gamma: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        a1 = np.asarray(self.a1, dtype=np.float64)
        a2 = np.asarray(self.a2, dtype=np.float64)
        kt = np.asarray(self.kt, dtype=np.float64)
        if a1.shape != (2,) or a2.shape != (2,) or kt.shape != (2,):
            raise ValueError(
                f"a1={self.a1!r}, a2={self.a2!r}, kt={self.kt!r}: expected three 2-vectors"
            )
        if not (np.all(np.isfinite(a1)) and np.all(np.isfinite(a2)) and np.all(np.isfinite(kt))):
            raise ValueError(f"a1={self.a1!r}, a2={self.a2!r}, kt={self.kt!r}: not finite")
        area = abs(a1[0] * a2[1] - a1[1] * a2[0])
        if not area > 1e-12 * np.linalg.norm(a1) * np.linalg.norm(a2):
            raise ValueError(f"a1={self.a1!r} and a2={self.a2!r} are parallel (or zero)")
        k = complex(self.k)
        if not (np.isfinite(k) and k.real > 0 and k.imag <= 0):
            raise ValueError(f"k={self.k!r}: expected Re k > 0 and Im k <= 0 (rad/m)")
        if not 1e-15 <= self.tolerance < 1e-2:
            raise ValueError(f"tolerance={self.tolerance!r}: expected a number in [1e-15, 0.01)")
        splitting = default_splitting(area, k) if self.splitting is None else self.splitting
        if not (np.isfinite(splitting) and splitting > 0):
            raise ValueError(f"splitting={self.splitting!r}: expected a positive number (1/m)")
        # the spatial terms carry e^((k/2E)²) and lose that factor of digits of precision
        smallest = abs(k) / (2.0 * math.sqrt(math.log(self.tolerance / EPSILON)))
        if splitting < smallest:
            raise ValueError(
                f"splitting={splitting:.6g} 1/m is too small at k={abs(k):.6g} rad/m: the "
                f"spatial sum would lose its digits; expected at least {smallest:.6g} 1/m "
                f"(|k|/2E at most sqrt(ln(tolerance/eps)))"
            )
        object.__setattr__(self, "a1", (float(a1[0]), float(a1[1])))
        object.__setattr__(self, "a2", (float(a2[0]), float(a2[1])))
        object.__setattr__(self, "kt", (float(kt[0]), float(kt[1])))
        object.__setattr__(self, "k", k)
        object.__setattr__(self, "splitting", float(splitting))
        E = float(splitting)
        lattice = np.array([a1, a2])
        diameter = float(max(np.linalg.norm(a1 + a2), np.linalg.norm(a1 - a2)))
        reach = diameter if self.reach is None else float(self.reach)
        log_tol = math.log(1.0 / self.tolerance)
        growth = (abs(k) / (2.0 * E)) ** 2  # the spatial terms' factor e^((k/2E)²)
        # spatial terms fall like e^(−(R E)² + (k/2E)²): keep R E <= sqrt(ln(1/tol) + growth)
        r_cut = math.sqrt(log_tol + growth + 2.0) / E
        images, _ = lattice_points(lattice, r_cut + reach)
        # spectral terms fall like e^(−(γ/2E)² + (zE)²) / γ, γ ≈ |κ| − k: keep
        # |κ| <= |k| + 2E sqrt(ln(1/tol) + 2) about k_t (z stays within the cell's reach)
        b1, b2 = reciprocal_vectors(a1, a2)
        recip = np.array([b1, b2])
        k_cut = abs(k) + 2.0 * E * math.sqrt(log_tol + 2.0 + (reach * E) ** 2)
        orders, kappa = lattice_points(recip, k_cut, centre=kt)
        gamma = np.sqrt(np.einsum("ij,ij->i", kappa, kappa) - k * k + 0j)
        gamma = np.where(gamma.real < 0, -gamma, gamma)
        near = np.abs(gamma) < 1e-9 * abs(k)
        if np.any(near):
            p, q = orders[np.argmax(near)]
            raise ValueError(
                f"k={k:.6g} rad/m, kt={self.kt!r}: at the onset of Floquet order ({p}, {q}) "
                "(a Wood anomaly: that order grazes the screen and the array's Green's function "
                "is infinite); change the frequency or the angle slightly"
            )
        object.__setattr__(self, "images", images)
        object.__setattr__(self, "orders", orders)
        object.__setattr__(self, "kappa", kappa)
        object.__setattr__(self, "gamma", gamma)

    # -- geometry ------------------------------------------------------------------------

    @property
    def split(self) -> float:
        """Ewald's E in use (1/m): ``splitting``, or its default when none was given."""
        assert self.splitting is not None  # set by __post_init__
        return self.splitting

    @property
    def area(self) -> float:
        """Cell area A (m²)."""
        (x1, y1), (x2, y2) = self.a1, self.a2
        return abs(x1 * y2 - y1 * x2)

    @property
    def lattice(self) -> np.ndarray:
        """(2, 2) float: rows a1, a2 (m)."""
        return np.array([self.a1, self.a2])

    def reduce(self, rho: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Points moved into the central cell, and the lattice shift (m, n) taken off each.

        ``rho = reduced + m a1 + n a2``, with the lattice coordinates of ``reduced`` in
        [−1/2, 1/2); G_p(rho) = e^(−j k_t·(m a1 + n a2)) G_p(reduced).
        """
        rho = np.asarray(rho, dtype=np.float64)
        frac = rho @ np.linalg.inv(self.lattice)
        shift = np.floor(frac + 0.5)
        return rho - shift @ self.lattice, shift.astype(np.int64)

    # -- evaluation ----------------------------------------------------------------------

    def __call__(self, rho: np.ndarray, z: np.ndarray | float = 0.0) -> np.ndarray:
        """G_p at in-plane offsets ``rho`` (N, 2) m and heights ``z`` (N,) or scalar m.

        Returns (N,) complex. Infinite where (ρ, z) is a lattice point.
        """
        return self._evaluate(rho, z, regular=False)

    def regular(self, rho: np.ndarray, z: np.ndarray | float = 0.0) -> np.ndarray:
        """G_p minus the (0, 0) image e^(−jkR)/R, R = |(ρ, z)|: smooth, finite at R = 0.

        Returns (N,) complex. This is what the periodic solver integrates by plain
        quadrature; the (0, 0) image goes through the free-space solver's singular rules.
        """
        return self._evaluate(rho, z, regular=True)

    def _evaluate(self, rho: np.ndarray, z: np.ndarray | float, regular: bool) -> np.ndarray:
        rho = np.asarray(rho, dtype=np.float64)
        if rho.ndim != 2 or rho.shape[1] != 2:
            raise ValueError(f"rho: expected an (N, 2) array of offsets, got shape {rho.shape}")
        z = np.broadcast_to(np.asarray(z, dtype=np.float64), (len(rho),))
        out = np.empty(len(rho), dtype=np.complex128)
        for start in range(0, len(rho), BLOCK_POINTS):
            block = slice(start, start + BLOCK_POINTS)
            out[block] = self._block(rho[block], z[block], regular)
        return out

    def _block(self, rho: np.ndarray, z: np.ndarray, regular: bool) -> np.ndarray:
        reduced, shift = self.reduce(rho)
        phase = np.exp(-1j * ((shift @ self.lattice) @ np.asarray(self.kt)))
        # the caller's (0, 0) image is the reduced point's (0, 0) image where the reduction
        # did not move the point; where it did, that image is far away and subtracted directly
        moved = np.any(shift != 0, axis=1)
        centre = np.full(len(rho), regular) & ~moved
        value = phase * (self._spatial(reduced, z, centre) + self._spectral(reduced, z))
        if regular and np.any(moved):
            r = np.hypot(np.linalg.norm(rho[moved], axis=1), z[moved])
            value[moved] -= np.exp(-1j * self.k * r) / r
        return value

    def _spatial(self, rho: np.ndarray, z: np.ndarray, centre_regular: np.ndarray) -> np.ndarray:
        """Σ over images; where ``centre_regular``, the (0, 0) image minus e^(−jkR)/R."""
        E, k = self.split, self.k
        c = 1j * k / (2.0 * E)
        offsets = self.images @ self.lattice  # (M, 2)
        phase = np.exp(-1j * (offsets @ np.asarray(self.kt)))  # (M,)
        d = rho[:, None, :] - offsets[None, :, :]
        r = np.sqrt(np.einsum("nmi,nmi->nm", d, d) + (z * z)[:, None])  # (N, M)
        with np.errstate(divide="ignore", invalid="ignore"):
            if k.imag == 0.0:
                # c is imaginary, so erfc(RE + c) = conj(erfc(RE − c)): the two halves are
                # conjugate and the term is real, Re(e^(−jkR) erfc(RE − c)) / R
                terms = (np.exp(-1j * k * r) * erfc(r * E - c)).real / r
            else:
                terms = (
                    np.exp(-1j * k * r) * erfc(r * E - c) + np.exp(1j * k * r) * erfc(r * E + c)
                ) / (2.0 * r)
        regular = None
        if np.any(centre_regular):
            at = int(np.flatnonzero(np.all(self.images == 0, axis=1))[0])
            rc = r[centre_regular, at]
            with np.errstate(divide="ignore", invalid="ignore"):
                reg = (
                    np.exp(1j * k * rc) * erfc(rc * E + c) - np.exp(-1j * k * rc) * erfc(c - rc * E)
                ) / (2.0 * rc)
            limit = 1j * k * erfc(c) - 2.0 * E / math.sqrt(math.pi) * np.exp(-(c * c))
            regular = np.where(rc * E < SMALL_RE, limit, reg)
            terms[centre_regular, at] = 0.0  # its phase is 1: added after the sum
        if np.iscomplexobj(terms):
            out = terms @ phase
        else:
            out = terms @ phase.real + 1j * (terms @ phase.imag)
        if regular is not None:
            out[centre_regular] += regular
        return out

    def _spectral(self, rho: np.ndarray, z: np.ndarray) -> np.ndarray:
        E = self.split
        gamma = self.gamma[None, :]
        zz = z[:, None]
        u = gamma / (2.0 * E)
        # e^(γz) erfc(u + zE) = e^(−u² − (zE)²) erfcx(u + zE), stable where Re(u + zE) >= 0
        base = np.exp(-(u * u) - (zz * E) ** 2)
        plus, minus = u + zz * E, u - zz * E
        with np.errstate(over="ignore", invalid="ignore"):  # the branch np.where drops
            up = np.where(plus.real >= 0, base * erfcx(plus), np.exp(gamma * zz) * erfc(plus))
            down = np.where(minus.real >= 0, base * erfcx(minus), np.exp(-gamma * zz) * erfc(minus))
        waves = np.exp(-1j * (rho @ self.kappa.T))  # (N, P)
        return (np.pi / self.area) * ((waves * (up + down)) @ (1.0 / self.gamma))

    # -- Floquet modes -------------------------------------------------------------------

    def propagating(self) -> np.ndarray:
        """Boolean (P,): the Floquet orders that propagate (|κ_pq| < Re k)."""
        return np.abs(self.gamma.real) < np.abs(self.gamma.imag)

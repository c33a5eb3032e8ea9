"""The Ewald periodic Green's function against sums that need no splitting.

References that share nothing with the Ewald code:
- on a lossy medium (Im k < 0) the plain image sum Σ e^(−j k_t·ρ_mn) e^(−jkR)/R converges
  exponentially and is summed directly;
- off the plane (z ≠ 0) the plain Floquet sum (2π/A) Σ e^(−j κ_pq·ρ) e^(−γ|z|)/γ converges
  exponentially and is summed directly.
Plus the invariants: independence of the splitting parameter, quasi-periodicity,
reciprocity, symmetry in z, and a bounded number of terms.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from barymesh.mom.periodic_green import PeriodicGreen, default_splitting, reciprocal_vectors

A = 0.01  # 10 mm cells
LATTICES = {
    "square": ((A, 0.0), (0.0, A)),
    "rectangular": ((A, 0.0), (0.0, 0.6 * A)),
    "hexagonal": ((A, 0.0), (A / 2, A * math.sqrt(3) / 2)),
    "oblique": ((A, 0.0), (0.3 * A, 0.7 * A)),
}
#: Wavelengths: a long one (a = λ/3), one with several grating lobes (a = 1.7 λ).
WAVELENGTHS = (3 * A, A / 1.7)


def incidence(k: float, theta_deg: float, phi_deg: float) -> tuple[float, float]:
    th, ph = math.radians(theta_deg), math.radians(phi_deg)
    return (k * math.sin(th) * math.cos(ph), k * math.sin(th) * math.sin(ph))


def points(n: int = 40, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    return rng.uniform(-1.5 * A, 1.5 * A, (n, 2)), rng.uniform(-0.4 * A, 0.4 * A, n)


def direct_images(a1, a2, k, kt, rho, z, rings):
    """Σ over |m|, |n| <= rings of the images, summed plainly."""
    m = np.arange(-rings, rings + 1)
    mn = np.stack(np.meshgrid(m, m, indexing="ij"), -1).reshape(-1, 2)
    offsets = mn @ np.array([a1, a2])
    d = rho[:, None, :] - offsets[None]
    r = np.sqrt((d**2).sum(-1) + z[:, None] ** 2)
    return (np.exp(-1j * k * r) / r) @ np.exp(-1j * offsets @ np.asarray(kt))


def direct_orders(a1, a2, k, kt, rho, z, rings):
    """(2π/A) Σ over |p|, |q| <= rings of e^(−j κ·ρ) e^(−γ|z|)/γ, summed plainly."""
    b1, b2 = reciprocal_vectors(np.array(a1), np.array(a2))
    p = np.arange(-rings, rings + 1)
    pq = np.stack(np.meshgrid(p, p, indexing="ij"), -1).reshape(-1, 2)
    kappa = np.asarray(kt) + pq @ np.array([b1, b2])
    gamma = np.sqrt((kappa**2).sum(-1) - k * k + 0j)
    gamma = np.where(gamma.real < 0, -gamma, gamma)
    area = abs(a1[0] * a2[1] - a1[1] * a2[0])
    waves = np.exp(-1j * rho @ kappa.T) * np.exp(-gamma[None] * np.abs(z)[:, None])
    return (2 * np.pi / area) * (waves @ (1 / gamma))


@pytest.mark.parametrize("lattice", LATTICES)
@pytest.mark.parametrize("wavelength", WAVELENGTHS)
@pytest.mark.parametrize("angles", [(0, 0), (30, 0), (50, 70)])
def test_independent_of_the_splitting_parameter(lattice, wavelength, angles):
    # the test: E changed fourfold, the sum agrees to 1e-8 relative
    k = 2 * np.pi / wavelength
    kt = incidence(k, *angles)
    rho, z = points()
    g = PeriodicGreen(*LATTICES[lattice], k, kt)
    for factor in (4.0, 0.25):
        try:
            other = PeriodicGreen(*LATTICES[lattice], k, kt, splitting=factor * g.splitting)
        except ValueError as exc:  # E/4 at high frequency: refused, not wrong
            assert factor < 1 and "too small" in str(exc)
            continue
        for zz in (np.zeros(len(z)), z):
            a, b = g(rho, zz), other(rho, zz)
            assert np.max(np.abs(a - b) / np.abs(a)) < 1e-8
            ra, rb = g.regular(rho, zz), other.regular(rho, zz)
            assert np.max(np.abs(ra - rb) / np.abs(a)) < 1e-8


def test_a_fourfold_smaller_splitting_is_used_where_it_is_safe():
    # at a = λ/3 the fourfold smaller E is legal, so the test above compares both ways
    k = 2 * np.pi / WAVELENGTHS[0]
    g = PeriodicGreen(*LATTICES["square"], k)
    PeriodicGreen(*LATTICES["square"], k, splitting=g.splitting / 4)


@pytest.mark.parametrize("lattice", LATTICES)
@pytest.mark.parametrize("angles", [(0, 0), (40, 25)])
def test_lossy_medium_matches_the_plain_image_sum(lattice, angles):
    a1, a2 = LATTICES[lattice]
    k0 = 2 * np.pi / (2.2 * A)
    k = k0 * (1 - 0.35j)  # e^(−Im k R) makes the image sum converge
    kt = incidence(k0, *angles)
    rho, z = points(25)
    reference = direct_images(a1, a2, k, kt, rho, z, rings=40)
    ewald = PeriodicGreen(a1, a2, k, kt)(rho, z)
    assert np.max(np.abs(ewald - reference) / np.abs(reference)) < 1e-9


@pytest.mark.parametrize("lattice", LATTICES)
@pytest.mark.parametrize("wavelength", WAVELENGTHS)
def test_off_the_plane_matches_the_plain_floquet_sum(lattice, wavelength):
    a1, a2 = LATTICES[lattice]
    k = 2 * np.pi / wavelength
    kt = incidence(k, 35, 20)
    rho, _ = points(25)
    z = np.full(len(rho), 0.45 * A)  # e^(−|κ| z) makes the Floquet sum converge
    reference = direct_orders(a1, a2, k, kt, rho, z, rings=40)
    ewald = PeriodicGreen(a1, a2, k, kt)(rho, z)
    assert np.max(np.abs(ewald - reference) / np.abs(reference)) < 1e-9


@pytest.mark.parametrize("lattice", LATTICES)
def test_quasi_periodic_reciprocal_and_even_in_z(lattice):
    a1, a2 = LATTICES[lattice]
    k = 2 * np.pi / (1.3 * A)
    kt = incidence(k, 25, 60)
    g = PeriodicGreen(a1, a2, k, kt)
    rho, z = points(30)
    base = g(rho, z)
    for m, n in ((1, 0), (0, 1), (-2, 3)):
        shift = m * np.array(a1) + n * np.array(a2)
        expected = np.exp(-1j * shift @ np.array(kt)) * base
        assert np.max(np.abs(g(rho + shift, z) - expected) / np.abs(base)) < 1e-10
    # reciprocity: G(ρ; k_t) = G(−ρ; −k_t)
    mirror = PeriodicGreen(a1, a2, k, (-kt[0], -kt[1]))
    assert np.max(np.abs(mirror(-rho, z) - base) / np.abs(base)) < 1e-10
    assert np.max(np.abs(g(rho, -z) - base) / np.abs(base)) < 1e-10


def test_regular_part_is_the_sum_without_its_centre_and_finite_at_zero():
    a1, a2 = LATTICES["hexagonal"]
    k = 2 * np.pi / (2.5 * A)
    g = PeriodicGreen(a1, a2, k, incidence(k, 20, 10))
    rho, z = points(30)
    r = np.hypot(np.linalg.norm(rho, axis=1), z)
    assert np.max(np.abs(g.regular(rho, z) + np.exp(-1j * k * r) / r - g(rho, z))) < 1e-9 * (
        np.max(np.abs(g(rho, z)))
    )
    # approaching the source along a line, the regular part is smooth (no 1/R left)
    t = np.geomspace(1e-9, 1e-3, 25) * A
    line = np.stack([t, 0.5 * t], axis=1)
    values = g.regular(line)
    at_zero = g.regular(np.zeros((1, 2)))[0]
    assert np.all(np.abs(values - at_zero) <= 50 * np.abs(at_zero) * (t / A) + 1e-9 * abs(at_zero))


@pytest.mark.parametrize("wavelength", [100 * A, 3 * A, 1.1 * A, 0.37 * A])
@pytest.mark.parametrize("theta", [0, 60, 89])
def test_terms_are_bounded(wavelength, theta):
    # the spatial sum stays a few rings at every frequency and angle; the spectral sum
    # grows only with the number of propagating orders, ~ π (k + |k_t|)² A / (2π)²
    k = 2 * np.pi / wavelength
    for a1, a2 in LATTICES.values():
        g = PeriodicGreen(a1, a2, k, incidence(k, theta, 30))
        area = abs(a1[0] * a2[1] - a1[1] * a2[0])
        visible = math.pi * (2 * k) ** 2 * area / (4 * math.pi**2)
        assert len(g.images) < 200
        assert len(g.orders) < 120 + 4 * visible


def test_propagating_orders_and_splitting_default():
    a1, a2 = LATTICES["square"]
    k = 2 * np.pi / (A / 1.7)  # a = 1.7 λ: orders with |κ| < k propagate
    g = PeriodicGreen(a1, a2, k)
    kappa = np.linalg.norm(g.kappa, axis=1)
    assert np.array_equal(g.propagating(), kappa < k)
    assert g.propagating().sum() == 9  # (0,0), 4 × (±1,0)-type, 4 × (±1,±1) (√2 < 1.7)
    assert default_splitting(A * A, 1.0) == pytest.approx(math.sqrt(math.pi) / A)
    assert default_splitting(A * A, 1e5) == pytest.approx(1e5 / 6)


def test_bad_input_is_named():
    a1, a2 = LATTICES["square"]
    with pytest.raises(ValueError, match="parallel"):
        PeriodicGreen(a1, (2 * A, 0.0), 100.0)
    with pytest.raises(ValueError, match="k="):
        PeriodicGreen(a1, a2, -1.0)
    with pytest.raises(ValueError, match="splitting="):
        PeriodicGreen(a1, a2, 100.0, splitting=0.0)
    with pytest.raises(ValueError, match="too small"):
        PeriodicGreen(a1, a2, 2 * np.pi / (A / 3), splitting=1.0)
    with pytest.raises(ValueError, match="rho"):
        PeriodicGreen(a1, a2, 100.0)(np.zeros(3))
    # normal incidence at a = λ: the (±1, 0) orders graze the screen
    with pytest.raises(ValueError, match=r"Wood anomaly"):
        PeriodicGreen(a1, a2, 2 * np.pi / A)

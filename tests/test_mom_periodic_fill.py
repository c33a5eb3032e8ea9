"""The fast periodic fill against a straightforward one.

:func:`barymesh.mom.periodic.periodic_impedance_matrix` integrates the smooth part of the
periodic Green's function, G_reg, by a second-order Taylor expansion about each triangle
pair's centroid offset (read from a per-frequency grid), and the nearest image's
e^(−jkR)/R by the free-space solver's rules on half the pairs. The reference here does
it the plain way: the far rule on every point pair of every triangle pair, with G_reg
summed by Ewald's method at each of those points (no table, no expansion), and the
closed-form 1/R and R moments on the pairs that touch. Both make the same O(h³) error
in G_reg; the two matrices must agree to a stated tolerance.
"""

from __future__ import annotations

import numpy as np
import pytest

from barymesh.cell import Lattice, PixelGrid, UnitCell, build_cell
from barymesh.constants import ETA0
from barymesh.mom import PeriodicGreen
from barymesh.mom.geometry import static_moments
from barymesh.mom.operator import wavenumber
from barymesh.mom.periodic import periodic_geometry, periodic_impedance_matrix

P = 10.0  # mm
NEAR_FACTOR = 1.5


def pixel_cell(mask: np.ndarray, subdivisions: int = 1):
    pixels = PixelGrid(
        mask, pixel_size=P / len(mask), origin=(-P / 2, -P / 2), subdivisions=subdivisions
    )
    return build_cell(
        UnitCell(lattice=Lattice.rectangular(P), pixels=pixels, mode="conforming")
    ).mesh


def reference_matrix(pg, k: float, kt: tuple[float, float]) -> np.ndarray:
    """Z with the far rule at every point pair, G_reg by Ewald sums there (no table)."""
    base = pg.base
    far, near = base.far, base.near
    t = base.n_triangles
    kt = np.asarray(kt, dtype=np.float64)
    lattice = pg.lattice
    centroids = base.centroids[:, :2]
    frac = (centroids[:, None] - centroids[None, :]) @ np.linalg.inv(lattice)
    sigma = np.rint(frac)
    shift = sigma @ lattice  # (T, T, 2)
    green = PeriodicGreen(tuple(lattice[0]), tuple(lattice[1]), k, tuple(kt))
    # far rule, every pair: G of the nearest image + G_reg
    delta = (
        far.points[:, None, :, None, :2]
        - far.points[None, :, None, :, :2]
        - shift[:, :, None, None, :]
    )  # (T, T, Q, Q, 2)
    dist = np.linalg.norm(delta, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        kernel = np.where(dist > 0, np.exp(-1j * k * dist) / dist, 0.0)
    # a pixel mesh repeats its point offsets: one Ewald sum per distinct offset (to 1 nm)
    distinct, where = np.unique(np.rint(delta.reshape(-1, 2) * 1e9), axis=0, return_inverse=True)
    kernel_g = kernel.copy()
    kernel = kernel + green.regular(distinct * 1e-9)[where.ravel()].reshape(dist.shape)
    w, rho = far.weights, far.rho[:, :, :2]
    m = np.empty((8, t, t), dtype=np.complex128)
    m[0] = np.einsum("oa,sb,osab->os", w, w, kernel)
    for c in range(2):
        m[1 + c] = np.einsum("oa,sb,osab->os", w * rho[:, :, c], w, kernel)
        m[4 + c] = np.einsum("oa,sb,osab->os", w, w * rho[:, :, c], kernel)
    m[7] = np.einsum("oac,sbc,osab->os", w[:, :, None] * rho, w[:, :, None] * rho, kernel)
    m[3] = m[6] = 0
    # near pairs: the closed-form moments of G replace the far rule's
    gap = np.linalg.norm((frac - sigma) @ lattice, axis=-1)
    obs, src = np.nonzero(gap < NEAR_FACTOR * np.maximum(base.sizes[:, None], base.sizes))
    offset = np.concatenate([shift[obs, src], np.zeros((len(obs), 1))], axis=1)
    corners = base.vertices[base.triangles][src] + offset[:, None, :]
    inv_r, r1 = static_moments(
        near, corners, base.centroids[src] + offset, obs, np.arange(len(obs))
    )
    d = near.points[obs][:, :, None] - (near.points[src] + offset[:, None])[:, None]
    nd = np.linalg.norm(d, axis=-1)
    x = k * nd
    with np.errstate(divide="ignore", invalid="ignore"):
        smooth = np.where(nd > 0, (np.cos(x) - 1 + 0.5 * x * x - 1j * np.sin(x)) / nd, -1j * k)
    wo, ws = near.weights[obs], near.weights[src]
    ro, rs = near.rho[obs], near.rho[src]
    g = np.empty((8, len(obs)), dtype=np.complex128)
    g[0] = np.einsum("ka,kb,kab->k", wo, ws, smooth)
    g[1:4] = np.einsum("ka,kac,kb,kab->ck", wo, ro, ws, smooth)
    g[4:7] = np.einsum("ka,kb,kbc,kab->ck", wo, ws, rs, smooth)
    g[7] = np.einsum("ka,kac,kb,kbc,kab->k", wo, ro, ws, rs, smooth)
    g += (inv_r - 0.5 * k * k * r1).T
    far_g = np.empty_like(g)
    kn = kernel_g[obs, src]
    far_g[0] = np.einsum("ka,kb,kab->k", w[obs], w[src], kn)
    for c in range(2):
        far_g[1 + c] = np.einsum("ka,kb,kab->k", w[obs] * rho[obs][:, :, c], w[src], kn)
        far_g[4 + c] = np.einsum("ka,kb,kab->k", w[obs], w[src] * rho[src][:, :, c], kn)
    far_g[7] = np.einsum(
        "kac,kbc,kab->k", w[obs][:, :, None] * rho[obs], w[src][:, :, None] * rho[src], kn
    )
    far_g[3] = far_g[6] = 0
    m[:, obs, src] += g - far_g
    m *= np.exp(-1j * (shift @ kt))
    # Z = test · S · basisᵀ over [C | D_x | D_y]
    s = np.zeros((3, t, 3, t), dtype=np.complex128)
    s[0, :, 0] = k * m[7] - (4.0 / k) * m[0]
    for c in range(2):
        s[0, :, 1 + c] = k * m[1 + c]
        s[1 + c, :, 0] = k * m[4 + c]
        s[1 + c, :, 1 + c] = k * m[0]
    basis, test = pg.basis_maps(kt)
    z = test @ (basis @ s.reshape(3 * t, 3 * t).T).T
    return np.asarray(z) * (1j * ETA0 / (4.0 * np.pi))


def strips():
    mask = np.zeros((8, 8), dtype=bool)
    mask[:, 2:6] = True  # touching both sides: unknowns across the cell boundary
    return pixel_cell(mask)


def sheet():
    return pixel_cell(np.ones((8, 8), dtype=bool))  # every side crossed


#: (mesh, frequency, direction of incidence (sin θ cos φ, sin θ sin φ)); k h = 0.44 to 0.74
CASES = [
    (strips, 17e9, (0.3, -0.2)),
    (sheet, 12e9, (0.0, 0.0)),
    (sheet, 20e9, (0.2, 0.4)),
]


@pytest.mark.parametrize(("make", "frequency", "direction"), CASES)
def test_fast_fill_matches_the_plain_one(make, frequency, direction):
    # measured: 0.9e-4 to 2.8e-4 in the Frobenius norm, 4e-5 to 8e-5 of the largest entry
    # (the two second-order rules for G_reg differ by O((k h)³)); a wrong term is 1e-2
    pg = periodic_geometry(make())
    k = wavenumber(frequency)
    kt = (direction[0] * k, direction[1] * k)
    fast = periodic_impedance_matrix(pg, k, kt)
    plain = reference_matrix(pg, k, kt)
    assert np.linalg.norm(fast - plain) < 5e-4 * np.linalg.norm(plain)
    assert np.abs(fast - plain).max() < 2e-4 * np.abs(plain).max()

"""An independent reference for strip gratings on a substrate: the 1-D spectral-domain
Galerkin method (Itoh & Mittra's approach for strips), written apart from barymesh.

PEC strips of width ``w`` along y, period ``P`` along x, lie on the top face of a slab
of thickness ``d`` and permittivity ``eps`` (vacuum or a ground plane under it; vacuum
above); a plane wave comes from above in the xz plane at ``theta``. The strip current
is expanded in Chebyshev functions that carry the edge behaviour:

- E along the strips (TE): J_y = Σ c_m T_m(u) / sqrt(1 − u²), u = 2x/w, whose transforms
  are (w/2) π j^m J_m(κ w/2);
- E across them (TM): J_x = Σ c_m U_m(u) sqrt(1 − u²), transforms (w/2) π j^m (m + 1)
  J_{m+1}(a)/a, a = κ w/2.

Each Floquet harmonic κ_n = k0 sin θ + 2πn/P sees the sheet's impedance η0 / (y_up +
y_down), the vacuum above and the slab below as transmission lines, and the tested
field equation Σ_l c_l (1/P) Σ_n Z(κ_n) B̃_l(κ_n) B̃_m(−κ_n) = V_bg B̃_m(−k_t) is solved
for c. The harmonics are summed to |n| = ``terms`` (the terms fall like 1/n², the rest
is estimated by a Richardson step over two truncations). R is the (0, 0) order's
reflection at the slab's top face, the strips' plane.
"""

from __future__ import annotations

import numpy as np
from scipy.special import jv

C0 = 299_792_458.0
ETA0 = 376.730313412


def _admittances(kappa: np.ndarray, k0: float, eps: complex, d: float, ground: bool):
    """(y_up, y_down) over 1/η0 for TE and TM, each (N, 2)."""
    g0 = np.sqrt(kappa**2 - k0**2 + 0j)
    gd = np.sqrt(kappa**2 - k0**2 * eps + 0j)
    y0 = np.stack([g0 / (1j * k0), 1j * k0 / g0], axis=1)
    yd = np.stack([gd / (1j * k0), 1j * k0 * eps / gd], axis=1)
    t = np.tanh(gd * d)[:, None]
    if ground:
        down = yd / t
    else:
        down = yd * (y0 + yd * t) / (yd + y0 * t)
    return y0, down


def strip_reflection(
    frequency: float,
    period_mm: float,
    width_mm: float,
    eps: complex,
    thickness_mm: float,
    ground: bool,
    polarization: str,
    theta_deg: float = 0.0,
    basis: int = 8,
    terms: int = 40_000,
) -> complex:
    """R of the (0, 0) order (TE: E along the strips; TM: E across them)."""
    pol = 0 if polarization == "te" else 1
    k0 = 2 * np.pi * frequency / C0
    p, w, d = period_mm * 1e-3, width_mm * 1e-3, thickness_mm * 1e-3
    kt = k0 * np.sin(np.radians(theta_deg))

    def solve(n_terms: int) -> complex:
        n = np.arange(-n_terms, n_terms + 1)
        kappa = kt + 2 * np.pi * n / p
        up, down = _admittances(kappa, k0, eps, d, ground)
        z = ETA0 / (up[:, pol] + down[:, pol])

        def transform(k: np.ndarray) -> np.ndarray:  # (basis, N)
            a = k * w / 2
            m = np.arange(basis)[:, None]
            if pol == 0:
                return (w / 2) * np.pi * (1j**m) * jv(m, a)
            safe = np.where(np.abs(a) < 1e-12, 1.0, a)
            # J_{m+1}(a)/a -> 1/2 at a = 0 for m = 0, 0 otherwise
            ratio = np.where(np.abs(a) < 1e-12, np.where(m == 0, 0.5, 0.0), jv(m + 1, a) / safe)
            return (w / 2) * np.pi * (1j**m) * (m + 1) * ratio

        b_plus, b_minus = transform(kappa), transform(-kappa)
        matrix = (b_minus * z) @ b_plus.T / p
        up0, down0 = _admittances(np.array([kt]), k0, eps, d, ground)
        gamma = (up0[0, pol] - down0[0, pol]) / (up0[0, pol] + down0[0, pol])
        v_bg = 1.0 + gamma  # the tangential field at the strips' plane, unit incident
        rhs = v_bg * transform(np.array([-kt]))[:, 0]
        c = np.linalg.solve(matrix, rhs)
        j0 = transform(np.array([kt]))[:, 0] @ c
        z0 = ETA0 / (up0[0, pol] + down0[0, pol])
        return complex(gamma - z0 * j0 / p)

    # the truncation error falls like 1/N: one Richardson step over N and N/2
    full, half = solve(terms), solve(terms // 2)
    return 2 * full - half

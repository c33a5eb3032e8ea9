"""A 1-D spectral-domain solution of the strip grating, and Marcuvitz's quasi-static formulas.

Perfectly conducting strips of width w, period P along x, infinite along y, zero
thickness, in free space; a plane wave comes in the xz plane at θ from the normal
(k_x0 = k sin θ). Floquet harmonics k_xn = k_x0 + 2πn/P, k_zn = √(k² − k_xn²) (−j√ for
evanescent ones). A sheet current J e^{−j k_xn x} radiates, at z = 0,

* E along the strips (TE, current J_y): E_y = −ωμ J / (2 k_zn);
* E across the strips (TM, current J_x): E_x = −k_zn J / (2ωε).

Galerkin's method with the edge behaviour built in: J_y = Σ a_m T_m(t)/√(1 − t²) and
J_x = Σ a_m U_m(t) √(1 − t²), t = 2x/w, whose Fourier transforms are Bessel functions
(π j^m J_m(a) and π j^m (m + 1) J_{m+1}(a)/a, a = k w/2). A few basis functions and a
long Floquet sum (its terms fall as n⁻²; the tail beyond ``harmonics`` is summed by its
asymptotic form) give R to about 1e-6. R is the ratio of the reflected to the incident
tangential E of the (0, 0) order (T = 1 + R), as :func:`barymesh.mom.periodic_solve`
reports it.

>>> r = strip_reflection(10.0, 5.0, 0.5 * 299792458.0 / 0.01, "across")
>>> round(abs(r), 4), round(float(np.degrees(np.angle(r))), 1)  # Collin: 0.3598, -111.1
(0.3598, -111.1)
"""

from __future__ import annotations

import numpy as np
from scipy.special import jv

C0 = 299792458.0
MU0 = 4e-7 * np.pi
EPS0 = 1.0 / (MU0 * C0 * C0)


def strip_reflection(
    period: float,
    width: float,
    frequency: float,
    polarization: str,
    theta: float = 0.0,
    basis: int = 8,
    harmonics: int = 4000,
) -> complex:
    """The (0, 0) reflection coefficient of the strip grating.

    Parameters
    ----------
    period, width : float
        P and w (mm), 0 < w < P.
    frequency : float
        Hz.
    polarization : {"along", "across"}
        E along the strips (TE) or across them (TM, E in the plane of incidence).
    theta : float
        Angle of incidence (degrees) in the xz plane, across the strips.
    basis : int
        Chebyshev basis functions.
    harmonics : int
        Floquet harmonics each side of n = 0 summed exactly.

    Returns
    -------
    complex
    """
    p, w = period * 1e-3, width * 1e-3
    k = 2 * np.pi * frequency / C0
    omega = 2 * np.pi * frequency
    kx0 = k * np.sin(np.radians(theta))
    n = np.arange(-harmonics, harmonics + 1)
    kx = kx0 + 2 * np.pi * n / p
    kz = np.sqrt((k * k - kx * kx).astype(complex))
    kz = np.where(kz.imag > 0, -kz, kz)  # decaying away from the sheet: Im kz <= 0
    a = kx * w / 2
    m = np.arange(basis)[:, None]
    if polarization == "along":
        f = (w / 2) * np.pi * (1j**m) * jv(m, a)  # ∫ f_m e^{+j kx x} dx
        f_minus = (w / 2) * np.pi * ((-1j) ** m) * jv(m, a)  # ∫ f_m e^{-j kx x} dx
        weight = -omega * MU0 / (2 * p * kz)
    elif polarization == "across":
        safe = np.where(a == 0, 1.0, a)
        ratio = np.where(a == 0, np.where(m == 0, 0.5, 0.0), jv(m + 1, a) / safe)
        f = (w / 2) * np.pi * (1j**m) * (m + 1) * ratio
        f_minus = (w / 2) * np.pi * ((-1j) ** m) * (m + 1) * ratio
        weight = -kz / (2 * omega * EPS0 * p)
    else:
        raise ValueError(f"polarization={polarization!r}; expected 'along' or 'across'")
    z = (f_minus * weight) @ f.T  # Z[m, q] = Σ_n f_m(−k_n) w_n f_q(k_n)
    z += _tail(period, width, frequency, polarization, basis, harmonics)
    zero = harmonics
    rhs = -f_minus[:, zero]  # the incident tangential E (amplitude 1): E_s = −E_inc on the strips
    coeff = np.linalg.solve(z, rhs)
    current = coeff @ f[:, zero]  # J̃ at k_x0
    return complex(weight[zero] * current)


def _tail(
    period: float, width: float, frequency: float, polarization: str, basis: int, harmonics: int
) -> np.ndarray:
    """Σ over |n| > ``harmonics`` of the Galerkin terms, in closed form to O(n⁻³).

    Far out k_zn = −j|k_xn| and J_m(a)J_q(a) → (2/πa) cos(a − mπ/2 − π/4) cos(a − qπ/2 −
    π/4), whose oscillating part averages out over the harmonics (the strip width and
    the period are incommensurate in general, and any residue is O(1/N²)); what is left
    is ½ (2/πa) cos((m − q)π/2) summed as Σ 1/n² ≈ 2/N.
    """
    p, w = period * 1e-3, width * 1e-3
    omega = 2 * np.pi * frequency
    m = np.arange(basis)[:, None]
    q = np.arange(basis)[None, :]
    # Σ_{|n| > N} 1/|k_xn|² ≈ 2 Σ_{n > N} (P / 2πn)² ≈ 2 (P/2π)² / N
    s2 = 2 * (p / (2 * np.pi)) ** 2 / harmonics
    phase = np.cos((m - q) * np.pi / 2) * (1j ** (m + q)) * ((-1.0) ** m)
    if polarization == "along":
        # f_m(−k) f_q(k) (−ωμ / (2P kz)) with kz = −j|k|: (w/2)²π² J_m J_q (−j ωμ/(2P|k|));
        # J_m J_q → (1/π|a|) cos(...) (mean), |a| = |k| w/2, so the term is ∝ 1/|k|²
        coef = (w / 2) ** 2 * np.pi**2 * (-1j * omega * MU0 / (2 * p)) / (np.pi * w / 2)
        return coef * phase * s2
    # across: (m + 1)(q + 1) J_{m+1} J_{q+1} / a² · (−kz/(2ωεP)), kz = −j|k|: ∝ 1/|k|²
    shift = np.cos((m - q) * np.pi / 2)  # the same mean for J_{m+1} J_{q+1}
    phase = shift * (1j ** (m + q)) * ((-1.0) ** m)
    coef = (
        (w / 2) ** 2
        * np.pi**2
        * (m + 1)
        * (q + 1)
        * (1j / (2 * omega * EPS0 * p))
        / (np.pi * (w / 2) ** 3)
    )
    return coef * phase * s2


def marcuvitz_reflection(
    period: float, width: float, frequency: float, polarization: str
) -> complex:
    """Normal incidence, P/λ small: the grating as a shunt element on a line of Z0.

    Marcuvitz, *Waveguide Handbook* (1951), §5.18 and §5.19, first terms: E along the
    strips an inductance X/Z0 = (P/λ) ln csc(π w / 2P); E across them a capacitance
    B/Y0 = (4P/λ) ln csc(π d / 2P), d = P − w the gap. Γ = −Y/(2 + Y) with Y the
    normalised shunt admittance (−j/X or jB). Good to a few per cent of B or X for
    P/λ ≤ 0.1.

    >>> round(abs(marcuvitz_reflection(10.0, 5.0, 0.1 * 299792458.0 / 0.01, "along")), 4)
    0.9976
    """
    ratio = period * 1e-3 * frequency / C0  # P / λ
    if polarization == "along":
        x = ratio * np.log(1.0 / np.sin(np.pi * width / (2 * period)))
        y = -1j / x
    else:
        b = 4 * ratio * np.log(1.0 / np.sin(np.pi * (period - width) / (2 * period)))
        y = 1j * b
    return complex(-y / (2 + y))

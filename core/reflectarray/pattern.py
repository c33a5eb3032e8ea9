"""The far field of a planar array: element pattern × array factor, and its directivity.

Pure functions over the excitation of an N1 × N2 array on a lattice (a1, a2), element
(i, j) at ``(i - (N1 - 1)/2) a1 + (j - (N2 - 1)/2) a2`` in the plane z = 0, radiating
into z > 0. Time convention e^(jωt), as the solver's: the field of the array in the
direction û (far away) is

    E(û) = cos^qe θ · Σ_ij a_ij exp(+j k û · r_ij),

``qe`` the element's pattern (cos θ for qe = 1, the usual model of a patch over ground)
and nothing below the plane (θ ≥ 90°). Since û · r_ij = i' α + j' β with α = û · a1 and
β = û · a2, the sum separates into two matrix products, and the power radiated into the
half space is a sum over the aperture's autocorrelation (see :func:`radiated_power`), so
the directivity needs no integration of the pattern.
"""

from __future__ import annotations

import numpy as np
from scipy.special import j0

#: Directions evaluated at once (memory: a few (M, N) complex blocks).
CHUNK = 4096


def centred(n: int) -> np.ndarray:
    """(n,) float: the element indices of one side counted from the aperture's centre."""
    return np.arange(n) - (n - 1) / 2.0


def array_field(
    excitation: np.ndarray,
    a1: np.ndarray,
    a2: np.ndarray,
    k: float,
    u: np.ndarray,
    v: np.ndarray,
    element_q: float,
) -> np.ndarray:
    """The far field E(û) of the array at the directions (u, v) = (sin θ cos φ, sin θ sin φ).

    Parameters
    ----------
    excitation : (N1, N2) complex
        a_ij, the field each element re-radiates (amplitude and phase).
    a1, a2 : (2,) float
        Lattice vectors (mm).
    k : float
        Wavenumber (rad/mm).
    u, v : (M,) float
        Direction cosines; outside the unit disc (no real direction) the field is 0.
    element_q : float
        The element pattern is cos^element_q θ.

    Returns
    -------
    (M,) complex
    """
    a = np.asarray(excitation, dtype=complex)
    u = np.asarray(u, dtype=float).ravel()
    v = np.asarray(v, dtype=float).ravel()
    i1, i2 = centred(a.shape[0]), centred(a.shape[1])
    out = np.zeros(len(u), dtype=complex)
    for s in range(0, len(u), CHUNK):
        uu, vv = u[s : s + CHUNK], v[s : s + CHUNK]
        alpha = uu * a1[0] + vv * a1[1]
        beta = uu * a2[0] + vv * a2[1]
        e1 = np.exp(1j * k * np.outer(alpha, i1))  # (M, N1)
        e2 = np.exp(1j * k * np.outer(beta, i2))  # (M, N2)
        out[s : s + CHUNK] = np.einsum("mi,ij,mj->m", e1, a, e2, optimize=True)
    w2 = 1.0 - u * u - v * v
    visible = w2 > 0
    out[~visible] = 0.0
    out[visible] *= np.sqrt(w2[visible]) ** element_q
    return out


def hemisphere_kernel(rho: np.ndarray, k: float, element_q: float) -> np.ndarray:
    """G(ρ) = ∫ cos^(2 qe) θ exp(j k û · ρ) dΩ over the half space z > 0, ρ in the plane.

    Over φ the exponential integrates to 2π J0(k ρ sin θ); with t = cos θ what is left is
    2π ∫₀¹ t^(2 qe) J0(k ρ √(1 − t²)) dt, smooth in t (J0 is even), done by Gauss–Legendre
    with more nodes than the integrand has oscillations. G(0) = 2π / (2 qe + 1).

    Parameters
    ----------
    rho : (R,) float
        Distances (mm) between two elements.
    k : float
        Wavenumber (rad/mm).
    element_q : float

    Returns
    -------
    (R,) float
    """
    rho = np.asarray(rho, dtype=float)
    n = int(k * float(rho.max(initial=0.0))) + 64
    t, w = np.polynomial.legendre.leggauss(n)
    t, w = 0.5 * (t + 1.0), 0.5 * w  # [-1, 1] -> [0, 1]
    s = np.sqrt(1.0 - t * t)
    weight = w * t ** (2.0 * element_q)
    out = np.empty(len(rho))
    block = max(1, 2**22 // n)
    for a in range(0, len(rho), block):
        out[a : a + block] = j0(k * np.outer(rho[a : a + block], s)) @ weight
    return 2.0 * np.pi * out


def radiated_power(
    excitation: np.ndarray, a1: np.ndarray, a2: np.ndarray, k: float, element_q: float
) -> float:
    """∫ |E(û)|² dΩ over the half space z > 0, exactly (no sampling of the pattern).

    |E|² = cos^(2 qe) θ Σ_mn a_m a_n* exp(j k û · (r_m − r_n)) depends on the pairs only
    through their separation Δ = (Δi, Δj): the power is Σ_Δ C(Δ) G(|Δi a1 + Δj a2|),
    C the aperture's autocorrelation (one FFT convolution) and G
    :func:`hemisphere_kernel`.

    Parameters
    ----------
    excitation : (N1, N2) complex
    a1, a2 : (2,) float
        Lattice vectors (mm).
    k : float
        Wavenumber (rad/mm).
    element_q : float

    Returns
    -------
    float
    """
    from scipy.signal import fftconvolve

    a = np.asarray(excitation, dtype=complex)
    n1, n2 = a.shape
    corr = fftconvolve(a, np.conj(a[::-1, ::-1]))  # [n] = Σ_m a[m] a*[m + N - 1 - n]
    d1 = (n1 - 1) - np.arange(2 * n1 - 1)
    d2 = (n2 - 1) - np.arange(2 * n2 - 1)
    sep = d1[:, None, None] * np.asarray(a1) + d2[None, :, None] * np.asarray(a2)
    rho = np.hypot(sep[..., 0], sep[..., 1]).ravel()
    distinct, back = np.unique(np.round(rho, 9), return_inverse=True)
    g = hemisphere_kernel(distinct, k, element_q)[back]
    return float(np.real(corr.ravel() @ g))


def pattern_grid(
    excitation: np.ndarray,
    a1: np.ndarray,
    a2: np.ndarray,
    k: float,
    element_q: float,
    per_lobe: int = 6,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """|E|² on a grid of the visible directions, fine enough to resolve every lobe.

    The grid is even in α = û · a1 and β = û · a2 (the array factor is periodic in each
    with period λ and its lobes are λ/N wide), ``per_lobe`` points per λ/N, so the sum
    is two matrix products.

    Returns
    -------
    u, v : (M1, M2) float
        Direction cosines of the grid.
    power : (M1, M2) float
        |E|², NaN outside the visible disc.
    """
    a = np.asarray(excitation, dtype=complex)
    n1, n2 = a.shape
    wavelength = 2.0 * np.pi / k
    ends = (float(np.hypot(*a1)), float(np.hypot(*a2)))
    m1 = min(2049, max(33, int(np.ceil(2 * ends[0] * per_lobe * n1 / wavelength)) + 1))
    m2 = min(2049, max(33, int(np.ceil(2 * ends[1] * per_lobe * n2 / wavelength)) + 1))
    alpha = np.linspace(-ends[0], ends[0], m1)
    beta = np.linspace(-ends[1], ends[1], m2)
    e1 = np.exp(1j * k * np.outer(alpha, centred(n1)))  # (M1, N1)
    e2 = np.exp(1j * k * np.outer(beta, centred(n2)))  # (M2, N2)
    af = e1 @ a @ e2.T  # (M1, M2)
    lat = np.array([a1, a2], dtype=float)  # rows a1, a2: lat @ (u, v) = (α, β)
    aa, bb = np.meshgrid(alpha, beta, indexing="ij")
    uv = np.linalg.solve(lat, np.stack([aa.ravel(), bb.ravel()]))
    u, v = uv[0].reshape(aa.shape), uv[1].reshape(aa.shape)
    w2 = 1.0 - u * u - v * v
    power = np.full(aa.shape, np.nan)
    visible = w2 > 0
    power[visible] = np.abs(af[visible]) ** 2 * w2[visible] ** element_q
    return u, v, power


def local_maxima(power: np.ndarray) -> np.ndarray:
    """(K, 2) int: grid indices of the local maxima of ``power`` (NaN: no direction).

    A point is a maximum when no neighbour of its 3 × 3 block is larger and it is > 0.
    """
    from scipy.ndimage import maximum_filter

    p = np.where(np.isnan(power), -np.inf, power)
    top = maximum_filter(p, size=3, mode="constant", cval=-np.inf)
    return np.argwhere((p == top) & (p > 0))

"""What a solve returns: coefficients and everything derived from them.

Time convention e^(jωt). The current on triangle p is linear::

    J(r) = α_p (r − c_p) + β_p,   α = Aᵀ I,  β = Dᵀ I

(A, D the sparse coefficient and offset matrices of
:class:`~barymesh.mom.geometry.MomGeometry`), so J at the centroid is β_p,
∇·J = 2 α_p, and moments of J over a triangle are exact.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from scipy.special import roots_legendre

from ..constants import ETA0, SPEED_OF_LIGHT
from .excitation import PlaneWave, VoltageSource
from .geometry import METRES_PER_MESH_UNIT, MomGeometry
from .operator import gram_matrix


def directions(theta: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """(..., 3) unit vectors r̂(θ, φ) for angles in radians (broadcast together)."""
    theta, phi = np.broadcast_arrays(np.asarray(theta, float), np.asarray(phi, float))
    st = np.sin(theta)
    return np.stack([st * np.cos(phi), st * np.sin(phi), np.cos(theta)], axis=-1)


@dataclass(frozen=True, eq=False)
class Solution:
    """The currents of one solve, and the physics derived from them.

    Attributes
    ----------
    geometry : MomGeometry
    frequency : float
        Hz.
    excitation : PlaneWave or VoltageSource
    coefficients : (N,) complex128
        I_n (A), one per RWG function, in the order of ``mesh.rwg``.
    voltages : (N,) complex128
        The right-hand side V_m = ∫ f_m·E_inc dS (V).
    condition_number : float
        1-norm condition number of Z, estimated from its LU factors.
    residual : float
        ‖Z I − V‖ / ‖V‖.
    warnings : tuple of str
        Caveats, e.g. overlapping patches in a paper-mode mesh.
    sheet_impedance : complex
        Z_s of the surface (Ω per square); 0 for a perfect conductor.
    """

    geometry: MomGeometry
    frequency: float
    excitation: PlaneWave | VoltageSource
    coefficients: np.ndarray
    voltages: np.ndarray
    condition_number: float = float("nan")
    residual: float = float("nan")
    warnings: tuple[str, ...] = field(default=())
    sheet_impedance: complex = 0j

    # -- current and charge -------------------------------------------------

    @property
    def wavenumber(self) -> float:
        """k = ω / c (rad/m)."""
        return 2.0 * np.pi * self.frequency / SPEED_OF_LIGHT

    @cached_property
    def _linear(self) -> tuple[np.ndarray, np.ndarray]:
        g = self.geometry
        alpha = g.coef_matrix.T @ self.coefficients
        beta = np.stack([m.T @ self.coefficients for m in g.offset_matrices], axis=1)
        return alpha, beta

    @property
    def current_density(self) -> np.ndarray:
        """(T, 3) complex128 surface current density J (A/m) at the triangle centroids."""
        return self._linear[1]

    def current_at(self, triangles: np.ndarray, points: np.ndarray) -> np.ndarray:
        """J (A/m) at ``points`` (M, 3, mm) lying on ``triangles`` (M,) int.

        Returns
        -------
        (M, 3) complex128
        """
        tri = np.asarray(triangles, dtype=np.intp)
        r = np.asarray(points, dtype=np.float64) * METRES_PER_MESH_UNIT
        alpha, beta = self._linear
        return alpha[tri, None] * (r - self.geometry.centroids[tri]) + beta[tri]

    def current_at_quadrature_points(self) -> tuple[np.ndarray, np.ndarray]:
        """The near rule's points (T, Q, 3) in metres and J there (T, Q, 3) complex (A/m)."""
        alpha, beta = self._linear
        rule = self.geometry.near
        return rule.points, alpha[:, None, None] * rule.rho + beta[:, None, :]

    @property
    def charge_density(self) -> np.ndarray:
        """(T,) complex128 surface charge density ρ_s = j ∇·J / ω (C/m²), per triangle."""
        omega = 2.0 * np.pi * self.frequency
        return 1j * 2.0 * self._linear[0] / omega

    # -- power and cross-sections --------------------------------------------

    @property
    def _incident_intensity(self) -> float:
        if not isinstance(self.excitation, PlaneWave):
            raise ValueError(
                "cross-sections need a plane-wave excitation; this solve was driven by a "
                "voltage source (see input_impedance and radiated_power)"
            )
        return self.excitation.amplitude**2 / (2.0 * ETA0)

    @property
    def extinction_power(self) -> float:
        """½ Re ∫ E_inc·J* dS = ½ Re(Iᴴ V) (W): the power the excitation delivers."""
        return 0.5 * float(np.real(np.vdot(self.coefficients, self.voltages)))

    @property
    def extinction_cross_section(self) -> float:
        """σ_ext = P_ext / (|E0|² / 2η) (m²), from the currents."""
        return self.extinction_power / self._incident_intensity

    @cached_property
    def radiated_power(self) -> float:
        """Power (W) of the scattered far field, integrated over the whole sphere.

        Either on a sphere rule exact for the far field's harmonics (degree 2 k R + 12,
        ``sphere_rule``), or, when that rule would need more directions than the
        currents have quadrature points (an electrically large mesh: (k R)² directions),
        as the same integral done in closed form over pairs of points
        (``far_field_power_pairs``). Both integrate the far field of the same point
        currents, exactly: they agree to rounding, and the work is bounded by
        min(directions, points) × points either way.
        """
        degree = self._sphere_degree()
        points = self.geometry.near.weights.size
        if sphere_rule_size(degree) > PAIR_COST * points:
            return self._radiated_power_pairs()
        return self._radiated_power_sphere(degree)

    def _radiated_power_sphere(self, degree: int | None = None) -> float:
        """:attr:`radiated_power` on the sphere rule of ``degree`` (default the exact one)."""
        theta, phi, weights = sphere_rule(self._sphere_degree() if degree is None else degree)
        e = self.far_field(theta, phi, radians=True)
        return float(np.sum(weights * np.sum(np.abs(e) ** 2, axis=-1)) / (2.0 * ETA0))

    def _radiated_power_pairs(self) -> float:
        """:attr:`radiated_power` in closed form over pairs of quadrature points."""
        points, current = self.current_at_quadrature_points()
        w = self.geometry.near.weights.reshape(-1)
        moments = current.reshape(-1, 3) * w[:, None]
        k = self.wavenumber
        integral = far_field_power_pairs(points.reshape(-1, 3), moments, k)
        # |E|² = (k η / 4π)² |F_⊥|², and P = ∫ |E|² dΩ / 2η
        return float(k * k * ETA0 / (32.0 * np.pi**2) * integral)

    @property
    def scattering_cross_section(self) -> float:
        """σ_s (m²) from the far field integrated over the sphere."""
        return self.radiated_power / self._incident_intensity

    @property
    def absorption_cross_section(self) -> float:
        """σ_ext − σ_s (m²): ≈ 0 for a perfect conductor, a check of the solve; for a
        resistive sheet, ≈ :attr:`ohmic_power` over the incident intensity."""
        return self.extinction_cross_section - self.scattering_cross_section

    @cached_property
    def ohmic_power(self) -> float:
        """½ Re(Z_s) ∫ |J|² dS (W): the power a sheet impedance dissipates (0 for a PEC)."""
        if self.sheet_impedance == 0:
            return 0.0
        gram = gram_matrix(self.geometry)
        current = self.coefficients
        return 0.5 * self.sheet_impedance.real * float(np.real(np.vdot(current, gram @ current)))

    def _sphere_degree(self) -> int:
        g = self.geometry
        radius = float(np.max(np.linalg.norm(g.vertices - g.centroids.mean(axis=0), axis=1)))
        return int(np.ceil(2.0 * self.wavenumber * radius)) + 12

    # -- far field --------------------------------------------------------------

    def far_field(self, theta, phi, *, radians: bool = False) -> np.ndarray:
        """The scattered far-field pattern r e^(jkr) E_s (V), as Cartesian vectors.

        Parameters
        ----------
        theta, phi : array_like
            Observation angles (degrees unless ``radians``), broadcast together.

        Returns
        -------
        (..., 3) complex128
            −jωμ/4π (I − r̂r̂)·∫ J e^(jk r̂·r') dS' — transverse to r̂.
        """
        if not radians:
            theta, phi = np.radians(theta), np.radians(phi)
        r_hat = directions(theta, phi)
        shape = r_hat.shape
        r_hat = r_hat.reshape(-1, 3)
        points, current = self.current_at_quadrature_points()
        w = self.geometry.near.weights.reshape(-1)
        pts = points.reshape(-1, 3)
        wj = current.reshape(-1, 3) * w[:, None]
        k = self.wavenumber
        out = np.empty((len(r_hat), 3), dtype=np.complex128)
        step = max(1, (1 << 20) // max(1, len(pts)))
        for lo in range(0, len(r_hat), step):
            rh = r_hat[lo : lo + step]
            vec = np.exp(1j * k * (rh @ pts.T)) @ wj  # ∫ J e^{jk r̂·r'}
            vec -= rh * np.sum(rh * vec, axis=1, keepdims=True)
            out[lo : lo + step] = vec
        out *= -1j * k * ETA0 / (4.0 * np.pi)
        return out.reshape(shape)

    def bistatic_rcs(self, theta, phi, *, radians: bool = False) -> np.ndarray:
        """σ(θ, φ) = 4π |r E_s|² / |E0|² (m²) on a grid of observation angles."""
        if not isinstance(self.excitation, PlaneWave):
            raise ValueError("a radar cross-section needs a plane-wave excitation")
        e = self.far_field(theta, phi, radians=radians)
        return 4.0 * np.pi * np.sum(np.abs(e) ** 2, axis=-1) / self.excitation.amplitude**2

    # -- moments and circuit quantities ------------------------------------------

    def dipole_moments(self, origin=(0.0, 0.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
        """The induced electric and magnetic dipole moments.

        Parameters
        ----------
        origin : 3 floats
            Reference point (mm) of the magnetic moment.

        Returns
        -------
        p : (3,) complex128
            ∫ J dS / (jω) (C·m).
        m : (3,) complex128
            ½ ∫ (r − origin) × J dS (A·m²).
        """
        g = self.geometry
        beta = self._linear[1]
        areas = g.areas[:, None]
        omega = 2.0 * np.pi * self.frequency
        p = np.sum(areas * beta, axis=0) / (1j * omega)
        arm = g.centroids - np.asarray(origin, dtype=float) * METRES_PER_MESH_UNIT
        # ∫ ρ dS = 0 on each triangle, so the centroid carries the whole moment
        m = 0.5 * np.sum(areas * np.cross(arm, beta), axis=0)
        return p, m

    @property
    def feed_current(self) -> complex:
        """The current (A) through the gap of a voltage source."""
        if not isinstance(self.excitation, VoltageSource):
            raise ValueError("feed_current needs a VoltageSource excitation")
        signs = self.excitation.feed_signs(self.geometry)
        return complex(np.sum(signs * self.geometry.rwg_lengths * self.coefficients))

    @property
    def input_power(self) -> float:
        """½ Re(V I*) (W) delivered by a voltage source; equals the radiated power for PEC."""
        source = self.excitation
        if not isinstance(source, VoltageSource):
            raise ValueError("input_power needs a VoltageSource excitation")
        return 0.5 * float(np.real(source.voltage * np.conj(self.feed_current)))

    @property
    def input_impedance(self) -> complex:
        """Z_in = V / I_feed (Ω) of a voltage source."""
        source = self.excitation
        if not isinstance(source, VoltageSource):
            raise ValueError("input_impedance needs a VoltageSource excitation")
        return source.voltage / self.feed_current


#: The closed-form pair sum costs about this many far-field directions per point pair.
PAIR_COST = 4
#: Below this k R the pair kernel is summed as its Taylor series (its closed form cancels).
_SERIES_BELOW = 1.0


def sphere_rule_size(degree: int) -> int:
    """Directions of :func:`sphere_rule` of ``degree``: (degree // 2 + 1) (degree + 1)."""
    return (degree // 2 + 1) * (degree + 1)


def sphere_rule(degree: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A product rule on the unit sphere exact for spherical harmonics up to ``degree``.

    Gauss–Legendre in cos θ (:func:`scipy.special.roots_legendre`, O(n) for large n),
    uniform in φ.

    Returns
    -------
    theta, phi : (M,) float64
        Radians.
    weights : (M,) float64
        Solid-angle weights, summing to 4π.
    """
    n_theta = degree // 2 + 1
    n_phi = degree + 1
    x, wx = roots_legendre(n_theta)
    phi = 2.0 * np.pi * np.arange(n_phi) / n_phi
    theta = np.arccos(x)
    tt, pp = np.meshgrid(theta, phi, indexing="ij")
    weights = np.repeat(wx, n_phi) * (2.0 * np.pi / n_phi)
    return tt.ravel(), pp.ravel(), weights


def _series(x2: np.ndarray, first: float, order: int) -> np.ndarray:
    """Σ_k (−x²/2)^k / (k! (2 order + 2k + 1)!!) times the first term's denominator."""
    term = np.ones_like(x2)
    total = np.ones_like(x2)
    double_factorial = 2 * order + 1
    for k in range(1, 12):
        double_factorial += 2
        term = term * (-x2 / 2.0) / (k * double_factorial)
        total = total + term
    return first * total


def transverse_kernel(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(f, h) with ∫ (I − r̂r̂) e^(j x r̂·û) dΩ / 4π = f(x) I + h(x) x² ûû.

    f = j0 − j1/x and h = j2/x² (spherical Bessel functions, both finite at x = 0:
    2/3 and 1/15); below x = 1 from their Taylor series, where the closed forms cancel.
    """
    x = np.asarray(x, dtype=np.float64)
    small = x < _SERIES_BELOW
    f = np.empty_like(x)
    h = np.empty_like(x)
    xs = x[small]
    x2 = xs * xs
    # j0 = Σ (−x²/2)^k / (k! (2k+1)!!), j1/x the same from 3!!, j2/x² from 5!!
    f[small] = _series(x2, 1.0, 0) - _series(x2, 1.0 / 3.0, 1)
    h[small] = _series(x2, 1.0 / 15.0, 2)
    xl = x[~small]
    inv = 1.0 / xl
    inv2 = inv * inv
    sin, cos = np.sin(xl) * inv, np.cos(xl) * inv2  # j0 = sin x / x; cos x / x²
    f[~small] = sin * (1.0 - inv2) + cos  # j0 − j1/x, j1/x = sin x / x³ − cos x / x²
    h[~small] = (
        (3.0 * inv2 - 1.0) * sin - 3.0 * cos
    ) * inv2  # j2/x², j2 = (3/x³ − 1/x) sin x − 3 cos x / x²
    return f, h


def far_field_power_pairs(points: np.ndarray, moments: np.ndarray, k: float) -> float:
    """∫ |F_⊥(r̂)|² dΩ for F(r̂) = Σ_p a_p e^(jk r̂·r_p), summed over pairs in closed form.

    ∫ (I − r̂r̂) e^(jk r̂·(r_q − r_p)) dΩ = 4π [f(x) I + h(x) k² d dᵀ] with d = r_q − r_p,
    x = k|d| (:func:`transverse_kernel`), so the integral is
    4π Σ_pq [f (a_p*·a_q) + h k² (a_p*·d)(d·a_q)]: no quadrature over directions, whose
    number grows as (k R)².

    Parameters
    ----------
    points : (P, 3) float
        r_p (m).
    moments : (P, 3) complex
        a_p (A m, a current times its quadrature weight).
    k : float
        Wavenumber (rad/m).

    Returns
    -------
    float
        The integral (A² m²), ≥ 0.
    """
    points = np.asarray(points, dtype=np.float64)
    a = np.asarray(moments, dtype=np.complex128)
    total = 0.0
    step = max(1, (1 << 20) // max(1, len(points)))
    for lo in range(0, len(points), step):
        d = points[None, :, :] - points[lo : lo + step, None, :]  # (B, P, 3): r_q − r_p
        x = k * np.sqrt(np.einsum("bpc,bpc->bp", d, d))
        f, h = transverse_kernel(x)
        ap = np.conj(a[lo : lo + step])  # (B, 3)
        dot = ap @ a.T  # a_p*·a_q, (B, P)
        left = np.einsum("bc,bpc->bp", ap, d)  # a_p*·d
        right = np.einsum("pc,bpc->bp", a, d)  # d·a_q
        total += float(np.real(np.sum(f * dot + (k * k) * h * left * right)))
    return 4.0 * np.pi * total

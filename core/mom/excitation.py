"""Excitations: the right-hand side V_m = ∫ f_m·E_inc dS of the EFIE.

Time convention e^(jωt): a plane wave travelling along d is
E(r) = E0 p e^(−jk d·r).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .geometry import METRES_PER_MESH_UNIT, MomGeometry


def _unit(value: object, name: str, dtype: type = float) -> np.ndarray:
    try:
        v: np.ndarray = np.asarray(value, dtype=dtype)
    except (TypeError, ValueError):
        raise ValueError(f"{name}={value!r} is not a 3-vector of numbers") from None
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise ValueError(f"{name}={value!r} is invalid; expected 3 finite numbers")
    norm = np.linalg.norm(v)
    if norm == 0:
        raise ValueError(f"{name}={value!r} is the zero vector; expected a direction")
    return v / norm


@dataclass(frozen=True, eq=False)
class PlaneWave:
    """A plane wave E(r) = amplitude · polarization · e^(−jk direction·r).

    Parameters
    ----------
    direction : 3 floats
        Direction of travel (normalised here); (0, 0, −1) falls on a z = 0 mesh from above.
    polarization : 3 numbers
        Direction of E (normalised; complex for elliptic polarisation); must be
        perpendicular to ``direction``.
    amplitude : float
        |E| in V/m.

    Examples
    --------
    >>> PlaneWave().polarization
    array([1., 0., 0.])
    >>> w = PlaneWave.from_angles(0, 0)  # from straight above, E along θ̂ = x
    >>> w.direction.round(12) + 0.0, w.polarization.round(12) + 0.0
    (array([ 0.,  0., -1.]), array([1., 0., 0.]))
    """

    direction: np.ndarray = (0.0, 0.0, -1.0)  # type: ignore[assignment]
    polarization: np.ndarray = (1.0, 0.0, 0.0)  # type: ignore[assignment]
    amplitude: float = 1.0

    def __post_init__(self) -> None:
        d = _unit(self.direction, "direction")
        pol = np.asarray(self.polarization)
        p = _unit(self.polarization, "polarization", complex if np.iscomplexobj(pol) else float)
        if abs(np.dot(d, p)) > 1e-9:
            raise ValueError(
                f"polarization={np.round(p, 6).tolist()} is not perpendicular to "
                f"direction={np.round(d, 6).tolist()}; a plane wave's E is transverse"
            )
        amp = float(self.amplitude)
        if not np.isfinite(amp) or amp <= 0:
            raise ValueError(f"amplitude={self.amplitude!r} is invalid; expected a positive V/m")
        for name, value in (("direction", d), ("polarization", p), ("amplitude", amp)):
            if isinstance(value, np.ndarray):
                value.flags.writeable = False
            object.__setattr__(self, name, value)

    @classmethod
    def from_angles(
        cls, theta: float, phi: float, polarization_angle: float = 0.0, amplitude: float = 1.0
    ) -> PlaneWave:
        """A wave coming from the direction (θ, φ) (degrees), i.e. travelling along −r̂(θ, φ).

        ``polarization_angle`` (degrees) turns E from θ̂ (0) towards φ̂ (90).
        """
        t, f, a = np.radians([theta, phi, polarization_angle])
        r_hat = np.array([np.sin(t) * np.cos(f), np.sin(t) * np.sin(f), np.cos(t)])
        theta_hat = np.array([np.cos(t) * np.cos(f), np.cos(t) * np.sin(f), -np.sin(t)])
        phi_hat = np.array([-np.sin(f), np.cos(f), 0.0])
        return cls(-r_hat, np.cos(a) * theta_hat + np.sin(a) * phi_hat, amplitude)

    def field(self, points: np.ndarray, k: float) -> np.ndarray:
        """(..., 3) complex E (V/m) at ``points`` (..., 3) in metres."""
        phase = np.exp(-1j * k * (np.asarray(points) @ self.direction))
        return self.amplitude * phase[..., None] * self.polarization


@dataclass(frozen=True, eq=False)
class VoltageSource:
    """A delta-gap voltage source on the mesh edges lying on a segment.

    Every RWG edge whose two vertices lie on the segment from ``start`` to
    ``end`` (mesh units, mm) is fed: V_m = ± voltage · l_m, the sign making
    the driven current flow across the segment towards the side that
    ``polarity`` points to (by default the in-plane normal of the segment).

    Parameters
    ----------
    start, end : 2 or 3 floats
        The feed segment (mm). For a strip dipole along x fed at x = 0, the
        segment runs across the strip at x = 0.
    voltage : float
        Volts.
    polarity : 3 floats, optional
        Direction the driven current takes across the gap; default: the
        segment's direction turned by +90° about z.
    """

    start: np.ndarray
    end: np.ndarray
    voltage: float = 1.0
    polarity: np.ndarray | None = None

    def __post_init__(self) -> None:
        pts = []
        for name in ("start", "end"):
            try:
                v = np.asarray(getattr(self, name), dtype=float)
            except (TypeError, ValueError):
                raise ValueError(f"{name}={getattr(self, name)!r} is not a point") from None
            if v.shape == (2,):
                v = np.append(v, 0.0)
            if v.shape != (3,) or not np.all(np.isfinite(v)):
                raise ValueError(
                    f"{name}={getattr(self, name)!r} is invalid; expected 2 or 3 numbers"
                )
            pts.append(v)
            object.__setattr__(self, name, v)
        if np.linalg.norm(pts[1] - pts[0]) == 0:
            raise ValueError("the feed segment has zero length: start == end")
        volts = float(self.voltage)
        if not np.isfinite(volts) or volts == 0:
            raise ValueError(f"voltage={self.voltage!r} is invalid; expected a non-zero number")
        object.__setattr__(self, "voltage", volts)
        if self.polarity is None:
            axis = pts[1] - pts[0]
            object.__setattr__(self, "polarity", _unit([-axis[1], axis[0], 0.0], "polarity"))
        else:
            object.__setattr__(self, "polarity", _unit(self.polarity, "polarity"))

    def feed_signs(self, geom: MomGeometry) -> np.ndarray:
        """(N,) float: ±1 on the fed unknowns, 0 elsewhere.

        Raises
        ------
        ValueError
            If no interior edge lies on the segment.
        """
        a = self.start * METRES_PER_MESH_UNIT
        b = self.end * METRES_PER_MESH_UNIT
        axis = b - a
        length = float(np.linalg.norm(axis))
        tri = geom.rwg_triangles
        # the edge's vertices: the two corners of T+ that are not its free vertex
        # (found as the vertices shared by T+ and T−)
        tp, tm = geom.triangles[tri[:, 0]], geom.triangles[tri[:, 1]]
        shared = (tp[:, :, None] == tm[:, None, :]).any(axis=2)  # (N, 3)
        ends = geom.vertices[tp]  # (N, 3, 3)
        rel = ends - a
        along = rel @ axis / length**2
        off = np.linalg.norm(rel - along[..., None] * axis, axis=2)
        tol = 1e-6 * max(length, float(geom.sizes.max()))
        on = (off <= tol) & (along >= -1e-9) & (along <= 1 + 1e-9)
        fed = np.all(on | ~shared, axis=1)
        if not fed.any():
            raise ValueError(
                f"no interior edge lies on the feed segment from {self.start.tolist()} to "
                f"{self.end.tolist()} mm; put it along mesh edges across the conductor"
            )
        across = geom.centroids[tri[:, 1]] - geom.centroids[tri[:, 0]]
        sign = np.sign(across @ self.polarity)
        return np.where(fed, sign, 0.0)


def excitation_vector(
    geom: MomGeometry, k: float, excitation: PlaneWave | VoltageSource
) -> np.ndarray:
    """(N,) complex V_m = ∫ f_m·E dS (volts) for ``excitation`` at wavenumber ``k``."""
    if isinstance(excitation, VoltageSource):
        return excitation.voltage * excitation.feed_signs(geom) * geom.rwg_lengths + 0j
    if not isinstance(excitation, PlaneWave):
        raise TypeError(
            f"excitation must be a PlaneWave or a VoltageSource, got {type(excitation).__name__}"
        )
    rule = geom.near
    e = excitation.field(rule.points, k)  # (T, Q, 3)
    e0 = np.einsum("tq,tqc->tc", rule.weights, e)  # ∫ E
    e1 = np.einsum("tq,tqc->t", rule.weights, rule.rho * e)  # ∫ ρ·E
    v = geom.coef_matrix @ e1
    for c in range(3):
        v = v + geom.offset_matrices[c] @ e0[:, c]
    return v

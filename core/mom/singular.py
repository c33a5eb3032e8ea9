"""Closed-form integrals of 1/R and R over a flat triangle.

For an observation point r and a source triangle T with unit normal n, let
ρ be the projection of r on T's plane and d = n·(r − r₁) its signed height.
With R = |r − r'| the four integrals over r' ∈ T

    ∫ 1/R dS',   ∫ R dS',   ∫ (r' − r)/R dS',   ∫ (r' − r) R dS'

reduce, by the divergence and gradient theorems in T's plane, to sums over
the three edges of one-dimensional integrals of R^n along each edge:

    ∇'·((ρ' − ρ) R^n) = (n + 2) R^n − n d² R^(n−2)
    ∇' R^(n+2)       = (n + 2) R^n (ρ' − ρ)

so that, with t_i the signed distance from ρ to edge i (positive inside),
u_i its outward in-plane normal, and Ω the solid angle T subtends at r,

    ∫ 1/R       = Σ t_i ∫_i 1/R dl − |d| Ω
    ∫ R         = (Σ t_i ∫_i R dl + d² ∫ 1/R) / 3
    ∫ (ρ'−ρ)/R  = Σ u_i ∫_i R dl
    ∫ (ρ'−ρ) R  = Σ u_i ∫_i R³ dl / 3

and r' − r = (ρ' − ρ) − d n. The edge integrals are elementary
(R² = l² + R₀² along an edge, R₀ the distance from r to the edge's line).
This is the approach of D. R. Wilton et al., IEEE Trans. AP-32 (1984)
276–281, and R. D. Graglia, IEEE Trans. AP-41 (1993) 1448–1455, derived
afresh here.

>>> import numpy as np
>>> tri = np.array([[[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]])
>>> far = np.array([[0.0, 0, 1e4]])
>>> i_inv, *_ = potential_integrals(far, tri)
>>> round(float(i_inv[0] * 1e4), 6)   # area / distance
0.5
"""

from __future__ import annotations

import numpy as np


def potential_integrals(
    r: np.ndarray, corners: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The integrals of 1/R, R, (r' − r)/R and (r' − r) R over triangles.

    Parameters
    ----------
    r : (M, 3) float64
        Observation points.
    corners : (M, 3, 3) float64
        The source triangle of each point, corner by corner.

    Returns
    -------
    inv_r : (M,) float64
        ∫ 1/R dS'.
    r1 : (M,) float64
        ∫ R dS'.
    vec_inv_r : (M, 3) float64
        ∫ (r' − r)/R dS'.
    vec_r1 : (M, 3) float64
        ∫ (r' − r) R dS'.

    Notes
    -----
    Valid for any r, on or off the plane; a point on the line through an
    edge (R₀ = 0) is handled by a floor on R₀ at 1e-12 of the edge length,
    where the terms it enters vanish anyway.
    """
    r = np.asarray(r, dtype=np.float64)
    corners = np.asarray(corners, dtype=np.float64)
    v0, v1, v2 = corners[:, 0], corners[:, 1], corners[:, 2]
    normal = np.cross(v1 - v0, v2 - v0)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    d = np.einsum("ij,ij->i", r - v0, normal)
    rho = r - d[:, None] * normal
    h = np.abs(d)
    d2 = d * d

    sum_t_inv = np.zeros(len(r))
    sum_t_r1 = np.zeros(len(r))
    solid = np.zeros(len(r))
    vec_r1 = np.zeros((len(r), 3))
    vec_r3 = np.zeros((len(r), 3))
    for i in range(3):
        start, end = corners[:, i], corners[:, (i + 1) % 3]
        edge = end - start
        length = np.linalg.norm(edge, axis=1)
        lhat = edge / length[:, None]
        uhat = np.cross(lhat, normal)  # outward for counter-clockwise corners about n
        l_plus = np.einsum("ij,ij->i", end - rho, lhat)
        l_minus = np.einsum("ij,ij->i", start - rho, lhat)
        t = np.einsum("ij,ij->i", start - rho, uhat)
        r0sq = np.maximum(t * t + d2, (1e-12 * length) ** 2)
        r0 = np.sqrt(r0sq)
        r_plus = np.sqrt(l_plus * l_plus + r0sq)
        r_minus = np.sqrt(l_minus * l_minus + r0sq)
        f = np.arcsinh(l_plus / r0) - np.arcsinh(l_minus / r0)  # ∫ 1/R dl
        e_r1 = 0.5 * (l_plus * r_plus - l_minus * r_minus + r0sq * f)  # ∫ R dl
        e_r3 = (
            0.25 * (l_plus * r_plus**3 - l_minus * r_minus**3)
            + 0.375 * r0sq * (l_plus * r_plus - l_minus * r_minus)
            + 0.375 * r0sq * r0sq * f
        )  # ∫ R³ dl
        sum_t_inv += t * f
        sum_t_r1 += t * e_r1
        solid += np.arctan2(t * l_plus, r0sq + h * r_plus) - np.arctan2(
            t * l_minus, r0sq + h * r_minus
        )
        vec_r1 += uhat * e_r1[:, None]
        vec_r3 += uhat * e_r3[:, None]
    inv_r = sum_t_inv - h * solid
    r1 = (sum_t_r1 + d2 * inv_r) / 3.0
    vec_inv_r = vec_r1 - (d * inv_r)[:, None] * normal
    vec_r = vec_r3 / 3.0 - (d * r1)[:, None] * normal
    return inv_r, r1, vec_inv_r, vec_r

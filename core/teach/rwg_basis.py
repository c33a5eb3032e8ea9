"""Sampling one RWG basis function, for teaching and inspection.

For an interior edge n of length l_n shared by triangles T+ and T− (areas
A±, free vertices r±)::

    f_n(r) =  l_n / (2 A+) ρ+,  ρ+ = r − r+   for r in T+
    f_n(r) =  l_n / (2 A−) ρ−,  ρ− = r− − r   for r in T−
    ∇·f_n  = ±l_n / A±

The function is sampled at the quadrature points: the centroids of each
triangle's n² uniform sub-triangles.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..mesh import TriMesh
from ..subdivision import uniform_subdivision


@dataclass(frozen=True)
class BasisSample:
    """One RWG basis function, sampled.

    Attributes
    ----------
    edge : int
        Edge id in ``mesh.edges``.
    row : int
        Row of the edge in ``mesh.rwg`` (the unknown's index).
    vertices : (2,) int
        The edge's vertices.
    t_plus, t_minus : int
    free_plus, free_minus : int
        Free vertices of T+ and T−.
    length, area_plus, area_minus : float
    centroid_plus, centroid_minus : (3,) float64
    rho_plus, rho_minus : (3,) float64
        ρ± at the centroids: from the free vertex of T+ to its centroid, and
        from the centroid of T− to its free vertex (both point across the
        edge from T+ into T−).
    points_plus, points_minus : (k, 3) float64
        Quadrature points in T+ and T−.
    values_plus, values_minus : (k, 3) float64
        f_n at those points.
    divergence_plus, divergence_minus : float
        l_n / A+ and −l_n / A−.
    """

    edge: int
    row: int
    vertices: np.ndarray
    t_plus: int
    t_minus: int
    free_plus: int
    free_minus: int
    length: float
    area_plus: float
    area_minus: float
    centroid_plus: np.ndarray
    centroid_minus: np.ndarray
    rho_plus: np.ndarray
    rho_minus: np.ndarray
    points_plus: np.ndarray
    points_minus: np.ndarray
    values_plus: np.ndarray
    values_minus: np.ndarray
    divergence_plus: float
    divergence_minus: float


def quadrature_points(corners: np.ndarray, n: int) -> np.ndarray:
    """Centroids of the n² uniform sub-triangles of one triangle.

    Parameters
    ----------
    corners : (3, 3) float64
    n : int

    Returns
    -------
    (n², 3) float64
    """
    bary, tri = uniform_subdivision(n)
    st = bary[tri].mean(axis=1)  # (n², 2)
    p0, p1, p2 = corners
    return p0 + st[:, :1] * (p1 - p0) + st[:, 1:] * (p2 - p0)


def edge_status(mesh: TriMesh, edge: int) -> str:
    """Why an edge carries an RWG function or not, in one sentence."""
    if not 0 <= edge < len(mesh.edges):
        raise ValueError(f"edge={edge!r} is out of range; the mesh has {len(mesh.edges)} edges")
    valence = int(mesh.topology.valence[edge])
    if valence == 2:
        return "interior edge: shared by two triangles, it carries one RWG basis function"
    if valence == 1:
        return (
            "boundary edge: on one triangle only, no current may cross it, "
            "so it carries no RWG basis function"
        )
    return (
        f"junction edge: shared by {valence} triangles; a single RWG function pairs exactly "
        "two triangles, so a junction needs special junction basis functions"
    )


def sample_rwg(mesh: TriMesh, edge: int, quadrature: int = 4) -> BasisSample:
    """Sample the RWG basis function of an interior edge.

    Parameters
    ----------
    mesh : TriMesh
    edge : int
        Edge id (not the RWG row).
    quadrature : int
        n: the function is sampled at the centroids of n² sub-triangles.

    Raises
    ------
    ValueError
        If the edge is not an interior edge (the message says why).

    Examples
    --------
    >>> from barymesh import MeshParams, build_mesh
    >>> mesh = build_mesh(MeshParams(structure="patch", subdivisions=1))
    >>> b = sample_rwg(mesh, int(mesh.interior_edges[0]), quadrature=2)
    >>> b.points_plus.shape, round(b.divergence_plus + b.divergence_minus, 12)
    ((4, 3), 0.0)
    """
    if not 0 <= edge < len(mesh.edges) or mesh.topology.valence[edge] != 2:
        raise ValueError(f"edge {edge} has no RWG function: {edge_status(mesh, edge)}")
    rwg = mesh.rwg
    row = int(np.searchsorted(rwg.edge, edge))
    tp, tm = int(rwg.t_plus[row]), int(rwg.t_minus[row])
    fp, fm = int(rwg.free_vertex_plus[row]), int(rwg.free_vertex_minus[row])
    length = float(rwg.length[row])
    ap, am = float(mesh.areas[tp]), float(mesh.areas[tm])
    qp = quadrature_points(mesh.points[mesh.triangles[tp]], quadrature)
    qm = quadrature_points(mesh.points[mesh.triangles[tm]], quadrature)
    rp, rm = mesh.points[fp], mesh.points[fm]
    cp, cm = mesh.centroids[tp], mesh.centroids[tm]
    return BasisSample(
        edge=int(edge),
        row=row,
        vertices=rwg.vertices[row].copy(),
        t_plus=tp,
        t_minus=tm,
        free_plus=fp,
        free_minus=fm,
        length=length,
        area_plus=ap,
        area_minus=am,
        centroid_plus=cp.copy(),
        centroid_minus=cm.copy(),
        rho_plus=cp - rp,
        rho_minus=rm - cm,
        points_plus=qp,
        points_minus=qm,
        values_plus=length / (2 * ap) * (qp - rp),
        values_minus=length / (2 * am) * (rm - qm),
        divergence_plus=length / ap,
        divergence_minus=-length / am,
    )

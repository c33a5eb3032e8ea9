"""Periodic boundary matching: edges on one side of the cell and their translated partners.

Periodic MoM codes (scuff-em among them) need every mesh edge lying on the
cell boundary to have an identical edge on the opposite side, translated by
a lattice vector. The cell is the parallelogram ``s a1 + t a2``,
``|s|, |t| <= 1/2``; the "minus" side of lattice vector k is where the k-th
lattice coordinate is −1/2 (the master in Gmsh's words) and the "plus" side
where it is +1/2 (the slave, the master moved by a_k).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from ..topology import edge_keys
from .model import Lattice


class EdgedMesh(Protocol):
    """What the matching reads of a mesh (a :class:`barymesh.mesh.TriMesh`, read only).

    The mesh module asks this one for :attr:`barymesh.mesh.TriMesh.periodic_pairs`, so
    this module names no mesh class: it is below the mesh.
    """

    @property
    def points(self) -> np.ndarray:
        """(V, 2 or 3) float64 vertex coordinates (mm)."""
        ...

    @property
    def edges(self) -> np.ndarray:
        """(E, 2) int vertex pairs of every edge."""
        ...

    @property
    def boundary_edges(self) -> np.ndarray:
        """(B,) int ids of the edges on one triangle only."""
        ...


@dataclass(frozen=True)
class PeriodicPairs:
    """Matching vertices and edges on opposite sides of the cell.

    Attributes
    ----------
    vertices : (K, 2) int
        (vertex on the minus side, vertex on the plus side): the second is
        the first moved by lattice vector ``vertex_shift``.
    vertex_shift : (K,) int
        0 for a1, 1 for a2.
    edges : (M, 2) int
        (edge on the minus side, edge on the plus side), mesh edge ids.
    edge_shift : (M,) int
    unmatched_edges : (U,) int
        Boundary edges lying on a side of the cell with no partner on the
        opposite side (empty for a periodic mesh).
    """

    vertices: np.ndarray
    vertex_shift: np.ndarray
    edges: np.ndarray
    edge_shift: np.ndarray
    unmatched_edges: np.ndarray

    @property
    def matched(self) -> bool:
        """True when every boundary edge on a side of the cell has its partner."""
        return len(self.unmatched_edges) == 0


def side_vertices(points: np.ndarray, lattice: Lattice, tolerance: float) -> np.ndarray:
    """(V, 2) int8: for each lattice vector, -1 / +1 where a vertex lies on the minus / plus side.

    A side is the segment between two corners of the cell: a vertex on the
    line through it but beyond a corner is on no side.

    Parameters
    ----------
    points : (V, 2 or 3) float64
    lattice : Lattice
    tolerance : float
        Distance (mm) from a side within which a vertex is on it.
    """
    frac = lattice.fractional(points)
    # the tolerance in lattice coordinates: distance between the two sides of each pair
    d = tolerance * np.array([np.hypot(*lattice.a2), np.hypot(*lattice.a1)]) / lattice.area
    within = np.abs(frac) <= 0.5 + d
    out = np.zeros(frac.shape, dtype=np.int8)
    for k in (0, 1):
        along = within[:, 1 - k]
        out[(np.abs(frac[:, k] + 0.5) <= d[k]) & along, k] = -1
        out[(np.abs(frac[:, k] - 0.5) <= d[k]) & along, k] = 1
    return out


def periodic_pairs(mesh: EdgedMesh, lattice: Lattice, tolerance: float) -> PeriodicPairs:
    """Match the boundary edges on opposite sides of the cell.

    Parameters
    ----------
    mesh : EdgedMesh
        The cell's mesh (a :class:`barymesh.mesh.TriMesh`), with the cell centred on the origin.
    lattice : Lattice
    tolerance : float
        Distance (mm) within which a translated vertex meets its partner.

    Returns
    -------
    PeriodicPairs
    """
    xy = np.asarray(mesh.points[:, :2])
    edges = mesh.edges
    boundary = mesh.boundary_edges.astype(np.int64)
    from scipy.spatial import cKDTree  # here: ``barymesh --help`` stays quick

    side = side_vertices(xy, lattice, tolerance)
    vert, vshift, epairs, eshift, unmatched = [], [], [], [], []
    for k, shift in enumerate((lattice.a1, lattice.a2)):
        s0, s1 = side[edges[boundary, 0], k], side[edges[boundary, 1], k]
        minus = boundary[(s0 == -1) & (s1 == -1)]
        plus = boundary[(s0 == 1) & (s1 == 1)]
        if len(minus) == 0 or len(plus) == 0:
            unmatched += [minus, plus]
            continue
        v_minus = np.unique(edges[minus])
        v_plus = np.unique(edges[plus])
        dist, near = cKDTree(xy[v_plus]).query(xy[v_minus] + shift, distance_upper_bound=tolerance)
        nearest = np.asarray(near)  # (n,) for n query points (a scalar only for one point)
        found = np.isfinite(dist)
        partner = np.full(len(xy), -1, dtype=np.int64)
        partner[v_minus[found]] = v_plus[nearest[found]]
        vert.append(np.stack([v_minus[found], v_plus[nearest[found]]], axis=1))
        vshift.append(np.full(found.sum(), k))
        image = partner[edges[minus]]  # (m, 2) the translated ends
        has = (image >= 0).all(axis=1)
        plus_keys = edge_keys(edges[plus, 0], edges[plus, 1], len(xy))
        order = np.argsort(plus_keys)
        keys = edge_keys(image[has, 0], image[has, 1], len(xy))
        at = np.searchsorted(plus_keys[order], keys).clip(max=len(plus) - 1)
        hit = plus_keys[order][at] == keys
        m_edges = minus[has][hit]
        p_edges = plus[order[at[hit]]]
        epairs.append(np.stack([m_edges, p_edges], axis=1))
        eshift.append(np.full(len(m_edges), k))
        unmatched.append(np.setdiff1d(minus, m_edges))
        unmatched.append(np.setdiff1d(plus, p_edges))

    def cat(parts: list[np.ndarray], shape: tuple[int, ...]) -> np.ndarray:
        return np.concatenate(parts).astype(np.int64) if parts else np.empty(shape, np.int64)

    return PeriodicPairs(
        vertices=cat(vert, (0, 2)).reshape(-1, 2),
        vertex_shift=cat(vshift, (0,)),
        edges=cat(epairs, (0, 2)).reshape(-1, 2),
        edge_shift=cat(eshift, (0,)),
        unmatched_edges=np.unique(cat(unmatched, (0,))),
    )

"""The frequency-independent geometry of an infinite array: one cell and its lattice.

:func:`periodic_geometry` builds, once per mesh and lattice, what every solve of the
array reads whatever its frequency and incidence (:class:`PeriodicGeometry`): the
free-space geometry of the cell, the RWG functions across the cell's sides (T+ in the
cell, T− the triangle on the opposite side seen from the next cell), the image σ of each
triangle pair (the source image nearest the observation triangle), the pairs near
through an image with their closed-form static moments, and the fill's plan
(:mod:`barymesh.mom.periodic_plan`).

It sits below the fill (:mod:`barymesh.mom.periodic_fill`) and the solve
(:mod:`barymesh.mom.periodic`), which both take a :class:`PeriodicGeometry`.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
import scipy.sparse as sp

from ..mesh import TriMesh
from .geometry import (
    METRES_PER_MESH_UNIT,
    MIRROR_MOMENTS,
    SIZE_TIE,
    MomGeometry,
    close_pairs,
    mom_geometry,
    static_moments,
)
from .periodic_checks import as_lattice, check_periodic_memory
from .periodic_plan import FillPlan, fill_plan

#: Near triples: centroids closer than this many times the larger triangle's longest edge.
NEAR_FACTOR = 1.5
#: Largest triangle, as a fraction of the cell's smallest height.
MAX_TRIANGLE = 0.2


def lattice_metres(mesh: TriMesh, lattice: Any) -> np.ndarray:
    """The lattice vectors (2, 2) in metres: ``lattice``'s, or else the mesh's own."""
    lat = lattice if lattice is not None else getattr(mesh, "lattice", None)
    if lat is None:
        raise ValueError(
            "the mesh carries no lattice: an infinite array needs a unit cell "
            "(mesh a cell, or pass lattice=Lattice(...))"
        )
    vectors = np.array([lat.a1, lat.a2], dtype=np.float64) * METRES_PER_MESH_UNIT
    return vectors


@dataclass(frozen=True, eq=False)
class PeriodicGeometry:
    """The frequency-independent part of an infinite-array solve (metres).

    Attributes
    ----------
    base : MomGeometry
        The mesh's free-space geometry (rules, its interior RWG maps, its near pairs:
        those of the periodic fill whose nearest image is the triangle itself).
    lattice : (2, 2) float
        Rows a1, a2 (m).
    maps : (N, 3T) sparse float
        The RWG functions of cell (0, 0) as [C | D_x | D_y] (see
        :mod:`barymesh.mom.geometry`): the interior ones, then one per pair of matching
        edges on opposite sides of the cell, whose T+ lies inside the cell at the minus
        side and whose T− is the triangle at the plus side, seen from the next cell.
        ``maps`` holds every half but those T−, which are in ``folded``.
    folded : (N, 3T) sparse float
        The T− halves of the unknowns across the cell's sides, at their place in cell
        (0, 0); they carry the Floquet phase e^(−j k_t·a) of the lattice vector a they
        are moved by (``crossing``).
    crossing : (N, 2) float
        That lattice vector (m), zero for the interior unknowns.
    shift : (T, T, 2) int8
        σ of each pair (observation, source): the source image used; σ(s, o) = −σ(o, s).
    cross : (K, 2) int
        (observation, source) pairs whose image σ ≠ 0 touches the observation triangle
        (near across the cell's sides), sorted by observation.
    cross_static_inv_r, cross_static_r : (K, 8) float
        The eight moments of 1/R and R over those pairs (near rule outside, closed form
        inside), against the shifted source.
    cross_distances : (K, Qn, Qn) float
        |r − r' − ρ_σ| between their near rule's points.
    plan : FillPlan
        How the matrix is filled (:mod:`barymesh.mom.periodic_fill`).
    """

    base: MomGeometry
    lattice: np.ndarray
    maps: sp.csr_matrix
    folded: sp.csr_matrix
    crossing: np.ndarray
    shift: np.ndarray
    cross: np.ndarray
    cross_static_inv_r: np.ndarray
    cross_static_r: np.ndarray
    cross_distances: np.ndarray
    plan: FillPlan

    @property
    def area(self) -> float:
        return float(abs(np.linalg.det(self.lattice)))

    @property
    def n_unknowns(self) -> int:
        return self.maps.shape[0]

    @property
    def n_crossing(self) -> int:
        """Unknowns across the cell's sides."""
        return int(np.count_nonzero(np.any(self.crossing != 0, axis=1)))

    @cached_property
    def near(self) -> np.ndarray:
        """(K, 2) int: every near (observation, source) pair, sorted by observation."""
        pairs = np.concatenate([self.base.near_pairs, self.cross])
        return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]

    def basis_maps(self, kt: np.ndarray) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """The (N, 3T) complex maps of the basis functions and of the testing functions.

        Basis halves moved by a carry e^(−j k_t·a), testing halves its conjugate. The last
        k_t's pair is kept: a solve asks for it three times (the right-hand side, the
        orders taken out of G_reg, the current). Read only.
        """
        kt = np.asarray(kt, dtype=np.float64)
        key = (float(kt[0]), float(kt[1]))
        last = self.__dict__.get("_last_basis_maps")
        if last is not None and last[0] == key:
            return last[1]
        phase = np.exp(-1j * (self.crossing @ kt))
        basis = self.maps + sp.diags(phase) @ self.folded
        test = self.maps + sp.diags(np.conj(phase)) @ self.folded
        maps = (basis.tocsr(), test.tocsr())
        self.__dict__["_last_basis_maps"] = (key, maps)  # a frozen dataclass: not setattr
        return maps


def _shift_vectors(shift: np.ndarray, lattice: np.ndarray) -> np.ndarray:
    """ρ_σ = σ_1 a1 + σ_2 a2 (..., 2), elementwise so that ρ_(−σ) = −ρ_σ bit for bit."""
    s = shift.astype(np.float64)
    return s[..., :1] * lattice[0] + s[..., 1:] * lattice[1]


def _rwg_maps(
    mesh: TriMesh, base: MomGeometry, lattice: Any, vectors: np.ndarray
) -> tuple[sp.csr_matrix, sp.csr_matrix, np.ndarray]:
    """[C | D_x | D_y] of the interior unknowns and of those across the cell's sides."""
    from ..cell.periodic import periodic_pairs

    lat = lattice if lattice is not None else mesh.lattice
    pairs = periodic_pairs(mesh, lat, mesh.tolerance)
    if not pairs.matched:
        raise ValueError(
            f"{len(pairs.unmatched_edges)} boundary edge(s) of the metal lie on a side of the "
            "cell with no matching edge on the opposite side: the metal crosses the cell "
            "boundary, but its mesh is not periodic there (mesh the cell with a lattice)"
        )
    t = base.n_triangles
    interior = [base.coef_matrix] + list(base.offset_matrices[:2])
    n_int = base.n_unknowns
    topo = mesh.topology
    minus, plus = pairs.edges[:, 0], pairs.edges[:, 1]
    m = len(minus)
    points = base.vertices
    rows: list[np.ndarray] = []
    cols: list[np.ndarray] = []
    values: list[np.ndarray] = []
    rows_b: list[np.ndarray] = []
    cols_b: list[np.ndarray] = []
    values_b: list[np.ndarray] = []
    if m:
        ends = topo.edges[minus]
        length = np.linalg.norm(points[ends[:, 0]] - points[ends[:, 1]], axis=1)
        for side, (edge, sign) in enumerate(((minus, 1.0), (plus, -1.0))):
            tri = topo.edge_triangles[edge, 0]
            corners = base.triangles[tri]
            on_edge = (corners[:, :, None] == topo.edges[edge][:, None, :]).any(axis=2)
            free = corners[np.arange(m), np.argmin(on_edge, axis=1)]
            coef = sign * length / (2.0 * base.areas[tri])
            offset = base.centroids[tri] - points[free]
            row = n_int + np.arange(m)
            for c, value in enumerate((coef, coef * offset[:, 0], coef * offset[:, 1])):
                (rows_b if side else rows).append(row)
                (cols_b if side else cols).append(tri + c * t)
                (values_b if side else values).append(value)
    n = n_int + m
    head = sp.vstack([sp.hstack(interior, "csr"), sp.csr_matrix((m, 3 * t))], "csr")

    def matrix(r: list, c: list, v: list) -> sp.csr_matrix:
        if not r:
            return sp.csr_matrix((n, 3 * t))
        return sp.csr_matrix(
            (np.concatenate(v), (np.concatenate(r), np.concatenate(c))), shape=(n, 3 * t)
        )

    crossing = np.zeros((n, 2))
    crossing[n_int:] = vectors[pairs.edge_shift] if m else 0.0
    return (head + matrix(rows, cols, values)).tocsr(), matrix(rows_b, cols_b, values_b), crossing


_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def periodic_geometry(
    mesh: TriMesh, lattice: Any = None, *, memory_limit: float | None = None
) -> PeriodicGeometry:
    """The frequency-independent data of the array of ``mesh`` on ``lattice`` (or its own).

    Cached per mesh and lattice: a sweep over frequency or angle computes it once.

    Parameters
    ----------
    mesh : TriMesh
        One cell of the screen (mm).
    lattice : Lattice, optional
        Default: the mesh's own.
    memory_limit : float, optional
        A cap in bytes for building it and one solve beside it
        (:func:`check_periodic_memory`, checked before the T² tables are allocated).

    Raises
    ------
    ProblemTooLarge
        When the geometry and a solve would not fit in memory.
    ValueError
        A mesh off z = 0, triangles too large for the cell, metal across the cell's
        sides without matching periodic edges.
    """
    lattice = as_lattice(lattice)  # a Lattice, or two vectors in mm
    vectors = lattice_metres(mesh, lattice)
    key = tuple(vectors.ravel())
    per_mesh = _CACHE.setdefault(mesh, {})
    if key not in per_mesh:
        per_mesh.clear()  # one lattice per mesh at a time; keeps memory bounded
        per_mesh[key] = _periodic_geometry(mesh, lattice, vectors, memory_limit)
    return per_mesh[key]


def _periodic_geometry(
    mesh: TriMesh, lattice: Any, vectors: np.ndarray, memory_limit: float | None
) -> PeriodicGeometry:
    # before the geometry (a minute for a large cell): the memory of the unknowns (the
    # interior ones and the pairs across the sides, counted cheaply)
    from ..cell.periodic import periodic_pairs

    lat = lattice if lattice is not None else mesh.lattice
    pairs = periodic_pairs(mesh, lat, mesh.tolerance)
    check_periodic_memory(mesh.n_triangles, len(mesh.rwg) + len(pairs.edges), memory_limit)
    base = mom_geometry(mesh, near_factor=NEAR_FACTOR)  # its near pairs: those of σ = 0
    if np.any(base.vertices[:, 2] != 0.0):
        raise ValueError("the periodic solver takes flat screens only: the mesh is not in z = 0")
    heights = abs(np.linalg.det(vectors)) / np.linalg.norm(vectors, axis=1)
    if base.sizes.max() > MAX_TRIANGLE * heights.min():
        raise ValueError(
            f"triangles of up to {base.sizes.max() * 1e3:.4g} mm are too large for a cell of "
            f"height {heights.min() * 1e3:.4g} mm; refine the mesh (at most "
            f"{MAX_TRIANGLE:g} of the cell's height)"
        )
    maps, folded, crossing = _rwg_maps(mesh, base, lattice, vectors)
    check_periodic_memory(base.n_triangles, maps.shape[0], memory_limit)
    centroids = base.centroids[:, :2]
    lat = centroids @ np.linalg.inv(vectors)  # lattice coordinates of the centroids
    frac = lat[:, None, :] - lat[None, :, :]  # (T, T, 2), antisymmetric bit for bit
    shift = np.rint(frac)  # rint is odd (ties to even), so σ(s, o) = −σ(o, s)
    frac -= shift  # the reduced centroid offsets, in [−½, ½]²
    shift = shift.astype(np.int8)
    cross = _cross_pairs(base, vectors, shift)
    obs, src = cross[:, 0], cross[:, 1]
    offset = _shift_vectors(shift[obs, src], vectors)  # (K, 2)
    offset3 = np.concatenate([offset, np.zeros((len(offset), 1))], axis=1)
    static = _cross_static_moments(base, obs, src, offset3)
    rule = base.near
    d = rule.points[obs][:, :, None, :] - (rule.points[src] + offset3[:, None, :])[:, None]
    cross_distances = np.sqrt(np.einsum("kabc,kabc->kab", d, d))
    return PeriodicGeometry(
        base=base,
        lattice=vectors,
        maps=maps,
        folded=folded,
        crossing=crossing,
        shift=shift,
        cross=cross,
        cross_static_inv_r=static[0],
        cross_static_r=static[1],
        cross_distances=cross_distances,
        plan=fill_plan(base, vectors, shift, frac, cross, maps, folded),
    )


def _cross_static_moments(
    base: MomGeometry, obs: np.ndarray, src: np.ndarray, offset3: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The free-space solver's closed-form 1/R and R moments of the pairs near through an
    image, against the shifted sources; on one of each mirrored pair (o, s + a) and
    (s, o − a), the one with the smaller triangle under the rule, as for the pairs in the
    cell (:func:`barymesh.mom.geometry._mirrored_static_moments`): the other is its
    mirror, and Z(0) is symmetric across the cell's sides too."""
    n = base.n_triangles
    key = obs * n + src  # ascending: the pairs are sorted
    want = src * n + obs
    partner = np.minimum(np.searchsorted(key, want), max(len(key) - 1, 0))
    paired = (key[partner] == want) if len(key) else np.zeros(0, dtype=bool)
    sizes = base.sizes
    tie = np.abs(sizes[obs] - sizes[src]) <= SIZE_TIE * np.maximum(sizes[obs], sizes[src])
    smaller = (~tie & (sizes[obs] < sizes[src])) | (tie & (obs < src))
    computed = ~paired | smaller
    rows = np.flatnonzero(computed)
    corners = base.vertices[base.triangles]
    inv_r, r1 = static_moments(
        base.near,
        corners[src[rows]] + offset3[rows, None, :],
        base.centroids[src[rows]] + offset3[rows],
        obs[rows],
        np.arange(len(rows)),
    )
    where = np.full(len(obs), -1, dtype=np.intp)
    where[rows] = np.arange(len(rows))
    mirrors = np.flatnonzero(~computed)
    out = []
    for m in (inv_r, r1):
        full = np.empty((len(obs), 8))
        full[rows] = m
        full[mirrors] = m[where[partner[mirrors]]][:, MIRROR_MOMENTS]
        out.append(full)
    return out[0], out[1]


def _cross_pairs(base: MomGeometry, vectors: np.ndarray, shift: np.ndarray) -> np.ndarray:
    """(K, 2) pairs (o, s) near through an image σ ≠ 0, sorted (the σ = 0 ones: ``base``)."""
    centroids = base.centroids[:, :2]
    sizes = base.sizes
    low, high = shift.reshape(-1, 2).min(axis=0), shift.reshape(-1, 2).max(axis=0)
    found = []
    for s1 in range(int(low[0]), int(high[0]) + 1):
        for s2 in range(int(low[1]), int(high[1]) + 1):
            if s1 == 0 and s2 == 0:
                continue
            image = centroids + s1 * vectors[0] + s2 * vectors[1]
            hits = close_pairs(centroids, image, sizes, sizes, NEAR_FACTOR)
            o, s = hits[:, 0], hits[:, 1]
            keep = np.all(shift[o, s] == (s1, s2), axis=1)
            found.append(hits[keep])
    pairs = np.concatenate(found) if found else np.zeros((0, 2), dtype=np.intp)
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]


def cell_current(
    pg: PeriodicGeometry, kt: np.ndarray, current: np.ndarray, rho: np.ndarray
) -> np.ndarray:
    """(T, Q, 3) J of cell (0, 0) at points ρ (T, Q, 3) from their triangles' centroids."""
    t = pg.base.n_triangles
    basis, _ = pg.basis_maps(kt)
    linear = basis.T @ current  # (3T,): C, D_x, D_y per triangle
    alpha = linear[:t]
    beta = np.stack([linear[t : 2 * t], linear[2 * t :], np.zeros(t)], axis=1)
    return alpha[:, None, None] * rho + beta[:, None, :]

"""The frequency-independent part of an RWG solve, computed once per mesh.

:func:`mom_geometry` turns a :class:`~barymesh.mesh.TriMesh` (mm) into a
:class:`MomGeometry` (metres): triangle areas, normals and quadrature
points, the RWG coefficients as sparse maps from triangles to unknowns,
the near triangle pairs and the static (1/R and R) parts of their
integrals. A sweep over frequency reuses it; only the kernel e^(−jkR)/R
changes from one frequency to the next.

RWG function n on its triangles T± (free vertices v±, edge length l)::

    f_n(r) = s l / (2 A) (r − v),  ∇·f_n = s l / A,   s = +1 on T+, −1 on T−

written per triangle p as ``coef * (ρ + offset)`` with ρ = r − c_p (the
centroid) and ``offset = c_p − v``. A triangle-pair integral then needs
only eight moments of the kernel g(r, r')::

    ∫∫ g,  ∫∫ ρ g (3),  ∫∫ ρ' g (3),  ∫∫ ρ·ρ' g

(``MOMENTS`` names them), and an RWG integral is a sum of at most four
of those, collected by the sparse (N, T) matrices ``coef_matrix`` and
``offset_matrices``.
"""

from __future__ import annotations

import itertools
import weakref
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from ..mesh import TriMesh
from .quadrature import ORDERS, triangle_rule
from .singular import potential_integrals

#: Metres per mesh unit (meshes are in mm).
METRES_PER_MESH_UNIT = 1e-3
#: Order of the eight triangle-pair moments along the first axis of moment arrays.
MOMENTS = ("1", "rho_x", "rho_y", "rho_z", "rho'_x", "rho'_y", "rho'_z", "rho.rho'")
#: Default polynomial degree of the near-pair (and excitation, far-field) rule.
NEAR_ORDER = 5
#: Default degree of the rule for far pairs.
FAR_ORDER = 2
#: Pairs whose centroids are closer than this many times the larger triangle's longest
#: edge are near: integrated with singularity subtraction and the near rule.
NEAR_FACTOR = 1.5
#: Largest cached table of far-pair point distances (bytes); above it, recomputed per fill.
DISTANCE_CACHE_BYTES = 160 * 2**20
#: Entries of the scratch slab in which point distances are computed.
DISTANCE_SLAB = 1 << 18
#: Near pairs per block of :func:`static_moments` (about 3 KB of temporaries each).
STATIC_BLOCK = 1 << 15


@dataclass(frozen=True, eq=False)
class Rule:
    """A quadrature rule mapped onto every triangle.

    Attributes
    ----------
    order : int
        Polynomial degree.
    points : (T, Q, 3) float64
        Quadrature points (m).
    weights : (T, Q) float64
        Weights including the triangle's area (m²).
    rho : (T, Q, 3) float64
        Points minus their triangle's centroid (m).
    """

    order: int
    points: np.ndarray
    weights: np.ndarray
    rho: np.ndarray

    @property
    def size(self) -> int:
        return self.weights.shape[1]


@dataclass(frozen=True, eq=False)
class MomGeometry:
    """Everything about a mesh that an RWG solve needs and no frequency changes.

    Attributes
    ----------
    vertices : (V, 3) float64
        Vertex coordinates (m).
    triangles : (T, 3) int
    areas : (T,) float64
        m².
    centroids : (T, 3) float64
    sizes : (T,) float64
        Longest edge of each triangle (m).
    rwg_triangles : (N, 2) int
        T+ and T− of each unknown (``mesh.rwg.t_plus``, ``t_minus``).
    rwg_lengths : (N,) float64
        Edge lengths (m).
    coef_matrix : (N, T) sparse float64
        ± l / (2 A) where unknown n lives on triangle p.
    offset_matrices : tuple of three (N, T) sparse float64
        ``coef * (c_p − v_free)``, one matrix per coordinate.
    far, near : Rule
        The two quadrature rules.
    near_pairs : (K, 2) int
        (observation, source) triangle pairs integrated with singularity
        subtraction, self pairs included, sorted by observation triangle.
    near_upper : (H,) int
        The near pairs with observation ≤ source triangle (self pairs and one
        of each mirrored pair): the kernel is evaluated on those only.
    near_half : (K,) int
        For each near pair, the row of ``near_upper`` holding it or its mirror.
    near_mirrored : (K,) bool
        True where that row is the mirror (source, observation) of the pair.
    near_distances : (H, Qn, Qn) float64
        |r − r'| between the near rule's points of each pair of ``near_upper``.
    static_inv_r, static_r : (K, 8) float64
        The eight moments (:data:`MOMENTS`) of 1/R and of R over each near
        pair: outer integral by the near rule, inner one in closed form.
    far_distances : (T Qf, T Qf) float64 or None
        |r − r'| between all far-rule points (zeros replaced by 1; those pairs
        are near ones), kept when it fits :data:`DISTANCE_CACHE_BYTES`; built on
        first use.
    near_factor : float
    """

    vertices: np.ndarray
    triangles: np.ndarray
    areas: np.ndarray
    centroids: np.ndarray
    sizes: np.ndarray
    rwg_triangles: np.ndarray
    rwg_lengths: np.ndarray
    coef_matrix: sp.csr_matrix
    offset_matrices: tuple[sp.csr_matrix, sp.csr_matrix, sp.csr_matrix]
    far: Rule
    near: Rule
    near_pairs: np.ndarray
    near_upper: np.ndarray
    near_half: np.ndarray
    near_mirrored: np.ndarray
    near_distances: np.ndarray
    static_inv_r: np.ndarray
    static_r: np.ndarray
    near_factor: float

    @cached_property
    def far_distances(self) -> np.ndarray | None:
        """(T Qf, T Qf) |r − r'| between all far-rule points, or None when too large.

        Built on first use (the free-space fill; the periodic one has no use for it) and
        kept when it fits ``DISTANCE_CACHE_BYTES``.
        """
        n_points = self.far.points.shape[0] * self.far.size
        if n_points * n_points * 8 > DISTANCE_CACHE_BYTES:
            return None
        return far_point_distances(self.far, 0, self.n_triangles)

    @property
    def n_unknowns(self) -> int:
        return len(self.rwg_lengths)

    @property
    def n_triangles(self) -> int:
        return len(self.triangles)

    @property
    def divergence_matrix(self) -> sp.csr_matrix:
        """(N, T) sparse: ∇·f_n = ± l / A on each triangle of unknown n."""
        return self.coef_matrix * 2.0


_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def mom_geometry(
    mesh: TriMesh,
    order: int = NEAR_ORDER,
    far_order: int = FAR_ORDER,
    near_factor: float = NEAR_FACTOR,
) -> MomGeometry:
    """The frequency-independent solver data of ``mesh``, cached per mesh.

    Parameters
    ----------
    mesh : TriMesh
        Coordinates in mm (converted to metres here).
    order : int
        Degree of the near rule (self and near pairs, excitation, far field).
    far_order : int
        Degree of the rule for far pairs.
    near_factor : float
        Near-pair distance in units of the larger triangle's longest edge.

    Returns
    -------
    MomGeometry

    Raises
    ------
    ValueError
        If the mesh has no RWG unknowns, a degenerate triangle, or an
        option is out of range.
    """
    if not isinstance(mesh, TriMesh):
        raise TypeError(f"mesh must be a TriMesh, got {type(mesh).__name__}")
    for name, value in (("order", order), ("far_order", far_order)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
            raise TypeError(f"{name} must be an integer, got {value!r}")
        if value not in ORDERS:
            raise ValueError(f"{name}={value} has no quadrature rule; expected one of {ORDERS}")
    near_factor = float(near_factor)
    if not np.isfinite(near_factor) or near_factor < 1.0:
        raise ValueError(f"near_factor={near_factor} is invalid; expected a number >= 1")
    key = (int(order), int(far_order), near_factor)
    per_mesh = _CACHE.setdefault(mesh, {})
    if key not in per_mesh:
        per_mesh.clear()  # one set of options per mesh is enough; keep memory bounded
        per_mesh[key] = _build(mesh, int(order), int(far_order), near_factor)
    return per_mesh[key]


def close_pairs(
    a: np.ndarray, b: np.ndarray, size_a: np.ndarray, size_b: np.ndarray, factor: float
) -> np.ndarray:
    """(K, 2) pairs (i, j), sorted, with |a_i − b_j| < factor · max(size_a[i], size_b[j]).

    Each point is searched within its own radius, so the work and memory grow with the
    pairs found, not with the largest size (a fixed radius of factor × max size made a
    graded mesh's candidates nearly all T² pairs).
    """
    if len(a) == 0 or len(b) == 0:
        return np.zeros((0, 2), dtype=np.intp)
    tree_a, tree_b = cKDTree(a), cKDTree(b)
    by_a = tree_b.query_ball_point(a, factor * size_a)  # j near i within i's radius
    by_b = tree_a.query_ball_point(b, factor * size_b)  # i near j within j's radius
    count_a = np.fromiter(map(len, by_a), dtype=np.intp, count=len(a))
    count_b = np.fromiter(map(len, by_b), dtype=np.intp, count=len(b))
    i = np.concatenate([np.repeat(np.arange(len(a)), count_a), _flat(by_b, count_b)])
    j = np.concatenate([_flat(by_a, count_a), np.repeat(np.arange(len(b)), count_b)])
    key = np.unique(i * len(b) + j)
    i, j = np.divmod(key, len(b))
    dist = np.linalg.norm(a[i] - b[j], axis=1)
    keep = dist < factor * np.maximum(size_a[i], size_b[j])
    return np.stack([i[keep], j[keep]], axis=1)


def _flat(lists: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """The concatenation of ``lists`` (an object array of index lists) as intp."""
    total = int(counts.sum())
    if total == 0:
        return np.zeros(0, dtype=np.intp)
    return np.fromiter(itertools.chain.from_iterable(lists), dtype=np.intp, count=total)


def _rule(corners: np.ndarray, areas: np.ndarray, centroids: np.ndarray, order: int) -> Rule:
    bary, w = triangle_rule(order)
    points = np.einsum("qk,tkc->tqc", bary, corners)
    return Rule(order, points, areas[:, None] * w[None, :], points - centroids[:, None, :])


def _build(mesh: TriMesh, order: int, far_order: int, near_factor: float) -> MomGeometry:
    rwg = mesh.rwg
    if len(rwg) == 0:
        raise ValueError(
            "the mesh has no interior edges, so no RWG unknowns: nothing to solve "
            f"({mesh.n_triangles} triangles)"
        )
    vertices = np.asarray(mesh.points, dtype=np.float64) * METRES_PER_MESH_UNIT
    triangles = np.asarray(mesh.triangles, dtype=np.intp)
    corners = vertices[triangles]
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    areas = 0.5 * np.linalg.norm(cross, axis=1)
    sides = np.linalg.norm(corners - np.roll(corners, -1, axis=1), axis=2)
    sizes = sides.max(axis=1)
    if np.any(areas <= 1e-12 * sizes**2):
        bad = int(np.argmax(areas <= 1e-12 * sizes**2))
        raise ValueError(f"triangle {bad} is degenerate (zero area); it cannot carry RWG current")
    centroids = corners.mean(axis=1)

    # -- RWG functions as sparse maps from triangles to unknowns -------------------
    n = len(rwg)
    tri = np.stack([rwg.t_plus, rwg.t_minus], axis=1).astype(np.intp)
    free = np.stack([rwg.free_vertex_plus, rwg.free_vertex_minus], axis=1).astype(np.intp)
    lengths = np.asarray(rwg.length, dtype=np.float64) * METRES_PER_MESH_UNIT
    coef = lengths[:, None] / (2.0 * areas[tri]) * np.array([1.0, -1.0])
    offset = centroids[tri] - vertices[free]  # (N, 2, 3)
    rows = np.repeat(np.arange(n), 2)
    cols = tri.ravel()

    def matrix(values: np.ndarray) -> sp.csr_matrix:
        return sp.csr_matrix((values.ravel(), (rows, cols)), shape=(n, len(triangles)))

    coef_matrix = matrix(coef)
    offset_matrices = (
        matrix(coef * offset[:, :, 0]),
        matrix(coef * offset[:, :, 1]),
        matrix(coef * offset[:, :, 2]),
    )

    far = _rule(corners, areas, centroids, far_order)
    near = _rule(corners, areas, centroids, order)

    # -- near pairs ------------------------------------------------------------------
    pairs = close_pairs(centroids, centroids, sizes, sizes, near_factor)
    pairs = pairs[pairs[:, 0] < pairs[:, 1]]
    selfs = np.repeat(np.arange(len(triangles))[:, None], 2, axis=1)
    near_pairs = np.concatenate([selfs, pairs, pairs[:, ::-1]]).astype(np.intp)
    near_pairs = near_pairs[np.lexsort((near_pairs[:, 1], near_pairs[:, 0]))]
    obs, src = near_pairs[:, 0], near_pairs[:, 1]
    # (a, b) and (b, a) share their point distances, transposed: keep one of the two
    near_mirrored = obs > src
    near_upper = np.flatnonzero(~near_mirrored)
    key = obs * len(triangles) + src  # ascending, as the pairs are sorted
    partner = np.where(near_mirrored, np.searchsorted(key, src * len(triangles) + obs), 0)
    rank = np.cumsum(~near_mirrored) - 1
    near_half = np.where(near_mirrored, rank[partner], rank)
    near_distances = _pair_distances(near.points[obs[near_upper]], near.points[src[near_upper]])
    static_inv_r, static_r = _mirrored_static_moments(
        near, corners, centroids, sizes, obs, src, near_upper, near_half, near_mirrored
    )

    return MomGeometry(
        vertices=vertices,
        triangles=triangles,
        areas=areas,
        centroids=centroids,
        sizes=sizes,
        rwg_triangles=tri,
        rwg_lengths=lengths,
        coef_matrix=coef_matrix,
        offset_matrices=offset_matrices,
        far=far,
        near=near,
        near_pairs=near_pairs,
        near_upper=near_upper,
        near_half=near_half,
        near_mirrored=near_mirrored,
        near_distances=near_distances,
        static_inv_r=static_inv_r,
        static_r=static_r,
        near_factor=near_factor,
    )


def far_point_distances(
    far: Rule, lo: int, hi: int, src_lo: int = 0, src_hi: int | None = None
) -> np.ndarray:
    """(Tb Qf, Ts Qf) distances from the far points of triangles lo..hi to those of src_lo..src_hi.

    ``src_hi`` defaults to the last triangle. Exact zeros (a point paired with
    itself) are replaced by 1: such pairs are always near pairs, whose
    far-rule values are overwritten. The table is symmetric bit for bit:
    swapping the two ranges gives its transpose.
    """
    obs = far.points[lo:hi].reshape(-1, 3)
    src = far.points[src_lo:src_hi].reshape(-1, 3)
    axes = [c for c in range(3) if obs[:, c].any() or src[:, c].any()]  # z = 0: no z
    dist = np.zeros((len(obs), len(src)))
    if not axes or not dist.size:
        dist[...] = 1.0
        return dist
    # rows in slabs of about DISTANCE_SLAB entries, so that the only large array
    # written is the table itself (fresh memory is slow to touch on a shared VM)
    rows = max(1, DISTANCE_SLAB // len(src))
    scratch = np.empty((min(rows, len(obs)), len(src)))
    for start in range(0, len(obs), rows):
        stop = min(len(obs), start + rows)
        out, tmp = dist[start:stop], scratch[: stop - start]
        for c in axes:
            np.subtract(obs[start:stop, c, None], src[None, :, c], out=tmp)
            np.multiply(tmp, tmp, out=tmp)
            out += tmp
        np.sqrt(out, out=out)
        out[out == 0.0] = 1.0
    return dist


def _pair_distances(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(K, Q, Q) |a_i − b_j| for point sets a, b (K, Q, 3), coordinate by coordinate."""
    d2 = np.zeros(a.shape[:2] + b.shape[1:2])
    for c in range(3):
        ac, bc = a[:, :, c], b[:, :, c]
        if not (ac.any() or bc.any()):
            continue  # a flat mesh in z = 0
        diff = ac[:, :, None] - bc[:, None, :]
        diff *= diff
        d2 += diff
    return np.sqrt(d2, out=d2)


#: Triangle sizes closer than this (relative) are a tie in choosing which of a pair is
#: under the rule (:func:`_mirrored_static_moments`).
SIZE_TIE = 1e-6
#: The static moments of the mirrored pair (b, a) from those of (a, b): the source's
#: and the observer's first moments trade places.
MIRROR_MOMENTS = np.array([0, 4, 5, 6, 1, 2, 3, 7])


def _mirrored_static_moments(
    near: Rule,
    corners: np.ndarray,
    centroids: np.ndarray,
    sizes: np.ndarray,
    obs: np.ndarray,
    src: np.ndarray,
    upper: np.ndarray,
    half: np.ndarray,
    mirrored: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`static_moments` of all near pairs, computed on one of each mirrored pair:
    the one with the smaller triangle outside, under the rule.

    The closed form is exact on the inner (source) triangle whatever its size, while the
    outer rule samples the source's potential at a few points: a small source beside a
    large observer peaks between them. On a graded mesh (edge triangles a tenth of their
    neighbours) the two orders of such a pair differed by up to 18 % of the entry, and Z
    by 3e-3 of its largest entry from its transpose; now Z is symmetric by construction,
    as Galerkin testing of a reciprocal operator is.
    """
    up_obs, up_src = obs[upper], src[upper]
    # the rule on the smaller of the two; a tie (equal up to rounding, which moves with
    # the mesh's position) keeps the pair's own order, so a moved mesh gives the same Z
    flip = sizes[up_obs] > sizes[up_src] * (1.0 + SIZE_TIE)
    inner_obs = np.where(flip, up_src, up_obs)
    inner_src = np.where(flip, up_obs, up_src)
    inv_r, r1 = static_moments(near, corners, centroids, inner_obs, inner_src)
    swap = flip[half] != mirrored  # pair p is the one computed, or its mirror
    out = []
    for m in (inv_r, r1):
        m = m[half]
        m[swap] = m[swap][:, MIRROR_MOMENTS]
        out.append(m)
    return out[0], out[1]


def static_moments(
    near: Rule, corners: np.ndarray, centroids: np.ndarray, obs: np.ndarray, src: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(K, 8) moments of 1/R and R: near rule outside, closed form inside.

    Pair i is observation triangle ``obs[i]`` of the rule against the source triangle in
    row ``src[i]`` of ``corners`` and ``centroids``, which need not be the mesh's own (the
    periodic solver passes images of them moved by lattice vectors). Computed in blocks
    of :data:`STATIC_BLOCK` pairs, so the temporaries stay bounded on meshes with many
    near pairs (graded meshes: over 100 per triangle).
    """
    k = len(obs)
    inv_r, r1 = np.empty((k, 8)), np.empty((k, 8))
    for start in range(0, k, STATIC_BLOCK):
        part = slice(start, start + STATIC_BLOCK)
        inv_r[part], r1[part] = _static_block(near, corners, centroids, obs[part], src[part])
    return inv_r, r1


def _static_block(
    near: Rule, corners: np.ndarray, centroids: np.ndarray, obs: np.ndarray, src: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    k, q = len(obs), near.size
    r = near.points[obs].reshape(-1, 3)  # (K Q, 3)
    inv_r, r1, vec_inv_r, vec_r1 = potential_integrals(r, corners, np.repeat(src, q))
    w = near.weights[obs]  # (K, Q)
    rho = near.rho[obs]  # (K, Q, 3)
    to_centroid = (r - np.repeat(centroids[src], q, axis=0)).reshape(k, q, 3)
    out = []
    for scalar, vector in ((inv_r, vec_inv_r), (r1, vec_r1)):
        s = scalar.reshape(k, q)
        # ∫ ρ' g dS' = ∫ (r' − r) g + (r − c_src) ∫ g
        v = vector.reshape(k, q, 3) + to_centroid * s[:, :, None]
        m = np.empty((k, 8))
        m[:, 0] = (w * s).sum(axis=1)
        m[:, 1:4] = np.einsum("kq,kqc->kc", w * s, rho)
        m[:, 4:7] = np.einsum("kq,kqc->kc", w, v)
        m[:, 7] = np.einsum("kq,kqc->k", w, rho * v)
        out.append(m)
    return out[0], out[1]

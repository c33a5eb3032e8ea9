"""The finished mesh: an immutable bundle of arrays with lazily derived topology."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np
import scipy.sparse as sp

from .assembly import patch_topology
from .overlap import union_area
from .quality import (
    TriangleQuality,
    lattice_diagonal,
    lattice_quality_summary,
    quality_summary,
    triangle_quality,
)
from .sizing import sizing_stats
from .structures import _sector_chain_vertices
from .subdivision import PatchTemplate
from .topology import (
    BLOCK,
    CHAIN,
    INDEX,
    MIDDLE,
    EdgeTopology,
    RWGTable,
    _adjacency_without_junctions,
    chain_adjacency,
    chain_rwg,
    chain_topology,
    copies_adjacency,
    copies_rwg,
    copies_topology,
    edge_topology,
    patch_edge_counts,
    rwg_table,
    segment_lengths,
    triangle_adjacency,
    vertex_adjacency,
)

if TYPE_CHECKING:
    from .params import MeshParams


def _frozen(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a)
    a.flags.writeable = False
    return a


#: Translated copies stand in for the full computation only when every patch's vertices,
#: relative to its first, are within this fraction of the shortest side of where the
#: first patch has them (rounding included). On random paper rings the aggregates then
#: differ from the full computation by at most a quarter of this (below 1e-13).
_COPY_TOLERANCE = 2.5e-13


#: Chains of sectors the chain paths take at most (a conforming ring has one or two
#: rings of one or two arcs); more and the mesh takes the general paths.
_MAX_CHAINS = 16

#: (id of the template, closed) -> (template, topology of its short chain); a few entries.
_SHORT_CHAINS: dict[tuple[int, bool], tuple[PatchTemplate, EdgeTopology]] = {}


def _short_chain_topology(template: PatchTemplate, closed: bool) -> EdgeTopology:
    """``patch_topology`` of a chain of :data:`barymesh.topology.CHAIN` sectors, by formula."""
    key = (id(template), closed)
    hit = _SHORT_CHAINS.get(key)
    if hit is not None and hit[0] is template:  # the template itself is kept: ids stay unique
        return hit[1]
    ids, _ = _sector_chain_vertices(template, CHAIN, [closed])
    s = len(template.sides[0])
    n_vertices = CHAIN * (len(template.uv) - s) + (0 if closed else s)
    topo = patch_topology(template, ids.reshape(CHAIN, -1), n_vertices)
    if len(_SHORT_CHAINS) >= 16:
        _SHORT_CHAINS.clear()
    _SHORT_CHAINS[key] = (template, topo)
    return topo


def _count_distinct(labels: np.ndarray) -> int:
    """Number of distinct values of integer labels, without sorting them.

    The smallest and the largest label are there; only labels strictly between
    them are looked for (none for one or two regions, the usual case).
    """
    if len(labels) == 0:
        return 0
    lo, hi = int(labels.min()), int(labels.max())
    if hi - lo < 64:
        return min(2, hi - lo + 1) + sum(bool((labels == v).any()) for v in range(lo + 1, hi))
    if lo >= 0 and hi < 1 << 20:
        return int(np.count_nonzero(np.bincount(labels)))
    return len(np.unique(labels))


@dataclass(frozen=True, eq=False)
class TriMesh:
    """A triangle mesh ready for RWG basis functions.

    Attributes
    ----------
    points : (V, 3) float64
        Vertex coordinates in mm (z = 0 for our structures).
    triangles : (T, 3) int
        Vertex indices, counter-clockwise seen from +z.
    patch_ids : (T,) int
        The patch (or sector) each triangle came from.
    regions : (T,) int
        Region of each triangle (1: the patch or the inner ring, 2: the outer ring).
    n_patches : int
    mode : str
        ``"paper"``, ``"conforming"`` or ``"imported"``.
    tolerance : float
        The welding distance used (mm); 0 for imported meshes.
    patch_rects : (P, 4) float64 or None
        Axis-aligned patches (x0, y0, x1, y1) in paper mode, for the overlap ratio.
    ignored_cells : dict
        For imported meshes: cell type -> number of non-triangle cells skipped.
    params : MeshParams or None
        The parameters :func:`barymesh.build.build_mesh` built it from, with the
        ``subdivisions`` the sizing chose when ``frequency`` or ``max_edge`` is set;
        None for imported, cell and scaled meshes.
    min_angle_floor : float or None
        Conforming circular rings: the best smallest angle (degrees) their
        geometry allows (see :class:`barymesh.sectors.SectorPlan`).
    lattice : barymesh.cell.Lattice or None
        The lattice of the unit cell (or array) the mesh is, set by
        :func:`barymesh.cell.build_cell` and :func:`barymesh.cell.tile`; None otherwise.
        It gives :attr:`periodic_pairs`.

    Everything else (centroids, edges, RWG table, connectivity, quality) is
    derived on first use and cached.
    """

    points: np.ndarray
    triangles: np.ndarray
    patch_ids: np.ndarray
    regions: np.ndarray
    n_patches: int
    mode: str = "conforming"
    tolerance: float = 0.0
    patch_rects: np.ndarray | None = None
    ignored_cells: dict[str, int] = field(default_factory=dict)
    _template: PatchTemplate | None = field(default=None, repr=False)
    params: MeshParams | None = field(default=None, repr=False)
    min_angle_floor: float | None = None
    lattice: Any = field(default=None, repr=False)

    def __post_init__(self) -> None:
        pts = np.asarray(self.points, dtype=np.float64)
        if pts.ndim != 2 or pts.shape[1] not in (2, 3):
            raise ValueError(f"points must have shape (V, 3), got {pts.shape}")
        if pts.shape[1] == 2:
            pts = np.column_stack([pts, np.zeros(len(pts))])
        tri = np.asarray(self.triangles)
        if tri.ndim != 2 or tri.shape[1] != 3:
            raise ValueError(f"triangles must have shape (T, 3), got {tri.shape}")
        if len(tri) and (tri.min() < 0 or tri.max() >= len(pts)):
            raise ValueError(
                f"triangles refer to vertex {int(tri.max())} or {int(tri.min())}, "
                f"but there are {len(pts)} vertices"
            )
        put = object.__setattr__
        put(self, "points", _frozen(pts))
        put(self, "triangles", _frozen(tri.astype(INDEX, copy=False)))
        for name in ("patch_ids", "regions"):
            arr = np.asarray(getattr(self, name)).astype(INDEX, copy=False)
            if arr.shape != (len(tri),):
                raise ValueError(f"{name} must have shape ({len(tri)},), got {arr.shape}")
            put(self, name, _frozen(arr))

    # -- geometry ----------------------------------------------------------

    @property
    def n_vertices(self) -> int:
        return len(self.points)

    @property
    def n_triangles(self) -> int:
        return len(self.triangles)

    @cached_property
    def _columns(self) -> list[np.ndarray]:
        """Contiguous copies of the x and y columns of the points, and of z unless all zero.

        Gathers from a 1-D column are much faster than from a column of the (V, 3)
        array; centroids, quality and lengths share these copies.
        """
        columns = [np.ascontiguousarray(self.points[:, a]) for a in (0, 1)]
        if self.points[:, 2].any():
            columns.append(np.ascontiguousarray(self.points[:, 2]))
        return columns

    @cached_property
    def centroids(self) -> np.ndarray:
        """(T, 3) float64 barycentres (Eqs. 25–26): the RWG quadrature points."""
        # block by block, coordinate by coordinate, corner by corner: no (T, 3, 3)
        # temporary, same rounding; a coordinate that is zero everywhere (z) stays zero
        out = np.zeros((self.n_triangles, 3))
        axes = [(a, x) for a, x in enumerate(self._columns) if x.any()]
        for lo in range(0, self.n_triangles, BLOCK):
            tri = self.triangles[lo : lo + BLOCK]
            corners = [tri[:, k].astype(np.intp) for k in range(3)]
            for axis, x in axes:
                c = x.take(corners[0])
                c += x.take(corners[1])
                c += x.take(corners[2])
                c /= 3.0
                out[lo : lo + BLOCK, axis] = c
        return _frozen(out)

    @cached_property
    def quality(self) -> TriangleQuality:
        """Areas, smallest angles and aspect ratios, computed together in one pass."""
        if "edge_lengths" in self.__dict__:  # already known (stats): sides from the edges
            q = triangle_quality(
                self.points,
                self.triangles,
                self._columns,
                self.edge_lengths,
                self.topology.triangle_edges,
            )
        else:
            q = triangle_quality(self.points, self.triangles, self._columns)
        return TriangleQuality(*(_frozen(a) for a in q))

    @property
    def areas(self) -> np.ndarray:
        """(T,) float64 triangle areas (mm²)."""
        return self.quality.areas

    @property
    def min_angles(self) -> np.ndarray:
        """(T,) float64 smallest angle of each triangle (degrees)."""
        return self.quality.min_angles_deg

    @property
    def aspect_ratios(self) -> np.ndarray:
        """(T,) float64 aspect ratio, 1 for an equilateral triangle."""
        return self.quality.aspect_ratios

    # -- topology ----------------------------------------------------------

    @cached_property
    def topology(self) -> EdgeTopology:
        """Edges and their incidence (see :class:`barymesh.topology.EdgeTopology`)."""
        t = self._template
        if t is None:
            return edge_topology(self.triangles, self.n_vertices)
        nv = len(t.uv)
        if self.n_vertices == self.n_patches * nv and self._unwelded_copies:
            local = patch_topology(t, np.arange(nv, dtype=INDEX)[None], nv)
            return copies_topology(local, self.n_patches, nv, len(t.triangles))
        chains = self._chain_arguments()
        if chains is None:
            return patch_topology(t, self._vertex_map, self.n_vertices)
        return chain_topology(*chains)

    def _chain_arguments(
        self,
    ) -> tuple[list[EdgeTopology], list[int], int, int, list[int]] | None:
        """(short chains, m_i, triangles and vertices per sector, vertices per chain) or None."""
        chains = self._sector_chains
        t = self._template
        if chains is None or t is None:
            return None
        ms, closed = chains
        s = len(t.sides[0])
        shorts = [_short_chain_topology(t, c) for c in closed]
        counts = [m * (len(t.uv) - s) + (0 if c else s) for m, c in zip(ms, closed, strict=True)]
        return shorts, list(ms), len(t.triangles), len(t.uv) - s, counts

    @cached_property
    def _unwelded_copies(self) -> bool:
        """Whether patch p's triangles use vertices p Nv … p Nv + Nv − 1 in template order.

        True for paper meshes whose patches share no vertex (nothing welded):
        their topology is the template's, copy after copy
        (:func:`barymesh.topology.copies_topology`). Checked on the vertex map,
        block by block.
        """
        t = self._template
        if t is None or self.n_patches == 0:
            return False
        nv = len(t.uv)
        if self.n_vertices != self.n_patches * nv or self.n_triangles != self.n_patches * len(
            t.triangles
        ):
            return False
        vmap = self._vertex_map
        rows = max(1, BLOCK // nv)
        local = np.arange(nv, dtype=INDEX)
        for lo in range(0, self.n_patches, rows):
            ids = vmap[lo : lo + rows]
            base = (np.arange(lo, lo + len(ids), dtype=INDEX) * INDEX(nv))[:, None]
            if not np.array_equal(ids - base, np.broadcast_to(local, ids.shape)):
                return False
        return True

    @cached_property
    def _sector_chains(self) -> tuple[tuple[int, ...], tuple[bool, ...]] | None:
        """(m_i, closed_i) per chain when the mesh is chains of sectors numbered by formula.

        A conforming ring's arc (closed, or ended by a slot) is a chain of m_i ≥
        :data:`barymesh.topology.CHAIN` sectors glued side 2 to side 0; rings and
        arcs may hold different numbers of sectors. The chains are read off the
        vertex map (where a sector's side 2 is not the next one's side 0, a chain
        ends; it is closed when its last side 2 is its first side 0), then the
        whole map is checked, every entry, against
        :func:`barymesh.structures._sector_chain_vertices` for those chains: only
        then does the topology repeat that of short chains
        (:func:`barymesh.topology.chain_topology`). None for anything else
        (touching rings, a chain shorter than ``CHAIN``, renumbered vertices,
        paper mode, imported meshes).
        """
        t = self._template
        n_p = self.n_patches
        if t is None or n_p < CHAIN or self.mode != "conforming":
            return None
        nv, nt = len(t.uv), len(t.triangles)
        side0, side2 = np.asarray(t.sides[0]), np.asarray(t.sides[2])
        s = len(side0)
        if self.n_triangles != n_p * nt or len(side2) != s:
            return None
        vmap = self._vertex_map
        glued = (vmap[:-1].take(side2, axis=1) == vmap[1:].take(side0, axis=1)).all(axis=1)
        starts = np.flatnonzero(np.r_[True, ~glued])
        if len(starts) > _MAX_CHAINS:
            return None
        ends = np.r_[starts[1:], n_p]
        ms = ends - starts
        if ms.min() < CHAIN:
            return None
        closed = (vmap[ends - 1].take(side2, axis=1) == vmap[starts].take(side0, axis=1)).all(1)
        ms, closed = tuple(int(m) for m in ms), tuple(bool(c) for c in closed)
        sizes = [m * (nv - s) + (0 if c else s) for m, c in zip(ms, closed, strict=True)]
        if self.n_vertices != sum(sizes):
            return None
        ids, _ = _sector_chain_vertices(t, list(ms), list(closed))
        if not np.array_equal(vmap.ravel(), ids):
            return None
        return ms, closed

    @property
    def _vertex_map(self) -> np.ndarray:
        """(P, Nv) int: global vertex of each template vertex of each patch."""
        corners = self.triangles.reshape(self.n_patches, -1)
        # the template's triangles cover all its vertices: recover the patch vertex
        # map by taking, for each local vertex, one triangle corner where it sits
        assert self._template is not None  # only meshes built from a template have the map
        _, where = np.unique(self._template.triangles.ravel(), return_index=True)
        return corners.take(where, axis=1)

    @property
    def edges(self) -> np.ndarray:
        """(E, 2) int vertex pairs of the unique edges."""
        return self.topology.edges

    @property
    def triangle_edges(self) -> np.ndarray:
        """(T, 3) int edge id of side k (vertex k to k + 1) of each triangle."""
        return self.topology.triangle_edges

    @property
    def edge_triangles(self) -> np.ndarray:
        """(E, 2) int the first two triangles on each edge, -1 where missing."""
        return self.topology.edge_triangles

    @property
    def interior_edges(self) -> np.ndarray:
        return self.topology.interior_edges

    @property
    def boundary_edges(self) -> np.ndarray:
        return self.topology.boundary_edges

    @property
    def junction_edges(self) -> np.ndarray:
        return self.topology.junction_edges

    @cached_property
    def edge_lengths(self) -> np.ndarray:
        """(E,) float64 edge lengths (mm)."""
        return _frozen(segment_lengths(self.points, self.edges, self._columns))

    @cached_property
    def rwg(self) -> RWGTable:
        """The RWG table: one row per interior edge (see :class:`barymesh.topology.RWGTable`)."""
        t = self._template
        if t is not None:  # repeated structures: rows of the topology, repeated as it is
            nv, nt = len(t.uv), len(t.triangles)
            if self._unwelded_copies:
                local = patch_topology(t, np.arange(nv, dtype=INDEX)[None], nv)
                return copies_rwg(local, self.n_patches, nv, nt, self.points, self._columns)
            chains = self._chain_arguments()
            if chains is not None:
                return chain_rwg(*chains, self.points, self._columns)
        return rwg_table(self.points, self.triangles, self.topology, self._columns)

    @cached_property
    def connectivity(self) -> sp.csr_matrix:
        """T x T symmetric 0/1 matrix of triangles sharing an edge (the paper's Eq. 27)."""
        t = self._template
        if t is not None:  # repeated structures: rows repeated as the edges are
            nv, nt = len(t.uv), len(t.triangles)
            if self._unwelded_copies:
                local = _adjacency_without_junctions(
                    nt, patch_topology(t, np.arange(nv, dtype=INDEX)[None], nv)
                )
                if local is not None:
                    return copies_adjacency(local, self.n_patches)
            chains = self._chain_arguments()
            if chains is not None:
                shorts = [_adjacency_without_junctions(CHAIN * nt, c) for c in chains[0]]
                present = [c for c in shorts if c is not None]
                if len(present) == len(shorts):
                    return chain_adjacency(present, chains[1], nt)
        return triangle_adjacency(self.n_triangles, self.topology)

    @cached_property
    def vertex_adjacency(self) -> sp.csr_matrix:
        """V x V symmetric 0/1 matrix of vertices joined by an edge."""
        return vertex_adjacency(self.n_vertices, self.edges)

    @cached_property
    def overlap_ratio(self) -> float | None:
        """1 − (area of the union of the patches) / (sum of patch areas), paper mode only."""
        if self.patch_rects is None or len(self.patch_rects) == 0:
            return None
        r = self.patch_rects
        total = float(((r[:, 2] - r[:, 0]) * (r[:, 3] - r[:, 1])).sum())
        return max(0.0, 1.0 - union_area(r) / total)

    def _copy_stats(self) -> dict[str, Any] | None:
        """Topology counts and quality aggregates of a mesh of unwelded translated copies.

        When no vertex is shared between patches and every patch is the first one
        translated (checked: each patch's coordinates relative to its first vertex
        match the first patch's to ``_COPY_TOLERANCE`` of the shortest side, counting
        the rounding of the coordinates), the edges are the template's, patch by
        patch, and the edge lengths and triangle quality are the first patch's, so
        one patch is measured instead of all. Returns None when that does not hold
        (welded, deformed or imported meshes): :meth:`stats` then measures every
        triangle. The per-triangle arrays are not made; they stay lazy.
        """
        t = self._template
        n_p = self.n_patches
        if t is None or n_p == 0:
            return None
        nv, nt = len(t.uv), len(t.triangles)
        if self.n_vertices != n_p * nv or self.n_triangles != n_p * nt:
            return None
        # the patch vertex map, as the template topology recovers it: unwelded means
        # patch p owns vertices p Nv ... p Nv + Nv - 1 in template order
        vmap = self._vertex_map
        rows = max(1, BLOCK // nv)
        local = np.arange(nv, dtype=INDEX)
        # reductions gathered into arrays, so that a NaN anywhere makes the check fail
        extent = np.max([[x.max(), -x.min()] for x in self._columns])
        deviations = []
        columns = [x.reshape(n_p, nv) for x in self._columns]
        firsts = [x[0] - x[0, 0] for x in columns]
        for lo in range(0, n_p, rows):
            ids = vmap[lo : lo + rows]
            expect = local + (np.arange(lo, lo + len(ids), dtype=INDEX) * INDEX(nv))[:, None]
            if not np.array_equal(ids, expect):
                return None
            for x, first in zip(columns, firsts, strict=True):
                block = x[lo : lo + rows]
                rel = block - block[:, :1]
                rel -= first
                deviations += [rel.max(), -rel.min()]
        pts = self.points[:nv]
        lengths = segment_lengths(pts, t.edges)
        shortest = float(lengths.min()) if len(lengths) else 0.0
        slack = np.max(deviations) + 2.0 * np.finfo(np.float64).eps * extent
        if not (shortest > 0 and slack <= _COPY_TOLERANCE * shortest):
            return None
        q = triangle_quality(pts, t.triangles)
        valence = np.bincount(t.valence, minlength=3)
        return {
            "edges": n_p * len(t.edges),
            "interior_edges": n_p * int(valence[2]),
            "boundary_edges": n_p * int(valence[1]),
            "junction_edges": n_p * int(valence[3:].sum()),
            "min_edge": shortest,
            "max_edge": float(lengths.max()),
            "min_angle_deg": float(q.min_angles_deg.min()),
            "max_aspect_ratio": float(q.aspect_ratios.max()),
            "area": n_p * float(q.areas.sum()),
        }

    def _sector_edge_counts(self) -> np.ndarray | None:
        """Edge counts by valence of closed rings of sectors glued side 2 to side 0.

        A conforming ring without a slot (and not touching the other ring) is a
        closed chain of sectors (m_i in ring i); when the vertex map is exactly those
        chains', ring after ring (checked against
        :func:`barymesh.structures._sector_chain_vertices`, every m_i ≥ 3), every sector
        adds the same edges, so the counts are Σ m_i / 3 times those of a closed
        chain of three sectors: the counts of
        :func:`barymesh.topology.patch_edge_counts` without sorting the glued edges.
        Rings of at least :data:`barymesh.topology.CHAIN` sectors, closed or split, whose
        numbering the build has already checked (``_sector_chains``, cached) add up
        the counts of their short chains' sectors instead, as
        :func:`barymesh.topology.chain_topology` repeats them.
        Returns None otherwise (touching, paper or imported rings).
        """
        chains = self._chain_arguments() if "_sector_chains" in self.__dict__ else None
        if chains is not None:
            shorts, ms, n_tri = chains[:3]
            counts = np.zeros(4, dtype=np.int64)
            for short, m in zip(shorts, ms, strict=True):
                cut = np.searchsorted(short.edge_triangles[:, 0] // n_tri, np.arange(CHAIN + 1))
                for lo, hi, times in (
                    (0, MIDDLE, 1),
                    (MIDDLE, MIDDLE + 1, m - CHAIN + 1),
                    (MIDDLE + 1, CHAIN, 1),
                ):
                    part = np.bincount(short.valence[cut[lo] : cut[hi]], minlength=4)
                    counts[: len(part)] += times * part[:4]
            return counts[: max(3, len(np.trim_zeros(counts, "b")))]  # as a bincount
        t = self._template
        n_p = self.n_patches
        if t is None or n_p == 0 or self.mode != "conforming":
            return None
        nv, nt = len(t.uv), len(t.triangles)
        if self.n_triangles != n_p * nt:
            return None
        ring_of_patch = self.regions[::nt]
        starts = np.flatnonzero(np.r_[True, ring_of_patch[1:] != ring_of_patch[:-1]])
        n_rings = len(starts)
        sectors = np.diff(np.r_[starts, n_p]).tolist()  # sectors of each ring
        if min(sectors) < 3:
            return None
        s = len(t.sides[0])
        if self.n_vertices != n_p * (nv - s):
            return None
        ids, _ = _sector_chain_vertices(t, sectors, [True] * n_rings)
        if not np.array_equal(self._vertex_map.ravel(), ids):
            return None
        chain3, _ = _sector_chain_vertices(t, 3, [True])
        counts3 = patch_edge_counts(t.edges, t.valence, chain3.reshape(3, nv), 3 * (nv - s))
        if (counts3 % 3).any():  # not one sector's worth three times: count them all
            return None
        return counts3 // 3 * np.int64(n_p)

    def _measured_stats(self) -> dict[str, Any]:
        """Topology counts and quality aggregates from every edge and triangle.

        A mesh of patch copies whose edges and quality are not known yet counts its
        edges without making them (:func:`barymesh.topology.patch_edge_counts`) and
        reduces the quality block by block (:func:`barymesh.quality.quality_summary`,
        whose side range is the edge range); the per-triangle arrays stay lazy.
        Other meshes find their edges and use the cached per-triangle quality.
        """
        t = self._template
        known = "topology" in self.__dict__ or "quality" in self.__dict__
        if t is not None and not known:
            counts = self._sector_edge_counts()
            if counts is None:
                counts = patch_edge_counts(t.edges, t.valence, self._vertex_map, self.n_vertices)
            cells = (len(t.sides[0]) - 1, len(t.sides[1]) - 1)  # n x n, or a sector's n x n_v
            diagonal = lattice_diagonal(t.triangles, len(t.uv), cells)
            if diagonal is not None and len(self._columns) == 2:  # planar grid patches
                s = lattice_quality_summary(self._columns, self._vertex_map, diagonal, cells)
            else:
                s = quality_summary(self.points, self.triangles, self._columns)
            summary = s.min_angle_deg, s.max_aspect_ratio, s.area
            side_range = s.shortest_side, s.longest_side
        else:
            counts = np.bincount(self.topology.valence, minlength=3)  # one pass, not three
            lengths = self.edge_lengths
            side_range = (lengths.min(), lengths.max()) if len(lengths) else (0.0, 0.0)
            empty = self.n_triangles == 0
            summary = (
                0.0 if empty else self.min_angles.min(),
                0.0 if empty else self.aspect_ratios.max(),
                self.areas.sum(),
            )
        return {
            "edges": int(counts.sum()),
            "interior_edges": int(counts[2]),
            "boundary_edges": int(counts[1]),
            "junction_edges": int(counts[3:].sum()),
            "min_edge": float(side_range[0]),
            "max_edge": float(side_range[1]),
            "min_angle_deg": float(summary[0]),
            "max_aspect_ratio": float(summary[1]),
            "area": float(summary[2]),
        }

    @cached_property
    def periodic_pairs(self) -> Any:
        """The cell-boundary edges and their partners on the opposite side.

        A :class:`barymesh.cell.PeriodicPairs` for the mesh of a unit cell
        (:attr:`lattice` set): ``edges`` (K, 2) vertex pairs on the boundary,
        ``partners``, ``matched`` and the ``unmatched_edges`` (what scuff-em
        and the ``$Periodic`` section of an msh file need); None for a mesh
        that is not a cell's.
        """
        if self.lattice is None:
            return None
        from .cell.periodic import periodic_pairs

        return periodic_pairs(self, self.lattice, self.tolerance)

    def stats(self) -> dict[str, Any]:
        """Counts and quality figures as a plain, JSON-ready dict.

        Keys: ``patches``, ``vertices``, ``triangles``, ``edges``,
        ``interior_edges`` (= RWG unknowns), ``boundary_edges``,
        ``junction_edges``, ``min_edge``, ``max_edge`` (mm), ``min_angle_deg``,
        ``max_aspect_ratio``, ``area`` (mm², overlaps counted twice),
        ``euler_characteristic`` (V − E + F), ``regions``, for conforming
        circular rings ``min_angle_floor_deg`` (the best smallest angle their
        track width, sector bound and slot allow the construction: below 30°,
        the geometry is to blame), in paper mode ``overlap_ratio``; for
        imported meshes ``ignored_cells``; for meshes sized by ``frequency`` or
        ``max_edge`` the keys of :func:`barymesh.sizing.sizing_stats`.
        """
        known = "topology" in self.__dict__ and "quality" in self.__dict__
        measured = None if known else self._copy_stats()
        if measured is None:
            measured = self._measured_stats()
        out: dict[str, Any] = {
            "patches": int(self.n_patches),
            "vertices": int(self.n_vertices),
            "triangles": int(self.n_triangles),
            **measured,  # edges ... area, in the order of the docstring
            "euler_characteristic": int(self.n_vertices - measured["edges"] + self.n_triangles),
            "regions": _count_distinct(self.regions),
        }
        if self.min_angle_floor is not None:
            out["min_angle_floor_deg"] = float(self.min_angle_floor)
        if self.mode == "paper":
            out["overlap_ratio"] = self.overlap_ratio
        if self.ignored_cells:
            out["ignored_cells"] = dict(self.ignored_cells)
        if self.params is not None and self.params.sized:
            out.update(sizing_stats(self, measured["max_edge"]))
        return out

    def scaled(self, factor: float) -> TriMesh:
        """A copy with coordinates multiplied by ``factor`` (for unit conversion)."""
        rects = None if self.patch_rects is None else self.patch_rects * factor
        return TriMesh(
            self.points * factor,
            self.triangles,
            self.patch_ids,
            self.regions,
            self.n_patches,
            self.mode,
            self.tolerance * factor,
            rects,
            dict(self.ignored_cells),
            self._template,
            min_angle_floor=self.min_angle_floor,  # params stays None (the next field)
        )

"""The finished mesh: an immutable bundle of arrays with lazily derived topology."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np

from .overlap import union_area
from .quality import TriangleQuality, cell_figures, triangle_quality
from .repeat import (
    Repetition,
    copy_slack,
    patch_centroids,
    repeated_connectivity,
    repeated_rwg,
    repeated_topology,
)
from .stats import mesh_stats
from .topology import (
    BLOCK,
    INDEX,
    EdgeTopology,
    RWGTable,
    edge_topology,
    rwg_table,
    segment_lengths,
    triangle_adjacency,
    vertex_adjacency,
)

if TYPE_CHECKING:
    import meshio
    import scipy.sparse as sp

    from .params import MeshParams


def _frozen(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a)
    a.flags.writeable = False
    return a


#: Methods moved out of :class:`TriMesh`, and where they are now.
_MOVED = {
    "to_pyvista": (
        "use barymesh.app.view.polydata.to_pyvista(mesh) (the app extra), "
        "or pyvista.from_meshio(mesh.to_meshio())"
    ),
}


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
    repetition : barymesh.repeat.Repetition or None
        How the mesh repeats one patch template (the template, the vertex map,
        the kind of repetition), recorded by the build; None for a mesh that is
        not copies of one template (imported meshes, a single triangle). It
        chooses the repeated paths of the derived topology, RWG table,
        connectivity and statistics; the results are the general paths', which
        a mesh without one takes.

    Provenance (how the mesh was made; reported, never used to choose an algorithm):

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
    repetition: Repetition | None = field(default=None, repr=False)
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
        # the reductions of tri.min() and tri.max(), without their Python frames
        if len(tri) and (
            np.minimum.reduce(tri, axis=None) < 0 or np.maximum.reduce(tri, axis=None) >= len(pts)
        ):
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
        rep = self.repetition
        if rep is not None:
            if not isinstance(rep, Repetition):
                raise TypeError(f"repetition must be a Repetition, got {type(rep).__name__}")
            per_patch = len(rep.template.triangles)
            if rep.n_patches != self.n_patches or len(tri) != rep.n_patches * per_patch:
                raise ValueError(
                    f"repetition has {rep.n_patches} patches of {per_patch} triangles, but the "
                    f"mesh has {self.n_patches} patches and {len(tri)} triangles"
                )
            if rep.vertex_map.size and np.maximum.reduce(rep.vertex_map, axis=None) >= len(pts):
                raise ValueError(
                    f"repetition refers to vertex {int(rep.vertex_map.max())}, "
                    f"but there are {len(pts)} vertices"
                )

    # -- geometry ----------------------------------------------------------

    @property
    def n_vertices(self) -> int:
        return len(self.points)

    @property
    def n_triangles(self) -> int:
        return len(self.triangles)

    @cached_property
    def columns(self) -> list[np.ndarray]:
        """Contiguous (V,) copies of the x and y columns of the points, and of z unless all zero.

        Gathers from a 1-D column are much faster than from a column of the (V, 3)
        array; centroids, quality and lengths share these copies. A build whose layout
        wrote the points (unwelded paper patches) hands over the copies it wrote with
        them, read-only.
        """
        columns = [np.ascontiguousarray(self.points[:, a]) for a in (0, 1)]
        if self.points[:, 2].any():
            columns.append(np.ascontiguousarray(self.points[:, 2]))
        return columns

    @cached_property
    def translation_slack(self) -> float | None:
        """For unwelded copies of one patch (repetition kind ``"copies"``): how far
        they are from translations of the first (:func:`barymesh.repeat.copies.copy_slack`).

        One pass over the points, found once and shared by the invariant check
        (:func:`barymesh.check.check_mesh`, which then need not read every
        triangle) and :meth:`stats` (which then measures one patch); None for
        other meshes.
        """
        rep = self.repetition
        if rep is None or rep.kind != "copies":
            return None
        return copy_slack(len(rep.template.uv), self.columns)

    @cached_property
    def centroids(self) -> np.ndarray:
        """(T, 3) float64 barycentres (Eqs. 25–26): the RWG quadrature points."""
        rep = self.repetition
        if rep is not None:  # patch by patch: each patch's vertices read once, same sums
            return _frozen(
                patch_centroids(
                    self.columns, rep.vertex_map, rep.template.triangles, rep.kind == "copies"
                )
            )
        # block by block, coordinate by coordinate, corner by corner: no (T, 3, 3)
        # temporary, same rounding; a coordinate that is zero everywhere (z) stays zero
        out = np.zeros((self.n_triangles, 3))
        axes = [(a, x) for a, x in enumerate(self.columns) if x.any()]
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
        q = triangle_quality(self.points, self.triangles, self.columns)
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
        """Edges and their incidence (see :class:`barymesh.topology.EdgeTopology`).

        A mesh with a :attr:`repetition` takes its repeated path
        (:func:`barymesh.repeat.repeated_topology`), any other the general edge
        finder; both give the same arrays.
        """
        if self.repetition is None:
            return edge_topology(self.triangles, self.n_vertices)
        return repeated_topology(self.repetition, self.n_vertices)

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
        return _frozen(segment_lengths(self.points, self.edges, self.columns))

    @cached_property
    def rwg(self) -> RWGTable:
        """The RWG table: one row per interior edge (see :class:`barymesh.topology.RWGTable`)."""
        if self.repetition is not None:  # copies and chains: rows repeated as the edges are
            table = repeated_rwg(self.repetition, self.points, self.columns)
            if table is not None:
                return table
        return rwg_table(self.points, self.triangles, self.topology, self.columns)

    @cached_property
    def connectivity(self) -> sp.csr_matrix:
        """T x T symmetric 0/1 matrix of triangles sharing an edge (the paper's Eq. 27)."""
        if self.repetition is not None:  # copies and chains: rows repeated as the edges are
            matrix = repeated_connectivity(self.repetition)
            if matrix is not None:
                return matrix
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
        return mesh_stats(self)

    # -- hand-offs to other libraries ---------------------------------------

    def to_meshio(self, wavelength: float | None = None) -> meshio.Mesh:
        """The mesh as a :class:`meshio.Mesh`, to write any format meshio knows.

        Parameters
        ----------
        wavelength : float, optional
            λ in mm: the cell data also get ``edge_wavelength``.

        Returns
        -------
        meshio.Mesh
            Points (V, 3) in mm, one ``triangle`` block (T, 3) int64, and as cell data
            the per-triangle figures of :func:`barymesh.quality.cell_figures`
            (``patch_id``, ``region``, ``area`` in mm², ``min_angle``, ``aspect_ratio``).
            :func:`barymesh.io.write_mesh` writes files with units, tags and atomically.

        Examples
        --------
        >>> from barymesh import MeshParams, build_mesh
        >>> m = build_mesh(MeshParams(structure="patch", subdivisions=2)).to_meshio()
        >>> m.cells[0].data.shape, sorted(m.cell_data)
        ((8, 3), ['area', 'aspect_ratio', 'min_angle', 'patch_id', 'region'])
        """
        import meshio

        data = cell_figures(self, wavelength)
        return meshio.Mesh(
            np.array(self.points, dtype=np.float64),
            [("triangle", self.triangles.astype(np.int64))],
            cell_data={name: [values] for name, values in data.items()},
        )

    def __getattr__(self, name: str) -> Any:
        # (called only when the normal lookup failed) hand-offs that left the core, which
        # never imports VTK, say where they went
        if name in _MOVED:
            raise AttributeError(f"TriMesh.{name} is gone from the core: {_MOVED[name]}")
        if hasattr(type(self), name):  # a property raised AttributeError: let it show
            return object.__getattribute__(self, name)
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def scaled(self, factor: float) -> TriMesh:
        """A copy with coordinates multiplied by ``factor`` (for unit conversion).

        What still holds is kept: the :attr:`repetition` (it holds no coordinates),
        the ``min_angle_floor`` (angles do not scale), the patch rectangles, the
        tolerance and the :attr:`lattice` scaled with the points (None when the
        scaled vectors are no lattice, for a factor of 0). ``params`` becomes
        None: its lengths are the unscaled mesh's, and a build from them would
        not give this mesh.
        """
        rects = None if self.patch_rects is None else self.patch_rects * factor
        lattice = self.lattice
        if lattice is not None:
            try:
                lattice = dataclasses.replace(
                    lattice,
                    a1=tuple(factor * a for a in lattice.a1),
                    a2=tuple(factor * a for a in lattice.a2),
                )
            except ValueError:  # a factor no lattice can take (0, or out of range): dropped
                lattice = None
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
            self.repetition,
            min_angle_floor=self.min_angle_floor,
            lattice=lattice,
        )

"""What is under the cursor: the triangle, edge or vertex of a mesh at a point, in mm.

Pure numpy/scipy, no Qt and no rendering, so a hover stays cheap at any mesh size:
:class:`MeshLocator` is built once per mesh (a k-d tree of the triangle centroids, in a
worker thread for big meshes) and then answers a query with a handful of candidate
triangles, never a pass over the whole mesh.

A query point is a point of the mesh's plane (for the flat meshes of this program, the
camera ray meets the plane ``z = z0``); for a curved imported mesh the window passes the
point VTK's cell picker found.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from barymesh import TriMesh

#: Candidate triangles looked at per query (nearest centroids).
CANDIDATES = 12
#: A vertex or an edge is "under the cursor" within this many pixels of it.
SNAP_PIXELS = 6.0


@dataclass(frozen=True)
class Hit:
    """One element under the cursor.

    Attributes
    ----------
    kind : {"vertex", "edge", "triangle"}
    index : int
        Row of ``mesh.points``, ``mesh.edges`` or ``mesh.triangles``.
    triangle : int
        The triangle the cursor is over (for a vertex or an edge: the one it was found in).
    point : (3,) float64
        The cursor's point on the mesh, in mm.
    """

    kind: str
    index: int
    triangle: int
    point: np.ndarray


def decimals_for(pixels_per_mm: float) -> int:
    """Decimals of a coordinate in mm that one pixel still resolves (0 … 6).

    >>> decimals_for(50.0), decimals_for(0.5), decimals_for(5000.0)
    (2, 0, 4)
    """
    if not np.isfinite(pixels_per_mm) or pixels_per_mm <= 0:
        return 3
    return int(np.clip(np.ceil(np.log10(pixels_per_mm)), 0, 6))


def fmt_point(point: np.ndarray, decimals: int, with_z: bool = False) -> str:
    """``"(1.25, -3.00) mm"``: a point in mm with ``decimals`` decimals."""
    p = np.asarray(point, dtype=np.float64)
    parts = p[:3] if with_z else p[:2]
    return "(" + ", ".join(f"{v:.{decimals}f}" for v in parts) + ") mm"


def ray_plane_point(origin: np.ndarray, direction: np.ndarray, z0: float) -> np.ndarray | None:
    """Where the ray ``origin + t · direction`` meets the plane ``z = z0`` (None if parallel)."""
    o = np.asarray(origin, dtype=np.float64)
    d = np.asarray(direction, dtype=np.float64)
    if abs(d[2]) < 1e-12:
        return None
    t = (z0 - o[2]) / d[2]
    return o + t * d


class MeshLocator:
    """Find the triangle, edge or vertex of ``mesh`` at a point (see the module docstring).

    Parameters
    ----------
    mesh : TriMesh
    """

    def __init__(self, mesh: TriMesh) -> None:
        self.mesh = mesh
        pts = np.asarray(mesh.points, dtype=np.float64)
        self.points = pts
        self.triangles = np.asarray(mesh.triangles)
        n = len(self.triangles)
        if len(pts):
            lo, hi = pts.min(axis=0), pts.max(axis=0)
        else:
            lo = hi = np.zeros(3)
        self.size = float(max(hi[0] - lo[0], hi[1] - lo[1], 1e-12))
        #: a flat mesh (every point at one height): queries may come from a ray–plane cut
        self.planar = bool(hi[2] - lo[2] <= 1e-9 * self.size)
        self.z0 = float(lo[2])
        # imported here, off the window's start-up: scipy.spatial pulls in scipy.special
        # and scipy.sparse (a third of a second), and the first lookup runs in a worker
        from scipy.spatial import cKDTree

        self.tree = cKDTree(np.asarray(mesh.centroids)[:, :2]) if n else None
        self.triangle_edges = np.asarray(mesh.triangle_edges) if n else np.empty((0, 3), int)
        self.edges = np.asarray(mesh.edges) if n else np.empty((0, 2), int)
        self.rwg_edges = np.asarray(mesh.rwg.edge) if n else np.empty(0, int)

    # -- queries ---------------------------------------------------------------------

    def triangle_at(self, point: np.ndarray) -> int | None:
        """The triangle whose xy projection holds ``point`` (None off the mesh).

        Of the :data:`CANDIDATES` triangles with the nearest centroids, the one with the
        largest smallest barycentric coordinate (all ≥ 0 means inside, a tolerance of
        1e-9 allows a point on an edge).
        """
        if self.tree is None:
            return None
        p = np.asarray(point, dtype=np.float64)[:2]
        k = min(CANDIDATES, len(self.triangles))
        _, ids = self.tree.query(p, k=k)
        ids = np.atleast_1d(ids)
        ids = ids[ids < len(self.triangles)]
        corners = self.points[self.triangles[ids]][:, :, :2]  # (k, 3, 2)
        a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
        v0, v1, v2 = b - a, c - a, p - a
        d00 = np.einsum("ij,ij->i", v0, v0)
        d01 = np.einsum("ij,ij->i", v0, v1)
        d11 = np.einsum("ij,ij->i", v1, v1)
        d20 = np.einsum("ij,ij->i", v2, v0)
        d21 = np.einsum("ij,ij->i", v2, v1)
        denom = d00 * d11 - d01 * d01
        ok = np.abs(denom) > 1e-300
        with np.errstate(divide="ignore", invalid="ignore"):
            v = np.where(ok, (d11 * d20 - d01 * d21) / denom, -np.inf)
            w = np.where(ok, (d00 * d21 - d01 * d20) / denom, -np.inf)
        u = 1.0 - v - w
        worst = np.minimum(np.minimum(u, v), w)
        best = int(np.argmax(worst))
        return int(ids[best]) if worst[best] >= -1e-9 else None

    def hit(self, point: np.ndarray, tolerance: float, triangle: int | None = None) -> Hit | None:
        """The element at ``point``: a vertex or an edge within ``tolerance`` mm of it,
        else the triangle itself. ``triangle`` skips the search (a picked triangle)."""
        p = np.asarray(point, dtype=np.float64)
        t = self.triangle_at(p) if triangle is None else int(triangle)
        if t is None:  # off the mesh: a vertex or an edge may still be within reach
            t = self._nearest_triangle(p)
            if t is None:
                return None
            found = self.hit(p, tolerance, t)
            return found if found is not None and found.kind != "triangle" else None
        if not 0 <= t < len(self.triangles):
            return None
        corners = self.triangles[t]
        dist = np.linalg.norm(self.points[corners] - p, axis=1)
        if dist.min() <= tolerance:
            return Hit("vertex", int(corners[np.argmin(dist)]), t, p)
        edges = self.triangle_edges[t]
        ends = self.points[self.edges[edges]]  # (3, 2, 3)
        a, b = ends[:, 0], ends[:, 1]
        ab = b - a
        s = np.clip(
            np.einsum("ij,ij->i", p - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300),
            0.0,
            1.0,
        )
        d_edge = np.linalg.norm(a + s[:, None] * ab - p, axis=1)
        if d_edge.min() <= tolerance:
            return Hit("edge", int(edges[np.argmin(d_edge)]), t, p)
        return Hit("triangle", t, t, p)

    def _nearest_triangle(self, p: np.ndarray) -> int | None:
        """The triangle with the nearest corner to ``p`` among the candidates."""
        if self.tree is None:
            return None
        k = min(CANDIDATES, len(self.triangles))
        _, ids = self.tree.query(p[:2], k=k)
        ids = np.atleast_1d(ids)
        ids = ids[ids < len(self.triangles)]
        corners = self.points[self.triangles[ids]][:, :, :2]  # (k, 3, 2)
        dist = np.linalg.norm(corners - p[:2], axis=2).min(axis=1)
        return int(ids[np.argmin(dist)])

    # -- text ------------------------------------------------------------------------

    def describe(self, hit: Hit, decimals: int = 3) -> str:
        """One line for the readout: the element, its numbers and coordinates in mm."""
        m = self.mesh
        z = not self.planar
        if hit.kind == "vertex":
            return f"vertex {hit.index} at {fmt_point(self.points[hit.index], decimals, z)}"
        if hit.kind == "edge":
            a, b = (int(v) for v in self.edges[hit.index])
            length = float(np.linalg.norm(self.points[a] - self.points[b]))
            row = int(np.searchsorted(self.rwg_edges, hit.index))
            if row < len(self.rwg_edges) and self.rwg_edges[row] == hit.index:
                kind = f"interior, RWG unknown n = {row}"
            else:
                valence = int(m.topology.valence[hit.index])
                kind = "boundary" if valence == 1 else f"junction of {valence} triangles"
            return f"edge {hit.index} ({a}–{b}), l = {length:.{decimals + 1}g} mm, {kind}"
        t = hit.index
        centroid = np.asarray(m.centroids[t])
        return (
            f"triangle {t} (patch {int(m.patch_ids[t])}), "
            f"A = {float(m.areas[t]):.4g} mm², centroid {fmt_point(centroid, decimals, z)}"
        )

    def summary(self, hit: Hit, decimals: int = 3) -> str:
        """A short line for a selected element: what it is and where, in mm.

        ``"vertex 7 at (2.50, 5.00) mm"``, ``"edge 12 (3–4), midpoint (1.25, 0.00) mm"``,
        ``"triangle 21, centroid (3.33, 1.67) mm"`` (z too for a curved mesh).
        """
        z = not self.planar
        if hit.kind == "vertex":
            return f"vertex {hit.index} at {fmt_point(self.points[hit.index], decimals, z)}"
        if hit.kind == "edge":
            a, b = (int(v) for v in self.edges[hit.index])
            middle = 0.5 * (self.points[a] + self.points[b])
            return f"edge {hit.index} ({a}–{b}), midpoint {fmt_point(middle, decimals, z)}"
        centroid = np.asarray(self.mesh.centroids[hit.index])
        return f"triangle {hit.index}, centroid {fmt_point(centroid, decimals, z)}"


def distance_text(a: np.ndarray, b: np.ndarray, decimals: int = 3) -> str:
    """``"|AB| = 2.500 mm (Δx = 2.500, Δy = 0.000 mm)"`` for the measure tool."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    d = b - a
    text = (
        f"|AB| = {float(np.linalg.norm(d)):.{decimals}f} mm "
        f"(Δx = {d[0]:.{decimals}f}, Δy = {d[1]:.{decimals}f}"
    )
    if abs(d[2]) > 1e-12:
        text += f", Δz = {d[2]:.{decimals}f}"
    return text + " mm)"

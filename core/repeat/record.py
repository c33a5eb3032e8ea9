"""The record of a mesh's repeated structure, and the repeated paths chosen by it.

A mesh built from patches is copies of one template glued by a vertex map; the
build keeps that map and finds, once, which kind of repetition it is
(:meth:`Repetition.of`). The derived topology, RWG table and connectivity then
take the repeated path of that kind; a mesh without a record takes the general
paths of :mod:`barymesh.topology`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

import numpy as np

from ..subdivision import PatchTemplate
from ..topology import INDEX, EdgeTopology, RWGTable, adjacency_without_junctions
from .chains import CHAIN, chain_adjacency, chain_parts, chain_rwg, chain_topology, find_chains
from .copies import (
    copies_adjacency,
    copies_rwg,
    copies_topology,
    is_unwelded_copies,
    template_adjacency,
    template_plan,
    template_topology,
)
from .patches import patch_topology, patch_triangles

if TYPE_CHECKING:
    import scipy.sparse as sp

#: The kinds of repetition: see :class:`Repetition`.
Kind = Literal["copies", "chains", "patches"]


@dataclass(frozen=True, eq=False)
class Repetition:
    """How a mesh repeats one patch template: the template, the vertex map, the kind.

    Triangle p Nt + t of the mesh is ``vertex_map[p, template.triangles[t]]``.
    Made by :meth:`of` (which finds the kind) or :meth:`of_triangles`; it holds
    no coordinates, so it stays true when the mesh is scaled or moved.

    Attributes
    ----------
    template : PatchTemplate
        The patch (or sector) every patch is a copy of.
    vertex_map : (P, Nv) int
        Global vertex of each local vertex of each patch (read-only).
    kind : {"copies", "chains", "patches"}
        ``"copies"``: patch p owns vertices p Nv … p Nv + Nv − 1 in template
        order (:mod:`barymesh.repeat.copies`); ``"chains"``: chains of sectors
        numbered by formula, each at least :data:`barymesh.repeat.chains.CHAIN`
        long (:mod:`barymesh.repeat.chains`); ``"patches"``: any other vertex
        map (:mod:`barymesh.repeat.patches`).
    sectors : tuple of int
        Sectors of each chain (kind ``"chains"``; empty otherwise).
    closed : tuple of bool
        Whether each chain closes on itself (kind ``"chains"``; empty otherwise).
    """

    template: PatchTemplate
    vertex_map: np.ndarray
    kind: Kind = "patches"
    sectors: tuple[int, ...] = ()
    closed: tuple[bool, ...] = ()

    @classmethod
    def of(cls, template: PatchTemplate, vertex_map: np.ndarray, n_vertices: int) -> Repetition:
        """The record of copies of ``template`` on ``vertex_map`` in a mesh of ``n_vertices``.

        Parameters
        ----------
        template : PatchTemplate
        vertex_map : (P, Nv) int
        n_vertices : int
            Vertices of the whole mesh.

        Raises
        ------
        ValueError
            When the map's shape is not (P, Nv) or it names a vertex outside
            0 … ``n_vertices`` − 1.
        """
        nv = len(template.uv)
        vmap = np.ascontiguousarray(vertex_map, dtype=INDEX)
        if vmap.ndim != 2 or vmap.shape[1] != nv:
            raise ValueError(
                f"vertex_map must have shape (P, {nv}) for a template of {nv} vertices, "
                f"got {np.shape(vertex_map)}"
            )
        if vmap.size and (vmap.min() < 0 or vmap.max() >= n_vertices):
            raise ValueError(
                f"vertex_map refers to vertex {int(vmap.max())} or {int(vmap.min())}, "
                f"but there are {n_vertices} vertices"
            )
        vmap.flags.writeable = False
        if len(vmap) and n_vertices == vmap.size and is_unwelded_copies(vmap):
            return cls(template, vmap, "copies")
        chains = find_chains(template, vmap, n_vertices)
        if chains is not None:
            return cls(template, vmap, "chains", *chains)
        return cls(template, vmap, "patches")

    @classmethod
    def unwelded(cls, template: PatchTemplate, n_patches: int) -> Repetition:
        """The record of ``n_patches`` copies of ``template`` that share no vertex.

        Patch p's local vertex l is vertex p Nv + l: kind ``"copies"`` by construction,
        without :meth:`of`'s pass over the map (for layouts that welded nothing).
        """
        vmap = np.arange(n_patches * len(template.uv), dtype=INDEX).reshape(n_patches, -1)
        vmap.flags.writeable = False
        return cls(template, vmap, "copies")

    @classmethod
    def of_triangles(
        cls, template: PatchTemplate, triangles: np.ndarray, n_vertices: int
    ) -> Repetition:
        """The record of a mesh whose triangles are copies of ``template``'s, patch after patch.

        For meshes put together without their vertex map (unit cells, arrays of
        cells): the map is read back from the triangles, one corner for each
        local vertex.

        Raises
        ------
        ValueError
            When the triangles are not ``len(template.triangles)`` per patch, each
            patch's the template's on one vertex map.
        """
        nt = len(template.triangles)
        tri = np.asarray(triangles)
        if nt == 0 or len(tri) % nt:
            raise ValueError(
                f"{len(tri)} triangles are not whole copies of a template of {nt} triangles"
            )
        corners = tri.reshape(len(tri) // nt, -1)
        # the template's triangles cover all its vertices: for each local vertex, one
        # triangle corner where it sits
        _, where = np.unique(template.triangles.ravel(), return_index=True)
        vertex_map = corners.take(where, axis=1)
        if not np.array_equal(patch_triangles(template, vertex_map), tri):
            raise ValueError("the triangles are not copies of the template's on one vertex map")
        return cls.of(template, vertex_map, n_vertices)

    @property
    def n_patches(self) -> int:
        return len(self.vertex_map)


def repeated_topology(rep: Repetition, n_vertices: int) -> EdgeTopology:
    """The mesh's topology by the path of ``rep.kind``; equals the general edge finder's."""
    t = rep.template
    if rep.kind == "copies":
        local = template_topology(t)
        return copies_topology(local, rep.n_patches, len(t.uv), len(t.triangles), template_plan(t))
    if rep.kind == "chains":
        return chain_topology(chain_parts(t, rep.sectors, rep.closed))
    return patch_topology(t, rep.vertex_map, n_vertices)


def repeated_rwg(
    rep: Repetition, points: np.ndarray, columns: list[np.ndarray] | None = None
) -> RWGTable | None:
    """The RWG table of copies or chains, their rows repeated; None for other kinds.

    Equals :func:`barymesh.topology.rwg_table` of the mesh's topology, bit for bit.
    """
    t = rep.template
    if rep.kind == "copies":
        local = template_topology(t)
        plan = template_plan(t)
        return copies_rwg(local, rep.n_patches, len(t.uv), len(t.triangles), points, columns, plan)
    if rep.kind == "chains":
        return chain_rwg(chain_parts(t, rep.sectors, rep.closed), points, columns)
    return None


def repeated_connectivity(rep: Repetition) -> sp.csr_matrix | None:
    """The connectivity matrix of copies or chains, rows repeated; None when not repeated.

    Equals :func:`barymesh.topology.triangle_adjacency`, array for array; None
    for other kinds and when a template (or short chain) has two triangles
    sharing two edges.
    """
    t = rep.template
    nt = len(t.triangles)
    if rep.kind == "copies":
        local = template_adjacency(t)
        return None if local is None else copies_adjacency(local, rep.n_patches)
    if rep.kind == "chains":
        parts = chain_parts(t, rep.sectors, rep.closed)
        shorts = [adjacency_without_junctions(CHAIN * nt, c) for c in parts.shorts]
        found = [s for s in shorts if s is not None]
        if len(found) == len(shorts):
            return chain_adjacency(found, parts.sectors, nt)
    return None

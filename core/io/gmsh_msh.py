"""Gmsh MSH files through meshio: version 2.2 or 4.1, ASCII, with ``$Periodic`` for a cell.

The triangles carry the region as physical tag (1: the patch or the inner ring, 2: the
outer ring, or a cell's part number), named in ``$PhysicalNames``, and the patch (or
sector) as elementary tag, patch id + 1, so a solver can tell the parts apart and our
reader gets the patches back.

- **MSH 2.2** (the default: scuff-em, bempp-cl, OpenModes and the readers of Makarov's
  era read it) keeps both tags on every element.
- **MSH 4.1** (Gmsh 4's own format) keeps them on *entities*: each patch is a surface
  entity whose tag is patch id + 1 and whose physical group is its region, so its
  triangles come grouped by patch (in the mesh's order within each). Every entity
  lists at least one node in its node block (a patch whose vertices all lie on others
  gets one of its own by a bipartite matching), because Gmsh and meshio only know the
  entities that some node names.

A periodic unit cell (:func:`write_periodic_msh`) also gets the mesh edges lying on the
cell's sides as line elements on four curves: 1 and 2 are the minus and plus sides of
lattice vector a1, 3 and 4 those of a2 (physical groups of the same numbers + 1000,
named ``a1_minus`` …). ``$Periodic`` then declares curve 2 a copy of curve 1 moved by
a1 and curve 4 a copy of curve 3 moved by a2 (Gmsh's affine transform maps the master
onto the slave), with every pair of nodes. meshio writes the section in both versions
(``gmsh_periodic``); Gmsh reads it back (``gmsh.model.mesh.getPeriodicNodes``).
"""

from __future__ import annotations

import contextlib
import io
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..mesh import TriMesh
from .atomic import atomic_path

if TYPE_CHECKING:
    import meshio

#: The MSH versions written; the first is the default.
MSH_VERSIONS = ("2.2", "4.1")
#: meshio's writer of each version.
MESHIO_FORMAT = {"2.2": "gmsh22", "4.1": "gmsh"}
#: Curve tags of the cell's sides: (master, slave) for a1 and for a2.
SIDE_CURVES = ((1, 2), (3, 4))
SIDE_NAMES = {1: "a1_minus", 2: "a1_plus", 3: "a2_minus", 4: "a2_plus"}
#: Physical tags of the side curves are the curve tags plus this.
SIDE_PHYSICAL_OFFSET = 1000

__all__ = [
    "MSH_VERSIONS",
    "check_msh_version",
    "gmsh_mesh",
    "region_names",
    "write_gmsh",
    "write_periodic_msh",
]


def check_msh_version(version: Any) -> str:
    """``"2.2"`` or ``"4.1"`` for ``version`` (a string or a number); ``ValueError`` else.

    >>> check_msh_version(4.1), check_msh_version("2.2"), check_msh_version(None)
    ('4.1', '2.2', '2.2')
    """
    if version is None:
        return MSH_VERSIONS[0]
    text = str(version).strip()
    if text not in MSH_VERSIONS:
        raise ValueError(
            f"msh_version={version!r} is not a Gmsh version we write; expected "
            f"{' or '.join(MSH_VERSIONS)}"
        )
    return text


def region_names(mesh: TriMesh) -> dict[int, str]:
    """Physical names of the regions: ``patch``, ``ring``, ``inner_ring``, ``outer_ring``."""
    regions = np.unique(mesh.regions).tolist()
    if mesh.mode == "imported":
        return {r: f"region_{r}" for r in regions}
    if regions == [1] and mesh.n_patches == 1:
        return {1: "patch"}
    if regions == [1]:
        return {1: "ring"}
    names = {1: "inner_ring", 2: "outer_ring"}
    return {r: names.get(r, f"region_{r}") for r in regions}


@dataclass(frozen=True)
class _Sides:
    """The side curves of a periodic cell: line elements and the ``$Periodic`` links."""

    lines: tuple[tuple[int, np.ndarray], ...]  # (curve tag, (L, 2) vertex pairs)
    links: tuple[tuple[int, tuple[int, int], np.ndarray, np.ndarray], ...]


def _sides(mesh: TriMesh, pairs: Any, lattice: Any, per_mm: float) -> _Sides:
    lines, links = [], []
    for k, (master, slave) in enumerate(SIDE_CURVES):
        sel = pairs.edge_shift == k
        if not sel.any():
            continue
        lines.append((master, mesh.edges[pairs.edges[sel, 0]].astype(np.int64)))
        lines.append((slave, mesh.edges[pairs.edges[sel, 1]].astype(np.int64)))
        affine = np.eye(4)
        affine[:2, 3] = np.asarray(lattice.a1 if k == 0 else lattice.a2, dtype=float) * per_mm
        vp = pairs.vertices[pairs.vertex_shift == k]
        # (slave node, master node), 0-based: meshio adds 1
        nodes = np.column_stack([vp[:, 1], vp[:, 0]]).astype(np.int64)
        links.append((1, (slave, master), affine.ravel(), nodes))
    return _Sides(tuple(lines), tuple(links))


def _entities(mesh: TriMesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Surface entities of MSH 4.1: one per patch (per patch and region if a patch spans two).

    Returns ``(entity of each triangle (T,), entity tags (S,), their regions (S,))``.
    """
    keys = np.column_stack([mesh.patch_ids, mesh.regions]).astype(np.int64)
    unique, of_triangle = np.unique(keys, axis=0, return_inverse=True)
    of_triangle = of_triangle.reshape(-1)
    if len(np.unique(unique[:, 0])) == len(unique):  # each patch in one region
        tags = unique[:, 0] + 1
    else:
        tags = np.arange(1, len(unique) + 1, dtype=np.int64)
    return of_triangle, tags, unique[:, 1]


def _node_entities(n_points: int, blocks: list[tuple[int, int, np.ndarray]]) -> np.ndarray:
    """(V, 2) (dimension, entity tag) of every node, each entity naming one node at least.

    ``blocks`` are (dimension, entity tag, (n, k) vertex indices) in file order. A node
    goes to the first curve it lies on, else to the first surface; when an entity is
    then left with no node of its own, a maximum bipartite matching of entities to
    their vertices gives each one a node of its own.
    """
    dims = np.array([b[0] for b in blocks], dtype=np.int64)
    tags = np.array([b[1] for b in blocks], dtype=np.int64)
    owner = np.full(n_points, -1, dtype=np.int64)
    rows, cols = [], []
    for index, (_, _, cells) in enumerate(blocks):
        used = np.unique(cells)
        rows.append(np.full(len(used), index, dtype=np.int64))
        cols.append(used)
    order = np.argsort(dims, kind="stable")  # curves before surfaces; first one wins
    for index in order[::-1]:
        owner[cols[index]] = index
    if np.any(owner < 0):
        raise ValueError("a vertex is used by no element; the mesh cannot be written")
    if len(np.unique(owner)) < len(blocks):
        # scipy and meshio are imported where they are used: ``barymesh --help`` stays quick
        import scipy.sparse as sp
        from scipy.sparse.csgraph import maximum_bipartite_matching

        graph = sp.csr_matrix(
            (np.ones(sum(map(len, rows))), (np.concatenate(rows), np.concatenate(cols))),
            shape=(len(blocks), n_points),
        )
        match = maximum_bipartite_matching(graph, perm_type="column")
        if np.any(match < 0):
            raise ValueError(
                f"cannot write MSH 4.1: {int(np.sum(match < 0))} patch(es) or side(s) share "
                "all their vertices with others (duplicated triangles?); write MSH 2.2"
            )
        owner[match] = np.arange(len(blocks))
    return np.column_stack([dims[owner], tags[owner]])


def gmsh_mesh(
    mesh: TriMesh,
    per_mm: float = 1.0,
    msh_version: str = "2.2",
    *,
    names: dict[int, str] | None = None,
    periodic: tuple[Any, Any] | None = None,
) -> meshio.Mesh:
    """A meshio mesh that meshio's Gmsh writer turns into our MSH file.

    Parameters
    ----------
    mesh : TriMesh
        Coordinates in mm.
    per_mm : float
        File units per mm (1 for mm, 1e-3 for m); the translations scale too.
    msh_version : {"2.2", "4.1"}
    names : dict, optional
        Region -> physical name; default :func:`region_names`.
    periodic : (PeriodicPairs, Lattice), optional
        The matched sides of a unit cell and its lattice: adds the side curves and
        ``gmsh_periodic``.
    """
    import meshio

    version = check_msh_version(msh_version)
    points = np.asarray(mesh.points, dtype=np.float64) * per_mm
    triangles = np.asarray(mesh.triangles, dtype=np.int64)
    names = region_names(mesh) if names is None else names
    field_data = {name: np.array([tag, 2]) for tag, name in sorted(names.items())}
    sides = _sides(mesh, *periodic, per_mm) if periodic is not None else _Sides((), ())
    for tag, _ in sides.lines:
        field_data[SIDE_NAMES[tag]] = np.array([tag + SIDE_PHYSICAL_OFFSET, 1])
    gmsh_periodic = [list(link) for link in sides.links] or None
    cells: list[tuple[str, np.ndarray]] = [("line", lines) for _, lines in sides.lines]
    physical = [np.full(len(lines), tag + SIDE_PHYSICAL_OFFSET) for tag, lines in sides.lines]
    geometrical = [np.full(len(lines), tag) for tag, lines in sides.lines]
    point_data = {}
    if version == "2.2":
        cells.append(("triangle", triangles))
        physical.append(np.asarray(mesh.regions, dtype=np.int64))
        geometrical.append(np.asarray(mesh.patch_ids, dtype=np.int64) + 1)
    else:
        entity, tags, regions = _entities(mesh)
        order = np.argsort(entity, kind="stable")
        starts = np.searchsorted(entity[order], np.arange(len(tags) + 1))
        blocks = [(1, tag, lines) for tag, lines in sides.lines]
        for s, (tag, region) in enumerate(zip(tags.tolist(), regions.tolist(), strict=True)):
            block = triangles[order[starts[s] : starts[s + 1]]]
            cells.append(("triangle", block))
            physical.append(np.full(len(block), region))
            geometrical.append(np.full(len(block), tag))
            blocks.append((2, tag, block))
        point_data["gmsh:dim_tags"] = _node_entities(len(points), blocks)
    return meshio.Mesh(
        points,
        cells,
        point_data=point_data,
        cell_data={
            "gmsh:physical": [p.astype(np.int32) for p in physical],
            "gmsh:geometrical": [g.astype(np.int32) for g in geometrical],
        },
        field_data=field_data,
        gmsh_periodic=gmsh_periodic,
    )


def write_gmsh(path: str | Path, mesh: meshio.Mesh, msh_version: str = "2.2") -> None:
    """Write a mesh of :func:`gmsh_mesh` to ``path`` as ASCII MSH (not atomically)."""
    import meshio

    version = check_msh_version(msh_version)
    with contextlib.redirect_stderr(io.StringIO()):  # meshio prints warnings with rich
        meshio.write(path, mesh, file_format=MESHIO_FORMAT[version], binary=False)


def write_periodic_msh(
    cell_mesh: Any, path: str | Path, per_mm: float = 1.0, msh_version: str | None = "2.2"
) -> None:
    """Write a :class:`barymesh.cell.CellMesh` as MSH with ``$Periodic`` (atomically).

    Parameters
    ----------
    cell_mesh : CellMesh
    path : str or Path
    per_mm : float
        File units per mm (1 for mm, 1e-3 for m); the translations scale too.
    msh_version : {"2.2", "4.1"}
        The MSH version; 2.2 by default.

    Raises
    ------
    ValueError
        When the mesh is not periodic: an edge on a cell side has no partner
        on the opposite side (the message says where); for an unknown version.
    """
    version = check_msh_version(msh_version)
    mesh = cell_mesh.mesh
    pairs = cell_mesh.periodic_pairs
    if not pairs.matched:
        e = mesh.edges[pairs.unmatched_edges[0]]
        mid = mesh.points[e, :2].mean(axis=0)
        raise ValueError(
            f"{path}: the mesh is not periodic: {len(pairs.unmatched_edges)} edge(s) on the "
            f"cell's sides have no partner on the opposite side (first near "
            f"({mid[0]:.6g}, {mid[1]:.6g}) mm); no $Periodic section can describe it"
        )
    parts = cell_mesh.part_names
    names = {
        r: parts[r - 1] if 0 < r <= len(parts) else f"region_{r}"
        for r in np.unique(mesh.regions).tolist()
    }
    m = gmsh_mesh(mesh, per_mm, version, names=names, periodic=(pairs, cell_mesh.lattice))
    with atomic_path(Path(path)) as tmp:
        write_gmsh(tmp, m, version)

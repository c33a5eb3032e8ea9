"""Gmsh MSH 2.2 (ASCII) of a unit cell with its ``$Periodic`` section.

The triangles carry the part number as physical tag (named after the
element, ``$PhysicalNames``) and the patch id + 1 as elementary tag, as in
:mod:`barymesh.io.meshio_formats`. The mesh edges lying on the cell's sides are
written as line elements on four curves: 1 and 2 are the minus and plus
sides of lattice vector a1, 3 and 4 those of a2 (physical groups of the same
numbers + 1000, named ``a1_minus`` …). ``$Periodic`` then declares curve 2 a
copy of curve 1 moved by a1 and curve 4 a copy of curve 3 moved by a2 (Gmsh's
affine transform maps the master onto the slave), with every pair of nodes.
meshio reads the file back (``mesh.gmsh_periodic``).
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from .atomic import atomic_write_text

#: Curve tags of the cell's sides: (master, slave) for a1 and for a2.
SIDE_CURVES = ((1, 2), (3, 4))
SIDE_NAMES = {1: "a1_minus", 2: "a1_plus", 3: "a2_minus", 4: "a2_plus"}
#: Physical tags of the side curves are the curve tags plus this.
SIDE_PHYSICAL_OFFSET = 1000


def write_periodic_msh(cell_mesh, path: str | Path, per_mm: float = 1.0) -> None:
    """Write a :class:`barymesh.cell.CellMesh` as MSH 2.2 with ``$Periodic``.

    Parameters
    ----------
    cell_mesh : CellMesh
    path : str or Path
    per_mm : float
        File units per mm (1 for mm, 1e-3 for m); the translations scale too.

    Raises
    ------
    ValueError
        When the mesh is not periodic: an edge on a cell side has no partner
        on the opposite side (the message says where).
    """
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
    atomic_write_text(Path(path), periodic_msh_text(cell_mesh, per_mm))


def periodic_msh_text(cell_mesh, per_mm: float = 1.0) -> str:
    """The MSH 2.2 text written by :func:`write_periodic_msh` (no periodicity check)."""
    mesh = cell_mesh.mesh
    pairs = cell_mesh.periodic_pairs
    lattice = cell_mesh.lattice
    names = cell_mesh.part_names
    out = io.StringIO()
    out.write("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n")
    regions = np.unique(mesh.regions).tolist()
    physical = [(2, r, names[r - 1] if 0 < r <= len(names) else f"region_{r}") for r in regions]
    sides_used = sorted({c for k in np.unique(pairs.edge_shift).tolist() for c in SIDE_CURVES[k]})
    physical += [(1, c + SIDE_PHYSICAL_OFFSET, SIDE_NAMES[c]) for c in sides_used]
    out.write(f"$PhysicalNames\n{len(physical)}\n")
    for dim, tag, name in physical:
        out.write(f'{dim} {tag} "{name}"\n')
    out.write("$EndPhysicalNames\n")

    points = mesh.points * per_mm
    out.write(f"$Nodes\n{len(points)}\n")
    ids = np.arange(1, len(points) + 1)
    np.savetxt(out, np.column_stack([ids, points]), fmt=["%d", "%.17g", "%.17g", "%.17g"])
    out.write("$EndNodes\n")

    parts = []  # (curve tag, v0, v1)
    for k, (master, slave) in enumerate(SIDE_CURVES):
        sel = pairs.edge_shift == k
        parts.append(np.column_stack([np.full(sel.sum(), master), mesh.edges[pairs.edges[sel, 0]]]))
        parts.append(np.column_stack([np.full(sel.sum(), slave), mesh.edges[pairs.edges[sel, 1]]]))
    lines = np.concatenate(parts).astype(np.int64) if parts else np.empty((0, 3), np.int64)
    n_lines, n_tri = len(lines), mesh.n_triangles
    out.write(f"$Elements\n{n_lines + n_tri}\n")
    if n_lines:
        rows = np.column_stack(
            [
                np.arange(1, n_lines + 1),
                np.full(n_lines, 1),
                np.full(n_lines, 2),
                lines[:, 0] + SIDE_PHYSICAL_OFFSET,
                lines[:, 0],
                lines[:, 1:] + 1,
            ]
        )
        np.savetxt(out, rows, fmt="%d")
    tri = np.column_stack(
        [
            np.arange(n_lines + 1, n_lines + n_tri + 1),
            np.full(n_tri, 2),
            np.full(n_tri, 2),
            mesh.regions,
            mesh.patch_ids + 1,
            mesh.triangles + 1,
        ]
    )
    np.savetxt(out, tri, fmt="%d")
    out.write("$EndElements\n")

    entries = []
    for k, (master, slave) in enumerate(SIDE_CURVES):
        sel = pairs.vertex_shift == k
        if not (pairs.edge_shift == k).any():
            continue
        shift = np.asarray(lattice.a1 if k == 0 else lattice.a2) * per_mm
        affine = np.eye(4)
        affine[:2, 3] = shift
        entries.append((slave, master, affine, pairs.vertices[sel]))
    out.write(f"$Periodic\n{len(entries)}\n")
    for slave, master, affine, vp in entries:
        out.write(f"1 {slave} {master}\n")
        out.write("Affine " + " ".join(f"{v:.17g}" for v in affine.ravel()) + "\n")
        out.write(f"{len(vp)}\n")
        np.savetxt(out, np.column_stack([vp[:, 1] + 1, vp[:, 0] + 1]), fmt="%d")
    out.write("$EndPeriodic\n")
    return out.getvalue()

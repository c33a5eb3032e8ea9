"""The array preview: pale ghost copies of the cell's mesh and the cell outlines.

The copies are drawn, not meshed: the cell's triangles moved by ``i a1 + j a2`` with
``i`` in ``-(n1 - 1) // 2 … n1 // 2`` (and ``j`` alike), so the cell itself stays where
it is, at copy (0, 0). Only an export of the array (Cell ▸ Export array mesh…) welds the
copies into one mesh, with :func:`barymesh.cell.tile`.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pyvista as pv

from barymesh import TriMesh
from barymesh.cell import Lattice

#: Ghost copies are drawn up to this many triangles in all (beyond: outlines only).
GHOST_TRIANGLES = 2_000_000
GHOST_OPACITY = 0.3
#: A grey blue: copies read as copies beside the cell's own (light blue) faces.
GHOST_COLOR = "#b4bdc8"


def ghost_shade(color: str = GHOST_COLOR, opacity: float = GHOST_OPACITY) -> str:
    """``color`` at ``opacity`` over the white background, as one opaque colour: the copies
    are drawn opaque in it, so that overlapping paper patches do not stack their
    translucency into darker copies than the cell.

    >>> ghost_shade()
    '#e8ebee'
    """
    rgb = np.array([int(color[i : i + 2], 16) for i in (1, 3, 5)], dtype=float)
    mixed = np.round(opacity * rgb + (1.0 - opacity) * 255.0).astype(int)
    return "#" + "".join(f"{v:02x}" for v in mixed)


OUTLINE_COLOR = "#2b2b2b"
COPY_OUTLINE_COLOR = "#8c8c8c"
_NAMES = ("cell_ghosts", "cell_outline", "cell_copy_outlines")


def copy_shifts(lattice: Lattice, n1: int, n2: int) -> np.ndarray:
    """(n1 n2, 2) float64 translations of the copies, the cell's own (0, 0) first.

    >>> copy_shifts(Lattice.rectangular(2.0, 3.0), 2, 1).tolist()
    [[0.0, 0.0], [2.0, 0.0]]
    """
    i = np.arange(n1) - (n1 - 1) // 2
    j = np.arange(n2) - (n2 - 1) // 2
    ii, jj = np.meshgrid(i, j, indexing="ij")
    ij = np.stack([ii.ravel(), jj.ravel()], axis=1).astype(np.float64)
    ij = ij[np.argsort(np.abs(ij).sum(axis=1), kind="stable")]  # (0, 0) first
    return ij @ lattice.matrix.T


def _outlines(lattice: Lattice, shifts: np.ndarray) -> pv.PolyData:
    corners = lattice.corners()  # (4, 2)
    pts = (shifts[:, None, :] + corners[None]).reshape(-1, 2)
    pts3 = np.column_stack([pts, np.full(len(pts), 1e-6 * lattice.size)])
    base = 4 * np.arange(len(shifts))[:, None]
    loops = np.hstack([np.full((len(shifts), 1), 5), base + [0, 1, 2, 3, 0]])
    return pv.PolyData(pts3, lines=loops.ravel())


class ArrayPreview:
    """The preview's actors on one plotter (made when first needed, replaced on update)."""

    def __init__(self, plotter: Any) -> None:
        self.plotter = plotter
        self.copies = (1, 1)
        self.ghost_triangles = 0  # triangles drawn as ghosts (tests, the panel's note)
        self.bounds: tuple[float, float, float, float] | None = None

    def clear(self) -> bool:
        """Remove the preview's actors; whether there were any (a render is due then)."""
        drawn = [name for name in _NAMES if name in self.plotter.actors]
        for name in drawn:
            self.plotter.remove_actor(name, render=False)
        self.ghost_triangles = 0
        self.bounds = None
        return bool(drawn)

    def show(self, mesh: TriMesh | None, lattice: Lattice | None, n1: int, n2: int) -> None:
        """Draw the outline of the cell and of its n1 x n2 copies, and the copies' faces."""
        self.clear()
        self.copies = (n1, n2)
        if lattice is None:
            return
        shifts = copy_shifts(lattice, n1, n2)
        common = {"reset_camera": False, "lighting": False, "render": False, "pickable": False}
        self.plotter.add_mesh(
            _outlines(lattice, shifts[:1]),
            color=OUTLINE_COLOR,
            line_width=2.5,
            name="cell_outline",
            **common,
        )
        if len(shifts) > 1:
            self.plotter.add_mesh(
                _outlines(lattice, shifts[1:]),
                color=COPY_OUTLINE_COLOR,
                line_width=1.0,
                name="cell_copy_outlines",
                **common,
            )
        corners = (shifts[:, None, :] + lattice.corners()[None]).reshape(-1, 2)
        lo, hi = corners.min(axis=0), corners.max(axis=0)
        if mesh is not None and mesh.n_triangles:
            lo = np.minimum(lo, mesh.points[:, :2].min(axis=0))
            hi = np.maximum(hi, mesh.points[:, :2].max(axis=0) + shifts.max(axis=0))
        self.bounds = (float(lo[0]), float(hi[0]), float(lo[1]), float(hi[1]))
        ghosts = shifts[1:]
        if mesh is None or not len(ghosts) or len(ghosts) * mesh.n_triangles > GHOST_TRIANGLES:
            return
        v = mesh.n_vertices
        pts = (mesh.points[None, :, :2] + ghosts[:, None, :]).reshape(-1, 2)
        tri = (mesh.triangles[None] + (v * np.arange(len(ghosts)))[:, None, None]).reshape(-1, 3)
        faces = np.hstack([np.full((len(tri), 1), 3), tri]).astype(np.int64).ravel()
        poly = pv.PolyData(np.column_stack([pts, np.zeros(len(pts))]), faces=faces)
        self.plotter.add_mesh(poly, color=ghost_shade(), name="cell_ghosts", **common)
        self.ghost_triangles = len(tri)

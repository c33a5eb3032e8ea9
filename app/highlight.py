"""Two triangles marked in the 3D view: the row and column of a connectivity matrix cell."""

from __future__ import annotations

import numpy as np
import pyvista as pv

from core import TriMesh

ROW_COLOR = "#f28e2b"  # the triangle of the matrix row (as the row band of the spy plot)
COL_COLOR = "#7b3294"  # the triangle of the column
OUTLINE_WIDTH = 4.0


class TriangleHighlight:
    """Triangle i (row) and j (column) filled and outlined; actors created once.

    Parameters
    ----------
    plotter : pyvista.Plotter
    """

    def __init__(self, plotter: pv.Plotter) -> None:
        self.plotter = plotter
        self.datasets = {"row": pv.PolyData(), "col": pv.PolyData()}
        self.actors = {}
        self.scale = 1.0
        common = {"reset_camera": False, "lighting": False, "render": False, "pickable": False}
        for name, color in (("row", ROW_COLOR), ("col", COL_COLOR)):
            self.actors[name] = self.plotter.add_mesh(
                self.datasets[name], color=color, opacity=0.8, show_edges=True,
                edge_color=color, line_width=OUTLINE_WIDTH, **common,
            )
        self.triangles: tuple[int, ...] = ()
        self.set_visible(False)

    def show(self, mesh: TriMesh | None, row: int | None, col: int | None = None) -> None:
        """Mark triangles ``row`` and ``col`` of ``mesh`` (None: that one unmarked)."""
        shown = []
        for name, t in (("row", row), ("col", col)):
            poly = pv.PolyData()
            if mesh is not None and t is not None and 0 <= t < mesh.n_triangles:
                pts = np.asarray(mesh.points)
                span = float(np.ptp(pts[:, :2], axis=0).max()) if len(pts) else 1.0
                corners = pts[mesh.triangles[t]].astype(np.float64)
                corners[:, 2] += (1.5 if name == "col" else 1.0) * 1e-4 * max(span, 1e-9)
                poly = pv.PolyData.from_regular_faces(corners, np.array([[0, 1, 2]]))
                shown.append(int(t))
            self.datasets[name].copy_from(poly, deep=False)
        self.triangles = tuple(shown)
        self.set_visible(bool(shown))

    def set_scale(self, scale: float) -> None:
        self.scale = float(scale)
        for actor in self.actors.values():
            actor.prop.line_width = OUTLINE_WIDTH * self.scale

    def set_visible(self, on: bool) -> None:
        for actor in self.actors.values():
            actor.SetVisibility(bool(on))

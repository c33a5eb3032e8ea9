"""Two triangles marked in the 3D view: the row and column of a connectivity matrix cell.

A triangle of a dense mesh can be smaller than a pixel at the zoom the whole mesh is seen
at; then a fill alone would be invisible, so each marked triangle also gets a square
marker of a fixed size in pixels (:data:`MARKER_PIXELS`) until it is large enough on
screen (:meth:`TriangleHighlight.fit`). Over the RWG inspector's T+ and T− the marks are
outlines only, so the divergence colours (and their colour bar) stay true.
"""

from __future__ import annotations

import numpy as np
import pyvista as pv

from barymesh import TriMesh

ROW_COLOR = "#f28e2b"  # the triangle of the matrix row (as the row band of the spy plot)
COL_COLOR = "#7b3294"  # the triangle of the column
OUTLINE_WIDTH = 4.0
#: Markers are drawn while a marked triangle spans fewer pixels than this.
SMALL_PIXELS = 12.0
#: Marker sizes: the row's square around the column's, so two neighbours show both.
MARKER_PIXELS = {"row": 22.0, "col": 10.0}


class TriangleHighlight:
    """Triangle i (row) and j (column) filled and outlined; actors created once.

    Parameters
    ----------
    plotter : pyvista.Plotter
    """

    def __init__(self, plotter: pv.Plotter) -> None:
        self.plotter = plotter
        self.datasets = {
            "row": pv.PolyData(),
            "col": pv.PolyData(),
            "row_marker": pv.PolyData(),
            "col_marker": pv.PolyData(),
        }
        self.actors = {}
        self.scale = 1.0
        self.outline_only = False
        self._mesh: TriMesh | None = None
        self._dz = 0.0
        self._extent = 0.0  # the larger side of the marked triangles (mm)
        self._small = False
        common = {"reset_camera": False, "lighting": False, "render": False, "pickable": False}
        for name, color in (("row", ROW_COLOR), ("col", COL_COLOR)):
            self.actors[name] = self.plotter.add_mesh(
                self.datasets[name],
                color=color,
                opacity=0.8,
                show_edges=True,
                edge_color=color,
                line_width=OUTLINE_WIDTH,
                **common,
            )
            self.actors[f"{name}_marker"] = self.plotter.add_mesh(
                self.datasets[f"{name}_marker"],
                color=color,
                point_size=MARKER_PIXELS[name],
                style="points",
                render_points_as_spheres=False,
                **common,
            )
        self.triangles: tuple[int, ...] = ()
        self.set_visible(False)

    def _lift_for(self, mesh: TriMesh) -> float:
        if mesh is not self._mesh:  # once per mesh, not once per hover
            self._mesh = mesh
            pts = np.asarray(mesh.points)
            span = float(np.ptp(pts[:, :2], axis=0).max()) if len(pts) else 1.0
            self._dz = 1e-4 * max(span, 1e-9)
        return self._dz

    def show(self, mesh: TriMesh | None, row: int | None, col: int | None = None) -> None:
        """Mark triangles ``row`` and ``col`` of ``mesh`` (None: that one unmarked)."""
        shown = []
        extent = 0.0
        for name, t in (("row", row), ("col", col)):
            poly = pv.PolyData()
            marker = pv.PolyData()
            if mesh is not None and t is not None and 0 <= t < mesh.n_triangles:
                dz = self._lift_for(mesh)
                corners = np.asarray(mesh.points)[mesh.triangles[t]].astype(np.float64)
                corners[:, 2] += (1.5 if name == "col" else 1.0) * dz
                poly = pv.PolyData.from_regular_faces(corners, np.array([[0, 1, 2]]))
                centre = corners.mean(axis=0)
                # well above the scene: the centroid dots are drawn as spheres whose depth
                # reaches up by their radius in pixels
                centre[2] += (100 if name == "row" else 110) * dz
                marker = pv.PolyData(centre[None, :])
                extent = max(extent, float(np.ptp(corners[:, :2], axis=0).max()))
                shown.append(int(t))
            self.datasets[name].copy_from(poly, deep=False)
            self.datasets[f"{name}_marker"].copy_from(marker, deep=False)
        self.triangles = tuple(shown)
        self._extent = extent
        self.set_visible(bool(shown))

    def fit(self, pixels_per_mm: float) -> None:
        """Show the fixed-size markers while the marked triangles are tiny on screen."""
        self._small = self._extent * pixels_per_mm < SMALL_PIXELS
        self.set_visible(bool(self.triangles))

    @property
    def markers_shown(self) -> bool:
        return bool(self.triangles) and self._small

    def set_outline_only(self, on: bool) -> None:
        """Outlines without fills (over the inspector's T+ and T−)."""
        self.outline_only = bool(on)
        for name in ("row", "col"):
            prop = self.actors[name].prop
            prop.style = "wireframe" if self.outline_only else "surface"
            prop.opacity = 1.0 if self.outline_only else 0.8

    def set_scale(self, scale: float) -> None:
        self.scale = float(scale)
        for name in ("row", "col"):
            self.actors[name].prop.line_width = OUTLINE_WIDTH * self.scale
            self.actors[f"{name}_marker"].prop.point_size = MARKER_PIXELS[name] * self.scale

    def set_visible(self, on: bool) -> None:
        for name in ("row", "col"):
            self.actors[name].SetVisibility(bool(on))
            self.actors[f"{name}_marker"].SetVisibility(bool(on) and self._small)

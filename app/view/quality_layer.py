"""The worst triangles of the quality report drawn in red over the mesh, one of them chosen.

A handful of triangles (the report's worst list): each filled red with a square marker of
fixed size in pixels at its centroid, so that a sliver smaller than a pixel at the zoom
the whole mesh is seen at still shows; the chosen one (a click in the Quality panel's
list) gets a thick dark outline. Actors are created once and fed new datasets.
"""

from __future__ import annotations

import numpy as np
import pyvista as pv

from barymesh import TriMesh

WORST_COLOR = "#d0021b"
CHOSEN_COLOR = "#111111"
MARKER_PIXELS = 9.0
CHOSEN_WIDTH = 4.0


class WorstTrianglesLayer:
    """Red fills and markers of ``triangles`` of a mesh; the chosen one outlined.

    Parameters
    ----------
    plotter : pyvista.Plotter
    """

    def __init__(self, plotter: pv.Plotter) -> None:
        self.plotter = plotter
        self.datasets = {"fill": pv.PolyData(), "markers": pv.PolyData(), "chosen": pv.PolyData()}
        common = {"reset_camera": False, "lighting": False, "render": False, "pickable": False}
        self.actors = {
            "fill": plotter.add_mesh(
                self.datasets["fill"],
                color=WORST_COLOR,
                opacity=0.85,
                show_edges=True,
                edge_color=WORST_COLOR,
                line_width=2.0,
                **common,
            ),
            "markers": plotter.add_mesh(
                self.datasets["markers"],
                color=WORST_COLOR,
                point_size=MARKER_PIXELS,
                style="points",
                render_points_as_spheres=False,
                **common,
            ),
            "chosen": plotter.add_mesh(
                self.datasets["chosen"],
                color=CHOSEN_COLOR,
                style="wireframe",
                line_width=CHOSEN_WIDTH,
                **common,
            ),
        }
        self.visible = True
        self.triangles = np.empty(0, dtype=np.int64)
        self.chosen: int | None = None
        self._mesh: TriMesh | None = None
        self._lift_mesh: TriMesh | None = None
        self._dz = 0.0
        self._apply()

    def _lift(self, mesh: TriMesh) -> float:
        """Height above the faces (and the matrix highlight): a fraction of the mesh's
        span, from :meth:`show`'s ``span`` or else measured once per mesh."""
        if mesh is not self._lift_mesh:
            pts = np.asarray(mesh.points)
            span = max(float(np.ptp(pts[:, k])) for k in (0, 1)) if len(pts) else 1.0
            self._lift_mesh, self._dz = mesh, 2e-4 * max(span, 1e-9)
        return self._dz

    def show(
        self, mesh: TriMesh | None, triangles: np.ndarray | list[int], span: float | None = None
    ) -> None:
        """Draw ``triangles`` (indices into ``mesh``) in red; the chosen one is forgotten.

        ``span``: the larger side of the mesh's extent (mm) when the caller knows it (the
        scene does), which saves reducing millions of points on the GUI thread.
        """
        if mesh is not None and span is not None and np.isfinite(span):
            self._lift_mesh, self._dz = mesh, 2e-4 * max(float(span), 1e-9)
        tris = np.asarray(triangles, dtype=np.int64).reshape(-1)
        if mesh is None:
            tris = tris[:0]
            self._lift_mesh = None  # no reference to a mesh no longer shown
        else:
            tris = tris[(tris >= 0) & (tris < mesh.n_triangles)]
        self._mesh, self.triangles, self.chosen = mesh, tris, None
        fill, markers = pv.PolyData(), pv.PolyData()
        if len(tris):
            assert mesh is not None  # no triangles without one
            dz = self._lift(mesh)
            corners = np.asarray(mesh.points)[mesh.triangles[tris]].reshape(-1, 3).copy()
            corners[:, 2] += dz
            fill = pv.PolyData.from_regular_faces(corners, np.arange(len(corners)).reshape(-1, 3))
            centres = corners.reshape(-1, 3, 3).mean(axis=1)
            centres[:, 2] += 100 * dz  # above the centroid dots (spheres reach up)
            markers = pv.PolyData(centres)
        self.datasets["fill"].copy_from(fill, deep=False)
        self.datasets["markers"].copy_from(markers, deep=False)
        self.choose(None)

    def choose(self, triangle: int | None) -> None:
        """Outline ``triangle`` (None: none)."""
        mesh = self._mesh
        outline = pv.PolyData()
        self.chosen = None
        if mesh is not None and triangle is not None and 0 <= triangle < mesh.n_triangles:
            self.chosen = int(triangle)
            corners = np.asarray(mesh.points)[mesh.triangles[self.chosen]].astype(np.float64)
            corners[:, 2] += 150 * self._lift(mesh)
            outline = pv.PolyData.from_regular_faces(corners, np.array([[0, 1, 2]]))
        self.datasets["chosen"].copy_from(outline, deep=False)
        self._apply()

    def set_visible(self, on: bool) -> None:
        self.visible = bool(on)
        self._apply()

    def _apply(self) -> None:
        shown = self.visible and len(self.triangles) > 0
        self.actors["fill"].SetVisibility(shown)
        self.actors["markers"].SetVisibility(shown)
        self.actors["chosen"].SetVisibility(self.visible and self.chosen is not None)

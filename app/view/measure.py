"""View → Measure distance: two clicks in the 3D view, the distance between them in mm.

:class:`MeasureTool` keeps the two points (a click near a vertex snaps to it) and owns one
overlay on the plotter (the segment and its two end points, created once and updated in
place); the window turns clicks into :meth:`MeasureTool.add_point` and shows
:attr:`MeasureTool.text`. A third click starts a new measurement.
"""

from __future__ import annotations

import numpy as np
import pyvista as pv

from barymesh.app.view.readout import distance_text

COLOR = "#00a0b0"  # teal: apart from every layer colour of the scene
LINE_WIDTH = 3.0
POINT_SIZE = 11.0


class MeasureTool:
    """Two points and the segment between them, drawn over the mesh.

    Parameters
    ----------
    plotter : pyvista.Plotter
    """

    def __init__(self, plotter: pv.Plotter) -> None:
        self.plotter = plotter
        self.points: list[np.ndarray] = []
        self.line = pv.PolyData()
        self.ends = pv.PolyData()
        self.active = False
        self.lift = 0.0
        common = {"reset_camera": False, "lighting": False, "render": False, "pickable": False}
        self.actors = {
            "line": plotter.add_mesh(
                self.line, color=COLOR, line_width=LINE_WIDTH, style="wireframe", **common
            ),
            "ends": plotter.add_mesh(
                self.ends,
                color=COLOR,
                point_size=POINT_SIZE,
                render_points_as_spheres=True,
                style="points",
                **common,
            ),
        }
        self._draw()

    def set_active(self, on: bool) -> None:
        """Turn measuring on or off (off forgets the points)."""
        self.active = bool(on)
        if not self.active:
            self.points = []
        self._draw()

    def set_lift(self, lift: float) -> None:
        """Draw the overlay this far above the points (over the mesh's lines)."""
        self.lift = float(lift)
        self._draw()

    def add_point(self, point: np.ndarray) -> None:
        """A click at ``point`` (3,) mm: first end, second end, or a new first end."""
        if len(self.points) >= 2:
            self.points = []
        self.points.append(np.asarray(point, dtype=np.float64).reshape(3).copy())
        self._draw()

    @property
    def complete(self) -> bool:
        return len(self.points) == 2

    @property
    def distance(self) -> float | None:
        """|AB| in mm once both points are set."""
        if not self.complete:
            return None
        return float(np.linalg.norm(self.points[1] - self.points[0]))

    def text(self, decimals: int = 3) -> str:
        """What the readout says for the current state."""
        if not self.active:
            return ""
        if not self.points:
            return "Measure: click the first point"
        if len(self.points) == 1:
            return "Measure: click the second point"
        return "Measure: " + distance_text(self.points[0], self.points[1], decimals)

    def _draw(self) -> None:
        pts = [p + np.array([0.0, 0.0, self.lift]) for p in self.points]
        if len(pts) == 2:
            self.line.copy_from(pv.PolyData(np.array(pts), lines=np.array([2, 0, 1])), deep=True)
        else:
            self.line.copy_from(pv.PolyData(), deep=True)
        self.ends.copy_from(pv.PolyData(np.array(pts)) if pts else pv.PolyData(), deep=True)
        for actor in self.actors.values():
            actor.SetVisibility(self.active and bool(pts))

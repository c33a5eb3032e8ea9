"""What the 3D view has selected, and what Zoom to selection frames (no Qt).

A click with no click tool on selects the element under it (a :class:`Hit`-like object:
its ``triangle`` is what is marked and framed). Zoom to selection frames, in this order, a
finished measurement, what the Teach tools select (the inspected edge's two triangles, a
matrix cell's), then the clicked element's triangle.

>>> import numpy as np
>>> from types import SimpleNamespace as Mesh
>>> mesh = Mesh(points=np.eye(3), triangles=np.array([[0, 1, 2]]))
>>> selection = ViewSelection()
>>> selection.points(mesh) is None
True
>>> selection.click(Mesh(triangle=0))
>>> selection.points(mesh).shape
(3, 3)
>>> selection.points(mesh, measured=[(0, 0, 0), (1, 0, 0)]).tolist()  # a measurement first
[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from barymesh.app.model.events import Event


class ViewSelection:
    """The element a click selected in the view (``clicked``), or None.

    Events: ``changed(clicked or None)``.
    """

    def __init__(self) -> None:
        self.clicked: Any = None  # a barymesh.app.view.readout.Hit
        self.changed = Event()

    def click(self, hit: Any) -> None:
        """A click selected ``hit`` (None: a click on nothing, the selection goes)."""
        if hit is not self.clicked:
            self.clicked = hit
            self.changed.emit(hit)

    def clear(self) -> None:
        """A new mesh: nothing is selected (not announced: the mesh's owner redraws)."""
        self.clicked = None

    def points(
        self,
        mesh: Any,
        measured: Sequence[Sequence[float] | np.ndarray] | None = None,
        taught: Sequence[int] | None = None,
    ) -> np.ndarray | None:
        """The corners Zoom to selection frames, (k, 3) float mm, or None.

        Parameters
        ----------
        mesh : TriMesh or None
            The mesh on screen (``points`` (n, 3), ``triangles`` (m, 3)).
        measured : (2, 3) float, optional
            A finished measurement's two points: framed first, even without a mesh.
        taught : sequence of int, optional
            The triangles the Teach tools select: framed before a clicked element.
        """
        if measured is not None:
            return np.array(measured, dtype=np.float64)
        if mesh is None:
            return None
        if taught is not None:
            return mesh.points[mesh.triangles[list(taught)]].reshape(-1, 3)
        if self.clicked is not None:
            return mesh.points[mesh.triangles[self.clicked.triangle]].reshape(-1, 3)
        return None

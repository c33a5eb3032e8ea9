"""Camera framing of the 3D views: from above, a rectangle in mm fitted to the view's shape.

VTK's own ``ResetCamera`` fits a bounding sphere and ignores a tall, narrow view, so a
mesh in a narrow window was cropped at the sides. These helpers set the parallel scale
from the width *and* the height of the view, and keep the camera looking straight down
the z axis with y up (the paper's figures).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from barymesh.app.view.rulers import nice_span

#: Room around the mesh for the ruler labels (left and bottom) and a margin (right, top),
#: as fractions of the mesh's larger side.
RULER_PAD = (0.12, 0.04)


def view_size(plotter: Any) -> tuple[int, int]:
    """(width, height) in pixels of the plotter's active renderer (at least 1 each)."""
    # the widget's size (the render window and the renderer catch up with a resize only
    # when its event is handled or at the next render) times the renderer's viewport
    # (half the window in a side-by-side view)
    if callable(getattr(plotter, "devicePixelRatioF", None)):
        ratio = plotter.devicePixelRatioF()
        width, height = plotter.width() * ratio, plotter.height() * ratio
    else:  # an off-screen plotter
        width, height = plotter.window_size or (1, 1)
    try:
        x0, y0, x1, y1 = plotter.renderer.GetViewport()
    except AttributeError:
        x0, y0, x1, y1 = 0.0, 0.0, 1.0, 1.0
    size = (round(width * (x1 - x0)), round(height * (y1 - y0)))
    return max(int(size[0]), 1), max(int(size[1]), 1)


def look_from_above(plotter: Any) -> None:
    """Turn the camera to look straight down the z axis, y up, parallel projection.

    The focal point and the zoom (parallel scale) stay: only a tilt or a roll is undone.
    """
    camera = plotter.camera
    if not camera.parallel_projection:
        plotter.enable_parallel_projection()
    fx, fy, fz = camera.focal_point
    distance = max(float(camera.distance), 1e-9)
    camera.position = (fx, fy, fz + distance)
    camera.up = (0.0, 1.0, 0.0)
    plotter.renderer.ResetCameraClippingRange()


def frame_from_above(
    plotter: Any,
    bounds: tuple[float, float, float, float],
    rulers: bool = True,
    margin: float = 0.04,
    top: float = 0.0,
    right_px: float = 0.0,
    bottom_px: float = 0.0,
    top_px: float = 0.0,
) -> None:
    """Look down the z axis at the rectangle ``bounds`` = (x0, x1, y0, y1) in mm, all of it
    in view whatever the view's aspect ratio.

    Parameters
    ----------
    plotter : pyvista.Plotter
    bounds : (4,) float
    rulers : bool
        Leave room for the rulers' tick labels (the span is first rounded out to the
        rulers' nice ticks, see :func:`barymesh.app.view.rulers.nice_span`).
    margin : float
        Extra room on every side, as a fraction of the larger side.
    top : float
        More room on top (for a title drawn in the view), a fraction of the larger side.
    right_px : float
        Pixels at the right of the view kept free (for a legend drawn there, see
        :meth:`barymesh.app.view.scene.MeshScene.legend_px`): the rectangle is fitted to the rest.
    bottom_px : float
        Pixels at the bottom kept free (for the view's note,
        :meth:`barymesh.app.view.scene.MeshScene.note_px`), likewise.
    top_px : float
        Pixels at the top kept free (for a header drawn there: the RWG inspector's caption
        and colour bar, the surface current's horizontal colour bar), likewise.
    """
    x0, x1, y0, y1 = (float(v) for v in bounds)
    if rulers:
        (x0, x1, _), (y0, y1, _) = nice_span(x0, x1), nice_span(y0, y1)
    size = max(x1 - x0, y1 - y0, 1e-9)
    low, high = RULER_PAD if rulers else (margin, margin)
    x0, y0 = x0 - low * size, y0 - low * size
    x1, y1 = x1 + high * size, y1 + (high + top) * size
    if not plotter.camera.parallel_projection:
        plotter.enable_parallel_projection()
    camera = plotter.camera
    cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
    camera.focal_point = (cx, cy, 0.0)
    camera.position = (cx, cy, 10.0 * size)
    camera.up = (0.0, 1.0, 0.0)
    w, h = view_size(plotter)
    free = max(float(w) - max(float(right_px), 0.0), 0.25 * w)
    below, above = max(float(bottom_px), 0.0), max(float(top_px), 0.0)
    free_h = max(float(h) - below - above, 0.25 * h)
    scale = max(0.5 * (y1 - y0) * h / free_h, 0.5 * (x1 - x0) * h / free)
    camera.parallel_scale = scale
    if free < w or free_h < h:  # centred in the free part (left of a legend, over a note)
        cx += 0.5 * (w - free) * (2.0 * scale / h)
        if below + above > 0:  # between the note and the header, in their proportion
            cy -= 0.5 * (h - free_h) * (below - above) / (below + above) * (2.0 * scale / h)
        camera.focal_point = (cx, cy, 0.0)
        camera.position = (cx, cy, 10.0 * size)
    plotter.renderer.ResetCameraClippingRange()


def frame_points(
    plotter: Any, points: np.ndarray, fill: float = 0.35, min_size: float = 0.0
) -> None:
    """Centre the view on ``points`` (k, 3) so that they span about ``fill`` of the view.

    Used by zoom-to-selection: a triangle or two, an edge, a measured segment. The
    direction of view is kept straight down the z axis.
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if len(pts) == 0:
        return
    lo, hi = pts[:, :2].min(axis=0), pts[:, :2].max(axis=0)
    extent = max(float((hi - lo).max()), float(min_size), 1e-9)
    half = 0.5 * extent / max(min(fill, 1.0), 1e-3)
    centre = 0.5 * (lo + hi)
    frame_from_above(
        plotter,
        (centre[0] - half, centre[0] + half, centre[1] - half, centre[1] + half),
        rulers=False,
        margin=0.0,
    )


def pixels_per_mm(plotter: Any) -> float:
    """How many view pixels one mm covers at the current zoom (parallel projection)."""
    _, h = view_size(plotter)
    return h / max(2.0 * float(plotter.camera.parallel_scale), 1e-12)


def visible_rect(plotter: Any) -> tuple[float, float, float, float]:
    """(x0, x1, y0, y1) in mm of the plane z = 0 the view shows from above."""
    camera = plotter.camera
    w, h = view_size(plotter)
    half_h = float(camera.parallel_scale)
    half_w = half_h * w / h
    cx, cy = camera.focal_point[:2]
    return (cx - half_w, cx + half_w, cy - half_h, cy + half_h)


def rect_inside(inner: Any, outer: Any) -> bool:
    """Whether rectangle ``inner`` = (x0, x1, y0, y1) lies within ``outer``."""
    return (
        inner[0] >= outer[0]
        and inner[1] <= outer[1]
        and inner[2] >= outer[2]
        and inner[3] <= outer[3]
    )


def world_rect_on_screen(
    plotter: Any, bounds: tuple[float, float, float, float]
) -> tuple[float, float]:
    """(width, height) in pixels that the rectangle ``bounds`` covers at the current zoom."""
    k = pixels_per_mm(plotter)
    return (float(bounds[1] - bounds[0]) * k, float(bounds[3] - bounds[2]) * k)


class FramedCamera:
    """The camera of ``plotter`` as a mesh was last framed.

    The window keeps a framed mesh framed (through resizes, with the array preview's
    copies) until the camera is moved: :meth:`holds` says whether it still is as framed.
    """

    def __init__(self, plotter: Any) -> None:
        self.plotter = plotter
        self.framed: tuple[float, ...] | None = None

    def state(self) -> tuple[float, ...]:
        """Position, focal point, view up and parallel scale: 10 floats."""
        c = self.plotter.camera
        return (*c.position, *c.focal_point, *c.up, float(c.parallel_scale))

    def remember(self) -> None:
        """The camera as it is now is the framed one."""
        self.framed = self.state()

    def holds(self, exact: bool = False) -> bool:
        """Whether the camera is still as framed (to rounding, or ``exact``ly)."""
        if self.framed is None:
            return False
        now = self.state()
        if exact:
            return now == self.framed
        return bool(np.allclose(now, self.framed, rtol=1e-9, atol=1e-12))


class CameraWatch:
    """Calls ``moved()`` after each frame of ``plotter`` drawn with a camera other than the
    last frame's, however it was moved (the mouse, a key, a zoom to a selection, a tool).

    The window restarts its rest timer with it: a dense mesh's view asks for the full
    detail of the part in view once the camera rests (a zoom by a key or a button asked
    for nothing before; only the mouse's interaction events did). GUI thread only.
    """

    def __init__(self, plotter: Any, moved: Any) -> None:
        self.plotter = plotter
        self.moved = moved
        self.last: tuple[float, ...] | None = None
        plotter.ren_win.AddObserver("EndEvent", self._drawn)

    def state(self) -> tuple[float, ...]:
        """Position, focal point, view up, parallel scale, view angle, projection."""
        c = self.plotter.renderer.GetActiveCamera()
        return (
            *c.GetPosition(),
            *c.GetFocalPoint(),
            *c.GetViewUp(),
            float(c.GetParallelScale()),
            float(c.GetViewAngle()),
            float(c.GetParallelProjection()),
        )

    def _drawn(self, *_args: Any) -> None:
        now = self.state()
        if now != self.last:
            self.last = now
            self.moved()

"""Mouse events and pixel checks on the 3D views of the GUI tests.

World points (mm) are turned into the pixels the camera puts them at, so a test clicks,
hovers or reads a pixel exactly where a user would see a vertex, an edge or a triangle.
"""

import numpy as np
from PySide6.QtCore import QPoint, Qt


def hex_rgb(colour):
    """ "#rrggbb" -> (r, g, b) ints."""
    colour = colour.lstrip("#")
    return tuple(int(colour[i : i + 2], 16) for i in (0, 2, 4))


def display_point(plotter, world, renderer=None):
    """World (x, y, z) -> VTK display pixels (origin bottom left) of ``renderer``."""
    renderer = renderer or plotter.renderer
    renderer.SetWorldPoint(float(world[0]), float(world[1]), float(world[2]), 1.0)
    renderer.WorldToDisplay()
    x, y, _ = renderer.GetDisplayPoint()
    return x, y


def text_display_box(actor, renderer):
    """Where a text actor's text is drawn: (x0, x1, y0, y1) in display pixels."""
    box = [0.0] * 4
    actor.GetBoundingBox(renderer, box)  # about its position
    x, y = actor.GetPositionCoordinate().GetComputedDoubleDisplayValue(renderer)
    return box[0] + x, box[1] + x, box[2] + y, box[3] + y


def widget_pos(plotter, world, renderer=None):
    """The Qt widget position of a world point."""
    x, y = display_point(plotter, world, renderer)
    ratio = plotter.devicePixelRatioF()
    return QPoint(round(x / ratio), round(plotter.height() - 1 - y / ratio))


def click_world(qtbot, plotter, world):
    """A left click (press, release, no drag) on the 3D view at a world point."""
    qtbot.mouseClick(plotter, Qt.MouseButton.LeftButton, pos=widget_pos(plotter, world))


def hover_world(qtbot, plotter, world):
    """Move the mouse over the 3D view to a world point (no button held)."""
    qtbot.mouseMove(plotter, widget_pos(plotter, world))


def rendered(plotter):
    """The 3D view as an (h, w, 3) uint8 array, as on screen."""
    plotter.render()
    image = plotter.screenshot(None, return_img=True)
    return np.asarray(image)[..., :3]


def pixel(image, plotter, world, renderer=None):
    """(r, g, b) of ``image`` (a screenshot of ``plotter``) where ``world`` is drawn."""
    x, y = display_point(plotter, world, renderer)
    h = image.shape[0]
    return tuple(int(v) for v in image[h - 1 - int(round(y)), int(round(x))])


def near(rgb, colour, tol=40):
    """Whether ``rgb`` is within ``tol`` of ``colour`` (hex or rgb) in every channel."""
    ref = hex_rgb(colour) if isinstance(colour, str) else colour
    return all(abs(int(a) - int(b)) <= tol for a, b in zip(rgb, ref, strict=True))


def blend(colour, opacity, over="#ffffff"):
    """The colour of ``colour`` drawn with ``opacity`` over ``over``."""
    a = np.array(hex_rgb(colour) if isinstance(colour, str) else colour, dtype=float)
    b = np.array(hex_rgb(over) if isinstance(over, str) else over, dtype=float)
    return tuple(int(round(v)) for v in opacity * a + (1 - opacity) * b)


def _inside(p, corners) -> bool:
    """Whether ``p`` lies inside the triangle ``corners`` (their x and y)."""
    a, b, c = (np.asarray(v, dtype=float)[:2] for v in corners)
    m = np.column_stack([b - a, c - a])
    u, v = np.linalg.solve(m, np.asarray(p, dtype=float)[:2] - a)
    return u >= 0 and v >= 0 and u + v <= 1


def share(image, plotter, corners, colour, tol=40, samples=7, renderer=None, outside=None):
    """Fraction of sample points inside the triangle ``corners`` (3, 3) whose pixel is
    within ``tol`` of ``colour`` (the samples avoid the triangle's edges); with
    ``outside`` (another triangle's corners), the samples under that triangle are left out
    (an overlapping triangle drawn on top)."""
    corners = np.asarray(corners, dtype=float)
    hits = total = 0
    for i in range(1, samples):
        for j in range(1, samples - i):
            k = samples - i - j
            w = np.array([i, j, k], dtype=float) / samples
            p = w @ corners
            if outside is not None and _inside(p, outside):
                continue
            total += 1
            hits += near(pixel(image, plotter, p, renderer), colour, tol)
    return hits / max(total, 1)


def type_into(qtbot, spin, text):
    """Select a field's (or a spin box's) text, type ``text`` and press Return, as a user does."""
    edit = spin.lineEdit() if hasattr(spin, "lineEdit") else spin
    edit.setFocus()
    edit.selectAll()
    qtbot.keyClicks(edit, str(text))
    qtbot.keyClick(edit, Qt.Key.Key_Return)


def drawn_near(image, plotter, world, colour, tol=40, radius=2, renderer=None):
    """Whether a pixel within ``radius`` of where ``world`` is drawn has ``colour`` (for
    lines one or two pixels wide)."""
    x, y = display_point(plotter, world, renderer)
    h, w = image.shape[:2]
    row, col = h - 1 - int(round(y)), int(round(x))
    patch = image[max(row - radius, 0) : row + radius + 1, max(col - radius, 0) : col + radius + 1]
    return any(near(p, colour, tol) for p in patch.reshape(-1, patch.shape[-1]))


def colour_pixels(image, colour, tol=40):
    """How many pixels of ``image`` (h, w, 3 or 4) are within ``tol`` of the hex
    ``colour`` in every channel."""
    ref = np.array(hex_rgb(colour))
    return int((np.abs(np.asarray(image)[..., :3].astype(int) - ref).max(axis=-1) <= tol).sum())

"""Rulers in mm along the bottom and left of a box in the z = 0 plane.

:class:`Rulers` draws what ``pyvista.Plotter.show_bounds`` drew before (a
``vtkCubeAxesActor`` in its 2D mode, of which the view used one x and one y ruler), but
as a handful of plain props: one line set (the two rules and their ticks, in the z = 0
plane) and one 2D text actor per tick label and per title, each tied to a world point
and moved from it by a few pixels.

Why not the cube axes: a new tick count made ``vtkCubeAxesActor`` delete and rebuild the
label objects of all its twelve axes (3-D vector text, followers and 2D text each)
inside the next render, 40 to 70 ms of the GUI thread each time a wheel zoom came to
rest over a dense mesh (issue 30, item 13). Here a new count takes text actors from a
pool that grows to the largest count asked for (the spare ones hold no text), and new
values re-render a few short strings.

Pixel measures (tick length, gaps, the titles' distance) are multiples of the label font
size, so a copy whose fonts are k times larger (a 2x or 3x screenshot) draws its rulers
k times larger too, titles included.
"""

from __future__ import annotations

import numpy as np
from vtkmodules.vtkCommonCore import vtkCommand, vtkPoints, vtkStringArray
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
from vtkmodules.vtkRenderingCore import (
    vtkActor,
    vtkCoordinate,
    vtkPolyDataMapper,
    vtkProp,
    vtkProperty,
    vtkRenderer,
    vtkTextActor,
    vtkTextProperty,
)

#: Pixel measures at a 12-point label font, scaled with it: the ticks' length, the gap
#: between a tick's end and its label, and how far the x title's top and the y title's
#: right side are from their rule (at least; the y title clears its widest label).
TICK_PX = 6.0
GAP_PX = 4.0
X_TITLE_PX = 42.0
Y_TITLE_PX = 51.0
#: The titles stay this far inside their viewport's lower and left edges (as VTK's did).
EDGE_PX = 10.0
_FONT = 12.0


def _colour(hex_colour: str) -> tuple[float, float, float]:
    h = hex_colour.lstrip("#")
    return tuple(int(h[i : i + 2], 16) / 255.0 for i in (0, 2, 4))  # type: ignore[return-value]


def _text_property(
    colour: tuple[float, float, float], size: int, horizontal: str, vertical: str
) -> vtkTextProperty:
    prop = vtkTextProperty()
    prop.SetFontFamilyToArial()
    prop.SetFontSize(size)
    prop.SetColor(*colour)
    prop.SetBold(False)
    prop.SetItalic(False)
    prop.SetShadow(False)
    getattr(prop, f"SetJustificationTo{horizontal}")()
    getattr(prop, f"SetVerticalJustificationTo{vertical}")()
    return prop


class Rulers:
    """An x ruler under and a y ruler left of ``bounds`` (x0, x1, y0, y1, z0, z1), with
    ``n_xlabels`` and ``n_ylabels`` evenly spaced tick labels from end to end.

    The attributes the view reads and writes follow ``vtkCubeAxesActor`` and pyvista's
    wrapper of it (``bounds``, ``n_xlabels``, ``x_label_format``, ``x_title``,
    ``GetTitleTextProperty(axis)``, ``GetAxisLabels(axis)``, visibility), so the rulers
    of the main view, the teaching views and the scaled screenshots are driven as before.

    >>> from vtkmodules.vtkRenderingCore import vtkRenderer
    >>> rulers = Rulers(vtkRenderer())
    >>> rulers.n_xlabels = 3
    >>> rulers.bounds = (0.0, 10.0, -2.0, 2.0, 0.0, 0.0)
    >>> labels = rulers.GetAxisLabels(0)
    >>> [labels.GetValue(i) for i in range(labels.GetNumberOfValues())]
    ['0', '5', '10']
    """

    def __init__(
        self,
        renderer: vtkRenderer,
        color: str = "#303030",
        font_size: int = 12,
        xtitle: str = "x (mm)",
        ytitle: str = "y (mm)",
    ) -> None:
        self.renderer = renderer
        rgb = _colour(color)
        self._label_props = [
            _text_property(rgb, font_size, "Centered", "Top"),
            _text_property(rgb, font_size, "Right", "Centered"),
            _text_property(rgb, font_size, "Centered", "Centered"),
        ]
        self._title_props = [
            _text_property(rgb, font_size, "Centered", "Top"),
            _text_property(rgb, font_size, "Centered", "Bottom"),
            _text_property(rgb, font_size, "Centered", "Centered"),
        ]
        self._title_props[1].SetOrientation(90.0)  # read bottom to top, left of the rule
        self._bounds: tuple[float, ...] = (0.0, 1.0, 0.0, 1.0, 0.0, 0.0)
        self._counts = [5, 5]
        self._formats = ["{:.4g}", "{:.4g}"]
        self._visible = True
        self._pickable = False
        self._texts: list[list[str]] = [[], []]
        self._labels: list[list[vtkTextActor]] = [[], []]
        self._anchors: list[list[vtkCoordinate]] = [[], []]
        self._tick_world = -1.0  # tick length the line set was made with (world units)
        self._offsets_for: tuple = ()  # (font sizes, labels) the offsets were set for
        self._sizes = (0.0, 0.0, 0.0, 0.0)  # see _measure

        # the rules and ticks: lines in the z = 0 plane, in the scene like the mesh (a
        # measuring line or a highlight along a rule is drawn over it)
        self._poly = vtkPolyData()
        mapper = vtkPolyDataMapper()
        mapper.SetInputData(self._poly)
        self._lines = vtkActor()
        self._lines.SetMapper(mapper)
        line_prop = self._lines.GetProperty()
        line_prop.SetColor(*rgb)
        line_prop.SetLineWidth(1.0)
        line_prop.SetLighting(False)
        self._titles: list[vtkTextActor] = []
        self._title_anchors: list[vtkCoordinate] = []
        for axis, text in enumerate((xtitle, ytitle)):
            actor, anchor = self._anchored_text(self._title_props[axis])
            actor.SetInput(text)
            self._titles.append(actor)
            self._title_anchors.append(anchor)
        renderer.AddViewProp(self._lines)
        for actor in self._titles:
            renderer.AddViewProp(actor)
        # offsets follow the zoom and the font sizes: refreshed before each render
        self._observer = renderer.AddObserver(vtkCommand.StartEvent, self._before_render)
        self._rebuild()

    # -- the interface of vtkCubeAxesActor / pyvista's CubeAxesActor the view uses ----

    @property
    def bounds(self) -> tuple[float, ...]:
        return self._bounds

    @bounds.setter
    def bounds(self, value: tuple[float, ...]) -> None:
        value = tuple(float(v) for v in value)
        if value != self._bounds:
            self._bounds = value
            self._rebuild()

    @property
    def n_xlabels(self) -> int:
        return self._counts[0]

    @n_xlabels.setter
    def n_xlabels(self, value: int) -> None:
        self._set_count(0, value)

    @property
    def n_ylabels(self) -> int:
        return self._counts[1]

    @n_ylabels.setter
    def n_ylabels(self, value: int) -> None:
        self._set_count(1, value)

    @property
    def x_label_format(self) -> str:
        return self._formats[0]

    @x_label_format.setter
    def x_label_format(self, value: str) -> None:
        self._set_format(0, value)

    @property
    def y_label_format(self) -> str:
        return self._formats[1]

    @y_label_format.setter
    def y_label_format(self, value: str) -> None:
        self._set_format(1, value)

    @property
    def x_title(self) -> str:
        return str(self._titles[0].GetInput() or "")

    @x_title.setter
    def x_title(self, value: str) -> None:
        self._titles[0].SetInput(value)

    @property
    def y_title(self) -> str:
        return str(self._titles[1].GetInput() or "")

    @y_title.setter
    def y_title(self, value: str) -> None:
        self._titles[1].SetInput(value)

    def GetVisibility(self) -> bool:  # noqa: N802 (VTK's name)
        return self._visible

    def SetVisibility(self, visible: bool) -> None:  # noqa: N802
        visible = bool(visible)
        if visible == self._visible:
            return
        self._visible = visible
        for prop in self.props():
            prop.SetVisibility(visible)

    def SetPickable(self, pickable: bool) -> None:  # noqa: N802
        self._pickable = bool(pickable)
        for prop in self.props():
            prop.SetPickable(self._pickable)

    def GetTitleTextProperty(self, axis: int) -> vtkTextProperty:  # noqa: N802
        return self._title_props[axis]

    def GetLabelTextProperty(self, axis: int) -> vtkTextProperty:  # noqa: N802
        return self._label_props[axis]

    def GetAxisLabels(self, axis: int) -> vtkStringArray:  # noqa: N802
        """The tick labels of ruler ``axis`` (0: x, 1: y), first to last."""
        out = vtkStringArray()
        for text in self._texts[axis] if axis < 2 else []:
            out.InsertNextValue(text)
        return out

    def label_actors(self, axis: int) -> list[vtkTextActor]:
        """The text actors of ruler ``axis``'s labels (0: x, 1: y), first to last."""
        return self._labels[axis][: len(self._texts[axis])]

    def title_actor(self, axis: int) -> vtkTextActor:
        """The text actor of ruler ``axis``'s title."""
        return self._titles[axis]

    def line_property(self) -> vtkProperty:
        """The rules' and ticks' ``vtkProperty`` (colour, line width)."""
        return self._lines.GetProperty()

    def props(self) -> list[vtkProp]:
        """Every VTK prop the rulers put in their renderer."""
        return [self._lines, *self._titles, *self._labels[0], *self._labels[1]]

    def remove(self) -> None:
        """Take the rulers out of their renderer."""
        for prop in self.props():
            self.renderer.RemoveViewProp(prop)
        self.renderer.RemoveObserver(self._observer)

    # -- building --------------------------------------------------------------------

    def _anchored_text(self, prop: vtkTextProperty) -> tuple[vtkTextActor, vtkCoordinate]:
        """A text actor placed some pixels (its position, display units) from a world
        point (the returned anchor)."""
        anchor = vtkCoordinate()
        anchor.SetCoordinateSystemToWorld()
        actor = vtkTextActor()
        actor.SetTextProperty(prop)
        position = actor.GetPositionCoordinate()
        position.SetCoordinateSystemToDisplay()
        position.SetReferenceCoordinate(anchor)
        actor.SetPickable(self._pickable)
        actor.SetVisibility(self._visible)
        return actor, anchor

    def _set_count(self, axis: int, value: int) -> None:
        value = int(value)
        if value < 1:
            raise ValueError(f"a ruler needs at least one label, not {value}")
        if value != self._counts[axis]:
            self._counts[axis] = value
            self._rebuild()

    def _set_format(self, axis: int, value: str) -> None:
        value.format(1.0)  # a bad format fails here, not in a render
        if value != self._formats[axis]:
            self._formats[axis] = value
            self._rebuild()

    def _rebuild(self) -> None:
        """Labels, anchors and the rules' line set for the current bounds and counts."""
        x0, x1, y0, y1 = self._bounds[:4]
        ends = ((x0, x1), (y0, y1))
        for axis in range(2):
            n = self._counts[axis]
            lo, hi = ends[axis]
            values = np.linspace(lo, hi, n) if n > 1 else np.array([lo])
            texts = [self._formats[axis].format(0.0 if v == 0 else float(v)) for v in values]
            pool, anchors = self._labels[axis], self._anchors[axis]
            while len(pool) < n:
                actor, anchor = self._anchored_text(self._label_props[axis])
                actor.SetPickable(self._pickable)
                self.renderer.AddViewProp(actor)
                pool.append(actor)
                anchors.append(anchor)
            # the pool's spare actors hold no text (not hidden: a view that hides and
            # shows its props around a paint then shows them as they were)
            padded = texts + [""] * (len(pool) - n)
            for i, actor in enumerate(pool):
                if (actor.GetInput() or "") != padded[i]:
                    actor.SetInput(padded[i])
                if i < n:
                    point = (values[i], y0, 0.0) if axis == 0 else (x0, values[i], 0.0)
                    anchors[i].SetValue(*point)
            self._texts[axis] = texts
        self._title_anchors[0].SetValue(0.5 * (x0 + x1), y0, 0.0)
        self._title_anchors[1].SetValue(x0, 0.5 * (y0 + y1), 0.0)
        self._place(force=True)

    def _pixel(self) -> float:
        """World units a display pixel spans (parallel projection; else a 100th of the
        larger side, as if that side were 100 px)."""
        camera = self.renderer.GetActiveCamera()
        height = self.renderer.GetSize()[1]
        if camera.GetParallelProjection() and height > 0:
            return 2.0 * camera.GetParallelScale() / height
        x0, x1, y0, y1 = self._bounds[:4]
        return max(x1 - x0, y1 - y0, 1e-12) / 100.0

    def _place(self, force: bool = False) -> None:
        """Ticks, label and title offsets for the current zoom and font sizes."""
        scale = self._label_props[0].GetFontSize() / _FONT
        tick_px, gap = TICK_PX * scale, GAP_PX * scale
        tick = tick_px * self._pixel()
        if force or abs(tick - self._tick_world) > 1e-3 * max(abs(tick), 1e-300):
            self._tick_world = tick
            self._make_lines(tick)
        key = (
            tuple(p.GetFontSize() for p in (*self._label_props, *self._title_props)),
            tuple(self._texts[0]),
            tuple(self._texts[1]),
            self.x_title,
            self.y_title,
        )
        if force or key != self._offsets_for:
            measured = self._measure()
            if measured is not None:  # (the renderer is in a window): settled
                self._offsets_for = key
                self._sizes = measured
            for actor in self._labels[0]:
                actor.GetPositionCoordinate().SetValue(0.0, -(tick_px + gap))
            for actor in self._labels[1]:
                actor.GetPositionCoordinate().SetValue(-(tick_px + gap), 0.0)
        self._place_titles(scale)

    def _place_titles(self, scale: float) -> None:
        """The x title under the x labels, the y title left of the y labels; moved in
        towards them to stay :data:`EDGE_PX` (times the font's scale) inside the
        viewport's lower and left edges, never onto the labels."""
        widest, label_tall, x_tall, y_wide = self._sizes
        tick_px, gap = TICK_PX * scale, GAP_PX * scale
        down_min = tick_px + 2.0 * gap + label_tall
        left_min = tick_px + 2.0 * gap + widest
        down, left = max(X_TITLE_PX * scale, down_min), max(Y_TITLE_PX * scale, left_min)
        if self.renderer.GetVTKWindow() is not None:
            edge = EDGE_PX * scale
            origin = self.renderer.GetOrigin()
            ay = self._title_anchors[0].GetComputedDoubleDisplayValue(self.renderer)[1]
            down = max(min(down, ay - origin[1] - edge - x_tall), down_min)
            ax = self._title_anchors[1].GetComputedDoubleDisplayValue(self.renderer)[0]
            left = max(min(left, ax - origin[0] - edge - y_wide), left_min)
        self._titles[0].GetPositionCoordinate().SetValue(0.0, -down)
        self._titles[1].GetPositionCoordinate().SetValue(-left, 0.0)

    def _measure(self) -> tuple[float, float, float, float] | None:
        """In pixels: the widest y label's width, the x labels' height, the x title's
        height and the (turned) y title's width; None before the renderer is in a
        window."""
        if self.renderer.GetVTKWindow() is None:
            return None
        box = [0.0, 0.0, 0.0, 0.0]
        widest = label_tall = 0.0
        for actor, text in zip(self._labels[1], self._texts[1], strict=False):
            if text:
                actor.GetBoundingBox(self.renderer, box)
                widest = max(widest, float(box[1] - box[0]))
        for actor, text in zip(self._labels[0], self._texts[0], strict=False):
            if text:
                actor.GetBoundingBox(self.renderer, box)
                label_tall = max(label_tall, float(box[3] - box[2]))
        self._titles[0].GetBoundingBox(self.renderer, box)
        x_tall = float(box[3] - box[2])
        self._titles[1].GetBoundingBox(self.renderer, box)
        y_wide = float(box[1] - box[0])
        return widest, label_tall, x_tall, y_wide

    def _make_lines(self, tick: float) -> None:
        x0, x1, y0, y1 = self._bounds[:4]
        nx, ny = self._counts
        xs = np.linspace(x0, x1, nx) if nx > 1 else np.array([x0])
        ys = np.linspace(y0, y1, ny) if ny > 1 else np.array([y0])
        pts = [(x0, y0), (x1, y0), (x0, y1)]
        segments = [(0, 1), (0, 2)]
        for x in xs:
            segments.append((len(pts), len(pts) + 1))
            pts += [(x, y0), (x, y0 - tick)]
        for y in ys:
            segments.append((len(pts), len(pts) + 1))
            pts += [(x0, y), (x0 - tick, y)]
        points = vtkPoints()
        points.SetDataTypeToDouble()
        for x, y in pts:
            points.InsertNextPoint(x, y, 0.0)
        lines = vtkCellArray()
        for a, b in segments:
            lines.InsertNextCell(2)
            lines.InsertCellPoint(a)
            lines.InsertCellPoint(b)
        self._poly.SetPoints(points)
        self._poly.SetLines(lines)
        self._poly.Modified()

    def _before_render(self, *_args: object) -> None:
        if self._visible:
            self._place()


def _vtk_step(span: float) -> float:
    """The rulers' tick spacing for an axis of length ``span`` (the step VTK's cube-axes
    actor chose, which the view's rulers kept when they replaced it)."""
    power = np.log10(span)
    if power != 0.0:
        power = np.copysign(abs(power) + 1e-9, power)
    if power < 0.0:
        power -= 1.0
    decade = 10.0 ** int(power)
    ticks = int(span / decade) + 1
    return decade / (5.0 if ticks <= 2 else 2.0 if ticks < 5 else 1.0)


def nice_span(lo: float, hi: float, ticks: int = 5) -> tuple[float, float, int]:
    """Widen [lo, hi] to multiples of the step the rulers tick at; return it and the count.

    The step is the one the rulers put their ticks at (1, 2 or 5 times a power of ten,
    from the span, :func:`_vtk_step`), so every label sits on its tick line.

    >>> nice_span(-9.7, 9.7)
    (-10.0, 10.0, 5)
    >>> nice_span(0.0, 10.0)
    (0.0, 10.0, 6)
    """
    a, b = float(lo), float(hi)
    for _ in range(4):
        step = _vtk_step(max(b - a, 1e-12))
        a2 = float(np.floor(lo / step + 1e-9) * step)
        b2 = float(np.ceil(hi / step - 1e-9) * step)
        if (a2, b2) == (a, b):
            break
        a, b = a2, b2
    step = _vtk_step(max(b - a, 1e-12))
    return a, b, int(round((b - a) / step)) + 1


def nice_inside(lo: float, hi: float) -> tuple[float, float, int]:
    """The widest span on the rulers' tick step inside [lo, hi] (a part of a zoomed-in
    mesh): its ends and the count of ticks, every label on its tick line.

    >>> nice_inside(0.13, 0.91)
    (0.2, 0.9, 8)
    """
    step = _vtk_step(max(hi - lo, 1e-12))
    a = b = float(lo)
    for _ in range(6):
        a = float(np.ceil(lo / step - 1e-9) * step)
        b = float(np.floor(hi / step + 1e-9) * step)
        if b - a < step * (1 - 1e-9):  # one tick at most: a finer step
            step /= 2.0
            continue
        following = _vtk_step(b - a)
        if np.isclose(following, step, rtol=1e-9):
            break
        step = following
    if b <= a:
        return float(lo), float(hi), 2
    return a, b, int(round((b - a) / step)) + 1

"""Screenshots of the view at k times its size that look like the view itself.

VTK's own magnification (``plotter.screenshot(scale=k)``, ``vtkRenderLargeImage``)
renders the picture in k × k tiles and breaks every 2D actor on the way: ruler labels
land inside the drawing or are cut ("-3.("), axis titles vanish and the colour-bar title
stays at its 1× size. Instead, :func:`scaled_view_image` draws the same scene into an
off-screen plotter k times the view's size, with every font size, pixel offset, line
width and point size multiplied by k: the picture of the view, at k times the pixels.

All of it runs on the GUI thread (it creates and frees VTK objects).
"""

from __future__ import annotations

import numpy as np
import pyvista as pv

from barymesh.app.view.layers import LAYERS
from barymesh.app.view.scene import MeshScene

#: The largest magnification offered (File → Export screenshot).
MAX_SCALE = 4
#: Pixels a title moves per unit of its text's line offset (measured: half a pixel; down
#: for the x ruler's title, right for the y ruler's turned one).
_PX_PER_LINE_OFFSET = 0.5
#: Colours the titles are drawn in to find them in a probe render (nothing else is).
_PROBE = {0: (1.0, 0.0, 0.0), 1: (0.0, 0.0, 1.0)}


def _text_props(scene: MeshScene) -> list[object]:
    """Every text property of the scene's 2D annotation, in a fixed order."""
    props = [
        scene.actors["labels"].GetMapper().GetLabelTextProperty(),
        scene.scalar_bar.GetTitleTextProperty(),
        scene.scalar_bar.GetLabelTextProperty(),
        scene.legend_title.GetTextProperty(),
        scene.note.GetTextProperty(),
    ]
    for axis in range(3):
        props.append(scene.axes.GetTitleTextProperty(axis))
        props.append(scene.axes.GetLabelTextProperty(axis))
    return props


def _axes_line_props(scene: MeshScene) -> list[object]:
    axes = scene.axes
    return [
        axes.GetXAxesLinesProperty(),
        axes.GetYAxesLinesProperty(),
        axes.GetZAxesLinesProperty(),
    ]


def _copy_scaled(shown: MeshScene, copy: MeshScene, scale: int) -> None:
    """Make ``copy`` draw what ``shown`` draws, every pixel measure times ``scale``."""
    # what is drawn: the very datasets (shared, not copied), textures and visibilities
    for name in LAYERS:
        copy.datasets[name].copy_from(shown.datasets[name], deep=False)
        copy.actors[name].SetVisibility(shown.actors[name].GetVisibility())
        if name == "labels":  # a 2D actor: its font is scaled below
            continue
        prop, mine = shown.actors[name].prop, copy.actors[name].prop
        mine.line_width = prop.line_width * scale
        mine.point_size = prop.point_size * scale
    for quad, actor, texture in (
        ("overview_quad", "actors_overview", "overview_texture"),
        ("zoom_quad", "actors_zoom", "zoom_texture"),
    ):
        getattr(copy, quad).copy_from(getattr(shown, quad), deep=False)
        getattr(copy, actor).SetVisibility(getattr(shown, actor).GetVisibility())
        image = getattr(shown, texture).GetInput()
        if image is not None:
            getattr(copy, texture).SetInputDataObject(image)
    for name in ("scalar_bar", "legend_title", "note", "axes"):
        getattr(copy, name).SetVisibility(getattr(shown, name).GetVisibility())
    copy.note.SetInput(shown.note.GetInput() or "")
    copy.legend_title.SetInput(shown.legend_title.GetInput() or "")
    # the annotation: fonts, offsets and rule widths in pixels, times ``scale``
    for prop, mine in zip(_text_props(shown), _text_props(copy), strict=True):
        mine.SetFontSize(int(round(prop.GetFontSize() * scale)))
    for prop, mine in zip(_axes_line_props(shown), _axes_line_props(copy), strict=True):
        mine.SetLineWidth(prop.GetLineWidth() * scale)
    # the same camera: the same part of the plane, k times the pixels
    camera, mine = shown.plotter.camera, copy.plotter.camera
    mine.parallel_projection = camera.parallel_projection
    mine.position, mine.focal_point, mine.up = camera.position, camera.focal_point, camera.up
    mine.parallel_scale = camera.parallel_scale
    mine.view_angle = camera.view_angle
    copy.plotter.renderer.ResetCameraClippingRange()


def _scene_copy(scene: MeshScene, scale: int) -> tuple[pv.Plotter, MeshScene]:
    """An off-screen plotter ``scale`` times the view's size drawing what ``scene`` draws."""
    width, height = (int(v) for v in scene.plotter.ren_win.GetSize())
    plotter = pv.Plotter(off_screen=True, window_size=(width * scale, height * scale))
    try:
        copy = MeshScene(plotter, visible=dict(scene.visible), color_by=scene.color_by)
        # colour tables, legend ticks and ranges as the view has them (the overview
        # object and its images are shared, not rebuilt: their colouring is the same)
        copy.bounds, copy.ranges = scene.bounds, scene.ranges
        copy.n_triangles, copy.overview, copy.zoom = (scene.n_triangles, scene.overview, scene.zoom)
        copy.paper, copy.overlap_ratio = scene.paper, scene.overlap_ratio
        copy.axes.n_xlabels, copy.axes.n_ylabels = scene.axes.n_xlabels, scene.axes.n_ylabels
        copy.axes.bounds = scene.axes.bounds
        faces, mine = scene.actors["faces"].mapper, copy.actors["faces"].mapper
        copy.datasets["faces"].copy_from(scene.datasets["faces"], deep=False)
        mine.lookup_table = faces.lookup_table
        mine.SetScalarRange(faces.GetScalarRange())
        mine.SetScalarVisibility(faces.GetScalarVisibility())
        mine.SelectColorArray(faces.GetArrayName())
        copy.scalar_bar.SetLookupTable(scene.scalar_bar.GetLookupTable())
        for name in (
            "NumberOfLabels",
            "MaximumNumberOfColors",
            "LabelFormat",
            "UseCustomLabels",
            "DrawTickLabels",
        ):
            getattr(copy.scalar_bar, f"Set{name}")(getattr(scene.scalar_bar, f"Get{name}")())
        if scene.scalar_bar.GetCustomLabels() is not None:
            copy.scalar_bar.SetCustomLabels(scene.scalar_bar.GetCustomLabels())
        _copy_scaled(scene, copy, scale)
    except BaseException:
        plotter.close()
        raise
    return plotter, copy


def _title_spans(plotter: pv.Plotter, copy: MeshScene) -> dict[int, tuple[float, float]]:
    """Where the rulers' titles are, in display pixels: the x title's rows (key 0) and the
    y title's columns (key 1), each as (first, last + 1). Found in one render of the
    titles alone, each in a colour of its own (a first render: see :func:`_title_offsets`).
    """
    if not copy.axes.GetVisibility():
        return {}
    props = plotter.renderer.GetViewProps()
    for prop in [props.GetItemAsObject(i) for i in range(props.GetNumberOfItems())]:
        if prop is not copy.axes:
            prop.SetVisibility(False)  # (a throw-away copy: nothing to restore)
    for axis, colour in _PROBE.items():
        copy.axes.GetTitleTextProperty(axis).SetColor(colour)
    image = np.asarray(plotter.screenshot(None, return_img=True))[..., :3].astype(int)
    red = (image[..., 0] > 160) & (image[..., 1] < 90) & (image[..., 2] < 90)
    blue = (image[..., 2] > 160) & (image[..., 0] < 90) & (image[..., 1] < 90)
    spans = {}
    rows = np.nonzero(red.any(axis=1))[0]
    if len(rows):  # display y grows upwards
        spans[0] = (float(image.shape[0] - 1 - rows.max()), float(image.shape[0] - rows.min()))
    cols = np.nonzero(blue.any(axis=0))[0]
    if len(cols):
        spans[1] = (float(cols.min()), float(cols.max() + 1))
    return spans


def _title_offsets(scene: MeshScene, scale: int) -> dict[int, float]:
    """Line offsets that put the rulers' titles of a ``scale`` times larger copy of
    ``scene`` where the view has them, k times as far from its lower-left corner.

    VTK places a ruler's 2D title a fixed number of pixels (40 below the x ruler, 50 left
    of the y ruler, at least 10 from the window's edge) from where its 3D position
    projects: in a k times larger image the projected part grows k times, the fixed part
    does not, so the titles crept onto the labels. The titles' text line offset moves
    them; it only takes effect in a plotter's first render, so each probe is a new copy.
    """
    spans = []
    for k in (1, scale):
        plotter, copy = _scene_copy(scene, k)
        try:
            spans.append(_title_spans(plotter, copy))
        finally:
            plotter.close()
    at_one, have = spans
    offsets = {}
    for axis, (lo, hi) in at_one.items():
        if axis not in have:
            continue
        k_lo, k_hi = have[axis]
        # the middle of the title, k times as far out; a title cut by the window's lower
        # or left edge is measured from its other side
        middle = 0.5 * (k_lo + k_hi) if k_lo > 0 else k_hi - 0.5 * scale * (hi - lo)
        units = (0.5 * scale * (lo + hi) - middle) / _PX_PER_LINE_OFFSET  # up, right
        offsets[axis] = -units if axis == 0 else units
    return offsets


def scaled_view_image(scene: MeshScene, scale: int, transparent: bool = False) -> np.ndarray:
    """The view of ``scene`` at ``scale`` times its pixel size, drawn as the view looks.

    Parameters
    ----------
    scene : MeshScene
        The window's scene (its plotter is the on-screen view).
    scale : int
        1 to :data:`MAX_SCALE`; the image is ``scale`` times the render window's size.
    transparent : bool
        Transparent background (an RGBA image) instead of white.

    Returns
    -------
    (h * scale, w * scale, 3 or 4) uint8 ndarray
    """
    if (
        isinstance(scale, bool)
        or not isinstance(scale, int | np.integer)
        or not 1 <= int(scale) <= MAX_SCALE
    ):
        raise ValueError(f"scale={scale!r} is invalid; expected an integer 1..{MAX_SCALE}")
    scale = int(scale)
    offsets = _title_offsets(scene, scale) if scale > 1 else {}
    plotter, copy = _scene_copy(scene, scale)
    try:
        for axis, offset in offsets.items():
            prop = copy.axes.GetTitleTextProperty(axis)
            prop.SetLineOffset(prop.GetLineOffset() + offset)
        image = plotter.screenshot(None, transparent_background=transparent, return_img=True)
    finally:
        plotter.close()
    return np.ascontiguousarray(image)

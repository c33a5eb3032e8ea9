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

from app.view.layers import LAYERS
from app.view.scene import MeshScene

#: The largest magnification offered (File → Export screenshot).
MAX_SCALE = 4
#: How far VTK moves the x ruler's title down and the y ruler's title left, in pixels
#: (as text line offsets: down the text for the x title, up the turned y title).
_X_TITLE_PX = 40.0
_Y_TITLE_PX = -50.0


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
    return [axes.GetXAxesLinesProperty(), axes.GetYAxesLinesProperty(),
            axes.GetZAxesLinesProperty()]


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
    # The rulers' 2D titles sit a fixed number of pixels from where their 3D position
    # projects (vtkAxisActor's VerticalOffsetXTitle2D = -40 px below the x ruler,
    # HorizontalOffsetYTitle2D = -50 px left of the y ruler; the cube axes actor does
    # not expose them). The projected part grows with the image, the fixed part must
    # grow too: the text's line offset moves it (half a pixel per unit, measured).
    for axis, fixed_px in ((0, _X_TITLE_PX), (1, _Y_TITLE_PX)):
        prop = copy.axes.GetTitleTextProperty(axis)
        prop.SetLineOffset(shown.axes.GetTitleTextProperty(axis).GetLineOffset()
                           + 2.0 * fixed_px * (scale - 1))
    copy.scalar_bar.SetTextPad(shown.scalar_bar.GetTextPad() * scale)
    # the same camera: the same part of the plane, k times the pixels
    camera, mine = shown.plotter.camera, copy.plotter.camera
    mine.parallel_projection = camera.parallel_projection
    mine.position, mine.focal_point, mine.up = camera.position, camera.focal_point, camera.up
    mine.parallel_scale = camera.parallel_scale
    mine.view_angle = camera.view_angle
    copy.plotter.renderer.ResetCameraClippingRange()


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
    if isinstance(scale, bool) or not isinstance(scale, int | np.integer) \
            or not 1 <= int(scale) <= MAX_SCALE:
        raise ValueError(f"scale={scale!r} is invalid; expected an integer 1..{MAX_SCALE}")
    scale = int(scale)
    width, height = (int(v) for v in scene.plotter.ren_win.GetSize())
    plotter = pv.Plotter(off_screen=True, window_size=(width * scale, height * scale))
    try:
        copy = MeshScene(plotter, visible=dict(scene.visible), color_by=scene.color_by)
        # colour tables, legend ticks and ranges as the view has them (the overview
        # object and its images are shared, not rebuilt: their colouring is the same)
        copy.bounds, copy.ranges = scene.bounds, scene.ranges
        copy.n_triangles, copy.overview, copy.zoom = (scene.n_triangles, scene.overview,
                                                     scene.zoom)
        copy.paper, copy.overlap_ratio = scene.paper, scene.overlap_ratio
        copy.axes.n_xlabels, copy.axes.n_ylabels = scene.axes.n_xlabels, scene.axes.n_ylabels
        copy.axes.bounds = scene.axes.bounds
        faces, mine = scene.actors["faces"].mapper, copy.actors["faces"].mapper
        copy.datasets["faces"].copy_from(scene.datasets["faces"], deep=False)
        mine.lookup_table = scene.actors["faces"].mapper.lookup_table
        mine.SetScalarRange(faces.GetScalarRange())
        mine.SetScalarVisibility(faces.GetScalarVisibility())
        mine.SelectColorArray(faces.GetArrayName())
        copy.scalar_bar.SetLookupTable(scene.scalar_bar.GetLookupTable())
        for name in ("NumberOfLabels", "MaximumNumberOfColors", "LabelFormat",
                     "UseCustomLabels", "DrawTickLabels"):
            getattr(copy.scalar_bar, f"Set{name}")(getattr(scene.scalar_bar, f"Get{name}")())
        if scene.scalar_bar.GetCustomLabels() is not None:
            copy.scalar_bar.SetCustomLabels(scene.scalar_bar.GetCustomLabels())
        _copy_scaled(scene, copy, scale)
        image = plotter.screenshot(None, transparent_background=transparent, return_img=True)
    finally:
        plotter.close()
    return np.ascontiguousarray(image)

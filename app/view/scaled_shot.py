"""Screenshots of the view at k times its size that look like the view itself.

VTK's own magnification (``plotter.screenshot(scale=k)``, ``vtkRenderLargeImage``)
renders the picture in k × k tiles and breaks every 2D actor on the way: ruler labels
land inside the drawing or are cut ("-3.("), axis titles vanish and the colour-bar title
stays at its 1× size. Instead, :class:`ScaledShot` draws the picture in two layers:

* the annotation (rulers, their labels and titles, the colour bar and its title, the
  note, triangle numbers) in one off-screen render k times the view's size, every font
  size, pixel offset and rule width multiplied by k, on a transparent background;
* the mesh (faces, edges, centroids, the overview images) in tiles the view's size, each
  a render of one part of the k times larger picture (the camera's window shifted and
  narrowed, line widths and dot sizes multiplied by k), overlapping by a margin so that a
  dot or a wide line at a tile's edge is whole;

then lays the annotation over the tiles. Each render is one step (:meth:`ScaledShot.steps`)
and costs about what a frame of the view costs, so the window can run its event loop,
show progress and offer Cancel between them (File → Export screenshot); the command
line's ``--window-size`` above 1024 × 768 draws the same way
(:func:`render_screenshot`).

All of it runs on the GUI thread (it creates and frees VTK objects).
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pyvista as pv

from barymesh import TriMesh
from barymesh.app.model.layers import LAYERS
from barymesh.app.view.scene import MeshScene, prepare_headless, resized_image
from barymesh.app.view.scene_data import scene_data

if TYPE_CHECKING:
    from vtkmodules.vtkRenderingCore import vtkProp, vtkProperty, vtkTextProperty

#: The largest magnification offered (File → Export screenshot).
MAX_SCALE = 4
#: Extra pixels around a tile (beyond half the widest dot or line), cut off after.
_MARGIN_PX = 4


def _text_props(scene: MeshScene) -> list[vtkTextProperty]:
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


def _axes_line_props(scene: MeshScene) -> list[vtkProperty]:
    return [scene.axes.line_property()]


def _annotation(scene: MeshScene) -> list[vtkProp]:
    """The scene's 2D props: what the annotation layer draws and the tiles leave out."""
    return [
        scene.actors["labels"],
        scene.scalar_bar,
        scene.legend_title,
        scene.note,
        scene.axes,
    ]


def _mesh_props(scene: MeshScene) -> list[vtkProp]:
    """The scene's 3D props: what the tiles draw and the annotation layer leaves out."""
    props = [scene.actors[name] for name in LAYERS if name != "labels"]
    return [*props, scene.actors_overview, scene.actors_zoom]


def _copy_scaled(shown: MeshScene, copy: MeshScene, scale: float) -> None:
    """Make ``copy`` draw what ``shown`` draws, every pixel measure times ``scale``."""
    # what is drawn: the very datasets (shared, not copied), textures and visibilities
    for name in LAYERS:
        copy.datasets[name].copy_from(shown.datasets[name], deep=False)
    for quad, texture in (
        ("overview_quad", "overview_texture"),
        ("zoom_quad", "zoom_texture"),
    ):
        getattr(copy, quad).copy_from(getattr(shown, quad), deep=False)
        image = getattr(shown, texture).GetInput()
        if image is not None:
            getattr(copy, texture).SetInputDataObject(image)
    copy.note.SetInput(shown.note.GetInput() or "")
    copy.legend_title.SetInput(shown.legend_title.GetInput() or "")
    _show_as(shown, copy)
    _scale_pixels(shown, copy, scale)
    # the same camera: the same part of the plane, k times the pixels
    camera, mine = shown.plotter.camera, copy.plotter.camera
    mine.parallel_projection = camera.parallel_projection
    mine.position, mine.focal_point, mine.up = camera.position, camera.focal_point, camera.up
    mine.parallel_scale = camera.parallel_scale
    mine.view_angle = camera.view_angle
    copy.plotter.renderer.ResetCameraClippingRange()


def _show_as(shown: MeshScene, copy: MeshScene) -> None:
    """Show and hide ``copy``'s props as ``shown``'s are, its rulers' titles in their
    colours."""
    for name in LAYERS:
        copy.actors[name].SetVisibility(shown.actors[name].GetVisibility())
    for name in ("actors_overview", "actors_zoom", "scalar_bar", "legend_title", "note", "axes"):
        getattr(copy, name).SetVisibility(getattr(shown, name).GetVisibility())
    for axis in range(2):
        colour = shown.axes.GetTitleTextProperty(axis).GetColor()
        copy.axes.GetTitleTextProperty(axis).SetColor(colour)


def _scale_pixels(shown: MeshScene, copy: MeshScene, scale: float) -> None:
    """Lines, dots, fonts, text offsets and rule widths of ``copy``: ``shown``'s, times
    ``scale``."""
    for name in LAYERS:
        if name == "labels":  # a 2D actor: its font is scaled below
            continue
        prop, mine = shown.actors[name].prop, copy.actors[name].prop
        mine.line_width = prop.line_width * scale
        mine.point_size = prop.point_size * scale
    for prop, mine in zip(_text_props(shown), _text_props(copy), strict=True):
        mine.SetFontSize(int(round(prop.GetFontSize() * scale)))
        mine.SetLineOffset(prop.GetLineOffset())
    for prop, mine in zip(_axes_line_props(shown), _axes_line_props(copy), strict=True):
        mine.SetLineWidth(prop.GetLineWidth() * scale)


def _view_size(scene: MeshScene) -> tuple[int, int]:
    width, height = (int(v) for v in scene.plotter.ren_win.GetSize())
    return max(width, 1), max(height, 1)


def _scaled_size(scene: MeshScene, scale: float) -> tuple[int, int]:
    width, height = _view_size(scene)
    return max(1, round(width * scale)), max(1, round(height * scale))


def _scene_copy(
    scene: MeshScene, scale: float, size: tuple[int, int] | None = None
) -> tuple[pv.Plotter, MeshScene]:
    """An off-screen plotter of ``size`` pixels (default: ``scale`` times the view's)
    drawing what ``scene`` draws, every pixel measure times ``scale``; as many samples a
    pixel as the view (the view's look, and a software renderer's time)."""
    width, height = size if size is not None else _scaled_size(scene, scale)
    samples = int(scene.plotter.ren_win.GetMultiSamples())
    plotter = pv.Plotter(off_screen=True, window_size=(width, height))
    try:
        plotter.ren_win.SetMultiSamples(samples)
        copy = MeshScene(plotter, visible=dict(scene.visible), color_by=scene.color_by)
        # colour tables, legend ticks and ranges as the view has them (the overview
        # object and its images are shared, not rebuilt: their colouring is the same)
        copy.bounds, copy.ranges = scene.bounds, scene.ranges
        copy.n_triangles, copy.overview, copy.zoom = (scene.n_triangles, scene.overview, scene.zoom)
        copy.paper, copy.overlap_ratio = scene.paper, scene.overlap_ratio
        copy.axes.n_xlabels, copy.axes.n_ylabels = scene.axes.n_xlabels, scene.axes.n_ylabels
        copy.axes.x_label_format = scene.axes.x_label_format
        copy.axes.y_label_format = scene.axes.y_label_format
        copy.axes.x_title, copy.axes.y_title = scene.axes.x_title, scene.axes.y_title
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


def _check_scale(scale: object, limit: float | None = MAX_SCALE) -> float:
    if isinstance(scale, bool) or not isinstance(scale, int | float | np.integer | np.floating):
        raise ValueError(f"scale={scale!r} is invalid; expected a number 1..{limit}")
    value = float(scale)
    if not math.isfinite(value) or value < 1 or (limit is not None and value > limit):
        raise ValueError(f"scale={scale!r} is invalid; expected a number 1..{limit}")
    return value


class ScaledShot:
    """The view of ``scene`` at ``scale`` times its pixel size, drawn in steps.

    Parameters
    ----------
    scene : MeshScene
        The scene drawn (the window's, or an off-screen one of the command line).
    scale : float
        1 to :data:`MAX_SCALE` (any number from 1 up with ``size``).
    transparent : bool
        Transparent background (an RGBA image) instead of the scene's.
    size : (int, int), optional
        The image's width and height in pixels, about ``scale`` times the view's
        (default: exactly that, rounded).

    Examples
    --------
    The steps one at a time (an event loop may run between them), then the picture:

    >>> shot = ScaledShot(scene, 3)  # doctest: +SKIP
    >>> progress = [fraction for fraction, _text in shot.steps()]  # doctest: +SKIP
    >>> shot.image.shape  # (3 h, 3 w, 3)  # doctest: +SKIP
    """

    def __init__(
        self,
        scene: MeshScene,
        scale: float,
        transparent: bool = False,
        size: tuple[int, int] | None = None,
    ) -> None:
        self.scene = scene
        self.scale = _check_scale(scale, None if size is not None else MAX_SCALE)
        self.transparent = bool(transparent)
        self.size: tuple[int, int] = (
            (int(size[0]), int(size[1])) if size else _scaled_size(scene, self.scale)
        )
        self.view = _view_size(scene)
        width, height = self.size
        tile_w, tile_h = self.view
        #: lower-left corners (display pixels, y up) of the tiles covering the image
        self.tiles = [(x, y) for y in range(0, height, tile_h) for x in range(0, width, tile_w)]
        #: renders in all: the annotation, the tiles
        self.total = 1 + len(self.tiles)
        self.image: np.ndarray | None = None

    def _margin(self) -> int:
        """Pixels around a tile: half the widest dot or line of the copy, and some."""
        widest = 0.0
        for name in LAYERS:
            if name == "labels":
                continue
            prop = self.scene.actors[name].prop
            widest = max(widest, prop.point_size, prop.line_width)
        return int(math.ceil(0.5 * widest * self.scale)) + _MARGIN_PX

    def steps(self) -> Iterator[tuple[float, str]]:
        """Draw the picture one render at a time; yields (fraction done, what comes next)
        after each. :attr:`image` holds the picture once the steps are exhausted. Closing
        the generator early (Cancel) frees what it made."""
        done = 0

        def progress(text: str) -> tuple[float, str]:
            return done / self.total, text

        width, height = self.size
        tile_w, tile_h = self.view
        margin = self._margin()
        annotation = self._annotation()
        done += 1
        yield progress(f"drawing the mesh: tile 1 of {len(self.tiles)}")
        plotter, copy = _scene_copy(self.scene, 1.0, self.view)
        try:
            # the tiles: the view's size and a margin, lines and dots k times as wide
            plotter.window_size = (tile_w + 2 * margin, tile_h + 2 * margin)
            _show_as(self.scene, copy)
            _scale_pixels(self.scene, copy, self.scale)
            for prop in _annotation(copy):
                prop.SetVisibility(False)
            camera = copy.plotter.renderer.GetActiveCamera()
            full_scale = float(camera.GetParallelScale())
            full_angle = float(camera.GetViewAngle())
            tall = tile_h + 2 * margin
            # a tile's pixel is the image's: the tile's window is (its height) / (the
            # image's) of the view's, centred where the tile's middle is
            camera.SetParallelScale(full_scale * tall / height)
            half = math.radians(0.5 * full_angle)
            camera.SetViewAngle(2.0 * math.degrees(math.atan(math.tan(half) * tall / height)))
            channels = 4 if self.transparent else 3
            mesh = np.empty((height, width, channels), dtype=np.uint8)
            for i, (x0, y0) in enumerate(self.tiles):
                dx = x0 + 0.5 * tile_w - 0.5 * width
                dy = y0 + 0.5 * tile_h - 0.5 * height
                camera.SetWindowCenter(dx / (0.5 * (tile_w + 2 * margin)), dy / (0.5 * tall))
                plotter.render()
                shot = plotter.screenshot(
                    None, transparent_background=self.transparent, return_img=True
                )
                shot = np.asarray(shot)[margin : margin + tile_h, margin : margin + tile_w]
                w, h = min(tile_w, width - x0), min(tile_h, height - y0)
                # display rows grow upwards, image rows downwards
                rows = slice(height - y0 - h, height - y0)
                mesh[rows, x0 : x0 + w] = shot[tile_h - h :, :w, :channels]
                done += 1
                more = i + 1 < len(self.tiles)
                yield progress(
                    f"drawing the mesh: tile {i + 2} of {len(self.tiles)}"
                    if more
                    else "laying the rulers and legend over the mesh"
                )
        finally:
            plotter.close()
        self.image = _over(annotation, mesh, self.scene.plotter.background_color.float_rgb)

    def _annotation(self) -> np.ndarray:
        """The annotation alone at the image's size, (h, w, 4) uint8 over a transparent
        background (its colour left in the colour channels, as VTK blends). The rulers
        measure their ticks, gaps and titles' distances in multiples of their font size,
        so at k times the fonts they are k times as far out, as in a k times larger view."""
        plotter, copy = _scene_copy(self.scene, self.scale, self.size)
        try:
            for prop in _mesh_props(copy):
                prop.SetVisibility(False)
            plotter.render()
            shot = plotter.screenshot(None, transparent_background=True, return_img=True)
        finally:
            plotter.close()
        return np.asarray(shot)


def _over(annotation: np.ndarray, mesh: np.ndarray, background: tuple) -> np.ndarray:
    """``annotation`` (h, w, 4) laid over ``mesh`` (h, w, 3 or 4) as one render draws it.

    VTK blends a 2D prop's colour c at opacity a into a pixel as c a + (1 - a) p and
    keeps a as the alpha; over the cleared ``background`` colour B (0..1 floats) the
    annotation layer holds A = c a + (1 - a) B. Over the mesh's pixel T the single render
    would hold c a + (1 - a) T = A + (1 - a)(T - B); the alphas combine as usual.
    """
    out = np.array(mesh, dtype=np.uint8, order="C")
    drawn = annotation[..., 3] > 0  # (most pixels hold no annotation: the mesh's as is)
    a = annotation[drawn, 3:4].astype(np.float32) / 255.0
    back = np.asarray(background, dtype=np.float32)[:3] * 255.0
    under = mesh[drawn]
    rgb = annotation[drawn, :3].astype(np.float32) + (1.0 - a) * (
        under[:, :3].astype(np.float32) - back
    )
    out[drawn, :3] = np.clip(np.rint(rgb), 0, 255).astype(np.uint8)
    if mesh.shape[-1] == 4:
        alpha = 255.0 * a[:, 0] + (1.0 - a[:, 0]) * under[:, 3].astype(np.float32)
        out[drawn, 3] = np.clip(np.rint(alpha), 0, 255).astype(np.uint8)
    return out


def scaled_view_image(
    scene: MeshScene,
    scale: float,
    transparent: bool = False,
    size: tuple[int, int] | None = None,
) -> np.ndarray:
    """The view of ``scene`` at ``scale`` times its pixel size, drawn as the view looks
    (all of :meth:`ScaledShot.steps` at once).

    Parameters
    ----------
    scene : MeshScene
        The window's scene (its plotter is the on-screen view), or an off-screen one.
    scale : float
        1 to :data:`MAX_SCALE` (any number from 1 up with ``size``); the image is
        ``scale`` times the render window's size.
    transparent : bool
        Transparent background (an RGBA image) instead of white.
    size : (int, int), optional
        The image's exact width and height (about ``scale`` times the view's).

    Returns
    -------
    (h * scale, w * scale, 3 or 4) uint8 ndarray
    """
    shot = ScaledShot(scene, scale, transparent, size)
    for _ in shot.steps():
        pass
    assert shot.image is not None  # the steps ran to their end
    return shot.image


#: The size (px) a screenshot is drawn at as the window draws its view; a larger one is
#: that picture at more pixels, its text, lines and dots scaled along
#: (:func:`screenshot_scale`).
SCREENSHOT_BASE = (1024, 768)


def screenshot_scale(width: int, height: int) -> float:
    """How many times :data:`SCREENSHOT_BASE` the picture of a ``width`` x ``height``
    screenshot is: the smaller of the two ratios, at least 1 (a smaller image is drawn at
    its own size, text at its normal size).

    >>> screenshot_scale(3072, 2304), screenshot_scale(1600, 1200), screenshot_scale(200, 150)
    (3.0, 1.5625, 1.0)
    """
    base_w, base_h = SCREENSHOT_BASE
    return max(1.0, min(width / base_w, height / base_h))


def render_screenshot(
    mesh: TriMesh,
    path: str | os.PathLike[str],
    window_size: tuple[int, int] = (1024, 768),
    transparent: bool = False,
    *,
    visible: dict[str, bool] | None = None,
    color_by: str = "none",
) -> None:
    """Render ``mesh`` off-screen from above and save a PNG of exactly ``window_size``.

    Parallel projection, rulers in mm, triangles with their edges, centroids, shared
    and boundary edges (and junction edges, if any) in distinct colours. Works without
    an X display (VTK's EGL render window, Mesa's llvmpipe as the software driver).
    Above :data:`SCREENSHOT_BASE` the image is the picture at that size drawn with
    :func:`screenshot_scale` times the pixels, as File → Export screenshot draws the
    view at 2x to 4x (:class:`ScaledShot`): text, rulers, lines and dots
    grow with the image (tick labels about 12 px tall at 1024 x 768, 36 px at
    3072 x 2304), and what is drawn (the light look of small triangles) is decided at
    the base size.

    Parameters
    ----------
    mesh : TriMesh
    path : path-like
        Output PNG file.
    window_size : (int, int)
        Width and height in pixels.
    transparent : bool
        Transparent background instead of white.
    visible : dict of str to bool, optional
        Layer visibility overrides (see :data:`barymesh.app.model.layers.LAYERS`).
    color_by : str
        Face colouring, a key of :data:`barymesh.app.model.layers.COLOR_BY`.
    """
    width, height = (int(v) for v in window_size)
    if width < 1 or height < 1:
        raise ValueError(f"window_size={window_size!r} is invalid; expected two positive ints")
    path = Path(path)
    prepare_headless()
    scale = screenshot_scale(width, height)
    base = (max(1, round(width / scale)), max(1, round(height / scale)))
    plotter = pv.Plotter(off_screen=True, window_size=base)
    try:
        scene = MeshScene(plotter, visible=visible, color_by=color_by)
        scene.update(scene_data(mesh, pixels=(width, height)))
        scene.top_view()
        if scale > 1.0:
            image = scaled_view_image(scene, scale, transparent, size=(width, height))
        else:
            image = plotter.screenshot(None, transparent_background=transparent, return_img=True)
    finally:
        plotter.close()
    image = np.asarray(image)
    if image.shape[:2] != (height, width):  # high-DPI or a window manager resized it
        image = resized_image(image, width, height)
    import imageio.v3 as iio

    iio.imwrite(path, image, extension=".png")

"""Sweep animations: one parameter varied over K frames, saved as GIF or MP4.

Rendered off-screen with pyvista (no display needed) and encoded with imageio.
The camera is fixed on the union of all frames' extents so that a growing
radius is seen growing.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import numpy as np
import numpy.typing as npt
import pyvista as pv

from barymesh import MeshParams, build_mesh
from barymesh.app.view.scene import MeshScene, prepare_headless
from barymesh.app.view.scene_data import scene_data
from barymesh.io import atomic_write
from barymesh.teach.sweep import check_sweep_size, sweep_params

#: Encodings by extension.
ANIMATION_EXTENSIONS = (".gif", ".mp4")
#: GIF frame delays are whole hundredths of a second: 100 fps is the fastest.
MAX_FPS = 100

UNITS = {
    "inner_radius": "mm",
    "outer_radius": "mm",
    "patch_size": "mm",
    "angle_step": "°",
    "subdivisions": "",
    "gap_width": "mm",
    "gap_angle": "°",
}


class SweepCancelled(Exception):
    """The user stopped the sweep."""


def frame_caption(params: MeshParams, name: str, triangles: int) -> str:
    """The caption drawn on a frame, e.g. ``angle_step = 10°   (2,304 triangles)``."""
    value = getattr(params, name)
    text = f"{value:g}" if isinstance(value, float) else str(value)
    unit = UNITS.get(name, "")
    sep = "" if unit in ("°", "") else " "
    return f"{name} = {text}{sep}{unit}   ({triangles:,} triangles)"


def render_sweep(
    base: MeshParams,
    name: str,
    start: float,
    stop: float,
    frames: int,
    path: str | os.PathLike[str],
    *,
    window_size: tuple[int, int] = (800, 600),
    fps: float = 4.0,
    progress: Callable[[int, int], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> int:
    """Render a sweep of ``name`` from ``start`` to ``stop`` and save it.

    Parameters
    ----------
    base : MeshParams
        The other parameters.
    name, start, stop, frames
        See :func:`barymesh.teach.sweep.sweep_params`.
    path : path-like
        ``.gif`` or ``.mp4``; written atomically.
    window_size : (int, int)
        Frame size in pixels.
    fps : float
        Frames per second.
    progress : callable, optional
        Called with (done, total) after each meshed and each rendered frame.
    should_stop : callable, optional
        Polled between frames; when it returns True, :class:`SweepCancelled` is raised
        and nothing is written.

    Returns
    -------
    int
        The number of frames written.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in ANIMATION_EXTENSIONS:
        raise ValueError(
            f"{path}: unsupported animation format {suffix or '(none)'!r}; "
            f"expected one of {', '.join(ANIMATION_EXTENSIONS)}"
        )
    if not 0 < fps <= MAX_FPS:
        raise ValueError(f"fps={fps!r} is invalid; expected more than 0, up to {MAX_FPS}")
    check_sweep_size(frames, window_size)
    steps = sweep_params(base, name, start, stop, frames)
    total = 2 * len(steps)
    done = 0

    def tick() -> None:
        nonlocal done
        done += 1
        if progress is not None:
            progress(done, total)
        if should_stop is not None and should_stop():
            raise SweepCancelled("sweep cancelled")

    # first pass: every frame's extent and caption (one mesh in memory at a time)
    extents, captions = [], []
    for p in steps:
        mesh = build_mesh(p)
        pts = np.asarray(mesh.points)
        extents.append((pts[:, 0].min(), pts[:, 0].max(), pts[:, 1].min(), pts[:, 1].max()))
        captions.append(frame_caption(p, name, mesh.n_triangles))
        del mesh, pts
        tick()
    x0, x1, y0, y1 = (f(e[k] for e in extents) for k, f in enumerate((min, max, min, max)))

    # second pass: mesh again and render, so memory does not grow with the frame count
    width, height = (int(v) for v in window_size)
    prepare_headless()
    plotter = pv.Plotter(off_screen=True, window_size=(width, height))
    images: list[npt.ArrayLike] = []
    try:
        scene = MeshScene(plotter)
        caption = plotter.add_text("", position="upper_left", font_size=11, color="#202020")
        for p, text in zip(steps, captions, strict=True):
            caption.SetText(2, text)  # corner 2: upper left
            scene.update(scene_data(build_mesh(p)))
            scene.bounds = (x0, x1, y0, y1)
            scene.top_view()
            plotter.render()  # this frame's mesh *and* caption, before the grab
            images.append(np.asarray(plotter.screenshot(None, return_img=True))[:, :, :3])
            tick()
    finally:
        plotter.close()
    _encode(images, path, fps)
    return len(images)


def _encode(images: list[npt.ArrayLike], path: Path, fps: float) -> None:
    import imageio.v2 as imageio

    suffix = path.suffix.lower()

    def write(tmp: Path) -> None:
        if suffix == ".gif":  # imageio's GIF writer takes each frame's duration in ms
            imageio.mimwrite(tmp, images, format="GIF", duration=1000.0 / fps, loop=0)
        else:
            imageio.mimwrite(tmp, images, format="FFMPEG", fps=fps, macro_block_size=2)

    atomic_write(path, write)

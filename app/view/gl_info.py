"""Which OpenGL the windows draw with, asked once per process, and the multi-sampling
that follows from it.

Every 3D view (the main window, the pixel painter, the Compare and Construction views)
turns multi-sampling off on a software rasteriser: llvmpipe triples a frame's time with
4 samples (the drags' latency budget), and the picture barely changes. Each asked VTK
(``ReportCapabilities``) before; a view not yet painted answers that through a throwaway
OpenGL context and VTK window of pyvistaqt's, and it changed the samples of a render
window that had already drawn or not depending on whether its first paint or a zero timer
came first. Now one small Qt context is asked once, before any view exists, and every
view gets its samples when it is made, before its first frame.
"""

from __future__ import annotations

import functools
import logging
import os
from typing import Any

from PySide6.QtGui import QOffscreenSurface, QOpenGLContext

log = logging.getLogger(__name__)

#: Samples per pixel on a GPU; none on a software rasteriser. ``BARYMESH_MSAA`` overrides.
MULTI_SAMPLES = 4
#: Renderer names of software rasterisers (Mesa's).
SOFTWARE = ("llvmpipe", "softpipe", "swrast")
_GL_RENDERER = 0x1F01


@functools.lru_cache(maxsize=1)
def renderer_name() -> str:
    """``GL_RENDERER`` of an OpenGL context made as the views' are ("" if Qt cannot make
    one); needs the application. Asked once per process and left current nowhere."""
    before = QOpenGLContext.currentContext()
    surface_before = before.surface() if before is not None else None
    context = QOpenGLContext()
    surface = QOffscreenSurface()
    surface.create()
    name = ""
    try:
        if context.create() and surface.isValid() and context.makeCurrent(surface):
            name = str(context.functions().glGetString(_GL_RENDERER) or "")
            context.doneCurrent()
    except Exception:  # noqa: BLE001 - a name is a nicety: the views draw either way
        log.debug("could not ask OpenGL for its renderer", exc_info=True)
    finally:
        surface.destroy()
        if before is not None and surface_before is not None:
            before.makeCurrent(surface_before)
    return name


def multi_samples() -> int:
    """Samples per pixel for a new view: ``BARYMESH_MSAA`` if set, else none on a software
    rasteriser (:data:`SOFTWARE`) and :data:`MULTI_SAMPLES` otherwise."""
    wanted = os.environ.get("BARYMESH_MSAA")
    if wanted is not None:
        try:
            return max(0, int(wanted))
        except ValueError:
            log.warning("BARYMESH_MSAA=%r is not a whole number", wanted)
    name = renderer_name().lower()
    return 0 if any(s in name for s in SOFTWARE) else MULTI_SAMPLES


def tune_multi_samples(plotter: Any) -> int:
    """Give ``plotter``'s render window :func:`multi_samples` (call before its first frame);
    returns them."""
    samples = multi_samples()
    plotter.ren_win.SetMultiSamples(samples)
    return samples

"""The main 3D view's widget: a pyvistaqt ``QtInteractor`` that draws each frame once.

VTK's interactor styles render inside their event handlers (a wheel step, every mouse
move of a rotation or a pan), and pyvistaqt's widget renders again in ``paintGL``, which
the finished render's ``WindowFrameEvent`` schedules: each frame of an interaction was
drawn twice, and under a software renderer a 1M-triangle rotation or a wheel step over a
200k-triangle mesh held the event loop for both. :class:`ViewInteractor` switches the
interactor's own rendering off, as VTK's C++ ``QVTKOpenGLNativeWidget`` does: a render
asked for by VTK (``vtkRenderWindowInteractor::Render``, which still announces itself
with ``RenderEvent``) schedules a paint, and ``paintGL`` draws. Mouse moves that come
between two paints make one frame.

GUI thread only (it owns VTK objects).
"""

from __future__ import annotations

from typing import Any

from pyvistaqt import QtInteractor


class ViewInteractor(QtInteractor):
    """``QtInteractor`` whose VTK interaction renders are drawn by the next paint only.

    ``renders_asked`` counts the renders VTK asked for (each became a request for a
    paint, merged by Qt with the others before it).
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._painting = False
        self.renders_asked = 0
        interactor = self.ren_win.GetInteractor()
        interactor.EnableRenderOff()
        interactor.AddObserver("RenderEvent", self._render_asked)

    def _render_asked(self, *_args: Any) -> None:
        if not self._painting:
            self.renders_asked += 1
            self.update()

    def paintGL(self) -> None:  # noqa: N802 - Qt's name
        window = self.ren_win
        interactor = window.GetInteractor() if window is not None else None
        if interactor is None:
            super().paintGL()
            return
        self._painting = True
        interactor.EnableRenderOn()  # pyvistaqt's paint renders through the interactor
        try:
            super().paintGL()
        finally:
            interactor.EnableRenderOff()
            self._painting = False


def disable_view_keys(plotter: Any) -> None:
    """Keys typed into the 3D view do nothing of VTK's or pyvista's own.

    VTK's interactor style would switch to red-blue stereo on "3", to wireframe on "w",
    fly on "f", exit on "q"/"e"…, and pyvista adds "v" (isometric view) and others; none
    is a documented action of the window, whose own shortcuts (R, T, Ctrl+1…) are
    QActions and keep working. An observer of the style's CharEvent replaces its OnChar.
    """
    for key in list(getattr(plotter, "_key_press_event_callbacks", {})):
        plotter.clear_events_for_key(key, raise_on_missing=False)
    style = plotter.iren.interactor.GetInteractorStyle()
    if style is not None:
        style.AddObserver("CharEvent", lambda *_: None)


def close_view(plotter: Any) -> None:
    """Close a pyvistaqt view (its VTK render window finalised) and drop its wrapper of
    the widget's OpenGL surface.

    pyvistaqt keeps ``_surface``, a wrapper of the ``QSurface`` it made its context current
    on, after the widget and its context are deleted: shiboken cannot follow the lifetime
    of a class that is not a ``QObject``, so the dead surface's address stays mapped to
    that wrapper, and a widget Qt later makes at the same address was handed out as it (CI:
    a combo box's ``lineEdit()`` returned a ``QSurface``). Once the view is closed no frame
    is drawn in it, so the wrapper is forgotten here.
    """
    plotter.close()
    if getattr(plotter, "_surface", None) is not None:
        plotter._surface = None

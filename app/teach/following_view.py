"""Base of the teaching windows that follow the main window's parameters."""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
from PySide6.QtCore import QEvent, QObject, Qt, QTimer
from PySide6.QtGui import QCloseEvent, QKeySequence, QShortcut
from PySide6.QtWidgets import QWidget

if TYPE_CHECKING:
    from barymesh import MeshParams
    from barymesh.app.model import AppModel

log = logging.getLogger(__name__)

#: The window's own fonts grow by this factor in presentation mode (F5).
FONT_FACTOR = 1.5


class _AfterNextPaint(QObject):
    """Calls ``callback`` by a timer right after ``widget``'s next paint (once)."""

    def __init__(self, widget: QWidget, callback: Any) -> None:
        super().__init__(widget)
        self.callback = callback
        widget.installEventFilter(self)

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:  # noqa: N802 - Qt's name
        if event.type() == QEvent.Type.Paint:
            watched.removeEventFilter(self)
            QTimer.singleShot(1, self.callback)  # a timer: after this paint is done
            self.deleteLater()
        return False


class FollowingView(QWidget):
    """A window with its own pyvistaqt ``plotter`` that follows ``model.params_changed``.

    Subclasses set ``self.model``, ``self.plotter``, connect ``self._params_changed``,
    call :meth:`_add_presentation_key` and may extend :meth:`_stop` (called once, before
    the GL context is released) and :meth:`refit` (frame the view again after a resize).
    """

    _closed = False
    presenting = False
    _unrevealed: list[Any] | None = None
    # set by the subclasses
    model: AppModel
    plotter: Any  # a pyvistaqt QtInteractor
    _params_changed: Callable[[MeshParams], None]

    @property
    def closed(self) -> bool:
        """Whether the window was closed (it stopped following, its view is released)."""
        return self._closed

    def _add_presentation_key(self) -> None:
        """F5 in this window: full screen with larger fonts, F5 again: back."""
        shortcut = QShortcut(QKeySequence("F5"), self)
        shortcut.setContext(Qt.ShortcutContext.WindowShortcut)
        shortcut.activated.connect(self.toggle_presentation)

    def toggle_presentation(self) -> None:
        """Presentation mode of this window: the whole screen, fonts 1.5×, view re-framed."""
        self.presenting = not self.presenting
        if self.presenting:
            self._normal = (self.windowState(), self.geometry(), self.font())
            bigger = self.font()
            bigger.setPointSizeF(max(bigger.pointSizeF(), 9.0) * FONT_FACTOR)
            self.setFont(bigger)
            self.showFullScreen()
            self.setGeometry(self.screen().geometry())  # a bare X server has no manager
        else:
            state, geometry, font = self._normal
            self.setFont(font)
            self.setWindowState(state)
            if not state & (Qt.WindowState.WindowMaximized | Qt.WindowState.WindowFullScreen):
                self.setGeometry(geometry)
        QTimer.singleShot(0, self.refit)

    def refit(self) -> None:
        """Frame the view again (after a resize); the subclass knows what to frame."""

    def _paint_empty_first(self) -> None:
        """Hide every visible prop until the window has painted once, then show them.

        The first paint of a new window's view sets up its GL context and the scene's
        first render compiles its shaders (on llvmpipe, on this thread): together they
        held the event loop for one long pass. Now the first paint draws the background
        only and the scene comes by a timer right after it, in the next pass.
        """
        self._unrevealed = self._hide_props(self.plotter.renderers)
        _AfterNextPaint(self.plotter, self._reveal)

    @staticmethod
    def _hide_props(renderers: Any) -> list[Any]:
        """Hide the visible props of ``renderers``; returns them."""
        hidden = []
        for renderer in renderers:
            props = renderer.GetViewProps()
            for i in range(props.GetNumberOfItems()):
                prop = props.GetItemAsObject(i)
                if prop.GetVisibility():
                    prop.SetVisibility(False)
                    hidden.append(prop)
        return hidden

    def _draw_in_two_passes(self, renderers: Any) -> None:
        """Hide the props of ``renderers`` now and show them by a timer, in the next pass
        of the event loop (a scene's first render compiles its shaders: in two passes,
        half of them each)."""
        self._unrevealed = [*(self._unrevealed or []), *self._hide_props(renderers)]
        _AfterNextPaint(self.plotter, self._reveal)

    def _reveal(self) -> None:
        """Show the props :meth:`_paint_empty_first` hid (idempotent)."""
        hidden, self._unrevealed = getattr(self, "_unrevealed", None), None
        if not hidden or self._closed:
            return
        for prop in hidden:
            prop.SetVisibility(True)
        self.plotter.update()

    def view_image(self) -> np.ndarray:
        """The 3D view as an (h, w, 3) uint8 array (as it is now: a change waiting for its
        paint is rendered first)."""
        self._reveal()
        self.plotter.render()
        image = self.plotter.screenshot(None, return_img=True)
        self.plotter.render()
        return np.ascontiguousarray(image)

    def closeEvent(self, event: QCloseEvent) -> None:  # noqa: N802 - Qt's name
        self.shutdown()
        super().closeEvent(event)

    def _follow_cells(self) -> None:
        """Also follow the selected element of a unit cell: selecting another element
        changes ``model.params`` (the Parameters panel edits it) without a new mesh, so
        without ``params_changed``; ``cell_changed`` says so."""
        self._followed = self.model.params
        self.model.params_changed.connect(self._note_params)
        self.model.cell_changed.connect(self._cell_changed)

    def _note_params(self, params: Any) -> None:
        self._followed = params

    def _cell_changed(self, _state: Any) -> None:
        params = self.model.params
        if not self._closed and params != getattr(self, "_followed", None):
            self._followed = params
            self._params_changed(params)

    def shutdown(self) -> None:
        """Stop following the model and release the GL context (idempotent)."""
        if self._closed:
            return
        self._closed = True
        for event, slot in (
            (self.model.params_changed, self._params_changed),
            (self.model.params_changed, self._note_params),
            (self.model.cell_changed, self._cell_changed),
        ):
            try:
                event.disconnect(slot)
            except ValueError:
                pass
        self._stop()
        from barymesh.app.view.interactor import close_view

        close_view(self.plotter)  # pyvistaqt's surface wrapper dropped too

    def _stop(self) -> None:
        """Extra work before the GL context goes (background jobs)."""

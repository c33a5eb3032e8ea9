"""Presentation mode: full screen, panels hidden, thicker lines and larger fonts, one key
there and back.

The window keeps working as usual (menus, shortcuts, picking); only what is shown
changes. :class:`PresentationMode` remembers which docks, toolbars and the status bar were
visible, and the window state (normal, maximised), and restores exactly those. The mesh
grows with the view: a framed mesh stays framed through the resize (the window's
``refit_if_framed``), a zoomed-in view keeps its zoom and simply gets more pixels.
"""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtCore import Qt
from PySide6.QtGui import QFont
from PySide6.QtWidgets import QDockWidget, QMainWindow, QToolBar, QWidget

#: Lines, dots and 3D-view fonts are this many times larger in presentation mode.
EMPHASIS = 2.0
#: The window's own fonts (menus, status bar) grow by this factor.
FONT_FACTOR = 1.5


class PresentationMode:
    """Toggle a lecture-friendly look on ``window``.

    Parameters
    ----------
    window : QMainWindow
    emphasize : callable
        Called with the emphasis factor (``EMPHASIS`` on, 1.0 off) to scale the 3D view's
        lines and fonts; the caller renders.
    """

    def __init__(self, window: QMainWindow, emphasize: Callable[[float], None]) -> None:
        self.window = window
        self.emphasize = emphasize
        self.active = False
        self._hidden: list[QWidget] = []
        self._font: QFont | None = None
        self._state: Qt.WindowState | None = None

    def panels(self) -> list[QWidget]:
        """Docks and toolbars of the window (what presentation mode hides)."""
        w = self.window
        return [*w.findChildren(QDockWidget), *w.findChildren(QToolBar)]

    def set_active(self, on: bool) -> None:
        on = bool(on)
        if on == self.active:
            return
        w = self.window
        self.active = on
        if on:
            self._hidden = [p for p in self.panels() if p.isVisible() and p.parent() is w]
            for panel in self._hidden:
                panel.hide()
            self._status_visible = w.statusBar().isVisible()
            w.statusBar().hide()
            self._font = w.font()
            bigger = w.font()
            bigger.setPointSizeF(max(bigger.pointSizeF(), 9.0) * FONT_FACTOR)
            w.setFont(bigger)
            self._state = w.windowState()
            self._geometry = w.geometry()
            w.showFullScreen()
            # without a window manager (a bare X server) full screen is not applied by
            # anyone else: take the screen ourselves (a window manager overrides this)
            w.setGeometry(w.screen().geometry())
            self.emphasize(EMPHASIS)
        else:
            for panel in self._hidden:
                panel.show()
            self._hidden = []
            w.statusBar().setVisible(self._status_visible)
            if self._font is not None:
                w.setFont(self._font)
            if self._state is not None:
                w.setWindowState(self._state)
                if not self._state & (
                    Qt.WindowState.WindowMaximized | Qt.WindowState.WindowFullScreen
                ):
                    w.setGeometry(self._geometry)
            self.emphasize(1.0)

    def toggle(self) -> None:
        self.set_active(not self.active)

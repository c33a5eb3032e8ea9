"""Cell → Paint pixels… in the main window: the pixel painter opened from its Cell menu.

:class:`PainterOpener` adds the action to the menu and makes the painter
(:class:`barymesh.app.edit.painter.PixelPainterWindow`) on first use; :func:`cell_menu`
finds or makes the one "&Cell" menu that every cell tool adds to.
"""

from __future__ import annotations

import logging

from PySide6.QtCore import QEvent, QObject, Qt
from PySide6.QtWidgets import QMainWindow, QMenu

from barymesh.app.edit.painter import PixelPainterWindow
from barymesh.app.tool_host import ToolHost

log = logging.getLogger(__name__)


class PainterOpener(QObject):
    """Cell → Paint pixels… (Ctrl+Shift+P) of a main window: the painter, made on first use,
    closed with the main window."""

    def __init__(self, host: ToolHost, menu: QMenu) -> None:
        super().__init__(host.widget)
        self.host = host
        self.painter: PixelPainterWindow | None = None
        self.act_paint = host.add_action(
            "&Paint pixels…",
            self.show,
            "Ctrl+Shift+P",
            "Paint a coding cell's pixels in top view: symmetry, fill, invert, random, undo",
        )
        menu.addAction(self.act_paint)
        host.widget.installEventFilter(self)

    def show(self) -> PixelPainterWindow | None:
        if self.painter is None or self.painter.closed:
            try:
                self.painter = PixelPainterWindow(parent=self.host.widget)
            except Exception as exc:  # noqa: BLE001 - reported, never a crash
                log.exception("could not open the pixel painter")
                self.host.show_status(f"Could not open the pixel painter: {exc}")
                return None
        self.painter.show()
        self.painter.raise_()
        self.painter.activateWindow()
        return self.painter

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:  # noqa: N802 - Qt's name
        if watched is self.host.widget and event.type() == QEvent.Type.Close and self.painter:
            try:
                self.painter.close()
            except RuntimeError:  # already deleted by Qt
                pass
        return False


def cell_menu(main: QMainWindow) -> QMenu:
    """The main window's "&Cell" menu, made (before Help) when no one has made it yet."""
    bar = main.menuBar()
    for menu in bar.findChildren(QMenu, options=Qt.FindChildOption.FindDirectChildrenOnly):
        if menu.title() == "&Cell":
            return menu
    return bar.addMenu("&Cell")

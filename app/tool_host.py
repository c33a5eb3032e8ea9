"""The small interface a window tool gets instead of the whole main window (STYLE 14).

A tool (the Cell tools, the drag tool, the pixel painter's opener, the Teach tools and
windows, the View tools) and a dock's panel (the Solve and Quality docks) adds its actions
and docks, says things on the status bar, asks
for a render, reads and writes settings and reports a file it could not read or write,
all through a :class:`ToolHost`, which :class:`barymesh.app.window.MainWindow`
implements. Anything else a tool needs (the model, the plotter, another tool's picker)
is passed to it explicitly, so the order in which the window makes its tools is the order
of their arguments (see ``MainWindow._make_tools``).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any, Protocol, runtime_checkable

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction
from PySide6.QtWidgets import QDockWidget, QMainWindow, QWidget


@runtime_checkable
class ToolHost(Protocol):
    """What a window tool may ask of the window it belongs to."""

    @property
    def widget(self) -> QMainWindow:
        """The window: parent of the tool's widgets and dialogs; its close event closes
        the tool's own windows."""
        ...

    @property
    def closed(self) -> bool:
        """Whether the window has closed (its view released): draw nothing more."""
        ...

    @property
    def arranging_docks(self) -> bool:
        """Whether the window is moving its docks itself (a dock shown or hidden then is
        not the user's doing)."""
        ...

    def add_action(
        self,
        text: str,
        slot: Callable[..., Any],
        shortcut: Any = None,
        tip: str = "",
        checkable: bool = False,
    ) -> QAction:
        """An action of the window, its shortcut working even with the menu bar hidden;
        ``shortcut`` is a key sequence or a list of them."""
        ...

    def add_dock(
        self,
        title: str,
        widget: QWidget,
        area: Qt.DockWidgetArea,
        scroll: bool = False,
        name: str | None = None,
        tab_with: QDockWidget | None = None,
    ) -> QDockWidget:
        """A dock holding ``widget`` (in a scroll area with ``scroll``), saved and restored
        with the layout under ``name`` (default ``dock_<title>``), tabbed with
        ``tab_with`` if given."""
        ...

    def show_status(self, message: str, timeout_ms: int = 0) -> None:
        """Say ``message`` on the status bar (for ``timeout_ms``, 0: until the next)."""
        ...

    def status_message(self) -> str:
        """What the status bar says now."""
        ...

    def request_render(self) -> None:
        """Ask for one paint of the 3D view (coalesced with other requests)."""
        ...

    def setting(self, key: str, default: Any = None) -> Any:
        """The saved setting ``key`` (``paths/cell``, ``export/unit``…), or ``default``."""
        ...

    def set_setting(self, key: str, value: Any) -> None:
        """Save setting ``key`` (read back by :meth:`setting`, in this and later sessions)."""
        ...

    def file_error(
        self, title: str, exc: BaseException, path: str | os.PathLike[str] | None = None
    ) -> None:
        """Report a file that could not be read or written: one sentence naming it."""
        ...

"""One way to make a window's actions: the main window's and the pixel painter's.

An action is made with its text, its slot, its shortcuts (one key sequence or a list of
them) and its tip, and is added to its window so that its shortcuts work even where no
menu or toolbar shows it (a hidden menu bar, presentation mode).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import QWidget


def make_action(
    parent: QWidget,
    text: str,
    slot: Callable[..., Any],
    shortcut: Any = None,
    tip: str = "",
    checkable: bool = False,
    keys_in_tip: bool = False,
    application_keys: tuple[str, ...] = (),
) -> QAction:
    """An action of ``parent``, added to it.

    Parameters
    ----------
    shortcut
        A key sequence or a list of them (the first is the one menus show).
    tip
        The tool tip and status tip; with ``keys_in_tip`` the keys follow it in brackets
        (for toolbars, which do not show them).
    application_keys
        Shortcuts that work from every window of the program (F1, F7, F8 of the main
        window, also from its teaching windows).
    """
    action = QAction(text, parent)
    if shortcut is not None:
        keys = shortcut if isinstance(shortcut, list) else [shortcut]
        action.setShortcuts([QKeySequence(k) for k in keys])
        if keys_in_tip:
            tip = f"{tip} ({', '.join(QKeySequence(k).toString() for k in keys)})"
        if shortcut in application_keys:
            action.setShortcutContext(Qt.ShortcutContext.ApplicationShortcut)
    if tip or keys_in_tip:
        action.setStatusTip(tip)
        action.setToolTip(tip)
    action.setCheckable(checkable)
    action.triggered.connect(slot)
    parent.addAction(action)
    return action

"""Teach menu windows of the main window: construction step by step, paper vs conforming,
and File → Export sweep animation.

Each window is made on first use, follows the main window's parameters while open, and is
closed (its GL context released) with the main window.
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING, Any

from PySide6.QtCore import QEvent, QObject
from PySide6.QtWidgets import QMenu

from barymesh.app.model import AppModel
from barymesh.app.tool_host import ToolHost

if TYPE_CHECKING:
    from barymesh.app.teach.compare_view import CompareView
    from barymesh.app.teach.construction_view import ConstructionView
    from barymesh.app.teach.sweep_dialog import SweepDialog

log = logging.getLogger(__name__)


class TeachingWindows(QObject):
    """The construction window, the compare window and the sweep dialog of one window.

    Parameters
    ----------
    host : ToolHost
        The window: the actions, the parent of the windows (closed with it), status
        messages, the sweep's folder setting.
    model : AppModel
        What the windows follow.
    """

    def __init__(self, host: ToolHost, model: AppModel) -> None:
        super().__init__(host.widget)
        self.host, self.model = host, model
        self.construction: ConstructionView | None = None
        self.compare: CompareView | None = None
        self.sweep: SweepDialog | None = None
        a = host.add_action
        self.act_construction = a(
            "&Construction step by step…",
            self.show_construction,
            "F7",
            "The paper's construction of one patch: ABCD, m1 … m22, sub-triangles, "
            "centroids, shared edges",
        )
        self.act_compare = a(
            "Paper &vs conforming…",
            self.show_compare,
            "F8",
            "The same parameters in paper and conforming mode side by side, with statistics",
        )
        self.act_sweep = a(
            "Export s&weep animation…",
            self.show_sweep,
            "Ctrl+Shift+A",
            "A GIF or MP4 of one parameter swept over K frames",
        )
        host.widget.installEventFilter(self)

    def add_to_menu(self, menu: QMenu) -> None:
        """Add the construction and compare windows to the Teach menu."""
        menu.addSeparator()
        menu.addActions([self.act_construction, self.act_compare])

    # -- windows -------------------------------------------------------------------------

    def show_construction(self) -> ConstructionView | None:
        from barymesh.app.teach.construction_view import ConstructionView

        if self.construction is None or self.construction.closed:
            try:
                self.construction = ConstructionView(self.model, self.host.widget)
            except Exception as exc:  # noqa: BLE001 - reported, never a crash
                self._failed("construction view", exc)
                return None
        self._raise(self.construction)
        return self.construction

    def show_compare(self) -> CompareView | None:
        from barymesh.app.teach.compare_view import CompareView

        if self.compare is None or self.compare.closed:
            try:
                self.compare = CompareView(self.model, self.host.widget)
            except Exception as exc:  # noqa: BLE001 - reported, never a crash
                self._failed("paper vs conforming view", exc)
                return None
        self._raise(self.compare)
        return self.compare

    def show_sweep(self) -> SweepDialog | None:
        from barymesh.app.teach.sweep_dialog import SweepDialog

        if self.sweep is not None and self.sweep.running:
            self._raise(self.sweep)
            return self.sweep
        start = str(self.host.setting("paths/sweep_dir", ""))
        try:
            self.sweep = SweepDialog(lambda: self.model.params, self.host.widget, start_dir=start)
        except Exception as exc:  # noqa: BLE001 - reported, never a crash
            self._failed("sweep dialog", exc)
            return None
        self.sweep.finished_export.connect(self._sweep_done)
        self._raise(self.sweep)
        return self.sweep

    def _sweep_done(self, outcome: object) -> None:
        if isinstance(outcome, int) and self.sweep is not None:
            from pathlib import Path

            path = Path(self.sweep.path.text()).expanduser()
            self.host.set_setting("paths/sweep_dir", str(path.parent))
            self.host.show_status(f"Wrote {outcome} frames to {path}", 8000)

    @staticmethod
    def _raise(widget: Any) -> None:
        widget.show()
        widget.raise_()
        widget.activateWindow()

    def _failed(self, what: str, exc: BaseException) -> None:
        log.exception("could not open the %s", what)
        self.host.show_status(f"Could not open the {what}: {exc}")
        return None

    # -- closing with the main window ----------------------------------------------------

    def close_all(self) -> None:
        """Close every window (their interactors first, while the main one still exists)."""
        for widget in (self.sweep, self.construction, self.compare):
            if widget is not None:
                try:
                    widget.close()
                except RuntimeError:  # already deleted by Qt
                    pass

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:  # noqa: N802 - Qt's name
        if watched is self.host.widget and event.type() == QEvent.Type.Close:
            self.close_all()
        return False

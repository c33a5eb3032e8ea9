"""A matplotlib canvas that draws only while it is shown.

Qt keeps laying out and resizing the widgets of a hidden dock or tab, and matplotlib's Qt
canvas draws its figure after every resize and every ``draw_idle``: for a spy plot or a
sweep plot nobody sees, 50 to 100 ms of the event loop each time. :class:`ShownCanvas`
remembers that a draw was asked for while hidden and makes it once, when shown; and the
first paint after it is shown, when a draw is pending, is the bare background: the draw
comes in the next pass of the event loop, not in the one that also lays out and paints
the dock or tab just shown (which held the loop for both).
"""

from __future__ import annotations

from typing import Any

from matplotlib.backends.backend_qtagg import FigureCanvasQTAgg
from matplotlib.colors import to_hex
from PySide6.QtCore import QTimer
from PySide6.QtGui import QColor, QPainter


class ShownCanvas(FigureCanvasQTAgg):
    """``FigureCanvasQTAgg`` whose ``draw_idle`` waits while the canvas is hidden."""

    _wanted = False
    _fresh = False

    @property
    def draw_wanted(self) -> bool:
        """Whether a draw asked for while hidden waits for the canvas to be shown."""
        return self._wanted

    def draw_idle(self) -> None:
        if not self.isVisible():
            self._wanted = True
            return
        if self._fresh:  # just shown: drawn by a timer, after this pass has painted
            if not getattr(self, "_draw_pending", False):
                self._draw_pending = True
                QTimer.singleShot(1, self._draw_idle)  # a timer, not a posted call
            return
        super().draw_idle()

    def showEvent(self, event: Any) -> None:  # noqa: N802 - Qt's name
        super().showEvent(event)
        self._fresh = True
        if self._wanted:
            self._wanted = False
            self.draw_idle()

    def paintEvent(self, event: Any) -> None:  # noqa: N802 - Qt's name
        fresh, self._fresh = self._fresh, False
        if fresh and getattr(self, "_draw_pending", False):
            # the pending draw comes with the next pass of the event loop and paints again
            painter = QPainter(self)
            painter.fillRect(self.rect(), QColor(to_hex(self.figure.get_facecolor())))
            painter.end()
            return
        super().paintEvent(event)

"""A matplotlib canvas that draws only while it is shown.

Qt keeps laying out and resizing the widgets of a hidden dock or tab, and matplotlib's Qt
canvas draws its figure after every resize and every ``draw_idle``: for a spy plot or a
sweep plot nobody sees, 50 to 100 ms of the event loop each time. :class:`ShownCanvas`
remembers that a draw was asked for while hidden and makes it once, when shown.
"""

from __future__ import annotations

from typing import Any

from matplotlib.backends.backend_qtagg import FigureCanvasQTAgg


class ShownCanvas(FigureCanvasQTAgg):
    """``FigureCanvasQTAgg`` whose ``draw_idle`` waits while the canvas is hidden."""

    _wanted = False

    @property
    def draw_wanted(self) -> bool:
        """Whether a draw asked for while hidden waits for the canvas to be shown."""
        return self._wanted

    def draw_idle(self) -> None:
        if not self.isVisible():
            self._wanted = True
            return
        super().draw_idle()

    def showEvent(self, event: Any) -> None:  # noqa: N802 - Qt's name
        super().showEvent(event)
        if self._wanted:
            self._wanted = False
            super().draw_idle()

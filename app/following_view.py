"""Base of the teaching windows that follow the main window's parameters."""

from __future__ import annotations

import numpy as np
from PySide6.QtGui import QCloseEvent
from PySide6.QtWidgets import QWidget


class FollowingView(QWidget):
    """A window with its own pyvistaqt ``plotter`` that follows ``model.params_changed``.

    Subclasses set ``self.model``, ``self.plotter``, connect ``self._params_changed`` and
    may extend :meth:`_stop` (called once, before the GL context is released).
    """

    _closed = False

    def view_image(self) -> np.ndarray:
        """The 3D view as an (h, w, 3) uint8 array."""
        image = self.plotter.screenshot(None, return_img=True)
        self.plotter.render()
        return np.ascontiguousarray(image)

    def closeEvent(self, event: QCloseEvent) -> None:  # noqa: N802 - Qt's name
        self.shutdown()
        super().closeEvent(event)

    def shutdown(self) -> None:
        """Stop following the model and release the GL context (idempotent)."""
        if self._closed:
            return
        self._closed = True
        try:
            self.model.params_changed.disconnect(self._params_changed)
        except ValueError:
            pass
        self._stop()
        self.plotter.close()

    def _stop(self) -> None:
        """Extra work before the GL context goes (background jobs)."""

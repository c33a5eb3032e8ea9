"""The window's first frame, for ``benchmarks/startup.py``: run ``barymesh`` (the window,
with any options given) and print ``first-frame T`` (``time.monotonic()``, the clock every
process shares) once the 3D view has been painted with the mesh, then close.

The parent takes its own ``time.monotonic()`` just before it starts this process: the
difference is the time from launch to the first frame a user sees, imports included.
The window is the one ``barymesh`` opens (:func:`barymesh.app.window_main.main`); only its
paint counter's callback is wrapped, to notice the paint.
"""

from __future__ import annotations

import sys
import time

from PySide6.QtWidgets import QApplication

from barymesh.app import window_main


class TimedWindow(window_main.MainWindow):
    """The main window, which reports its first paint that shows a mesh and closes."""

    def __init__(self, *args: object, **kwargs: object) -> None:
        super().__init__(*args, **kwargs)
        self._window_painted = self.paint_counter.after_paint
        self.paint_counter.after_paint = self._first_frame
        self.first_frame: float | None = None

    def _first_frame(self) -> None:
        if self._window_painted is not None:
            self._window_painted()
        if self.first_frame is None and self.presenter.shown_scene is not None:
            self.first_frame = time.monotonic()
            print(f"first-frame {self.first_frame:.6f}", flush=True)
            self.close()
            QApplication.exit(0)


if __name__ == "__main__":
    window_main.MainWindow = TimedWindow  # type: ignore[misc]  # main() makes this one
    sys.exit(window_main.main(sys.argv[1:]))

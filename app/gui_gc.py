"""Python's cyclic garbage collection, run in the GUI thread only.

The window's worker threads (meshing, solves, Agg figures) allocate Python objects, and
CPython runs its cyclic collector in whichever thread happens to cross the allocation
threshold. When that is a worker and the garbage holds a VTK object, the worker (holding
the GIL) waits for VTK's garbage-collector lock while the GUI thread, inside a VTK render
that holds that lock, waits for the GIL in a Python observer: the window hangs. Seen in
``tests/test_app_views.py``: a wheel event rendering cube axes against the Infinite array
tab's figure drawn in a worker.

:func:`collect_in_gui_thread` turns the automatic collector off and runs it from a timer
of the application instead, with CPython's own generation thresholds, so that every
collection runs in the GUI thread, between events.
"""

from __future__ import annotations

import gc

from PySide6.QtCore import QCoreApplication, QObject, QThread, QTimer

#: How often the GUI thread looks at the allocation counts (ms).
INTERVAL_MS = 100

_COLLECTOR: GuiThreadCollector | None = None


class GuiThreadCollector(QObject):
    """A timer in the GUI thread that collects each generation past its threshold."""

    def __init__(self, parent: QObject) -> None:
        super().__init__(parent)
        self.thresholds = gc.get_threshold()
        self.collections = 0
        self.timer = QTimer(self)
        self.timer.setInterval(INTERVAL_MS)
        self.timer.timeout.connect(self.collect)
        self.timer.start()

    def collect(self) -> None:
        """Collect the oldest generation whose count is past its threshold (and the
        younger ones with it), as the automatic collector would."""
        counts = gc.get_count()
        generation = -1
        for g in range(3):
            if counts[g] > self.thresholds[g]:
                generation = g
            else:
                break
        if generation >= 0:
            gc.collect(generation)
            self.collections += 1


def collect_in_gui_thread() -> GuiThreadCollector:
    """Disable automatic collection and collect from a timer of the running application.

    Idempotent: one collector per process, parented to the ``QCoreApplication`` (so it
    lives as long as the event loop can run). Call it in the GUI thread, after the
    application exists.
    """
    global _COLLECTOR
    app = QCoreApplication.instance()
    if app is None:
        raise RuntimeError("collect_in_gui_thread needs a QApplication")
    if QThread.currentThread() is not app.thread():
        raise RuntimeError("collect_in_gui_thread must be called in the GUI thread")
    if _COLLECTOR is None or not _alive(_COLLECTOR, app):
        _COLLECTOR = GuiThreadCollector(app)
    gc.disable()
    return _COLLECTOR


def _alive(collector: GuiThreadCollector, app: QObject) -> bool:
    """Whether ``collector`` still exists and belongs to ``app`` (a test may make another)."""
    try:
        return collector.parent() is app
    except RuntimeError:  # its C++ object went with an earlier application
        return False

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
collection runs in the GUI thread, between events. A full collection (generation 2: about
300,000 objects in the window, 100-200 ms) waits while a mouse button is held (a slider
or the view being dragged, where it was a block of the drag), for up to
:data:`MAX_POSTPONE_S`; a younger generation is collected meanwhile.

No OpenGL context is current while it collects (:func:`collect`). The garbage can hold
VTK objects of a window closed a while ago (a window's actors, mappers and renderers are
in reference cycles with its Python objects, so they die at a collection, not at the
window's deletion); whatever graphics resource one of them still frees would otherwise be
freed in the context that happens to be current between events, another window's: the
driver then deletes that window's buffers or textures (pyvistaqt's notes call it heap
corruption that crashes at a distance; seen as segfaults in the painter tests, the first
GL window after a run of tests without one). With no context current the call does
nothing (libglvnd's no-op dispatch); every render makes its own context current first.
"""

from __future__ import annotations

import gc
import time
from collections.abc import Callable

from PySide6.QtCore import QCoreApplication, QObject, Qt, QThread, QTimer
from PySide6.QtGui import QGuiApplication, QOpenGLContext

#: How often the GUI thread looks at the allocation counts (ms).
INTERVAL_MS = 100
#: A full collection that is due waits for a drag's end at most this long (s).
MAX_POSTPONE_S = 30.0


def due_generation(
    counts: tuple[int, int, int],
    thresholds: tuple[int, ...],
    dragging: bool,
    postponed_s: float,
) -> int:
    """The generation to collect (-1: none): the oldest one past its threshold with the
    younger ones, as CPython's collector picks it, but 1 instead of 2 while ``dragging``
    unless the full collection has waited :data:`MAX_POSTPONE_S` or more (``postponed_s``).

    >>> due_generation((701, 11, 11), (700, 10, 10), dragging=True, postponed_s=5.0)
    1
    >>> due_generation((701, 11, 11), (700, 10, 10), dragging=False, postponed_s=5.0)
    2
    >>> due_generation((12, 0, 0), (700, 10, 10), dragging=False, postponed_s=5.0)
    -1
    """
    generation = -1
    for g in range(3):
        if counts[g] > thresholds[g]:
            generation = g
        else:
            break
    if generation == 2 and dragging and postponed_s < MAX_POSTPONE_S:
        return 1
    return generation


def collect(generation: int = 2) -> int:
    """``gc.collect(generation)`` with no OpenGL context current (see the module docstring);
    returns what ``gc.collect`` returns."""
    context = QOpenGLContext.currentContext()
    if context is not None:
        context.doneCurrent()
    return gc.collect(generation)


def _mouse_held() -> bool:
    return QGuiApplication.mouseButtons() != Qt.MouseButton.NoButton


_COLLECTOR: GuiThreadCollector | None = None


class GuiThreadCollector(QObject):
    """A timer in the GUI thread that collects each generation past its threshold."""

    def __init__(self, parent: QObject, dragging: Callable[[], bool] = _mouse_held) -> None:
        super().__init__(parent)
        self.thresholds = gc.get_threshold()
        self.collections = 0
        self.dragging = dragging  # whether a mouse button is held now
        self.postponed_since: float | None = None  # when a due full collection first waited
        self.timer = QTimer(self)
        self.timer.setInterval(INTERVAL_MS)
        self.timer.timeout.connect(self.collect)
        self.timer.start()

    def collect(self) -> None:
        """Collect the oldest generation whose count is past its threshold (and the
        younger ones with it), as the automatic collector would; a full collection
        waits for the end of a drag (:func:`due_generation`)."""
        counts = gc.get_count()
        if counts[0] <= self.thresholds[0]:
            return  # (nothing due: the common case, without asking about the mouse)
        now = time.monotonic()
        waited = 0.0 if self.postponed_since is None else now - self.postponed_since
        generation = due_generation(counts, self.thresholds, self.dragging(), waited)
        if generation == 1 and counts[2] > self.thresholds[2] and self.postponed_since is None:
            self.postponed_since = now  # a full collection was due: it waits
        if generation >= 0:
            collect(generation)
            self.collections += 1
            if generation == 2:
                self.postponed_since = None


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

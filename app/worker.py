"""Meshing without freezing the window: coalesced requests, a worker thread for big meshes.

:class:`MeshController` listens to ``AppModel.params_changed``. Requests arriving in one
burst (a slider drag) are coalesced by a zero-delay timer: the latest parameters win.
Small meshes are built on the GUI thread (faster than a thread hop); meshes predicted to
be larger than :data:`SYNC_TRIANGLES` are built in a ``QThreadPool`` worker while the
window keeps answering, with :attr:`MeshController.busy_changed` driving a busy
indicator. At most one job runs; a request that arrives meanwhile waits, and results
that are no longer the model's latest generation are dropped by ``AppModel.set_result``.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from functools import partial

from PySide6.QtCore import QObject, QRunnable, QThreadPool, QTimer, Signal

from core import MeshParams

from .model import AppModel, MeshResult, compute
from .scene import scene_data

log = logging.getLogger(__name__)

#: Meshes up to this many triangles are built on the GUI thread (well within a frame).
SYNC_TRIANGLES = 60_000


class Job(QRunnable):
    """Run ``work()`` on a thread-pool thread and emit its return value with ``done``.

    ``done`` is a signal of a QObject living on the GUI thread, so the result is
    delivered there (a queued connection).
    """

    def __init__(self, work: Callable[[], object], done: Signal) -> None:
        super().__init__()
        self.work, self.done = work, done
        self.setAutoDelete(True)

    def run(self) -> None:  # worker thread
        self.done.emit(self.work())


class MeshController(QObject):
    """Turns parameter changes into mesh results for the model (see module docstring)."""

    busy_changed = Signal(bool)
    _job_done = Signal(object)

    def __init__(self, model: AppModel, parent: QObject | None = None,
                 sync_triangles: int = SYNC_TRIANGLES) -> None:
        super().__init__(parent)
        self.model = model
        self.sync_triangles = sync_triangles
        self.pool = QThreadPool(self)
        self.pool.setMaxThreadCount(1)
        self._pending: tuple[MeshParams, int] | None = None
        self._running = False
        self.last_request_time = 0.0
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setInterval(0)
        self._timer.timeout.connect(self._flush)
        self._job_done.connect(self._finished)
        model.params_changed.connect(self._on_params_changed)

    @property
    def busy(self) -> bool:
        return self._running

    def request(self) -> None:
        """Mesh the model's current parameters (coalesced with other requests)."""
        self._pending = (self.model.params, self.model.generation)
        self.last_request_time = time.perf_counter()
        self._timer.start()

    def _on_params_changed(self, _params: MeshParams) -> None:
        self.request()

    def flush(self) -> None:
        """Start the pending request now (tests, scripted runs)."""
        self._timer.stop()
        self._flush()

    def _flush(self) -> None:
        if self._pending is None or self._running:
            return
        params, generation = self._pending
        self._pending = None
        # An explicit tolerance can make the weld slow or fail: never on the GUI thread.
        if params.predicted_triangles() <= self.sync_triangles and params.tolerance is None:
            self.model.set_result(compute(params, generation, prepare=scene_data))
            return
        self._running = True
        self.busy_changed.emit(True)
        self.pool.start(Job(partial(compute, params, generation, prepare=scene_data),
                            self._job_done))

    def _finished(self, result: MeshResult) -> None:
        self._running = False
        if self._pending is None:
            self.busy_changed.emit(False)
        self.model.set_result(result)  # dropped there if stale
        if self._pending is not None:
            self._flush()
            if not self._running:
                self.busy_changed.emit(False)

    def stop(self, msecs: int = 30_000) -> bool:
        """Forget pending requests and wait for a running job (the window is closing)."""
        self._timer.stop()
        self._pending = None
        self.model.params_changed.disconnect(self._on_params_changed)
        done = self.pool.waitForDone(msecs)
        self._job_done.disconnect(self._finished)
        return done

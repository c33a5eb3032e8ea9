"""Background work of the window and its panels: one way to run it.

Every window, panel and dialog that computes something slow (a mesh, a solve, a study, a
locator for the picker, a matrix picture) hands the work to its own :class:`Jobs`::

    self.jobs = Jobs(self)                       # a child of the widget
    self.jobs.submit(partial(solve, mesh), self._solved, token)
    ...
    def _solved(self, token, solution): ...      # on the GUI thread

``work()`` runs on a worker thread and must not touch Qt widgets or VTK. What it returns
is handed to ``on_done(*payload, result)`` on the GUI thread; what it raises to
``on_error(*payload, exc)``, or is logged when there is no ``on_error``. A job can be
cancelled (:meth:`Task.cancel`: its result is dropped, and work that takes the task can
stop early) and can report progress (:meth:`Task.report`, delivered to ``on_progress``).

Results reach a live owner only. The worker threads emit through a signal of the
:class:`Jobs` object under a lock that :meth:`Jobs.close` (and the object's own
destruction) takes too, so no thread ever emits into a QObject being deleted (that crashed
the process in tests' teardown, when a result arrived while the window was deleted).

Worker threads are daemon threads: closing the window returns at once, and a job still
running winds down on its own while its result goes nowhere. ``threads=1`` runs the
jobs of one owner one after another (a queue), ``threads=None`` each in a thread of its
own (mesh builds: an abandoned build winds down beside the next).
"""

from __future__ import annotations

import logging
import threading
from collections import deque
from collections.abc import Callable
from typing import Any

from PySide6.QtCore import QObject, Signal

log = logging.getLogger(__name__)

#: on_done, on_error, on_progress of a job
_Handlers = tuple[Callable[..., Any], Callable[..., Any] | None, Callable[..., Any] | None]


class Task:
    """One submitted job: its cancellation flag and its progress channel.

    Work submitted with ``with_task=True`` is called as ``work(task)`` and may poll
    ``cancelled`` and call :meth:`report` from its thread.
    """

    def __init__(self, jobs: Jobs, payload: tuple[Any, ...]) -> None:
        self._jobs = jobs
        self.payload = payload
        self.cancelled = False
        self.done = threading.Event()  # set when the work has returned or raised

    def cancel(self) -> None:
        """Drop the result (work that takes the task sees ``cancelled`` and may stop)."""
        self.cancelled = True

    def report(self, *values: Any) -> None:
        """From the worker thread: ``on_progress(*values)`` on the GUI thread (without the
        payload), if the job is live and has an ``on_progress``."""
        self._jobs._emit(("progress", self, values))


class _State:
    """What the worker threads share with the GUI thread (plain Python, outlives the
    QObject): the lock under which they emit, and whether emitting is over."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.closed = False


def _close(state: _State, *_args: object) -> None:
    with state.lock:
        state.closed = True


class Jobs(QObject):
    """The background jobs of one owner (see the module docstring).

    Parameters
    ----------
    owner : QObject
        The widget the results are for, on the GUI thread; this object is its child and
        goes with it.
    threads : int or None, default 1
        How many of its jobs run at once (the others wait in order); None: no limit.
    name : str
        The worker threads' name (for debuggers and ``threading.enumerate``).
    """

    _deliver = Signal(object)

    def __init__(self, owner: QObject, threads: int | None = 1, name: str = "barymesh-job") -> None:
        super().__init__(owner)
        if threads is not None and threads < 1:
            raise ValueError(f"threads={threads} is invalid; expected a whole number >= 1")
        self.threads, self.name = threads, name
        self._state = _State()
        # destroyed comes on the GUI thread before the C++ object goes: from then on no
        # worker emits (a plain function, not a method of the object being deleted)
        self.destroyed.connect(lambda *_a, state=self._state: _close(state))
        #: guards the queue, the running count and the live tasks; waited on by wait()
        self._idle = threading.Condition()
        self._queue: deque[tuple[Task, Callable[..., Any], bool]] = deque()
        self._running = 0  # worker threads serving this object
        self._live: set[Task] = set()  # submitted and not yet returned
        self._handlers: dict[Task, _Handlers] = {}  # GUI thread only
        self._deliver.connect(self._on_deliver)

    # -- the GUI thread ---------------------------------------------------------------------

    def submit(
        self,
        work: Callable[..., Any],
        on_done: Callable[..., Any],
        *payload: Any,
        on_error: Callable[..., Any] | None = None,
        on_progress: Callable[..., Any] | None = None,
        with_task: bool = False,
    ) -> Task:
        """Run ``work()`` (``work(task)`` with ``with_task``) on a worker thread; then
        ``on_done(*payload, result)`` on the GUI thread, or ``on_error(*payload, exc)``."""
        task = Task(self, payload)
        self._handlers[task] = (on_done, on_error, on_progress)
        with self._idle:
            self._live.add(task)
            self._queue.append((task, work, with_task))
            start = self.threads is None or self._running < self.threads
            if start:
                self._running += 1
        if start:
            threading.Thread(target=self._serve, daemon=True, name=self.name).start()
        return task

    @property
    def active(self) -> int:
        """Jobs running or waiting."""
        with self._idle:
            return len(self._live)

    def cancel_all(self) -> None:
        """Cancel every running and waiting job: no result of theirs is delivered."""
        with self._idle:
            for task in self._live:
                task.cancel()
            for task, _work, _with in self._queue:  # never started: done now
                self._live.discard(task)
                task.done.set()
            self._queue.clear()
            self._idle.notify_all()

    def close(self) -> None:
        """Nothing is delivered after this, and every job is cancelled (running ones wind
        down in their threads): the owner is closing."""
        _close(self._state)
        self.cancel_all()
        self._handlers.clear()

    def wait(self, timeout_ms: int = 30_000) -> bool:
        """Block until no job runs or waits (scripts, tests); False if ``timeout_ms``
        passed first. Results are delivered later, by the event loop."""
        with self._idle:
            return self._idle.wait_for(lambda: not self._live, timeout_ms / 1000)

    def _on_deliver(self, message: tuple[str, Task, Any]) -> None:
        kind, task, value = message
        handlers = self._handlers.get(task)
        if handlers is None:
            return
        if task.cancelled:
            if kind != "progress":
                del self._handlers[task]
            return
        on_done, on_error, on_progress = handlers
        if kind == "progress":
            if on_progress is not None:
                on_progress(*value)
            return
        del self._handlers[task]
        if kind == "done":
            on_done(*task.payload, value)
        elif on_error is not None:
            on_error(*task.payload, value)
        else:
            log.error("a background job failed", exc_info=value)

    # -- the worker threads -----------------------------------------------------------------

    def _emit(self, message: tuple[str, Task, Any]) -> None:
        with self._state.lock:
            if not self._state.closed:
                self._deliver.emit(message)

    def _serve(self) -> None:
        while True:
            with self._idle:
                if not self._queue:
                    self._running -= 1
                    return
                task, work, with_task = self._queue.popleft()
            self._run(task, work, with_task)

    def _run(self, task: Task, work: Callable[..., Any], with_task: bool) -> None:
        message: tuple[str, Task, Any]
        try:
            message = ("done", task, work(task) if with_task else work())
        except BaseException as exc:  # noqa: BLE001 - handed to the GUI thread
            message = ("error", task, exc)
        if not task.cancelled:
            self._emit(message)
        with self._idle:
            self._live.discard(task)
            task.done.set()
            self._idle.notify_all()

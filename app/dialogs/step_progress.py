"""A long job of the GUI thread done in steps under a progress dialog with Cancel.

Some work must stay on the GUI thread (VTK objects are made and freed there: the
scaled screenshot's renders, :mod:`barymesh.app.view.scaled_shot`). :func:`run_in_steps`
runs such a job one step per event-loop pass, a generator that yields after each step,
so the window keeps answering (timers, paints, the dialog's own Cancel) between steps;
work that needs no VTK (a PNG's encoding and writing) runs in a worker thread while the
generator yields ``None`` until it is done (:func:`thread_steps`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

from PySide6.QtCore import QEventLoop, QObject, Qt, QTimer
from PySide6.QtWidgets import QProgressDialog, QWidget

from barymesh.app.jobs import Jobs

#: A job shows its dialog only when it lasts longer than this (ms): a quick one flashes none.
SHOW_AFTER_MS = 300
#: While a worker thread runs (a step yields ``None``), the steps are polled this often (ms).
POLL_MS = 10
#: Steps 1000 parts of the dialog's bar.
_PARTS = 1000


def run_in_steps(
    parent: QWidget,
    title: str,
    label: str,
    steps: Iterator[tuple[float, str] | None],
    dialog: Callable[[QProgressDialog], None] | None = None,
) -> bool:
    """Run ``steps`` to their end, one step per event-loop pass, under a progress dialog.

    Parameters
    ----------
    parent : QWidget
        The window the (window-modal) dialog belongs to.
    title, label : str
        The dialog's title and its text; a step's own text follows the label.
    steps : iterator
        Each ``next()`` does one step and yields ``(fraction done, what comes next)``, or
        ``None`` while it waits for a worker thread (then it is polled every
        :data:`POLL_MS` ms rather than at once).
    dialog : callable, optional
        Called with the progress dialog once it exists (tests find its Cancel button).

    Returns
    -------
    bool
        True when the steps ran to their end, False when Cancel stopped them (the
        generator is closed at once: its ``finally`` clauses free what it made).

    Raises
    ------
    Exception
        What a step raised (the generator is closed).
    """
    progress = QProgressDialog(label, "Cancel", 0, _PARTS, parent)
    progress.setWindowTitle(title)
    progress.setWindowModality(Qt.WindowModality.WindowModal)
    progress.setAutoClose(False)
    progress.setAutoReset(False)
    progress.setMinimumDuration(0)
    progress.hide()
    if dialog is not None:
        dialog(progress)
    loop = QEventLoop()
    state: dict[str, Any] = {"ended": False, "ok": False, "error": None}
    show = QTimer()
    show.setSingleShot(True)
    show.timeout.connect(lambda: None if state["ended"] else progress.show())
    show.start(SHOW_AFTER_MS)
    step = QTimer()
    step.setSingleShot(True)

    def end(ok: bool, error: BaseException | None = None) -> None:
        if not state["ended"]:
            state.update(ended=True, ok=ok, error=error)
            step.stop()
            loop.quit()

    def next_step() -> None:
        if state["ended"]:
            return
        try:
            item = next(steps)
        except StopIteration:
            end(True)
            return
        except Exception as exc:  # noqa: BLE001 - raised again to the caller below
            end(False, exc)
            return
        if item is not None:
            fraction, text = item
            progress.setValue(int(round(_PARTS * min(max(fraction, 0.0), 1.0))))
            progress.setLabelText(f"{label}\n{text}…" if text else label)
        # a 1 ms timer, not a posted call: the other timers (a heartbeat, a rest timer)
        # and the window's events come first
        step.start(POLL_MS if item is None else 1)

    step.timeout.connect(next_step)
    progress.canceled.connect(lambda: end(False))
    step.start(1)
    loop.exec()
    show.stop()
    if not state["ok"]:
        steps_close = getattr(steps, "close", None)
        if steps_close is not None:
            steps_close()
    progress.canceled.disconnect()  # closing the dialog emits canceled
    progress.close()
    progress.deleteLater()
    if state["error"] is not None:
        raise state["error"]
    return bool(state["ok"])


def thread_steps(work: Callable[[], Any], owner: QObject) -> Iterator[None]:
    """Steps of :func:`run_in_steps` that run ``work()`` (no VTK, no Qt widgets) in a
    worker thread and yield ``None`` until it has finished; ``yield from`` them returns its
    result, or raises what it raised. ``owner`` (a QObject of the GUI thread) receives the
    result."""
    jobs = Jobs(owner, name="barymesh-steps")
    box: dict[str, Any] = {}
    jobs.submit(
        work,
        lambda result: box.setdefault("result", (True, result)),
        on_error=lambda exc: box.setdefault("result", (False, exc)),
    )
    try:
        while "result" not in box:
            yield None
    finally:
        jobs.close()  # cancelled (the dialog's Cancel): the work's result goes nowhere
        jobs.deleteLater()
    ok, value = box["result"]
    if not ok:
        raise value
    return value

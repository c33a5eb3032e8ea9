"""A build's progress on the window's status bar, and its Cancel (the button and Esc).

While the meshing controller (:class:`barymesh.app.worker.MeshController`) runs a build,
the status bar says "Meshing 4,844,160 triangles: 1.2 s of about 4 s · Esc cancels" with
a bar beside it, ten times a second; Cancel (or Esc anywhere in the window, also in a
text field) abandons the build and puts the parameters back to the mesh on screen, which
stays. When the build ends its message goes, and a value still refused says so again.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import cast

from PySide6.QtCore import QEvent, QObject, Qt, QTimer
from PySide6.QtGui import QAction, QKeyEvent
from PySide6.QtWidgets import QApplication, QProgressBar, QStatusBar, QToolButton

from barymesh.app.model import AppModel, ParamError
from barymesh.app.worker import BuildJob, MeshController


class BuildProgress(QObject):
    """The progress bar, the Cancel button and the Esc filter of one window's builds.

    Parameters
    ----------
    status_bar
        The window's status bar: the bar and the button are its permanent widgets.
    model, controller
        The window's model (to go back to the mesh on screen) and its builds.
    cancel_action
        The window's Edit ▸ Cancel action, enabled while a build runs.
    show_error
        Says a refused value on the status bar (the window's own wording).
    """

    def __init__(
        self,
        status_bar: QStatusBar,
        model: AppModel,
        controller: MeshController,
        cancel_action: QAction,
        show_error: Callable[[ParamError | None], None],
        parent: QObject,
    ) -> None:
        super().__init__(parent)
        self.status_bar = status_bar
        self.model = model
        self.controller = controller
        self.cancel_action = cancel_action
        self.show_error = show_error

        self.bar = QProgressBar(status_bar)
        self.bar.setRange(0, 0)
        self.bar.setMaximumWidth(160)
        self.bar.setTextVisible(True)
        self.bar.hide()
        self.cancel_button = QToolButton(status_bar)
        self.cancel_button.setText("Cancel")
        self.cancel_button.setToolTip("Abandon this build; the mesh on screen stays (Esc)")
        self.cancel_button.clicked.connect(self.cancel)
        self.cancel_button.hide()
        status_bar.addPermanentWidget(self.bar)
        status_bar.addPermanentWidget(self.cancel_button)
        # the status bar keeps the height it has with the progress bar shown, so showing
        # or hiding it never resizes (and repaints) the 3D view
        height = max(self.bar.sizeHint().height(), self.cancel_button.sizeHint().height())
        status_bar.setMinimumHeight(height + 6)

        self._escape = EscapeCancels(self)
        self._text: str | None = None  # the progress message on the status bar
        self.timer = QTimer(self)
        self.timer.setInterval(100)
        self.timer.timeout.connect(self.show_progress)
        controller.busy_changed.connect(self._busy_changed)
        controller.job_changed.connect(self._job_changed)

    def stop(self) -> None:
        """The window closes: no more progress."""
        self.timer.stop()
        app = QApplication.instance()
        if app is not None:
            app.removeEventFilter(self._escape)

    def _busy_changed(self, busy: bool) -> None:
        self.bar.setVisible(busy)
        self.cancel_button.setVisible(busy)
        self.cancel_action.setEnabled(busy)
        app = QApplication.instance()
        if busy:
            self.timer.start()
            if app is not None:
                app.installEventFilter(self._escape)
        else:
            self.timer.stop()
            if app is not None:
                app.removeEventFilter(self._escape)
            self._end()

    def _end(self) -> None:
        """No build runs: its progress message goes. A value still refused (an inner radius
        dragged too far while another slider drives the builds) says so again; the status
        bar never keeps "Meshing … · Esc cancels" for a mesh already on screen."""
        shown = self.status_bar.currentMessage()
        if self.model.error is None:
            self.status_bar.clearMessage()
        elif shown == self._text or not shown:
            self.show_error(self.model.error)
        self._text = None

    def _job_changed(self, job: BuildJob | None) -> None:
        if job is not None:
            self.show_progress()

    def show_progress(self) -> None:
        """'Meshing 4,844,160 triangles: 1.2 s of about 4 s' and the bar."""
        job = self.controller.current
        if job is None:
            return
        elapsed = time.perf_counter() - job.started
        expected = self.controller.estimate(job.triangles)
        text = f"Meshing {job.triangles:,} triangles: {elapsed:.1f} s"
        if expected is not None and elapsed <= expected:
            text += f" of about {expected:.1f} s"
            self.bar.setRange(0, 100)
            self.bar.setValue(int(min(99, 100 * elapsed / max(expected, 1e-3))))
        elif expected is not None:  # never "4.3 s of about 0.2 s": say why it is longer
            why = (
                "; a cancelled build is still stopping beside it"
                if self.controller.stopping
                else ""
            )
            text += f" (longer than the {expected:.1f} s estimated{why})"
            self.bar.setRange(0, 0)
        else:
            text += " (no estimate yet: the first large build measures this machine)"
            self.bar.setRange(0, 0)
        self._text = text + " · Esc cancels"
        self.status_bar.showMessage(self._text)

    def cancel(self) -> None:
        """Abandon the running build; the parameters go back to the mesh on screen."""
        if not self.controller.cancel():
            return
        model = self.model
        shown = model.result
        good = model.shown_state  # a unit cell on screen: back to it
        if shown is not None and shown.cell is not None and good is not None:
            if model.cell_state != good:
                if model.undo_stack and model.undo_stack[-1] == good:
                    model.undo()
                else:
                    model.set_cell(good.cell)
        elif shown is not None and shown.params is not None and model.params != shown.params:
            if model.undo_stack and model.undo_stack[-1] == shown.params:
                model.undo()
            else:
                model.set_params(shown.params)
        self.status_bar.showMessage("Meshing cancelled; the mesh on screen stays", 5000)


class EscapeCancels(QObject):
    """While installed on the application: Esc anywhere in the window cancels the build,
    also when a text field has the focus (it would take Esc for itself)."""

    def __init__(self, progress: BuildProgress) -> None:
        super().__init__(progress)
        self.progress = progress

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:  # noqa: N802 - Qt's name
        if (
            event.type() == QEvent.Type.KeyPress
            and cast(QKeyEvent, event).key() == Qt.Key.Key_Escape
            and not cast(QKeyEvent, event).modifiers()
            and self.progress.controller.busy
        ):
            self.progress.cancel()
            return True
        return False

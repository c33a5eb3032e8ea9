"""File → Export sweep animation: a GIF or MP4 of one parameter varied over K frames.

The dialog collects the parameter (one of :data:`barymesh.teach.sweep.SWEEPABLE`), from, to,
frames, frames per second, frame size and output file, checks them with
:func:`barymesh.teach.sweep.sweep_params` before anything runs, and then runs
:func:`barymesh.app.teach.sweep.render_sweep` (the function behind ``barymesh sweep``) in a child
process: it renders off-screen with VTK, and VTK objects are not thread-safe, so no
render may run in a thread of the window's process beside the window's own. A worker
thread only relays the child's progress, which drives the dialog's progress bar; Cancel
sets an event that ``render_sweep`` polls between frames, and the atomic write leaves
no file behind. Errors are shown in the dialog, never as a traceback.
"""

from __future__ import annotations

import logging
import multiprocessing
import queue
import threading
from collections.abc import Callable
from functools import partial
from pathlib import Path

from PySide6.QtCore import Signal
from PySide6.QtGui import QCloseEvent
from PySide6.QtWidgets import (
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QDoubleSpinBox,
    QFileDialog,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QProgressBar,
    QPushButton,
    QSpinBox,
    QWidget,
)

from barymesh import MeshParams
from barymesh.app.jobs import Jobs, Task
from barymesh.app.teach.sweep import ANIMATION_EXTENSIONS, UNITS, SweepCancelled, render_sweep
from barymesh.teach.sweep import MAX_FRAMES, SWEEPABLE, check_sweep_size, sweep_params

log = logging.getLogger(__name__)

TITLES = {
    "inner_radius": "Inner radius",
    "outer_radius": "Outer radius",
    "patch_size": "Patch size",
    "angle_step": "Angle step",
    "subdivisions": "Subdivisions n",
    "gap_width": "Gap width",
    "gap_angle": "Gap angle",
}
#: A sensible first sweep per parameter, (from, to); the current value is used otherwise.
SUGGESTED = {
    "angle_step": (20.0, 1.0),
    "subdivisions": (1.0, 8.0),
    "gap_angle": (0.0, 90.0),
}
SIZES = {
    "800 × 600": (800, 600),
    "1280 × 720 (16:9)": (1280, 720),
    "1024 × 1024": (1024, 1024),
    "640 × 480": (640, 480),
}


def _render_in_child(kwargs: dict, events: multiprocessing.Queue, stop: threading.Event) -> None:
    """The child process: render the sweep, reporting through ``events``."""
    try:
        frames = render_sweep(
            **kwargs, progress=lambda d, t: events.put(("progress", d, t)), should_stop=stop.is_set
        )
    except SweepCancelled:
        events.put(("finished", "cancelled"))
    except Exception as exc:  # noqa: BLE001 - shown in the dialog, never raised
        log.exception("sweep export failed")
        events.put(("finished", f"{exc}" or "the sweep export failed"))
    else:
        events.put(("finished", frames))


def _run_sweep(kwargs: dict, stop_asked: threading.Event, task: Task) -> object:
    """Run the sweep in a child process and relay its progress (worker thread, no VTK
    here): None on success, else the message (or "cancelled")."""
    context = multiprocessing.get_context("spawn")  # a fresh VTK, not a fork of ours
    events = context.Queue()
    stop = context.Event()
    child = context.Process(
        target=_render_in_child,
        args=(kwargs, events, stop),
        daemon=True,
        name="barymesh-sweep",
    )
    outcome: object = None
    try:
        child.start()
        while outcome is None:
            if stop_asked.is_set():
                stop.set()
            try:
                event = events.get(timeout=0.1)
            except queue.Empty:
                if not child.is_alive():
                    code = child.exitcode
                    outcome = f"the sweep renderer stopped unexpectedly (exit code {code})"
                continue
            if event[0] == "progress":
                task.report(event[1], event[2])
            else:
                outcome = event[1]
    except Exception as exc:  # noqa: BLE001 - shown in the dialog, never raised
        log.exception("sweep export failed")
        outcome = f"{exc}" or "the sweep export failed"
    finally:
        child.join(30)
        if child.is_alive():
            child.kill()
            child.join()
        events.close()
    return outcome


class SweepDialog(QDialog):
    """Choose a sweep and write it (see the module docstring).

    Parameters
    ----------
    params : MeshParams or callable returning MeshParams
        The other parameters. Pass a callable (e.g. ``lambda: window.model.params``)
        so that an export uses the parameters of the moment Export is pressed, not
        those of when the dialog opened.
    parent : QWidget, optional
    start_dir : str
        Where the output file goes by default (and what a relative file name is
        relative to); the home folder when empty. Never the working directory.
    """

    finished_export = Signal(object)  # frame count, "cancelled" or an error message
    #: (frames done, frames in all) as the sweep goes
    progressed = Signal(int, int)
    # attributes named over QWidget.size() and QDialog.result() (the tests use them)
    size: QComboBox  # type: ignore[assignment]
    result: object  # type: ignore[assignment]

    def __init__(
        self,
        params: MeshParams | Callable[[], MeshParams],
        parent: QWidget | None = None,
        start_dir: str = "",
    ) -> None:
        super().__init__(parent)
        self.setWindowTitle("Export sweep animation")
        self._params = params
        self.folder = Path(start_dir).expanduser() if start_dir else Path.home()
        self.folder = self.folder.absolute()
        self.jobs = Jobs(self, name="barymesh-sweep")
        self.stop = threading.Event()
        self.running = False
        self.result = None
        self.result_path: Path | None = None

        form = QFormLayout(self)
        self.param = QComboBox(self)
        for name in SWEEPABLE:
            unit = UNITS.get(name, "")
            self.param.addItem(f"{TITLES.get(name, name)}{f' ({unit})' if unit else ''}", name)
        self.start = QDoubleSpinBox(self)
        self.stop_value = QDoubleSpinBox(self)
        for box in (self.start, self.stop_value):
            box.setRange(-1e6, 1e6)
            box.setDecimals(3)
        self.frames = QSpinBox(self)
        self.frames.setRange(2, MAX_FRAMES)
        self.frames.setValue(20)
        self.fps = QDoubleSpinBox(self)
        self.fps.setRange(0.5, 60.0)
        self.fps.setDecimals(1)
        self.fps.setValue(4.0)
        self.fps.setSuffix(" fps")
        self.size = QComboBox(self)
        for title, size in SIZES.items():
            self.size.addItem(title, size)
        self.path = QLineEdit(self)
        self.path.setPlaceholderText("sweep.gif or sweep.mp4")
        self.path.setText(str(self.folder / "sweep.gif"))
        browse = QPushButton("Browse…", self)
        browse.clicked.connect(self._browse)
        path_row = QHBoxLayout()
        path_row.addWidget(self.path, 1)
        path_row.addWidget(browse)
        self.progress = QProgressBar(self)
        self.progress.setRange(0, 1)
        self.progress.setValue(0)
        self.message = QLabel(self)
        self.message.setWordWrap(True)
        self.message.setMinimumWidth(380)

        form.addRow("&Parameter", self.param)
        form.addRow("&From", self.start)
        form.addRow("&To", self.stop_value)
        form.addRow("F&rames", self.frames)
        form.addRow("&Speed", self.fps)
        form.addRow("Frame si&ze", self.size)
        path_label = QLabel("&Output file", self)
        path_label.setBuddy(self.path)
        form.addRow(path_label, path_row)
        form.addRow(self.progress)
        form.addRow(self.message)
        self.buttons = QDialogButtonBox(self)
        self.export_button = self.buttons.addButton(
            "&Export", QDialogButtonBox.ButtonRole.AcceptRole
        )
        self.cancel_button = self.buttons.addButton(QDialogButtonBox.StandardButton.Cancel)
        self.close_button = self.buttons.addButton(QDialogButtonBox.StandardButton.Close)
        self.export_button.clicked.connect(self.start_export)
        self.cancel_button.clicked.connect(self.cancel)
        self.close_button.clicked.connect(self.reject)
        self.cancel_button.setEnabled(False)
        form.addRow(self.buttons)

        self.param.currentIndexChanged.connect(self._param_changed)
        self.param.setCurrentIndex(self.param.findData("angle_step"))
        self._param_changed()

    @property
    def params(self) -> MeshParams:
        """The other parameters, as they are now (see the class docstring)."""
        return self._params() if callable(self._params) else self._params

    # -- inputs --------------------------------------------------------------------------

    def _param_changed(self, *_args: object) -> None:
        name = self.param.currentData()
        integer = name == "subdivisions"
        for box in (self.start, self.stop_value):
            box.setDecimals(0 if integer else 3)
            box.setSingleStep(1.0 if integer or UNITS.get(name) == "°" else 0.1)
        current = getattr(self.params, name)
        start, stop = SUGGESTED.get(name, (current, current * 2 if current else 1.0))
        self.start.setValue(float(start))
        self.stop_value.setValue(float(stop))
        self._say("")

    def _browse(self) -> None:
        path, _ = QFileDialog.getSaveFileName(
            self,
            "Export sweep animation",
            self.path.text(),
            "GIF animation (*.gif);;MP4 video (*.mp4)",
        )
        if path:
            if Path(path).suffix.lower() not in ANIMATION_EXTENSIONS:
                path += ".gif"
            self.path.setText(path)

    def _say(self, text: str, error: bool = False) -> None:
        self.message.setStyleSheet("color: #d0021b;" if error else "")
        self.message.setText(text)

    def sweep_kwargs(self) -> dict:
        """The ``render_sweep`` arguments; raises ValueError with a readable message."""
        text = self.path.text().strip()
        if not text:
            raise ValueError("choose an output file (.gif or .mp4)")
        path = Path(text).expanduser()
        if not path.is_absolute():  # relative to the dialog's folder, not the working directory
            path = self.folder / path
        if path.suffix.lower() not in ANIMATION_EXTENSIONS:
            raise ValueError(f"{path.name}: the output file must end in .gif or .mp4")
        if not path.parent.is_dir():
            raise ValueError(f"{path.parent}: no such folder")
        name = self.param.currentData()
        start, stop, frames = self.start.value(), self.stop_value.value(), self.frames.value()
        base = self.params  # read once: the parameters of the moment Export is pressed
        sweep_params(base, name, start, stop, frames)  # every frame valid?
        check_sweep_size(frames, self.size.currentData())
        return {
            "base": base,
            "name": name,
            "start": start,
            "stop": stop,
            "frames": frames,
            "path": path,
            "window_size": self.size.currentData(),
            "fps": self.fps.value(),
        }

    # -- running -------------------------------------------------------------------------

    def start_export(self) -> bool:
        """Check the inputs and start the worker; False (and a message) if they are bad."""
        if self.running:
            return False
        try:
            kwargs = self.sweep_kwargs()
        except (ValueError, TypeError, OSError) as exc:
            self._say(str(exc), error=True)
            return False
        self.stop.clear()
        self.result_path = kwargs["path"]
        self.running = True
        self.result = None
        self.progress.setRange(0, 2 * kwargs["frames"])
        self.progress.setValue(0)
        self._set_inputs_enabled(False)
        self._say(f"Rendering {kwargs['frames']} frames…")
        self.jobs.submit(
            partial(_run_sweep, kwargs, self.stop),
            self._finished,
            with_task=True,
            on_progress=self._progress,
        )
        return True

    def cancel(self) -> None:
        if self.running:
            self.stop.set()
            self._say("Cancelling…")

    def _progress(self, done: int, total: int) -> None:
        self.progress.setRange(0, total)
        self.progress.setValue(done)
        self.progressed.emit(done, total)

    def _finished(self, outcome: object) -> None:
        self.running = False
        self.result = outcome
        self._set_inputs_enabled(True)
        if outcome == "cancelled":
            self.progress.setValue(0)
            self._say("Cancelled: no file was written.")
        elif isinstance(outcome, int):
            self.progress.setValue(self.progress.maximum())
            self._say(f"Wrote {outcome} frames to {self.result_path}")
        else:
            self._say(f"Could not export the sweep: {outcome}", error=True)
        self.finished_export.emit(outcome)

    def _set_inputs_enabled(self, on: bool) -> None:
        for widget in (
            self.param,
            self.start,
            self.stop_value,
            self.frames,
            self.fps,
            self.size,
            self.path,
            self.export_button,
            self.close_button,
        ):
            widget.setEnabled(on)
        self.cancel_button.setEnabled(not on)

    def reject(self) -> None:
        """Escape or Close: cancel a running export first, then close."""
        if self.running:
            self.cancel()
            self.jobs.wait(60_000)
        super().reject()

    def closeEvent(self, event: QCloseEvent) -> None:  # noqa: N802 - Qt's name
        if self.running:
            self.cancel()
            self.jobs.wait(60_000)
        super().closeEvent(event)

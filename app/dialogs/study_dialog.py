"""File → Design study: a small study of the current structure on a local Dask cluster.

The dialog varies two parameters of the structure the window shows (each from, to, count),
solves each point over a frequency range in free space (:func:`barymesh.study.run` on a
``LocalCluster`` of worker processes), shows the progress as it comes and draws a heat
map of a derived figure (resonance frequency, Q or −3 dB bandwidth) over the two axes.
Clicking a cell of the map loads that design into the window.

The study runs in a worker thread of the dialog, which only relays numbers: the progress,
and at the end the derived figure as a numpy grid. Cancel stops it after the point that
is running; errors are shown in the dialog, never as a traceback.
"""

from __future__ import annotations

import dataclasses
import logging
import os
import threading
from collections.abc import Callable
from typing import Any

import numpy as np
from PySide6.QtCore import QObject, QRunnable, QThreadPool, Signal
from PySide6.QtGui import QCloseEvent
from PySide6.QtWidgets import (
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QProgressBar,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from barymesh import MeshParams

log = logging.getLogger(__name__)

#: Parameters a study may vary (mm or degrees), with their titles.
AXES = {
    "inner_radius": "Inner radius (mm)",
    "outer_radius": "Outer radius (mm)",
    "patch_size": "Patch size (mm)",
    "patch_width": "Patch width (mm)",
    "gap_width": "Gap width (mm)",
    "gap_angle": "Gap angle (°)",
    "angle_step": "Angle step (°)",
}
#: Figures the heat map shows: spec name -> (column, title, scale, unit).
FIGURES = {
    "resonance_frequency": ("resonance_frequency_hz", "Resonance frequency", 1e-9, "GHz"),
    "quality_factor": ("quality_factor", "Quality factor Q", 1.0, ""),
    "bandwidth_3db": ("bandwidth_3db_hz", "−3 dB bandwidth", 1e-9, "GHz"),
}
#: Most points a study of this dialog may have (a larger one belongs to ``barymesh study``).
MAX_POINTS = 400


class _Signals(QObject):
    progress = Signal(int, int, int)  # done, failed, total
    finished = Signal(object)  # (grid, statuses) on success, else the message


class _StudyJob(QRunnable):
    """Runs the study (worker thread); emits numbers only."""

    def __init__(self, spec: dict, workers: int, column: str, stop: threading.Event, signals):
        super().__init__()
        self.spec, self.workers, self.column = spec, workers, column
        self.stop, self.signals = stop, signals
        self.setAutoDelete(True)

    def run(self) -> None:  # worker thread
        from barymesh.study import parse_spec, run

        def progress(p: Any) -> None:
            self.signals.progress.emit(p.done, p.failed, p.total)
            if self.stop.is_set():
                raise KeyboardInterrupt  # run() cancels the tasks and keeps what finished

        try:
            spec = parse_spec(self.spec)
            result = run(spec, workers=self.workers, processes=True, progress=progress)
            shape = tuple(len(a.values) for a in spec.axes)
            grid = result.derived[self.column].to_numpy(dtype=float).reshape(shape)
            statuses = result.derived["status"].to_numpy(dtype=str).reshape(shape)
            outcome: object = (grid, statuses)
        except KeyboardInterrupt:
            outcome = "cancelled"
        except Exception as exc:  # noqa: BLE001 - shown in the dialog, never raised
            log.exception("design study failed")
            outcome = " ".join(str(exc).split()) or type(exc).__name__
        self.signals.finished.emit(outcome)


class StudyDialog(QDialog):
    """Run a two-axis study of the current structure and show a heat map.

    Parameters
    ----------
    params : callable returning MeshParams
        The structure to vary, as it is when Run is pressed.
    load : callable
        ``load(params)`` puts a design into the window (a click on the map).
    parent : QWidget, optional
    """

    finished_study = Signal(object)  # None when done, "cancelled" or the error message

    def __init__(
        self,
        params: Callable[[], MeshParams],
        load: Callable[[MeshParams], None],
        parent: QWidget | None = None,
    ) -> None:
        super().__init__(parent)
        self.setWindowTitle("Design study")
        self._params, self._load = params, load
        self.pool = QThreadPool(self)
        self.pool.setMaxThreadCount(1)
        self.stop = threading.Event()
        self.running = False
        self.grid: np.ndarray | None = None
        self.statuses: np.ndarray | None = None
        self.values: list[list[float]] = []
        self.base: MeshParams | None = None
        self.spec: dict[str, Any] = {}

        outer = QVBoxLayout(self)
        form = QFormLayout()
        outer.addLayout(form)
        self.axis_rows = []
        for k, default in enumerate(("inner_radius", "gap_width")):
            name = QComboBox(self)
            for key, title in AXES.items():
                name.addItem(title, key)
            name.setCurrentIndex(name.findData(default))
            start, stop = QLineEdit(self), QLineEdit(self)
            count = QSpinBox(self)
            count.setRange(1, 40)
            count.setValue(3)
            row = QHBoxLayout()
            for w, text in ((name, ""), (start, "from"), (stop, "to"), (count, "count")):
                if text:
                    row.addWidget(QLabel(text, self))
                row.addWidget(w, 1 if w is not count else 0)
            form.addRow(f"Axis {k + 1}", row)
            self.axis_rows.append((name, start, stop, count))
            name.currentIndexChanged.connect(lambda _i, k=k: self._suggest(k))
        self.frequencies = QLineEdit("4GHz:9GHz:21", self)
        form.addRow("&Frequencies", self.frequencies)
        self.figure_choice = QComboBox(self)
        for key, (_, title, _, _) in FIGURES.items():
            self.figure_choice.addItem(title, key)
        self.figure_choice.currentIndexChanged.connect(self._draw)
        form.addRow("&Show", self.figure_choice)
        self.workers = QSpinBox(self)
        self.workers.setRange(1, 64)
        self.workers.setValue(os.cpu_count() or 1)
        form.addRow("&Workers", self.workers)
        self.progress = QProgressBar(self)
        self.progress.setRange(0, 1)
        self.progress.setValue(0)
        outer.addWidget(self.progress)
        self.message = QLabel(self)
        self.message.setWordWrap(True)
        self.message.setMinimumWidth(420)
        outer.addWidget(self.message)

        from matplotlib.figure import Figure

        from barymesh.app.view.canvas import ShownCanvas

        self.figure = Figure(figsize=(4.6, 3.4), dpi=90, layout="constrained")
        self.canvas = ShownCanvas(self.figure)
        self.canvas.setMinimumHeight(280)
        self.axes = self.figure.add_subplot()
        self.image: Any = None
        self.colorbar: Any = None
        self.canvas.mpl_connect("button_press_event", self._pressed)
        outer.addWidget(self.canvas, 1)

        self.buttons = QDialogButtonBox(self)
        self.run_button = self.buttons.addButton("&Run", QDialogButtonBox.ButtonRole.AcceptRole)
        self.cancel_button = self.buttons.addButton(QDialogButtonBox.StandardButton.Cancel)
        self.close_button = self.buttons.addButton(QDialogButtonBox.StandardButton.Close)
        self.run_button.clicked.connect(self.start)
        self.cancel_button.clicked.connect(self.cancel)
        self.close_button.clicked.connect(self.reject)
        self.cancel_button.setEnabled(False)
        outer.addWidget(self.buttons)

        self.signals = _Signals(self)
        self.signals.progress.connect(self._progress)
        self.signals.finished.connect(self._finished)
        for k in range(len(self.axis_rows)):
            self._suggest(k)
        self._draw()

    # -- inputs ----------------------------------------------------------------------------

    def _suggest(self, k: int) -> None:
        """From and to around the current value of axis ``k``'s parameter (±10 %)."""
        name, start, stop, _ = self.axis_rows[k]
        value = getattr(self._params(), name.currentData())
        value = self._params().patch_size if value is None else float(value)
        start.setText(f"{0.9 * value:.4g}")
        stop.setText(f"{1.1 * value:.4g}")

    def _say(self, text: str, error: bool = False) -> None:
        self.message.setText(text)
        self.message.setStyleSheet("color: #b00020;" if error else "")

    def study_spec(self) -> dict[str, Any]:
        """The study spec of the inputs (see :mod:`barymesh.study.spec`).

        Raises
        ------
        ValueError
            An input that is not a number, the same parameter on both axes, too many points.
        """
        axes: dict[str, list[float]] = {}
        for k, (name, start, stop, count) in enumerate(self.axis_rows):
            key = name.currentData()
            if key in axes:
                raise ValueError("the two axes vary the same parameter; choose another")
            try:
                a, b = float(start.text().replace(",", ".")), float(stop.text().replace(",", "."))
            except ValueError:
                raise ValueError(f"axis {k + 1}: from and to must be numbers") from None
            n = count.value()
            if n > 1 and not a < b:
                raise ValueError(f"axis {k + 1}: from {a:g} must be below to {b:g}")
            axes[key] = [float(v) for v in np.linspace(a, b, n)]
        points = int(np.prod([len(v) for v in axes.values()]))
        if points > MAX_POINTS:
            raise ValueError(f"{points} points; at most {MAX_POINTS} here (use barymesh study)")
        base = self._params()
        return {
            "base": {"params": base.to_dict()},
            "axes": axes,
            "solve": {"kind": "free_space", "frequencies": self.frequencies.text().strip()},
            "derive": list(FIGURES),
        }

    # -- running ---------------------------------------------------------------------------

    def start(self) -> bool:
        """Check the inputs and start the study; False (and a message) when they are bad."""
        if self.running:
            return False
        try:
            spec = self.study_spec()
            from barymesh.study import parse_spec

            parse_spec(spec)  # a bad frequency text is said here, before any cluster
        except ImportError as exc:
            self._say(f"a study needs the study extra: pip install 'barymesh[study]' ({exc})", True)
            return False
        except ValueError as exc:
            self._say(str(exc), error=True)
            return False
        self.spec = spec
        self.base = self._params()
        self.values = [list(v) for v in spec["axes"].values()]
        self.stop.clear()
        self.running = True
        self._set_inputs_enabled(False)
        total = int(np.prod([len(v) for v in self.values]))
        self.progress.setRange(0, total)
        self.progress.setValue(0)
        self._say(f"starting a local cluster of {self.workers.value()} workers…")
        column = FIGURES[self.figure_choice.currentData()][0]
        job = _StudyJob(spec, self.workers.value(), column, self.stop, self.signals)
        self._column = column
        self.pool.start(job)
        return True

    def cancel(self) -> None:
        if self.running:
            self.stop.set()
            self._say("cancelling after the running points…")

    def _progress(self, done: int, failed: int, total: int) -> None:
        self.progress.setRange(0, total)
        self.progress.setValue(done)
        self._say(f"{done} of {total} points, {failed} failed")

    def _finished(self, outcome: object) -> None:
        self.running = False
        self._set_inputs_enabled(True)
        if isinstance(outcome, tuple):
            self.grid, self.statuses = outcome
            bad = int((self.statuses != "ok").sum())
            self._say(f"{self.grid.size} points, {bad} failed. Click a cell to load that design.")
            self._draw()
            self.finished_study.emit(None)
            return
        self._say("cancelled" if outcome == "cancelled" else str(outcome), outcome != "cancelled")
        self.finished_study.emit(outcome)

    def _set_inputs_enabled(self, on: bool) -> None:
        for row in self.axis_rows:
            for w in row:
                w.setEnabled(on)
        for w in (self.frequencies, self.workers, self.run_button, self.close_button):
            w.setEnabled(on)
        self.cancel_button.setEnabled(not on)

    # -- the heat map ----------------------------------------------------------------------

    def _draw(self, *_args: object) -> None:
        ax = self.axes
        ax.clear()
        if self.colorbar is not None:
            self.colorbar.remove()
            self.colorbar = None
        self.image = None
        names = [row[0].currentText() for row in self.axis_rows]
        ax.set_xlabel(names[1])
        ax.set_ylabel(names[0])
        if self.grid is None or len(self.values) != 2:
            ax.text(0.5, 0.5, "Run a study to see its map", ha="center", va="center")
            ax.set_xticks([])
            ax.set_yticks([])
            self.canvas.draw_idle()
            return
        key = self.figure_choice.currentData()
        column, title, scale, unit = FIGURES[key]
        if column != self._column:
            self._say(f"the map shows the figure of the last run; run again for {title}")
            column, title, scale, unit = next(v for v in FIGURES.values() if v[0] == self._column)
        rows, cols = self.values
        self.image = ax.imshow(
            self.grid * scale,
            origin="lower",
            aspect="auto",
            cmap="viridis",
            extent=(-0.5, len(cols) - 0.5, -0.5, len(rows) - 0.5),
        )
        ax.set_xticks(range(len(cols)), [f"{v:.3g}" for v in cols])
        ax.set_yticks(range(len(rows)), [f"{v:.3g}" for v in rows])
        self.colorbar = self.figure.colorbar(
            self.image, ax=ax, label=f"{title} ({unit})".replace(" ()", "")
        )
        self.canvas.draw_idle()

    def cell_params(self, i: int, j: int) -> MeshParams:
        """The design of the map's cell at row ``i`` (axis 1) and column ``j`` (axis 2)."""
        assert self.base is not None
        names = list(self.spec["axes"])
        return dataclasses.replace(
            self.base, **{names[0]: self.values[0][i], names[1]: self.values[1][j]}
        )

    def load_cell(self, i: int, j: int) -> None:
        """Load the design of a cell into the window (a click on the map)."""
        try:
            params = self.cell_params(i, j)
        except (TypeError, ValueError) as exc:
            self._say(f"that design cannot be built: {exc}", error=True)
            return
        self._load(params)
        names = list(self.spec["axes"])
        self._say(
            f"loaded {names[0]} = {self.values[0][i]:.4g}, {names[1]} = {self.values[1][j]:.4g}"
        )

    def _pressed(self, event: Any) -> None:
        if self.image is None or event.inaxes is not self.axes or event.xdata is None:
            return
        j, i = int(round(event.xdata)), int(round(event.ydata))
        if 0 <= i < len(self.values[0]) and 0 <= j < len(self.values[1]):
            self.load_cell(i, j)

    def reject(self) -> None:
        if self.running:
            self.cancel()
            return
        super().reject()

    def closeEvent(self, event: QCloseEvent) -> None:  # noqa: N802 - Qt's name
        if self.running:
            self.cancel()
            event.ignore()
            return
        super().closeEvent(event)

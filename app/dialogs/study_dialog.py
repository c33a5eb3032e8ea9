"""File → Design study: a small study of the current structure on a local Dask cluster.

The dialog varies two parameters of the structure the window shows (each from, to, count),
solves each point over a frequency range in free space under a plane wave whose direction
and polarisation are typed as in the Solve dock (:func:`barymesh.study.run` on a
``LocalCluster`` of worker processes), shows the progress as it comes and draws a heat
map of a derived figure (resonance frequency, Q or −3 dB bandwidth) over the two axes.
Clicking a cell of the map loads that design into the window.

A point whose figure does not exist in the band (no peak of the extinction cross-section
inside the sweep, a peak no Lorentzian fits, a half-power band that leaves the sweep) is
drawn hatched and named in the legend; a failed point is cross-hatched. When no point has
the figure, the map says so and why, and no colour bar is drawn.

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
from functools import partial
from typing import Any

import numpy as np
from PySide6.QtCore import Signal
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
    QSizePolicy,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from barymesh import MeshParams
from barymesh.app.jobs import Jobs, Task
from barymesh.app.model.solve_inputs import DIRECTION_PRESETS, POLARIZATION_PRESETS, read_vector

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
#: What a point without the figure (NaN, status ok) is called on the map, per figure.
MISSING = {
    "resonance_frequency": "no resonance in band",
    "quality_factor": "no Q (no peak a Lorentzian fits)",
    "bandwidth_3db": "no −3 dB band inside the sweep",
}
#: Hatches of the cells without a value: no figure in the band, and a failed point.
MISSING_HATCH, FAILED_HATCH = "///", "xx"


def missing_cells(grid: np.ndarray, statuses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(no figure, failed): boolean masks of the map's cells drawn hatched.

    A cell has no figure when its point solved (status ``ok``) but the value is NaN; a
    failed point is one whose status is an error message.

    >>> g = np.array([[1.0, np.nan], [np.nan, 2.0]])
    >>> s = np.array([["ok", "ok"], ["solver failed", "ok"]])
    >>> [m.tolist() for m in missing_cells(g, s)]
    [[[False, True], [False, False]], [[False, False], [True, False]]]
    """
    failed = np.asarray(statuses) != "ok"
    return ~failed & ~np.isfinite(np.asarray(grid, dtype=float)), failed


def _run_study(spec: dict, workers: int, stop: threading.Event, task: Task) -> object:
    """Run the study (worker thread): ({column: grid}, statuses), "cancelled" or the
    error message; progress goes out as (done, failed, total)."""
    from barymesh.study import parse_spec, run

    def progress(p: Any) -> None:
        task.report(p.done, p.failed, p.total)
        if stop.is_set():
            raise KeyboardInterrupt  # run() cancels the tasks and keeps what finished

    try:
        parsed = parse_spec(spec)
        result = run(parsed, workers=workers, processes=True, progress=progress)
        shape = tuple(len(a.values) for a in parsed.axes)
        grids = {
            column: result.derived[column].to_numpy(dtype=float).reshape(shape)
            for column, *_ in FIGURES.values()
        }
        statuses = result.derived["status"].to_numpy(dtype=str).reshape(shape)
        return grids, statuses
    except KeyboardInterrupt:
        return "cancelled"
    except Exception as exc:  # noqa: BLE001 - shown in the dialog, never raised
        log.exception("design study failed")
        return " ".join(str(exc).split()) or type(exc).__name__


class StudyDialog(QDialog):
    """Run a two-axis study of the current structure and show a heat map.

    Parameters
    ----------
    params : callable returning MeshParams
        The structure to vary, as it is when Run is pressed.
    load : callable
        ``load(params)`` puts a design into the window (a click on the map).
    parent : QWidget, optional
    incidence : (str, str), optional
        The plane wave's direction and polarisation as first shown (the Solve dock's);
        default ``("-z", "x")``.
    """

    finished_study = Signal(object)  # None when done, "cancelled" or the error message
    #: (points done, failed, points in all) as the study goes
    progressed = Signal(int, int, int)

    def __init__(
        self,
        params: Callable[[], MeshParams],
        load: Callable[[MeshParams], None],
        parent: QWidget | None = None,
        incidence: tuple[str, str] = ("-z", "x"),
    ) -> None:
        super().__init__(parent)
        self.setWindowTitle("Design study")
        self._params, self._load = params, load
        self.jobs = Jobs(self, name="barymesh-study")
        self.stop = threading.Event()
        self.running = False
        self.grid: np.ndarray | None = None  # the shown figure's grid (rows: axis 1)
        self.grids: dict[str, np.ndarray] = {}  # every figure's grid, by column
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
        self.direction = self._vector_box(
            DIRECTION_PRESETS,
            incidence[0],
            "Direction of travel of the plane wave: an axis (-z: from above) or x, y, z",
        )
        self.polarization = self._vector_box(
            POLARIZATION_PRESETS,
            incidence[1],
            "Direction of E: an axis or x, y, z, perpendicular to the direction. A ring's "
            "gap resonates with E across the gap",
        )
        form.addRow("&Direction", self.direction)
        form.addRow("&Polarisation E", self.polarization)
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
        # never squeezed below its wrapped lines by the map under it
        self.message.setSizePolicy(QSizePolicy.Policy.Preferred, QSizePolicy.Policy.Minimum)
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

        for k in range(len(self.axis_rows)):
            self._suggest(k)
        self._draw()

    # -- inputs ----------------------------------------------------------------------------

    def _vector_box(self, presets: tuple[str, ...], text: str, tip: str) -> QComboBox:
        """An editable box of axis presets, as the Solve dock's direction and polarisation."""
        box = QComboBox(self)
        box.setEditable(True)
        box.setInsertPolicy(QComboBox.InsertPolicy.NoInsert)
        box.addItems(list(presets))
        box.setCurrentText(text)
        box.setToolTip(tip)
        return box

    def incidence(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """(direction, polarisation) vectors of the fields; ValueError naming the field."""
        from barymesh.mom import PlaneWave

        d = read_vector(self.direction.currentText(), "Direction")
        p = read_vector(self.polarization.currentText(), "Polarisation")
        try:
            PlaneWave(direction=d, polarization=p)  # type: ignore[arg-type]  # numbers in, an array kept
        except ValueError as exc:
            raise ValueError(f"Polarisation: {exc}") from None
        return d, p

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
        direction, polarization = self.incidence()
        base = self._params()
        return {
            "base": {"params": base.to_dict()},
            "axes": axes,
            "solve": {
                "kind": "free_space",
                "frequencies": self.frequencies.text().strip(),
                "direction": list(direction),
                "polarization": list(polarization),
            },
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
        self.grids, self.statuses = {}, None  # the last map goes: its axes may differ
        self._draw()
        self.stop.clear()
        self.running = True
        self._set_inputs_enabled(False)
        total = int(np.prod([len(v) for v in self.values]))
        self.progress.setRange(0, total)
        self.progress.setValue(0)
        self._say(f"starting a local cluster of {self.workers.value()} workers…")
        self.jobs.submit(
            partial(_run_study, spec, self.workers.value(), self.stop),
            self._finished,
            with_task=True,
            on_progress=self._progress,
        )
        return True

    def cancel(self) -> None:
        if self.running:
            self.stop.set()
            self._say("cancelling after the running points…")

    def _progress(self, done: int, failed: int, total: int) -> None:
        self.progress.setRange(0, total)
        self.progress.setValue(done)
        self._say(f"{done} of {total} points, {failed} failed")
        self.progressed.emit(done, failed, total)

    def _finished(self, outcome: object) -> None:
        self.running = False
        self._set_inputs_enabled(True)
        if isinstance(outcome, tuple):
            self.grids, self.statuses = outcome
            self._draw()
            self.finished_study.emit(None)
            return
        self._say("cancelled" if outcome == "cancelled" else str(outcome), outcome != "cancelled")
        self.finished_study.emit(outcome)

    def _set_inputs_enabled(self, on: bool) -> None:
        for row in self.axis_rows:
            for w in row:
                w.setEnabled(on)
        for widget in (
            self.frequencies,
            self.direction,
            self.polarization,
            self.workers,
            self.run_button,
            self.close_button,
        ):
            widget.setEnabled(on)
        self.cancel_button.setEnabled(not on)

    # -- the heat map ----------------------------------------------------------------------

    def _band(self) -> str:
        """The swept band as typed, for messages ("4GHz:9GHz:11" -> "4–9 GHz")."""
        try:
            from barymesh.study import parse_spec

            f = parse_spec(self.spec).solve.frequencies
            return f"{f[0] / 1e9:.4g}–{f[-1] / 1e9:.4g} GHz"
        except (ImportError, ValueError, KeyError, IndexError):
            return "the band"

    def summary(self) -> str:
        """The finished study in one line: points, failed ones, those without the figure."""
        key = self.figure_choice.currentData()
        assert self.grid is not None and self.statuses is not None  # a study's map is shown
        missing, failed = missing_cells(self.grid, self.statuses)
        n, bad, none = self.grid.size, int(failed.sum()), int(missing.sum())
        text = f"{n} points, {bad} failed"
        if none:
            text += f", {none} with {MISSING[key]}"
        if none + bad == n:
            return text + f": the map has no value ({self._why_empty()})."
        return text + ". Click a cell to load that design."

    def _why_empty(self) -> str:
        """Why no point has the shown figure, and what to try."""
        key = self.figure_choice.currentData()
        assert self.grid is not None and self.statuses is not None  # a study's map is shown
        missing, failed = missing_cells(self.grid, self.statuses)
        if not missing.any():
            return "every point failed; the failures are in the log"
        d, p = self.direction.currentText(), self.polarization.currentText()
        if (
            key == "resonance_frequency"
            or not np.isfinite(
                self.grids.get(FIGURES["resonance_frequency"][0], np.array(np.nan))
            ).any()
        ):
            return (
                f"the extinction cross-section has no peak inside {self._band()} under "
                f"E along {p} travelling {d}: try another polarisation (E across a "
                "ring's gap) or a wider band"
            )
        return f"{MISSING[key]} at every point; choose Resonance frequency to see the peaks"

    def _draw(self, *_args: object) -> None:
        ax = self.axes
        if self.colorbar is not None:  # before the axes are cleared: it gives their room back
            self.colorbar.remove()
            self.colorbar = None
        ax.clear()
        self.image = None
        names = [row[0].currentText() for row in self.axis_rows]
        ax.set_xlabel(names[1])
        ax.set_ylabel(names[0])
        if not self.grids or len(self.values) != 2:
            self.grid = None
            ax.text(0.5, 0.5, "Run a study to see its map", ha="center", va="center")
            ax.set_xticks([])
            ax.set_yticks([])
            self.canvas.draw_idle()
            return
        from matplotlib.patches import Patch, Rectangle

        key = self.figure_choice.currentData()
        column, title, scale, unit = FIGURES[key]
        self.grid = self.grids[column]
        assert self.statuses is not None  # they come with the grids
        self._say(self.summary(), error=False)
        rows, cols = self.values
        extent = (-0.5, len(cols) - 0.5, -0.5, len(rows) - 0.5)
        missing, failed = missing_cells(self.grid, self.statuses)
        values = np.ma.masked_invalid(self.grid * scale)
        self.image = ax.imshow(values, origin="lower", aspect="auto", cmap="viridis", extent=extent)
        ax.set_xlim(extent[0], extent[1])
        ax.set_ylim(extent[2], extent[3])
        ax.set_xticks(range(len(cols)), [f"{v:.3g}" for v in cols])
        ax.set_yticks(range(len(rows)), [f"{v:.3g}" for v in rows])
        legend = []
        for mask, hatch, text in (
            (missing, MISSING_HATCH, MISSING[key]),
            (failed, FAILED_HATCH, "failed (see the log)"),
        ):
            for i, j in zip(*np.nonzero(mask), strict=True):
                ax.add_patch(
                    Rectangle(
                        (j - 0.5, i - 0.5),
                        1,
                        1,
                        facecolor="#eeeeee",
                        edgecolor="#555555",
                        hatch=hatch,
                        linewidth=0.5,
                    )
                )
            if mask.any():
                legend.append(
                    Patch(facecolor="#eeeeee", edgecolor="#555555", hatch=hatch, label=text)
                )
        if legend:
            ax.legend(
                handles=legend,
                loc="lower left",
                bbox_to_anchor=(0.0, 1.01),
                ncols=2,
                fontsize="small",
                frameon=False,
                borderaxespad=0.0,
            )
        if missing.sum() + failed.sum() == self.grid.size:
            ax.text(
                0.5,
                0.5,
                "No point has a value:\n" + _wrapped(self._why_empty(), 44),
                ha="center",
                va="center",
                transform=ax.transAxes,
                fontsize="small",
                bbox={"facecolor": "white", "edgecolor": "#b00020", "alpha": 0.95},
            )
            self._say(self.summary(), error=True)
        else:
            self.colorbar = self.figure.colorbar(
                self.image, ax=ax, label=f"{title} ({unit})".replace(" ()", "")
            )
        self.canvas.draw_idle()

    def cell_params(self, i: int, j: int) -> MeshParams:
        """The design of the map's cell at row ``i`` (axis 1) and column ``j`` (axis 2)."""
        assert self.base is not None
        names = list(self.spec["axes"])
        changes: dict[str, Any] = {names[0]: self.values[0][i], names[1]: self.values[1][j]}
        return dataclasses.replace(self.base, **changes)

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


def _wrapped(text: str, width: int) -> str:
    import textwrap

    return "\n".join(textwrap.wrap(text, width))

"""The Solve dock's "Reflection phase" tab: the S-curve of a unit cell (issue 33 §1).

When the mesh on screen is a unit cell (it carries a lattice and the window holds its
cell: a cell preset, a cell file, the cell editor), the tab takes one of the cell's
real-valued parameters (a combo box of the paths a study's axis takes,
``elements[0].inner_radius``), its range (start, stop, points), one frequency, the
incidence (θ, φ, TE or TM) and the layers around the sheet with an optional ground plane,
and shows the co-polar ∠R (degrees, unwrapped) and |R| of the cell's infinite array
against the parameter (:func:`barymesh.mom.reflection_library`), the cell on screen's
value marked, where ∠R is referred and how much of the 360° the curve covers written over
it. The curve lives in a dock of its own, **Phase curve**, under the 3D view (tabbed with
the Infinite array's **Array curve**), opened when the tab is first shown or Run is clicked.

The layers are the Infinite array tab's: the two tabs' stack editors show one stack, an
edit in either is an edit of both.

The curve is solved in the solver's process (:mod:`barymesh.app.panels.phase_curve`),
waited for by a worker thread of the tab's :class:`~barymesh.app.jobs.Jobs`, which also
draws it (Agg, :func:`barymesh.app.panels.phase_figure.draw_phase_curve`); the GUI thread
only shows the picture. Every :data:`~barymesh.app.panels.phase_curve.PREVIEW_STEP`-th
value is solved and drawn first (:attr:`ReflectionPhasePanel.preview`), then the rest
(:attr:`ReflectionPhasePanel.swept`). With **Live** on (after the first Run), a new mesh
on screen (a slider, the cell editor), a good edit of the stack, the frequency, the
incidence, the parameter or its range cancels the running curve and starts the next; a
result older than the latest request is dropped by its token. A new cell that differs
only in the parameter itself keeps the curve and moves the mark.

A click on the curve loads the cell of the nearest value solved: the model's cell takes
that value (one undo step, as an edit in the cell editor), and the window meshes it.

Once a whole curve is shown, **Design reflectarray…** opens the reflectarray designer on
it (:mod:`barymesh.app.dialogs.reflectarray_designer`, made and imported when first
opened); a new whole curve is handed to it while it is open. Its **Open as cell** opens
the array in the window through ``open_cell`` and turns Live off first (the array is not
the curve's cell, and its curve would be a long solve).

A bad input (a range the cell refuses, a frequency that is no number) is said in one red
line under the inputs; the last good curve stays. Without a cell the tab says why in one
line and its inputs are disabled.
"""

from __future__ import annotations

import html
import logging
import threading
from collections.abc import Callable
from functools import partial
from typing import Any

import numpy as np
from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDockWidget,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from barymesh import TriMesh
from barymesh.app.jobs import Jobs, Task
from barymesh.app.model.solve_inputs import read_frequency
from barymesh.app.panels.array_sweep import lattice_vectors
from barymesh.app.panels.curve_tab_parts import (
    GREY,
    add_messages,
    add_note_and_show_button,
    curve_area,
    stack_group,
)
from barymesh.app.panels.infinite_array_panel import PictureView, read_angle
from barymesh.app.panels.phase_curve import (
    MAX_VALUES,
    PhaseInputs,
    check_values,
    coverage,
    curve_key,
    default_range,
    parameter_paths,
    passes,
    solve_curve,
    state_with,
    value_of,
)
from barymesh.app.panels.phase_figure import coverage_text, draw_phase_curve, plane_text
from barymesh.app.panels.solve_panel import run_job
from barymesh.app.panels.stack_editor import StackEditor

log = logging.getLogger(__name__)

#: Height of the Phase curve dock when it first opens (pixels).
CURVE_DOCK_HEIGHT = 300


def read_number(text: str, name: str) -> float:
    """A typed number; ValueError naming ``name`` otherwise.

    >>> read_number(" 2.5 ", "Start")
    2.5
    """
    try:
        value = float(text.strip().replace("−", "-"))
    except ValueError:
        raise ValueError(f"{name} {text!r} is not a number; type e.g. 2.5") from None
    if not np.isfinite(value):
        raise ValueError(f"{name} {text!r} is not finite; type a number")
    return value


class PhaseCurveView(PictureView):
    """The S-curve's picture: a click on its axes reports the parameter's value there."""

    def mousePressEvent(self, event: Any) -> None:  # noqa: N802 - Qt's name
        if self.picture is None or event.button() != Qt.MouseButton.LeftButton:
            return
        pos = event.position()
        value = self.picture.value_at(pos.x(), pos.y())
        if value is not None:
            self.clicked.emit(value)


class ReflectionPhasePanel(QWidget):
    """The "Reflection phase" tab (see module docstring).

    Parameters
    ----------
    model : AppModel
        The window's model: the cell on screen (``shown_state``) and its edits.
    parent : QWidget, optional
    host : ToolHost, optional
        The window: the curve goes into a dock of its own (:attr:`curve_dock`). Without
        one it stays in the tab, under the inputs.
    stack_twin : StackEditor, optional
        The Infinite array tab's stack editor: the two show one stack.
    tab_with : QDockWidget, optional
        A dock the curve's dock is tabbed with (the Array curve).
    open_cell : callable, optional
        ``open_cell(cell, message)``: the window opens a unit cell (the reflectarray
        designer's **Open as cell**).
    """

    #: the preview (a ReflectionLibrary of the first pass's values) shown
    preview = Signal(object)
    #: the whole curve (a ReflectionLibrary) shown
    swept = Signal(object)

    def __init__(
        self,
        model: Any,
        parent: QWidget | None = None,
        host: Any = None,
        stack_twin: StackEditor | None = None,
        tab_with: QDockWidget | None = None,
        open_cell: Callable[[Any, str], None] | None = None,
    ) -> None:
        super().__init__(parent)
        self.model = model
        self.open_cell = open_cell
        self.designer: Any = None  # the reflectarray designer, made when first opened
        self.host = host
        self.stack_twin = stack_twin
        self.curve_dock: QDockWidget | None = None
        self._curve_sized = False
        self._shown_once = False
        self.jobs = Jobs(self, name="barymesh-phase")  # one curve at a time
        self.draw_jobs = Jobs(self, name="barymesh-phase-draw")  # redraws: a mark, a size
        self.library: Any = None  # the curve shown (a ReflectionLibrary)
        self.partial: Any = None  # the preview shown while the rest is solved
        self.curve_for: tuple[str, PhaseInputs] | None = None  # its cell key and inputs
        self.requested: tuple[str, PhaseInputs] | None = None  # the latest Run's
        self.marked: float | None = None  # the cell on screen's value, if it has one
        self.engaged = False  # set by the first Run: from then on Live follows
        self.cancelled: list[int] = []
        self.stopped: list[int] = []
        self.last_outcome: Any = None
        self._tokens = {"curve": 0, "draw": 0}
        self._cancel: dict[int, threading.Event] = {}
        self._syncing = False
        self._paths: list[str] = []
        self._build(tab_with)
        model.result_changed.connect(self._mesh_changed)
        self._mesh_changed(model.result)  # (the empty axes are drawn when first shown)

    # -- layout ----------------------------------------------------------------------

    def _build(self, tab_with: QDockWidget | None) -> None:
        col = QVBoxLayout(self)
        self.reason = QLabel(self)
        self.reason.setWordWrap(True)
        self.reason.setStyleSheet("color: #b35900;")
        col.addWidget(self.reason)
        self.inputs_box = QWidget(self)
        form = QFormLayout(self.inputs_box)
        form.setContentsMargins(0, 0, 0, 0)
        form.setRowWrapPolicy(QFormLayout.RowWrapPolicy.WrapLongRows)
        self.parameter = QComboBox(self)
        self.parameter.setToolTip(
            "The cell's value the curve runs over, as a study's axis names it"
        )
        self.parameter.setSizeAdjustPolicy(
            QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon
        )
        self.parameter.setMinimumContentsLength(10)
        self.parameter.activated.connect(self._parameter_chosen)
        form.addRow(self._label("Para&meter", self.parameter), self.parameter)
        self.start = QLineEdit("", self)
        self.start.setToolTip("The parameter's first value (mm, or ° for an angle)")
        self.stop_edit = QLineEdit("", self)
        self.stop_edit.setToolTip("The parameter's last value")
        row = QHBoxLayout()
        row.addWidget(self.start, 1)
        row.addWidget(QLabel("to", self))
        row.addWidget(self.stop_edit, 1)
        form.addRow(self._label("Rang&e", self.start), row)
        self.points = QSpinBox(self)
        self.points.setRange(2, MAX_VALUES)
        self.points.setValue(9)
        self.points.setToolTip(
            "Values in the range, evenly spaced; every 4th is solved and drawn first"
        )
        form.addRow("&Points", self.points)
        self.frequency = QLineEdit("10", self)
        self.frequency.setToolTip("The one frequency of the curve (GHz)")
        form.addRow(self._label("&Frequency (GHz)", self.frequency), self.frequency)
        self.theta = QLineEdit("0", self)
        self.theta.setToolTip("θ (degrees from the normal) of the direction the wave comes from")
        self.phi = QLineEdit("0", self)
        self.phi.setToolTip("φ (degrees from x) of the direction the wave comes from")
        row = QHBoxLayout()
        row.addWidget(QLabel("θ", self))
        row.addWidget(self.theta, 1)
        row.addWidget(QLabel("φ", self))
        row.addWidget(self.phi, 1)
        form.addRow(self._label("An&gle (°)", self.theta), row)
        self.polarization = QComboBox(self)
        for name in ("TE", "TM"):
            self.polarization.addItem(name, name)
        self.polarization.setCurrentIndex(1)  # TM: E along x at normal incidence
        self.polarization.setToolTip(
            "TE: E perpendicular to the plane of incidence; TM: in it (at normal incidence "
            "TM has E along x). ∠R is the co-polar reflection's"
        )
        self.polarization.activated.connect(lambda _i: self._edited())
        form.addRow("P&olarisation", self.polarization)
        self.live = QCheckBox("&Live: follow the cell", self)
        self.live.setChecked(True)
        self.live.setToolTip(
            "Solve again whenever the cell (a slider, the cell editor), the stack or an input "
            "changes"
        )
        self.run_button = QPushButton("&Run", self)
        self.run_button.setToolTip("Solve the reflection phase curve over the range")
        self.run_button.clicked.connect(self._run_clicked)
        row = QHBoxLayout()
        row.addWidget(self.run_button)
        row.addWidget(self.live, 1)
        form.addRow(row)
        col.addWidget(self.inputs_box)
        shown = add_messages(self, col)
        self.error, self.status, self.warnings = shown.error, shown.status, shown.warnings
        self.stack_box, box, self.stack_editor = stack_group(
            self,
            "Dielectric layers around the sheet, top first, and a ground plane under them: "
            "one stack with the Array tab (infinite array)",
        )
        if self.stack_twin is not None:
            shared = QLabel("One stack with the Array tab.", self.stack_box)
            shared.setWordWrap(True)
            shared.setStyleSheet(GREY)
            box.addWidget(shared)
            self.stack_editor.set_stack(self.stack_twin.stack)
            self.stack_twin.changed.connect(partial(self._twin_changed, self.stack_editor))
            self.stack_editor.changed.connect(partial(self._twin_changed, self.stack_twin))
        self.stack_editor.changed.connect(lambda _s: self._edited())
        box.addWidget(self.stack_editor)
        col.addWidget(self.stack_box)
        self.note, self.show_curve_button = add_note_and_show_button(self, col, "Phase curve")
        self.show_curve_button.clicked.connect(self.show_curve)
        self.design_button = QPushButton("Design reflectarra&y…", self)
        self.design_button.setToolTip(
            "Lay a reflectarray out from this curve: its elements' parameters, phase errors "
            "and pattern (a window of its own)"
        )
        self.design_button.setEnabled(False)  # until a whole curve is solved
        self.design_button.clicked.connect(self.open_designer)
        col.addWidget(self.design_button)
        self.curve_area, area, self.curve_line = curve_area("No curve yet: Run in the Phase tab.")
        grow = self.host is not None
        self.plot = PhaseCurveView(230 if grow else 330, self.curve_area, grow=grow)
        self.plot.setToolTip("Click a point of the curve: that cell becomes the one on screen")
        self.plot.clicked.connect(self.load_value)
        self.plot.resized.connect(self._redraw)
        area.addWidget(self.plot, 1)
        if self.host is None:
            self.show_curve_button.hide()
            col.addWidget(self.curve_area)
        else:
            self.curve_dock = self.host.add_dock(
                "Phase curve",
                self.curve_area,
                Qt.DockWidgetArea.BottomDockWidgetArea,
                name="dock_phase_curve",
                tab_with=tab_with,
            )
            self.curve_dock.hide()  # until the tab is shown
            self.curve_dock.visibilityChanged.connect(lambda _v: self._update_curve_button())
        col.addStretch(1)
        for edit in (self.start, self.stop_edit, self.frequency, self.theta, self.phi):
            edit.returnPressed.connect(self._edited)
        self.points.lineEdit().returnPressed.connect(self._edited)

    def _label(self, text: str, buddy: QWidget) -> QLabel:
        label = QLabel(text, self)
        label.setBuddy(buddy)
        return label

    def _twin_changed(self, other: StackEditor, stack: Any) -> None:
        """One stack for both tabs: a good stack in one editor is shown by the other."""
        if self._syncing or other.stack == stack:
            return
        self._syncing = True
        try:
            other.set_stack(stack)
        finally:
            self._syncing = False

    # -- inputs ----------------------------------------------------------------------

    @property
    def mesh(self) -> TriMesh | None:
        result = self.model.result
        return None if result is None else result.mesh

    @property
    def cell(self) -> Any:
        """The unit cell on screen (its visible elements), or None."""
        state = getattr(self.model, "shown_state", None)
        return None if state is None or self.mesh is None else state.visible

    def inputs(self) -> PhaseInputs:
        """The fields as :class:`PhaseInputs`; ValueError naming the field if invalid."""
        path = self.parameter.currentData()
        if not path:
            raise ValueError("Choose a parameter: the cell has none a curve can run over")
        a = read_number(self.start.text(), "Range start")
        b = read_number(self.stop_edit.text(), "Range stop")
        if a == b:
            raise ValueError(f"Range {a:g} to {b:g}: the stop must differ from the start")
        f = read_frequency(self.frequency.text(), "GHz")
        theta = read_angle(self.theta.text(), "θ", 0.0, 90.0)
        phi = read_angle(self.phi.text(), "φ", -360.0, 360.0)
        if self.stack_editor.error:
            raise ValueError(self.stack_editor.error)
        values = tuple(float(v) for v in np.linspace(a, b, self.points.value()))
        return PhaseInputs(
            path, values, f, theta, phi, self.polarization.currentData(), self.stack_editor.stack
        )

    def _reason(self) -> str:
        """Why the tab cannot solve the mesh on screen ("" if it can)."""
        mesh = self.mesh
        if mesh is None:
            return "No mesh on screen."
        try:
            lattice_vectors(mesh)
        except ValueError as exc:
            return f"{exc}."
        if self.cell is None:
            return "The mesh on screen is no cell the window holds: open a cell to vary it."
        return ""

    def _update_enabled(self) -> None:
        reason = self._reason()
        self.reason.setText(reason)
        self.reason.setVisible(bool(reason))
        self.inputs_box.setEnabled(not reason)
        self.stack_box.setEnabled(not reason)

    def _fill_parameters(self) -> None:
        """The cell's parameter paths in the combo box; the chosen one kept if it is there."""
        cell = self.cell
        paths = [p for p, _v in parameter_paths(cell)] if cell is not None else []
        if paths == self._paths:
            return
        keep = self.parameter.currentData()
        self._paths = paths
        self.parameter.blockSignals(True)
        self.parameter.clear()
        for p in paths:
            self.parameter.addItem(p, p)
        self.parameter.blockSignals(False)
        if keep in paths:
            self.parameter.setCurrentIndex(paths.index(keep))
        elif paths:
            self.parameter.setCurrentIndex(0)
            self._fill_range()

    def _fill_range(self) -> None:
        """A first range around the chosen parameter's value."""
        cell, path = self.cell, self.parameter.currentData()
        if cell is None or not path:
            return
        a, b = default_range(cell, path)
        self.start.setText(f"{a:.6g}")
        self.stop_edit.setText(f"{b:.6g}")

    def _parameter_chosen(self, _index: int) -> None:
        self._fill_range()
        self._edited()

    def _edited(self) -> None:
        """An input changed (Enter, a choice, a stack): check it, say a refusal in one
        line; Live solves again."""
        try:
            self.inputs()
        except ValueError as exc:
            self.error.setText(str(exc))
            return
        self.error.clear()
        if self.engaged and self.live.isChecked() and not self._reason():
            if self.requested is not None and self._request_key() == self.requested:
                return  # the inputs of the curve shown or coming (a value typed back)
            self.run()

    def _request_key(self) -> tuple[str, PhaseInputs] | None:
        """What a Run now would solve: the cell's key and the inputs (None: nothing)."""
        cell = self.cell
        try:
            inputs = self.inputs()
        except ValueError:
            return None
        return None if cell is None else (curve_key(cell, inputs.parameter), inputs)

    # -- the curve's dock ------------------------------------------------------------

    def show_curve(self) -> None:
        """Open (and raise) the Phase curve dock; the first time at a readable height."""
        dock = self.curve_dock
        if dock is None:
            return
        dock.show()
        dock.raise_()
        if not self._curve_sized and self.host is not None:
            self._curve_sized = True
            window = self.host.widget
            if window.dockWidgetArea(dock) == Qt.DockWidgetArea.BottomDockWidgetArea:
                window.resizeDocks([dock], [CURVE_DOCK_HEIGHT], Qt.Orientation.Vertical)
        self._update_curve_button()

    def _update_curve_button(self) -> None:
        dock = self.curve_dock
        self.show_curve_button.setVisible(dock is not None and not dock.isVisible())

    def showEvent(self, event: Any) -> None:  # noqa: N802 - Qt's name
        super().showEvent(event)
        if not self._shown_once:
            self._shown_once = True
            self.show_curve()
            if self.plot.picture is None:
                self._redraw()

    def _run_clicked(self) -> None:
        self.show_curve()
        self.run()

    # -- jobs ------------------------------------------------------------------------

    def run(self) -> bool:
        """Solve the curve of the cell on screen (a worker); False and a one-line message
        if the inputs or the cell cannot be solved (the last good curve stays)."""
        try:
            reason = self._reason()
            if reason:
                raise ValueError(reason)
            inputs = self.inputs()
            cell = self.cell
            check_values(cell, inputs.parameter, inputs.values)
        except ValueError as exc:
            self.error.setText(str(exc))
            return False
        self.error.clear()
        self.engaged = True
        self._cancel_running()
        self._tokens["curve"] += 1
        token = self._tokens["curve"]
        stop = self._cancel[token] = threading.Event()
        key = curve_key(cell, inputs.parameter)
        self.requested = (key, inputs)
        marked = self.marked = self._value_on_screen(inputs.parameter)
        mesh = self.mesh
        size, ratio = self.plot.request_size()
        first, rest = passes(len(inputs.values))

        def work(task: Task) -> tuple[Any, Any, str, PhaseInputs]:  # numpy, Agg
            def previewed(library: Any) -> None:
                picture = draw_phase_curve(library, marked, size, ratio, preview=len(rest))
                task.report("preview", token, library, picture)

            def progress(done: int, total: int) -> None:
                task.report("progress", token, done, total)

            library = solve_curve(cell, inputs, previewed, progress, stop.is_set)
            return library, draw_phase_curve(library, marked, size, ratio), key, inputs

        self.status.setText(f"Solving {len(inputs.values)} values ({len(first)} first)…")
        self.jobs.submit(
            lambda task: run_job(token, mesh, "curve", partial(work, task)),
            self._finished,
            with_task=True,
            on_progress=self._progress,
        )
        return True

    def _cancel_running(self) -> None:
        token = self._tokens["curve"]
        stop = self._cancel.pop(token, None)
        if stop is not None:
            stop.set()
            self.cancelled.append(token)

    def cancel(self) -> None:
        """Stop the running curve before its next value; drop its result."""
        if self._cancel:
            self._cancel_running()
            self._tokens["curve"] += 1
            self.status.setText("The phase curve was cancelled.")

    def _progress(self, kind: str, token: int, *values: Any) -> None:
        if token != self._tokens["curve"]:
            return
        if kind == "progress":
            done, total = values
            self.status.setText(f"Solving: {done} of {total} values…")
            return
        library, picture = values
        self.partial = library
        self.plot.show_picture(picture)
        self.curve_line.setText(f"Preview: {len(library.values)} values, refining…")
        self.preview.emit(library)

    def _redraw(self) -> None:
        """Draw the curve again (in a worker) at the view's size and with the mark."""
        library = self.library
        marked = self.marked
        size, ratio = self.plot.request_size()
        self._tokens["draw"] += 1
        token = self._tokens["draw"]

        def work() -> Any:
            if token != self._tokens["draw"]:  # a newer redraw is queued: skip this one
                return None
            return draw_phase_curve(library, marked, size, ratio)

        self.draw_jobs.submit(lambda: run_job(token, None, "draw", work), self._finished)

    def _finished(self, outcome: Any) -> None:
        if outcome.kind == "draw":
            if outcome.token == self._tokens["draw"] and outcome.result is not None:
                self.plot.show_picture(outcome.result)
            return
        self.last_outcome = outcome
        self._cancel.pop(outcome.token, None)
        if outcome.cancelled:
            self.stopped.append(outcome.token)
        if outcome.token != self._tokens["curve"] or outcome.cancelled:
            log.debug("dropped a stale phase curve")
            return
        if outcome.error is not None:
            self.status.clear()
            self.error.setText(f"The phase curve failed: {outcome.error}")
            return
        library, picture, key, inputs = outcome.result
        self.library, self.partial = library, None
        self.curve_for = (key, inputs)
        self._tokens["draw"] += 1  # a redraw asked for before is older than this
        self.plot.show_picture(picture)
        self.status.setText(f"Done in {outcome.seconds:.2f} s.")
        self._describe(library)
        self.design_button.setEnabled(True)
        if self.designer is not None and self.designer.isVisible():
            self.designer.set_library(library)  # the designer follows the curve
        self.swept.emit(library)
        # the cell may have moved while the curve was solved: its mark follows
        marked = self._value_on_screen(inputs.parameter)
        if marked != self.marked:
            self.marked = marked
            self._redraw()

    def _describe(self, library: Any) -> None:
        stack = library.stack
        on = f"on {stack.describe()}" if stack is not None else "in vacuum"
        text = (
            f"{library.parameter} from {library.values[0]:g} to {library.values[-1]:g}, "
            f"{library.frequencies[0] / 1e9:.4g} GHz, {on}: {coverage_text(coverage(library))}. "
            f"{plane_text(library)}. Click the curve to load that cell."
        )
        self.note.setText(text)
        self.curve_line.setText(f"{library.parameter}: click a point to load that cell")
        found: dict[str, str] = {}  # kind -> its first sentence: one of each
        for text in library.warnings:
            found.setdefault(text.split(":")[0], text)
        if found:
            self.warnings.setText("<br>".join(f"⚠ {html.escape(w)}" for w in found.values()))
            self.warnings.show()
        else:
            self.warnings.clear()
            self.warnings.hide()

    # -- the reflectarray designer -------------------------------------------------------

    def open_designer(self) -> Any:
        """Open (and raise) the reflectarray designer on the whole curve shown; it is
        made the first time (its modules imported then)."""
        if self.library is None:
            return None
        if self.designer is None:
            from barymesh.app.dialogs.reflectarray_designer import ReflectarrayDesigner

            self.designer = ReflectarrayDesigner(self._open_array_cell, self)
        self.designer.set_library(self.library)
        self.designer.show()
        self.designer.raise_()
        self.designer.activateWindow()
        return self.designer

    def _open_array_cell(self, cell: Any, message: str) -> None:
        """The designer's array opened as the window's cell: Live goes off first (the
        curve is the library's cell's, not the array's, whose curve would be long)."""
        if self.open_cell is None:
            return
        if self.live.isChecked():
            self.live.setChecked(False)
            self.status.setText("Live is off: the cell on screen is the reflectarray.")
        self.open_cell(cell, message)

    # -- the cell ----------------------------------------------------------------------

    def _value_on_screen(self, path: str) -> float | None:
        cell = self.cell
        if cell is None:
            return None
        try:
            return value_of(cell, path)
        except ValueError:
            return None

    def load_value(self, value: float) -> bool:
        """Make the cell with the curve's value nearest ``value`` the one on screen."""
        library = self.library
        state = self.model.cell_state
        if library is None or state is None or self.curve_for is None:
            return False
        values = np.asarray(library.values, dtype=float)
        chosen = float(values[int(np.argmin(np.abs(values - value)))])
        path = library.parameter
        self.status.setText(f"Loading the cell with {path} = {chosen:g}…")
        taken = self.model.edit_cell(lambda s: state_with(s, path, chosen))
        if not taken:
            self.error.setText(f"Could not load {path} = {chosen:g}: {self.model.cell_error}")
        return bool(taken)

    def _mesh_changed(self, result: Any) -> None:
        self._update_enabled()
        self._fill_parameters()
        if self.requested is None:
            return
        key, inputs = self.requested
        marked = self._value_on_screen(inputs.parameter)
        cell = self.cell
        same = cell is not None and curve_key(cell, inputs.parameter) == key
        if marked != self.marked:
            self.marked = marked
            if self.library is not None and (same or not self.live.isChecked()):
                self._redraw()
        if same:
            return
        live = self.engaged and self.live.isChecked()
        self.curve_line.setText(
            "Updating for the new cell…" if live else "This curve is for the previous cell."
        )
        if live:
            if self._reason():
                self._cancel_running()
                return
            self.run()

    def stop(self, msecs: int = 30_000) -> bool:
        """Cancel and wait for running jobs (the window is closing)."""
        for stop in self._cancel.values():
            stop.set()
        self._cancel.clear()
        for kind in self._tokens:
            self._tokens[kind] += 1
        try:
            self.model.result_changed.disconnect(self._mesh_changed)
        except (RuntimeError, ValueError):
            pass
        designed = self.designer is None or self.designer.stop(msecs)
        return self.jobs.wait(msecs) and self.draw_jobs.wait(msecs) and designed

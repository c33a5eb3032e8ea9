"""The Solve dock: an RWG Method-of-Moments solve (:mod:`barymesh.mom`) of the mesh on screen.

Two tabs. **Solve**: a frequency with its unit, the excitation: a plane wave (its
direction of travel and polarisation: an axis such as ``-z`` or ``x``, or a vector
``0, 0, -1``) or a delta-gap voltage feed (1 V across the mesh edges on a line between
two points typed in mm; the input impedance is shown after the solve), a Solve button,
and the "Surface current" layer's controls (show, linear/log colour map, phase slider and
animation; :class:`barymesh.app.view.current_layer.CurrentLayer` draws it).
**Sweep**: the extinction
cross-section against frequency (matplotlib), the resonances marked; a click on the
plot sets the frequency and solves there.

With **Solver-grade mesh** on (the default, as ``barymesh solve`` without
``--mesh-as-given``), the solve and the sweep are of the solver-grade mesh of the
structure or cell on screen (:mod:`barymesh.app.model.solver_mesh`: graded toward the
metal's edges, every edge within λ/10 at the highest frequency), built in the worker; the
result says which mesh was solved and with how many unknowns beside the drawn mesh's, and
the Surface current layer draws the current on the mesh solved. Off, the mesh is solved
as drawn.

Meshes solved as drawn with at most :data:`AUTO_SOLVE_UNKNOWNS` RWG unknowns are solved on
the GUI thread, and, once a user has asked for a solve, again whenever the mesh or a solve
input changes (auto-solve). Larger ones, and every solver-grade mesh, are solved when
asked, in a worker thread (:class:`barymesh.app.jobs.Jobs`) with a busy bar (a sweep:
progress per frequency) and Cancel. A result that no longer matches the mesh or the
inputs is cleared from the view and the panel says so.
"""

from __future__ import annotations

import html
import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import partial
from typing import TYPE_CHECKING, Any

import numpy as np
from PySide6.QtCore import (
    QEvent,
    QObject,
    QSize,
    Qt,
    QTimer,
    Signal,
)
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QProgressBar,
    QPushButton,
    QSizePolicy,
    QSlider,
    QSpinBox,
    QTabWidget,
    QVBoxLayout,
    QWidget,
)

from barymesh import TriMesh
from barymesh.app.jobs import Jobs, Task
from barymesh.app.model.solve_inputs import (
    DIRECTION_PRESETS,
    POLARIZATION_PRESETS,
    UNITS,
    format_frequency,
    format_impedance,
    read_frequency,
    read_point,
    read_vector,
)
from barymesh.app.model.solver_mesh import (
    SolvedMesh,
    SolverGradeRefused,
    gradable,
    solver_mesh,
)
from barymesh.app.panels.frequency_band import FrequencyBand
from barymesh.app.view.current_layer import SCALES, CurrentLayer

if TYPE_CHECKING:
    from barymesh.app.model import AppModel
    from barymesh.app.tool_host import ToolHost

log = logging.getLogger(__name__)

#: Meshes with at most this many RWG unknowns are solved on the GUI thread, and solved
#: again at once when the mesh or an input changes. Measured on the 2-core test machine
#: (``barymesh.mom.solve``, geometry + fill + LU, square patches): 40 unknowns 20 ms, 65
#: unknowns 36 ms, 96 unknowns 85–127 ms while other jobs loaded the cores.
AUTO_SOLVE_UNKNOWNS = 80
#: The widest the panel asks to be (px).
PANEL_WIDTH = 300
#: Phase step (degrees) of the animation, and its period (ms per step).
ANIMATION_STEP = 10
ANIMATION_MS = 60
#: The check box's tooltip (the Infinite array tab says the same of its layers).
SOLVER_GRADE_TIP = (
    "Solve the solver-grade mesh of the structure or cell on screen, as barymesh solve "
    "does: graded toward the metal's edges, every edge within λ/10 at the highest "
    "frequency (in the densest layer). Off: solve the mesh as drawn."
)


@dataclass(frozen=True)
class Solved:
    """What a solve or sweep job of the dock returns: the result, the mesh it is of, and
    the sentence saying which mesh that was (:meth:`SolvedMesh.describe`)."""

    result: Any  # barymesh.mom.Solution or SweepResult
    mesh: SolvedMesh
    said: str


def solve_graded(
    result: Any,
    top_frequency: float,
    graded: bool,
    then: Callable[[TriMesh], Any],
) -> Solved:
    """``then(mesh)`` on the solver-grade mesh of ``result`` (``graded``; else on the mesh
    drawn): the worker's whole job, the mesh built there, never on the GUI thread. The
    unknowns said are the RWG functions of each mesh (the free-space solver's)."""
    shown = result.mesh
    solved = solver_mesh(result, top_frequency) if graded else SolvedMesh(shown, shown)
    value = then(solved.mesh)
    shown_unknowns = (result.stats or {}).get("interior_edges")
    return Solved(value, solved, solved.describe(len(solved.mesh.rwg), shown_unknowns))


@dataclass
class Outcome:
    """What a solve or sweep job delivers to the GUI thread."""

    token: int
    mesh: TriMesh | None  # None: a redraw's
    kind: str  # "solve" or "sweep"
    result: Any = None  # barymesh.mom.Solution or SweepResult
    error: str | None = None
    cancelled: bool = False
    seconds: float = 0.0
    thread: int = field(default_factory=threading.get_ident)


def run_job(token: int, mesh: TriMesh | None, kind: str, work: Callable[[], Any]) -> Outcome:
    """Call ``work()`` and wrap what it returns or raises (never raises)."""
    from barymesh.mom import ProblemTooLarge, SolveCancelled

    start = time.perf_counter()
    try:
        result = work()
    except SolveCancelled as exc:
        return Outcome(token, mesh, kind, error=str(exc), cancelled=True)
    except (ProblemTooLarge, SolverGradeRefused) as exc:  # a refusal, not a fault
        log.info("the %s was refused: %s", kind, exc)
        return Outcome(token, mesh, kind, error=str(exc))
    except Exception as exc:  # noqa: BLE001 - shown in the panel, never a crash
        log.exception("the %s failed", kind)
        return Outcome(token, mesh, kind, error=str(exc) or type(exc).__name__)
    return Outcome(token, mesh, kind, result, seconds=time.perf_counter() - start)


class SweepPlot(QWidget):
    """Extinction cross-section against frequency; a click reports a frequency (Hz)."""

    clicked = Signal(float)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        from matplotlib.figure import Figure

        from barymesh.app.view.canvas import ShownCanvas

        self.figure = Figure(figsize=(3, 2.4), dpi=90, layout="constrained")
        # drawn only while its tab is shown: a new mesh marks it with every auto-solve
        self.canvas = ShownCanvas(self.figure)
        self.canvas.setMinimumHeight(220)
        self.axes = self.figure.add_subplot()
        self.result: Any = None
        self.marker: Any = None
        col = QVBoxLayout(self)
        col.setContentsMargins(0, 0, 0, 0)
        col.addWidget(self.canvas)
        self.canvas.mpl_connect("button_press_event", self._pressed)
        self.show_result(None)

    def show_result(self, result: Any, note: str = "") -> None:
        """Plot a ``barymesh.mom.SweepResult`` (None: an empty plot with a hint)."""
        self.result = result
        ax = self.axes
        ax.clear()
        self.marker = None
        ax.set_xlabel("frequency (GHz)")
        ax.set_ylabel("extinction cross-section (mm²)")
        ax.grid(alpha=0.3)
        if result is not None:
            f = result.frequencies / 1e9
            ax.plot(f, result.extinction_cross_section * 1e6, color="#1f77b4")
            for r in result.resonances:
                ax.axvline(r / 1e9, color="#d62728", lw=1.0, ls="--")
                ax.annotate(
                    f"{r / 1e9:.4g} GHz",
                    (r / 1e9, 0.97),
                    xycoords=("data", "axes fraction"),
                    ha="left",
                    va="top",
                    fontsize=8,
                    color="#d62728",
                )
        ax.set_title(
            note or ("click to solve at a frequency" if result is not None else "no sweep yet"),
            fontsize=9,
        )
        self.canvas.draw_idle()

    def mark(self, hz: float | None) -> None:
        """A vertical line at the frequency of the current on screen."""
        if self.marker is not None:
            self.marker.remove()
            self.marker = None
        if hz is not None and self.result is not None:
            self.marker = self.axes.axvline(hz / 1e9, color="0.3", lw=0.8)
        self.canvas.draw_idle()

    def data_to_widget(self, hz: float) -> tuple[int, int]:
        """Widget pixel (x, y) of frequency ``hz`` half way up the axes (tests click there)."""
        ymid = float(np.mean(self.axes.get_ylim()))
        x, y = self.axes.transData.transform((hz / 1e9, ymid))
        ratio = self.canvas.device_pixel_ratio or 1.0
        return round(x / ratio), round(self.canvas.height() - y / ratio)

    def _pressed(self, event: Any) -> None:
        if self.result is None or event.inaxes is not self.axes or event.xdata is None:
            return
        if event.xdata > 0:
            self.clicked.emit(float(event.xdata) * 1e9)


class SolvePanel(QWidget):
    """The Solve dock's widget (see module docstring).

    Parameters
    ----------
    host : ToolHost
        The window (:class:`barymesh.app.tool_host.ToolHost`): render requests; its
        closing stops a running job.
    model : AppModel
        The mesh on screen and its changes.
    plotter : pyvista plotter
        The 3D view: the Surface current layer goes there.
    covered : callable
        ``covered(shown)``: the current layer's colour bar was shown or hidden (the
        window fits the mesh beside it); the layer renders afterwards.
    """

    solved = Signal(object)  # the Solution now on screen

    def __init__(
        self, host: ToolHost, model: AppModel, plotter: Any, covered: Callable[[bool], None]
    ) -> None:
        super().__init__(host.widget)
        self.host = host
        self.model = model
        self.layer = CurrentLayer(plotter, host.request_render, covered)
        self.jobs = Jobs(self, name="barymesh-solve")  # one solve or sweep at a time
        self.auto_unknowns = AUTO_SOLVE_UNKNOWNS
        #: Set by the first Solve, sweep click or typed input: from then on small meshes
        #: are solved whenever they change (the window opens without a current).
        self.engaged = False
        self.solution: Any = None
        self.solution_mesh: TriMesh | None = None  # the mesh on screen it is for
        self.solved_mesh: TriMesh | None = None  # the mesh it was solved on
        self.solution_inputs: tuple[Any, ...] | None = None
        self.sweep_result: Any = None
        self.sweep_mesh: TriMesh | None = None
        self.last_outcome: Outcome | None = None
        self.coefficient_label: QLabel | None = None  # a line of the RWG inspector's
        self._inspector: Any = None  # the RWG inspector it tells I_n (attach_inspector)
        #: The latest job of each kind; a result whose token is older is dropped.
        self._tokens = {"solve": 0, "sweep": 0}
        self._running: set[str] = set()
        self._cancel = threading.Event()
        self._pages: list[QWidget] = []  # tabs added by add_page

        self.tabs = QTabWidget(self)
        self.tabs.addTab(self._solve_page(), "&Solve")
        self.tabs.addTab(self._sweep_page(), "S&weep")
        self.progress = QProgressBar(self)
        self.progress.hide()
        self.cancel_button = QPushButton("Cancel", self)
        self.cancel_button.setToolTip("Stop the solve or sweep running in the background")
        self.cancel_button.clicked.connect(self.cancel)
        self.cancel_button.setEnabled(False)
        row = QHBoxLayout()
        row.addWidget(self.progress, 1)
        row.addWidget(self.cancel_button)
        self.status = QLabel(self)
        self.status.setWordWrap(True)
        self.status.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        col = QVBoxLayout(self)
        col.addWidget(self.tabs)
        col.addLayout(row)
        col.addWidget(self.status)
        col.addStretch(1)

        self._narrow_combos()
        self.timer = QTimer(self)
        self.timer.setInterval(ANIMATION_MS)
        self.timer.timeout.connect(self._step_phase)
        self.model.result_changed.connect(self._mesh_changed)
        host.widget.installEventFilter(self)

    def _narrow_combos(self) -> None:
        """Combo boxes that do not widen the dock to their longest item."""
        for box in self.findChildren(QComboBox):
            box.setSizeAdjustPolicy(
                QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon
            )
            box.setMinimumContentsLength(6)

    def sizeHint(self) -> QSize:  # noqa: N802 - Qt's name
        """No wider than the Parameters panel asks: the 3D view keeps the width."""
        hint = super().sizeHint()
        return QSize(min(hint.width(), PANEL_WIDTH), hint.height())

    # -- layout ----------------------------------------------------------------------

    def _solve_page(self) -> QWidget:
        page = QWidget(self)
        form = QFormLayout(page)
        form.setRowWrapPolicy(QFormLayout.RowWrapPolicy.WrapLongRows)
        self.frequency = QLineEdit("1", page)
        self.frequency.setToolTip("The frequency of the plane wave or the feed voltage")
        self.unit = QComboBox(page)
        for u in UNITS:
            self.unit.addItem(u, u)
        self.unit.setCurrentText("GHz")
        row = QHBoxLayout()
        row.addWidget(self.frequency, 1)
        row.addWidget(self.unit)
        label = QLabel("&Frequency", page)
        label.setBuddy(self.frequency)
        form.addRow(label, row)
        self.direction, self.direction_edit = self._vector_box(
            DIRECTION_PRESETS,
            "Direction of travel of the plane wave: an axis (-z: from above) or x, y, z",
        )
        self.polarization, self.polarization_edit = self._vector_box(
            POLARIZATION_PRESETS,
            "Direction of E: an axis or x, y, z, perpendicular to the direction",
        )
        self.excitation = QComboBox(page)
        self.excitation.addItem("plane wave", "plane")
        self.excitation.addItem("voltage feed", "feed")
        self.excitation.setToolTip(
            "What drives the current: an incident plane wave, or a "
            "1 V delta-gap source on the mesh edges along a line"
        )
        form.addRow("E&xcitation", self.excitation)
        form.addRow("&Direction", self.direction)
        form.addRow("&Polarisation E", self.polarization)
        self.feed_start = QLineEdit("0, -10", page)
        self.feed_end = QLineEdit("0, 10", page)
        for edit in (self.feed_start, self.feed_end):
            edit.setToolTip(
                "An end of the feed line, x, y in mm: the 1 V gap lies on the "
                "interior mesh edges along the line, across the conductor"
            )
        form.addRow("Feed sta&rt (mm)", self.feed_start)
        form.addRow("Feed &end (mm)", self.feed_end)
        self.form = form
        self.solver_grade = QCheckBox("Solver-&grade mesh", page)
        self.solver_grade.setChecked(True)
        self.solver_grade.setToolTip(SOLVER_GRADE_TIP)

        # once solved, another mesh is another input (a window not yet solved stays so)
        def grade_toggled(_on: bool) -> None:
            if self.engaged:
                self._inputs_edited()

        self.solver_grade.toggled.connect(grade_toggled)
        form.addRow(self.solver_grade)
        self.auto = QCheckBox(f"Auto-solve N ≤ {AUTO_SOLVE_UNKNOWNS}", page)
        self.auto.setChecked(True)
        self.auto.setToolTip(
            f"Solve meshes of at most {AUTO_SOLVE_UNKNOWNS} RWG unknowns at "
            "once whenever the mesh or an input changes (the mesh as drawn: a "
            "solver-grade mesh is solved when asked)"
        )
        form.addRow(self.auto)
        self.solve_button = QPushButton("Solve", page)
        self.solve_button.setToolTip("Solve for the surface current of the mesh on screen")
        self.solve_button.clicked.connect(self.solve)
        form.addRow(self.solve_button)
        self.error = QLabel(page)
        self.error.setStyleSheet("color: #d0021b;")
        self.error.setWordWrap(True)
        form.addRow(self.error)
        self.stale = QLabel(page)
        self.stale.setStyleSheet("color: #b35900;")
        self.stale.setWordWrap(True)
        # never squeezed below its wrapped text's height (the tab page asks its rows for
        # their height at one line: the two-line warning was cut top and bottom)
        self.stale.setSizePolicy(QSizePolicy.Policy.Preferred, QSizePolicy.Policy.Minimum)
        self.stale.installEventFilter(self)
        self.stale.hide()
        form.addRow(self.stale)
        self.summary = QLabel("No result yet.", page)
        self.summary.setWordWrap(True)
        self.summary.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        form.addRow(self.summary)

        self.show_current = QCheckBox("Surface &current", page)
        self.show_current.setChecked(True)
        self.show_current.toggled.connect(self._show_toggled)
        form.addRow(self.show_current)
        self.quantity = QComboBox(page)
        self.quantity.addItem("current |J|", "current")
        self.quantity.addItem("charge Re(ρ·exp(jωt))", "charge")
        self.quantity.setToolTip("What the colours show; the charge follows the phase")
        self.quantity.currentIndexChanged.connect(self._quantity_changed)
        form.addRow("C&olour by", self.quantity)
        self.scale = QComboBox(page)
        for s in SCALES:
            self.scale.addItem(f"{s} |J|", s)
        self.scale.currentIndexChanged.connect(
            lambda _i: self.layer.set_scale(self.scale.currentData())
        )
        form.addRow("Colour &scale", self.scale)
        self.phase = QSlider(Qt.Orientation.Horizontal, page)
        self.phase.setRange(0, 360)
        self.phase.setSingleStep(5)
        self.phase.setPageStep(45)
        self.phase.setToolTip("Arrows: Re(J·exp(jωt)) at ωt = this phase")
        self.phase.valueChanged.connect(self._phase_changed)
        self.phase_label = QLabel("0°", page)
        self.phase_label.setMinimumWidth(36)
        self.animate = QCheckBox("&Animate", page)
        self.animate.toggled.connect(self._animate_toggled)
        row = QHBoxLayout()
        row.addWidget(self.phase, 1)
        row.addWidget(self.phase_label)
        row.addWidget(self.animate)
        label = QLabel("P&hase ωt", page)
        label.setBuddy(self.phase)
        form.addRow(label, row)

        for line in (
            self.frequency,
            self.direction_edit,
            self.polarization_edit,
            self.feed_start,
            self.feed_end,
        ):
            line.returnPressed.connect(self._inputs_edited)
            line.editingFinished.connect(self._inputs_edited)
        self.unit.currentIndexChanged.connect(lambda _i: self._inputs_edited())
        self.direction.activated.connect(lambda _i: self._inputs_edited())
        self.polarization.activated.connect(lambda _i: self._inputs_edited())
        self.excitation.currentIndexChanged.connect(self._excitation_changed)
        self._show_excitation_rows()
        return page

    def _show_excitation_rows(self) -> None:
        feed = self.excitation.currentData() == "feed"
        for widget in (self.direction, self.polarization):
            self.form.setRowVisible(widget, not feed)
        for feed_field in (self.feed_start, self.feed_end):
            self.form.setRowVisible(feed_field, feed)

    def _excitation_changed(self, _index: int) -> None:
        self._show_excitation_rows()
        self._inputs_edited()

    def _vector_box(self, presets: tuple[str, ...], tip: str) -> tuple[QComboBox, QLineEdit]:
        box = QComboBox(self)
        box.setEditable(True)
        # The box's field is made here and kept, not fetched with ``lineEdit()``: a lookup of
        # a C++-made child can return a stale wrapper of another type left at the same
        # address (CI: a ``QSurface`` that pyvistaqt kept of a closed view).
        edit = QLineEdit(box)
        box.setLineEdit(edit)
        box.setInsertPolicy(QComboBox.InsertPolicy.NoInsert)
        box.addItems(list(presets))
        box.setToolTip(tip)
        return box, edit

    def _sweep_page(self) -> QWidget:
        page = QWidget(self)
        col = QVBoxLayout(page)
        form = QFormLayout()
        form.setRowWrapPolicy(QFormLayout.RowWrapPolicy.WrapLongRows)
        self.sweep_band = FrequencyBand("3", "12", "Sweep range", page)
        band = self.sweep_band
        self.sweep_from, self.sweep_to, self.sweep_unit = band.start, band.stop, band.unit
        form.addRow("Range", band)
        self.sweep_count = QSpinBox(page)
        self.sweep_count.setRange(3, 1001)
        self.sweep_count.setValue(46)
        form.addRow("&Frequencies", self.sweep_count)
        self.sweep_button = QPushButton("Run sweep", page)
        self.sweep_button.setToolTip(
            "Extinction cross-section at each frequency, in the "
            "background (direction and polarisation of the Solve tab)"
        )
        self.sweep_button.clicked.connect(self.run_sweep)
        form.addRow(self.sweep_button)
        col.addLayout(form)
        self.plot = SweepPlot(page)
        self.plot.clicked.connect(self.solve_at)
        col.addWidget(self.plot, 1)
        self.resonance_label = QLabel(page)
        self.resonance_label.setWordWrap(True)
        col.addWidget(self.resonance_label)
        return page

    # -- inputs ----------------------------------------------------------------------

    @property
    def mesh(self) -> TriMesh | None:
        result = self.model.result
        return None if result is None else result.mesh

    def inputs(self) -> tuple[float, Any]:
        """(frequency in Hz, barymesh.mom.PlaneWave or VoltageSource) from the fields;
        ValueError naming the field if invalid."""
        from barymesh.mom import PlaneWave, VoltageSource

        hz = read_frequency(self.frequency.text(), self.unit.currentText())
        if self.excitation.currentData() == "feed":
            start = read_point(self.feed_start.text(), "Feed start")
            end = read_point(self.feed_end.text(), "Feed end")
            if len(start) != len(end):
                raise ValueError("Feed start and end: give both as x, y or both as x, y, z")
            try:
                return hz, VoltageSource(start, end)  # type: ignore[arg-type]  # numbers in, an array kept
            except ValueError as exc:
                raise ValueError(
                    f"Feed {self.feed_start.text()!r} to {self.feed_end.text()!r}: {exc}"
                ) from None
        d = read_vector(self.direction.currentText(), "Direction")
        p = read_vector(self.polarization.currentText(), "Polarisation")
        return hz, PlaneWave(direction=d, polarization=p)  # type: ignore[arg-type]  # numbers in, an array kept

    def _inputs_key(self) -> tuple[Any, ...] | None:
        from barymesh.mom import VoltageSource

        try:
            hz, wave = self.inputs()
        except ValueError:
            return None
        graded = self.graded()
        if isinstance(wave, VoltageSource):
            return hz, "feed", tuple(wave.start), tuple(wave.end), graded
        return hz, "plane", tuple(wave.direction), tuple(np.asarray(wave.polarization)), graded

    def graded(self) -> bool:
        """Whether a solve now is of the solver-grade mesh: the box is on and the mesh on
        screen was built from parameters or a cell (an imported file, a published preset
        are solved as they are: :func:`barymesh.app.model.solver_mesh.gradable`)."""
        return self.solver_grade.isChecked() and gradable(self.model.result)

    def _inputs_edited(self) -> None:
        self.engaged = True
        key = self._inputs_key()
        if key is None:
            try:
                self.inputs()
            except ValueError as exc:
                self.error.setText(str(exc))
            return
        self.error.clear()
        if self.solution is not None and key == self.solution_inputs:
            return
        if self._small():
            self.solve()  # replaces the current in place
        elif self.solution is not None:
            self._invalidate("The current on screen is for other inputs: Solve again.")

    def _small(self) -> bool:
        """Whether to solve at once: asked for once, auto-solve on, N small."""
        result = self.model.result
        if not (self.engaged and self.auto.isChecked()) or result is None or result.mesh is None:
            return False
        if self.graded():  # its size is known once built, in the worker: solved when asked
            return False
        # N from the statistics the worker computed: never the RWG table of a big mesh here
        unknowns = (result.stats or {}).get("interior_edges")
        if unknowns is None:
            return False
        return 0 < unknowns <= self.auto_unknowns

    # -- solving ---------------------------------------------------------------------

    def solve(self) -> bool:
        """Solve the mesh on screen with the fields' inputs (GUI thread when small)."""
        return self.solve_at(None)

    def solve_at(self, hz: float | None = None) -> bool:
        """Solve at ``hz`` (None: the field's frequency; else the field is set to it)."""
        self.engaged = True
        if hz is not None:
            number, unit = format_frequency(hz)
            self.unit.blockSignals(True)
            self.unit.setCurrentText(unit)
            self.unit.blockSignals(False)
            self.frequency.setText(number)
        mesh, result, graded = self.mesh, self.model.result, self.graded()
        try:
            frequency, wave = self.inputs()
            if mesh is None:
                raise ValueError("No mesh on screen to solve.")
            # the solver-grade mesh is built in the worker: its checks are the solver's there
            n = 0 if graded else len(mesh.rwg)
            if not graded and n == 0:
                raise ValueError("The mesh has no interior edges: no RWG unknowns to solve for.")
            from barymesh.mom import VoltageSource, check_memory, mom_geometry

            if not graded:
                check_memory(n)
                if isinstance(wave, VoltageSource):  # a line off the mesh edges: say so now
                    wave.feed_signs(mom_geometry(mesh))
        except ValueError as exc:
            self.error.setText(str(exc))
            return False
        self.error.clear()
        key = self._inputs_key()
        from barymesh.mom import solve

        def work(report: Callable[..., None] | None = None) -> Solved:
            return solve_graded(
                result,
                frequency,
                graded,
                lambda m: solve(m, frequency, wave),
            )

        self._tokens["solve"] += 1
        self._running.discard("solve")  # a running solve's result is now stale
        if not graded and n <= self.auto_unknowns:
            outcome = run_job(self._tokens["solve"], mesh, "solve", work)
            outcome.inputs = key  # type: ignore[attr-defined]
            self._finished(outcome)
            return True
        message = "Solving the solver-grade mesh…" if graded else f"Solving {n:,} unknowns…"
        self._start(mesh, "solve", work, key, message)
        return True

    def run_sweep(self) -> bool:
        """Sweep the extinction cross-section over the Sweep tab's range (a worker)."""
        mesh = self.mesh
        try:
            a, b = self.sweep_band.band()
            _hz, wave = self.inputs()
            if self.excitation.currentData() == "feed":
                raise ValueError(
                    "The sweep plots the extinction cross-section of a plane "
                    "wave: choose Excitation: plane wave (barymesh solve --feed "
                    "sweeps the input impedance)"
                )
            graded, result = self.graded(), self.model.result
            if mesh is None or (not graded and len(mesh.rwg) == 0):
                raise ValueError("The mesh on screen has no RWG unknowns to solve for.")
        except ValueError as exc:
            self.error.setText(str(exc))
            self.resonance_label.setText(str(exc))
            return False
        from barymesh.mom import sweep

        freqs = np.linspace(a, b, self.sweep_count.value())
        self._tokens["sweep"] += 1
        self._cancel.clear()

        def work(report: Callable[..., None]) -> Solved:
            return solve_graded(
                result,
                b,  # the λ/10 rule at the sweep's top
                graded,
                lambda m: sweep(
                    m,
                    freqs,
                    wave,
                    scattering=False,
                    progress=report,
                    cancel=self._cancel.is_set,
                ),
            )

        self._start(mesh, "sweep", work, None, f"Sweeping {len(freqs)} frequencies…")
        return True

    def _start(
        self,
        mesh: TriMesh,
        kind: str,
        work: Callable[[Callable[..., None]], Any],
        key: tuple[Any, ...] | None,
        message: str,
    ) -> None:
        token = self._tokens[kind]
        self._running.add(kind)
        self._cancel.clear()
        self.progress.setRange(0, 0)
        self.progress.setFormat("%v / %m")
        self.progress.show()
        self.cancel_button.setEnabled(True)
        self.status.setText(message)

        def job(task: Task) -> Outcome:
            outcome = run_job(token, mesh, kind, partial(work, task.report))
            outcome.inputs = key  # type: ignore[attr-defined]
            return outcome

        self.jobs.submit(
            job, self._finished, with_task=True, on_progress=partial(self._progress, token)
        )

    def cancel(self) -> None:
        """Stop the running job: a sweep stops before its next frequency; a single solve
        cannot be interrupted, so its result is dropped when it comes."""
        if not self._running:
            return
        self._cancel.set()
        for kind in self._running:
            self._tokens[kind] += 1  # whatever the running job returns is now stale
        self._job_ended()
        self.status.setText(f"The {' and the '.join(sorted(self._running))} was cancelled.")
        self._running.clear()

    def _job_ended(self) -> None:
        self.progress.hide()
        self.cancel_button.setEnabled(False)

    def _progress(self, token: int, done: int, total: int) -> None:
        if token == self._tokens["sweep"] and "sweep" in self._running:
            self.progress.setRange(0, total)
            self.progress.setValue(done)

    def _finished(self, outcome: Outcome) -> None:
        self.last_outcome = outcome
        if outcome.token != self._tokens[outcome.kind]:
            log.debug("dropped a stale %s", outcome.kind)
            return
        self._running.discard(outcome.kind)
        if not self._running:
            self._job_ended()
        if outcome.error is not None:
            self.status.setText(f"The {outcome.kind} failed: {outcome.error}")
            return
        if outcome.mesh is not self.mesh:
            self.status.setText(f"The {outcome.kind} was for a previous mesh: dropped.")
            return
        self.status.clear()
        self.error.clear()
        if outcome.kind == "sweep":
            self._show_sweep(outcome)
        else:
            self._show_solution(outcome)

    def _show_solution(self, outcome: Outcome) -> None:
        solved: Solved = outcome.result
        s = solved.result
        self.solution, self.solution_mesh = s, outcome.mesh
        self.solved_mesh = solved.mesh.mesh
        self.solution_inputs = getattr(outcome, "inputs", None)
        self.stale.hide()
        self.layer.set_phase(self.phase.value())
        self.layer.visible = self.show_current.isChecked()
        # the current is drawn on the mesh it was solved on (the solver-grade one, perhaps)
        self.layer.set_current(self.solved_mesh, s.current_density, s.charge_density)
        number, unit = format_frequency(s.frequency)
        assert self.layer.magnitude is not None  # set_current made it
        jmax = float(self.layer.magnitude.max())
        from barymesh.mom import VoltageSource

        driven = (
            f"input impedance {format_impedance(s.input_impedance)}"
            if isinstance(s.excitation, VoltageSource)
            else f"extinction cross-section {s.extinction_cross_section * 1e6:.5g} mm²"
        )
        lines = [
            f"<b>{len(s.coefficients):,} unknowns at {number} {unit}</b> "
            f"({outcome.seconds * 1e3:.0f} ms)",
            html.escape(solved.said[:1].upper() + solved.said[1:]),
            f"largest |J| {jmax:.5g} A/m",
            driven,
            f"condition number {s.condition_number:.3g}, residual {s.residual:.1e}",
        ]
        lines += [
            f"<span style='color:#b35900'>warning: {html.escape(w)}</span>" for w in s.warnings
        ]
        self.summary.setText("<br>".join(lines))
        self.plot.mark(s.frequency if self.sweep_mesh is outcome.mesh else None)
        self._show_coefficient()
        self.solved.emit(s)

    def add_page(self, page: QWidget, title: str, tooltip: str = "") -> None:
        """A further tab of the dock (the Infinite array); its ``stop()`` is called when the
        window closes."""
        index = self.tabs.addTab(page, title)
        if tooltip:
            self.tabs.setTabToolTip(index, tooltip)
        self._pages.append(page)
        self._narrow_combos()

    def show_array_current(self, mesh: TriMesh | None, current: Any) -> None:
        """Show another solver's (T, 3) current of ``mesh`` in the Surface current layer
        (the infinite array's cell), in place of the free-space result; ``(None, None)``
        takes it away again if it is still the one shown."""
        if mesh is None:
            if self.layer.current is not None and self.solution is None:
                self.layer.clear()
            return
        self.solution = self.solution_mesh = self.solved_mesh = self.solution_inputs = None
        self.stale.hide()
        self.layer.set_phase(self.phase.value())
        self.layer.visible = self.show_current.isChecked()
        self.layer.set_current(mesh, current)
        self.summary.setText("The current on screen is the infinite array's (its tab).")
        self._show_coefficient()

    # -- the RWG inspector's I_n -------------------------------------------------------

    def attach_inspector(self, inspector: Any) -> None:
        """Tell ``inspector`` (the RWG inspector) I_n of its edge: a line of its own
        (``add_line``) that follows its edge (``edge_selected``) and the solutions here."""
        self._inspector = inspector
        self.coefficient_label = inspector.add_line()
        inspector.edge_selected.connect(self._show_coefficient)
        self._show_coefficient()

    def coefficient_text(self, edge: int, mesh: TriMesh | None) -> str:
        """The inspector's line for ``edge`` of ``mesh``: I_n of the solution, or why not."""
        if edge < 0 or mesh is None:
            return ""
        if self.solution is None or self.solution_mesh is not mesh:
            return "I_n: no current for this mesh (Solve dock)."
        if self.solved_mesh is not mesh:
            return "I_n: the current was solved on the solver-grade mesh, not on the one drawn."
        rows = np.asarray(mesh.rwg.edge)
        n = int(np.searchsorted(rows, edge))
        if n >= len(rows) or rows[n] != edge:
            return "I_n: this edge carries no RWG function."
        c = complex(self.solution.coefficients[n])
        number, unit = format_frequency(self.solution.frequency)
        return (
            f"I_{n} = {c.real:.4g} {'+' if c.imag >= 0 else '−'} j{abs(c.imag):.4g} A "
            f"(|I_n| {abs(c):.4g} A, phase {np.degrees(np.angle(c)):.1f}°) at "
            f"{number} {unit}"
        )

    def _show_coefficient(self, edge: int | None = None) -> None:
        inspector = self._inspector
        if inspector is None or self.coefficient_label is None:  # made with the inspector
            return
        if edge is None:
            edge = -1 if inspector.edge is None else inspector.edge
        self.coefficient_label.setText(self.coefficient_text(int(edge), inspector.mesh))

    def _show_sweep(self, outcome: Outcome) -> None:
        solved: Solved = outcome.result
        r = solved.result
        self.sweep_result, self.sweep_mesh = r, outcome.mesh
        self.plot.show_result(r)
        res = ", ".join(f"{f / 1e9:.4g} GHz" for f in r.resonances)
        text = (
            f"Resonance{'s' if len(r.resonances) != 1 else ''}: {res}"
            if res
            else "No resonance in this range."
        )
        said = solved.said[:1].upper() + solved.said[1:] + "."
        self.resonance_label.setText(
            "\n".join([text, said] + [f"warning: {w}" for w in r.warnings])
        )
        self.tabs.setCurrentIndex(1)

    # -- invalidation ----------------------------------------------------------------

    def _invalidate(self, message: str) -> None:
        self.solution = self.solution_mesh = self.solved_mesh = self.solution_inputs = None
        self.layer.clear()
        self.stale.setText(message)
        self.stale.show()
        self._fit_stale()
        self.summary.setText("No result for what is on screen.")
        self.plot.mark(None)
        self._show_coefficient()

    def _fit_stale(self) -> None:
        """The warning as tall as its wrapped text at its width."""
        label = self.stale
        if label.isVisible() and label.width() > 0:
            need = label.heightForWidth(label.width())
            if need > 0 and need != label.minimumHeight():
                label.setMinimumHeight(need)

    def _mesh_changed(self, result: Any) -> None:
        mesh = result.mesh
        if self.sweep_result is not None and self.sweep_mesh is not mesh:
            self.plot.show_result(self.sweep_result, note="this sweep is for the previous mesh")
            self.sweep_mesh = None
        if self._running:
            self.cancel()
        if (self.solution is None or self.solution_mesh is not mesh) and self._small():
            # auto-solve: the new current replaces the old one in the layer's actors
            # (removing them first and adding them again cost two renders per mesh)
            self.solve()
        if self.solution is not None and self.solution_mesh is not mesh:
            self._invalidate("The result was for the previous mesh: Solve again.")

    # -- the layer's controls --------------------------------------------------------

    def _show_toggled(self, on: bool) -> None:
        self.layer.set_visible(on)
        if not on:
            self.animate.setChecked(False)

    def _quantity_changed(self, _index: int) -> None:
        quantity = self.quantity.currentData()
        self.scale.setEnabled(quantity == "current")
        self.layer.set_quantity(quantity)

    def _phase_changed(self, value: int) -> None:
        self.phase_label.setText(f"{value}°")
        self.layer.set_phase(value)

    def _animate_toggled(self, on: bool) -> None:
        if on:
            self.timer.start()
        else:
            self.timer.stop()

    def _step_phase(self) -> None:
        if not self.layer.shown:
            return
        self.phase.setValue((self.phase.value() + ANIMATION_STEP) % 360)

    # -- closing ---------------------------------------------------------------------

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:  # noqa: N802 - Qt's name
        if watched is self.host.widget and event.type() == QEvent.Type.Close:
            self.stop()
        if watched is self.stale and event.type() in (QEvent.Type.Resize, QEvent.Type.Show):
            self._fit_stale()  # (the stale-result warning, see _fit_stale)
        return False

    def stop(self, msecs: int = 30_000) -> bool:
        """Cancel and wait for a running job (the window is closing)."""
        self.timer.stop()
        self._cancel.set()
        for kind in self._tokens:
            self._tokens[kind] += 1
        try:
            self.model.result_changed.disconnect(self._mesh_changed)
        except ValueError:
            pass
        done = [page.stop(msecs) for page in self._pages if hasattr(page, "stop")]
        return self.jobs.wait(msecs) and all(done)

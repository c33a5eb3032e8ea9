"""The Solve dock's "Infinite array" tab: R and T of a unit cell's infinite array.

When the mesh on screen is a unit cell (it carries a lattice: a cell preset, a cell file,
the cell editor), the tab takes a band (start, stop, points), the angle the wave comes
from (θ, φ in degrees), TE or TM, an optional sheet impedance (Ω/sq) and the dielectric
layers around the sheet with an optional ground plane
(:class:`~barymesh.app.panels.stack_editor.StackEditor`: a table and a side view to
scale), and shows the co-polar (0, 0) |R| and |T| in dB and ∠R against frequency, ∠R's
reference plane named on its axis, the grating-lobe onsets and the onsets of orders
guided inside a layer marked and the resonances labelled. The sweep
(:func:`barymesh.app.panels.array_sweep.sweep_array`) runs in the solver process, waited
for by a worker thread, which then draws the figure
(:func:`barymesh.app.panels.array_figures.draw_curve`, Agg) into an image; the GUI thread
only shows it (:class:`PictureView`). With **Live** on, every new mesh (a slider, the cell
editor) and every good edit of the stack cancels the running sweep and starts the next
one. With **Equivalent circuit** ticked, the worker also fits the curve's Foster LC
(:mod:`barymesh.app.panels.array_circuit`) and the figure draws its R dashed, a schematic
with its values, the band where it stops describing the cell shaded and, for square
patches on a grounded slab, Luukkonen et al.'s model dotted; a refused fit is said in one
red line under the box and the curve stays. The solver's warnings
(``PeriodicSweep.warnings``: an ill-conditioned solve, a frequency at an onset, a mesh
coarse for the densest layer, metal beyond the cell…) are shown in an orange note in the
tab and named over the curve; a bad value in the stack is said under its table and the
last good curve stays.

The curve and the orders' drawing need more room than the Solve dock has beside the 3D
view (at the window's default size the dock is about 300 × 480 pixels, and the curve
was below its fold), so in the window they live in a dock of their own, **Array curve**,
under the 3D view, opened when the tab is first shown or **Run** is clicked (**Show
curve** opens it again once closed).

A click on the curve solves the array at that frequency (in the worker): the cell's
current goes into the Solve tab's "Surface current" layer (the cell editor's ghost copies
stay drawn around it), and the propagating Floquet orders into a table and a drawing
(:func:`~barymesh.app.panels.array_figures.draw_orders`: the screen, the incident wave,
and an arrow per order above (reflected) and below (transmitted), in the plane of
incidence). Without a lattice the tab says why in one line and its inputs are disabled.

With **Solver-grade mesh** on (the default, as ``barymesh periodic`` without
``--mesh-as-given``) the sweep and the solve at a clicked frequency are of the cell's
solver-grade mesh (:mod:`barymesh.app.model.solver_mesh`: graded toward the metal's edges,
every edge within λ/10 at the band's top in the densest layer of the stack), built in the
worker (and kept, so that Live does not build it again for a stack or band it has seen);
the status line says which mesh was solved, with its unknowns and the drawn mesh's, and
the current is drawn on the mesh solved. A band too high for the λ/10 rule is refused in
one line and the last good curve stays. Off, the cell is solved as drawn.
"""

from __future__ import annotations

import cmath
import html
import logging
import math
import threading
from collections.abc import Callable
from functools import partial
from typing import Any

import numpy as np
from PySide6.QtCore import QPoint, QSize, Qt, QTimer, Signal
from PySide6.QtGui import QColor, QImage, QPainter, QPen
from PySide6.QtWidgets import (
    QAbstractItemView,
    QCheckBox,
    QComboBox,
    QDockWidget,
    QFormLayout,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QLineEdit,
    QPushButton,
    QSizePolicy,
    QSpinBox,
    QSplitter,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from barymesh import TriMesh
from barymesh.app.jobs import Jobs, Task
from barymesh.app.model.solver_mesh import SolvedMesh, solver_mesh
from barymesh.app.model.stack_rows import reference_plane_names
from barymesh.app.panels.array_circuit import CircuitFit, fit_circuit
from barymesh.app.panels.array_figures import Picture, draw_curve, draw_orders
from barymesh.app.panels.array_sweep import (
    POLARIZATIONS,
    ArrayInputs,
    ArraySweep,
    array_unknowns,
    lattice_vectors,
    orders_rows,
    solve_point,
    sweep_array,
)
from barymesh.app.panels.curve_tab_parts import (
    add_messages,
    add_note_and_show_button,
    curve_area,
    stack_group,
)
from barymesh.app.panels.frequency_band import FrequencyBand
from barymesh.app.panels.solve_panel import (
    PANEL_WIDTH,
    SOLVER_GRADE_TIP,
    run_job,
)

log = logging.getLogger(__name__)

#: Height of the Array curve dock when it first opens (pixels).
CURVE_DOCK_HEIGHT = 300

#: The orders table's columns.
ORDER_COLUMNS = ("p", "q", "|R|", "|T|", "P_R", "P_T", "θ°", "φ°")
ORDER_TIPS = (
    "Floquet order p (along the first lattice vector's reciprocal)",
    "Floquet order q",
    "Reflected amplitude of the order, TE and TM together (incident amplitude 1)",
    "Transmitted amplitude (the (0, 0) order includes the incident wave)",
    "Reflected power of the order over the incident power",
    "Transmitted power of the order over the incident power",
    "Angle of the order's wave from the normal",
    "Azimuth of the order's wave (from x)",
)


def read_angle(text: str, name: str, low: float, high: float) -> float:
    """A typed angle in degrees within [low, high); ValueError naming ``name``.

    >>> read_angle("30", "θ", 0, 90)
    30.0
    """
    try:
        value = float(text.strip().replace("°", "").replace("−", "-"))
    except ValueError:
        raise ValueError(f"{name} {text!r} is not a number; type degrees, e.g. 30") from None
    if not math.isfinite(value) or not low <= value < high:
        raise ValueError(f"{name} {text!r} is out of range; expected {low:g} <= {name} < {high:g}°")
    return value


def read_impedance(text: str) -> complex:
    """A sheet impedance in Ω/sq: ``""`` -> 0, ``"377"``, ``"10-5j"``, ``"10 - j5"``.

    >>> read_impedance(""), read_impedance("10 - j5"), read_impedance("3+4j")
    (0j, (10-5j), (3+4j))
    """
    t = text.strip().replace("Ω", "").replace("−", "-").replace(" ", "").replace("i", "j")
    if not t:
        return 0j
    # "j5" and "-j5" after a sign: move the j behind the number (Python's 5j)
    parts, i = [], 0
    for j, ch in enumerate(t):
        if ch in "+-" and j > 0 and t[j - 1] not in "eE":
            parts.append(t[i:j])
            i = j
    parts.append(t[i:])
    fixed = []
    for part in parts:
        sign = part[0] if part[:1] in ("+", "-") else ""
        body = part[len(sign) :]
        if body.startswith("j") and len(body) > 1:
            body = body[1:] + "j"
        fixed.append(sign + body)
    try:
        z = complex("".join(fixed))
    except ValueError:
        raise ValueError(
            f"Sheet impedance {text!r} is not a complex number; type Ω/sq, e.g. 50 or 10-5j"
        ) from None
    if not (cmath.isfinite(z) and z.real >= 0):
        raise ValueError(
            f"Sheet impedance {text!r} is invalid; expected Re Z_s >= 0 (a passive sheet)"
        )
    return z


class PictureView(QWidget):
    """Shows a :class:`barymesh.app.panels.array_figures.Picture` drawn in the worker; a
    click on a curve's axes reports its frequency (Hz); :meth:`mark` draws a line at one."""

    clicked = Signal(float)
    resized = Signal()

    def __init__(self, height: int, parent: QWidget | None = None, grow: bool = False) -> None:
        super().__init__(parent)
        self.setMinimumHeight(height)
        vertical = QSizePolicy.Policy.Expanding if grow else QSizePolicy.Policy.Fixed
        self.setSizePolicy(QSizePolicy.Policy.Expanding, vertical)
        self._height = height
        self.picture: Picture | None = None
        self.marked: float | None = None
        self._image: QImage | None = None
        self._resize_timer = QTimer(self)
        self._resize_timer.setSingleShot(True)
        self._resize_timer.setInterval(150)
        self._resize_timer.timeout.connect(self.resized.emit)

    def sizeHint(self) -> QSize:  # noqa: N802 - Qt's name
        return QSize(PANEL_WIDTH, self._height)

    def request_size(self) -> tuple[tuple[int, int], float]:
        """(w, h) widget pixels and the device-pixel ratio to draw a picture at."""
        return (max(self.width(), 100), max(self.height(), 100)), self.devicePixelRatioF()

    def show_picture(self, picture: Picture) -> None:
        self.picture = picture
        rgba = np.ascontiguousarray(picture.rgba)
        h, w = rgba.shape[:2]
        image = QImage(rgba.data, w, h, 4 * w, QImage.Format.Format_RGBA8888).copy()
        image.setDevicePixelRatio(picture.ratio)
        self._image = image
        self.update()
        # drawn for a size the view no longer has (it was laid out, or resized, while the
        # picture was being drawn, before there was a picture to redraw): draw it again
        (want_w, want_h), _ratio = self.request_size()
        if abs(w / picture.ratio - want_w) > 2 or abs(h / picture.ratio - want_h) > 2:
            self._resize_timer.start()

    def mark(self, hz: float | None) -> None:
        self.marked = hz
        self.update()

    @property
    def figure(self) -> Any:
        """The matplotlib figure last drawn (its axes, lines and texts; read only)."""
        return None if self.picture is None else self.picture.figure

    def data_to_widget(self, hz: float) -> QPoint:
        """Widget pixel of frequency ``hz`` half way down the curve's axes (tests click)."""
        p = self.picture
        assert p is not None  # a curve is drawn
        return QPoint(round(p.widget_x(hz)), round(p.widget_y_middle()))

    def paintEvent(self, _event: Any) -> None:  # noqa: N802 - Qt's name
        painter = QPainter(self)
        painter.fillRect(self.rect(), QColor("white"))
        if self._image is not None:
            painter.drawImage(0, 0, self._image)
            p = self.picture
            if self.marked is not None and p is not None and p.x_range[1] > p.x_range[0]:
                x = p.widget_x(self.marked)
                painter.setPen(QPen(QColor(80, 80, 80), 1))
                painter.drawLine(
                    round(x),
                    round(p.y_pixels[0] / p.ratio),
                    round(x),
                    round(p.y_pixels[1] / p.ratio),
                )
        painter.end()

    def mousePressEvent(self, event: Any) -> None:  # noqa: N802 - Qt's name
        if self.picture is None or event.button() != Qt.MouseButton.LeftButton:
            return
        pos = event.position()
        hz = self.picture.frequency_at(pos.x(), pos.y())
        if hz is not None:
            self.clicked.emit(hz)

    def resizeEvent(self, event: Any) -> None:  # noqa: N802 - Qt's name
        super().resizeEvent(event)
        if self.picture is not None:
            self._resize_timer.start()


def said(solved: SolvedMesh) -> str:
    """Which mesh an array was solved on, its unknowns beside the drawn mesh's (the
    periodic solver's: interior RWG functions and the pairs matched across the sides).
    In the worker: the pairs of a big cell take a while to match."""
    shown = array_unknowns(solved.shown) if solved.graded else None
    return solved.describe(array_unknowns(solved.mesh), shown)


class InfiniteArrayPanel(QWidget):
    """The "Infinite array" tab (see module docstring).

    Parameters
    ----------
    model : AppModel
        The window's model (its ``result.mesh`` is the mesh on screen).
    show_current : callable
        ``show_current(mesh, current)`` puts a (T, 3) complex current into the Surface
        current layer (the Solve tab's), ``show_current(None, None)`` takes it away.
    parent : QWidget, optional
    host : ToolHost, optional
        The window (:class:`barymesh.app.tool_host.ToolHost`): the curve and the orders'
        drawing go into a dock of their own (:attr:`curve_dock`). Without one they stay
        in the tab, under its inputs.
    """

    #: an ArraySweep shown (tests, the docs' screenshot)
    swept = Signal(object)

    def __init__(
        self,
        model: Any,
        show_current: Callable[[TriMesh | None, Any], None],
        parent: QWidget | None = None,
        host: Any = None,
    ) -> None:
        super().__init__(parent)
        self.model = model
        self.show_current = show_current
        self.host = host  # a barymesh.app.tool_host.ToolHost: the curve gets a dock
        self.curve_dock: QDockWidget | None = None
        self._curve_sized = False
        self._shown_once = False
        self.jobs = Jobs(self, name="barymesh-array")  # one sweep, point or drawing at a time
        self.result: ArraySweep | None = None
        self.result_mesh: TriMesh | None = None  # the mesh on screen the curve is for
        self.solved: SolvedMesh | None = None  # the mesh the curve was solved on
        self.said = ""  # which mesh that was, in words (:func:`said`)
        self.point: Any = None  # the PeriodicSolution at the clicked frequency
        self.circuit_fit: CircuitFit | None = None  # the circuit of the curve (last fitted)
        self.point_mesh: TriMesh | None = None
        self.engaged = False  # set by the first Run: from then on Live follows the mesh
        self.cancelled: list[int] = []  # tokens of sweeps cancelled by a newer one
        self.stopped: list[int] = []  # tokens of sweeps that stopped early (SolveCancelled)
        self.last_outcome: Any = None
        #: the latest job of each kind: a sweep, a solve at a clicked frequency, a redraw of
        #: the curve or of the orders (a resize); an older job's result is dropped
        self._tokens = {"array": 0, "point": 0, "curve": 0, "orders": 0}
        self._cancel: dict[int, threading.Event] = {}
        self._build()
        model.result_changed.connect(self._mesh_changed)
        self._update_enabled()
        self._redraw("curve")
        self._redraw("orders")

    # -- layout ----------------------------------------------------------------------

    def _build(self) -> None:
        col = QVBoxLayout(self)
        self.reason = QLabel(self)
        self.reason.setWordWrap(True)
        self.reason.setStyleSheet("color: #b35900;")
        col.addWidget(self.reason)
        self.inputs_box = QWidget(self)
        form = QFormLayout(self.inputs_box)
        form.setContentsMargins(0, 0, 0, 0)
        form.setRowWrapPolicy(QFormLayout.RowWrapPolicy.WrapLongRows)
        self.band = FrequencyBand("10", "30", "Band", self)
        self.band_start, self.band_stop, self.unit = (
            self.band.start,
            self.band.stop,
            self.band.unit,
        )
        form.addRow(self._label("&Band", self.band_start), self.band)
        self.points = QSpinBox(self)
        self.points.setRange(2, 1001)
        self.points.setValue(21)
        self.points.setToolTip("Frequencies in the band, evenly spaced")
        form.addRow("&Points", self.points)
        self.theta = QLineEdit("0", self)
        self.theta.setToolTip("θ (degrees from the normal) of the direction the wave comes from")
        self.phi = QLineEdit("0", self)
        self.phi.setToolTip("φ (degrees from x) of the direction the wave comes from")
        row = QHBoxLayout()
        row.addWidget(QLabel("θ", self))
        row.addWidget(self.theta, 1)
        row.addWidget(QLabel("φ", self))
        row.addWidget(self.phi, 1)
        form.addRow(self._label("&Angle (°)", self.theta), row)
        self.polarization = QComboBox(self)
        for name in POLARIZATIONS:
            self.polarization.addItem(name, name)
        self.polarization.setToolTip("TE: E perpendicular to the plane of incidence; TM: in it")
        form.addRow("P&olarisation", self.polarization)
        self.sheet = QLineEdit("", self)
        self.sheet.setPlaceholderText("0 (perfect conductor)")
        self.sheet.setToolTip("Sheet impedance Z_s of the screen, Ω/sq, e.g. 50 or 10-5j")
        form.addRow("Sheet &impedance (Ω/sq)", self.sheet)
        self.solver_grade = QCheckBox("Solver-&grade mesh", self)
        self.solver_grade.setChecked(True)
        self.solver_grade.setToolTip(SOLVER_GRADE_TIP)
        self.solver_grade.toggled.connect(self._grade_toggled)
        form.addRow(self.solver_grade)
        self.live = QCheckBox("&Live: follow the mesh", self)
        self.live.setChecked(True)
        self.live.setToolTip(
            "Sweep again whenever the mesh changes (a slider, the cell editor) or the stack"
        )
        self.run_button = QPushButton("&Run", self)
        self.run_button.setToolTip("Sweep R and T of the infinite array over the band")
        self.run_button.clicked.connect(self._run_clicked)
        row = QHBoxLayout()
        row.addWidget(self.run_button)
        row.addWidget(self.live, 1)
        form.addRow(row)
        self.circuit_box = QCheckBox("&Equivalent circuit (LC) over the curve", self)
        self.circuit_box.setToolTip(
            "Fit the sheet with a series or parallel LC (Foster) circuit: its R dashed over "
            "the solved curve, a schematic with L, C and f0 beside it, the frequencies where "
            "it no longer describes the cell shaded; for square patches on a grounded slab, "
            "Luukkonen et al.'s analytic model (2008) dotted"
        )
        self.circuit_box.toggled.connect(self._circuit_toggled)
        form.addRow(self.circuit_box)
        # the circuit's values and where it stops, or why there is none (one line)
        self.circuit_note = QLabel(self)
        self.circuit_note.setWordWrap(True)
        self.circuit_note.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.circuit_note.hide()
        form.addRow(self.circuit_note)
        col.addWidget(self.inputs_box)
        shown = add_messages(self, col)  # the solver's warnings: visible, not modal
        self.error, self.status, self.warnings = shown.error, shown.status, shown.warnings
        # the stack under Run and the messages: those stay above the dock's fold
        self.stack_box, box, self.stack_editor = stack_group(
            self, "Dielectric layers around the sheet, top first, and a ground plane under them"
        )
        self.stack_editor.changed.connect(self._stack_changed)
        # a good stack again: a refusal of it under Run goes (a bad one is said in the box)
        self.stack_editor.edited.connect(
            lambda: None if self.stack_editor.error else self._edited()
        )
        box.addWidget(self.stack_editor)
        col.addWidget(self.stack_box)
        self.note, self.show_curve_button = add_note_and_show_button(self, col, "Array curve")
        self.show_curve_button.clicked.connect(self.show_curve)
        # one line over the curve: what it is, or its warnings' kinds
        self.curve_area, area, self.curve_line = curve_area("No curve yet: Run in the Array tab.")
        grow = self.host is not None
        self.plot = PictureView(230 if grow else 330, self.curve_area, grow=grow)
        self.plot.setToolTip("Click a frequency: the current and the Floquet orders there")
        self.plot.clicked.connect(self.solve_at)
        self.plot.resized.connect(lambda: self._redraw("curve"))
        self.drawing = PictureView(200, self.curve_area, grow=grow)
        self.drawing.resized.connect(lambda: self._redraw("orders"))
        if grow:  # side by side in the dock under the 3D view, the splitter between
            split = QSplitter(Qt.Orientation.Horizontal, self.curve_area)
            split.addWidget(self.plot)
            split.addWidget(self.drawing)
            split.setStretchFactor(0, 3)
            split.setStretchFactor(1, 1)
            split.setChildrenCollapsible(False)
            self.plot.setMinimumWidth(260)
            self.drawing.setMinimumWidth(160)
            area.addWidget(split, 1)
        else:
            area.addWidget(self.plot)
        self.summary = QLabel(self)
        self.summary.setWordWrap(True)
        self.summary.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        col.addWidget(self.summary)
        self.table = QTableWidget(0, len(ORDER_COLUMNS), self)
        self.table.setHorizontalHeaderLabels(list(ORDER_COLUMNS))
        for column, tip in enumerate(ORDER_TIPS):
            header_item = self.table.horizontalHeaderItem(column)
            assert header_item is not None  # made by the labels above
            header_item.setToolTip(tip)
        self.table.verticalHeader().hide()
        self.table.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.table.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        self.table.horizontalHeader().setMinimumSectionSize(20)
        self.table.verticalHeader().setDefaultSectionSize(20)
        font = self.table.font()
        font.setPointSizeF(font.pointSizeF() * 0.85)
        self.table.setFont(font)
        self.table.setMinimumHeight(110)
        if self.host is None:  # everything in the tab, the curve under the inputs
            self.show_curve_button.hide()
            col.insertWidget(col.indexOf(self.summary), self.curve_area)
            col.addWidget(self.table)
            col.addWidget(self.drawing)
        else:
            col.addWidget(self.table)
            self.curve_dock = self.host.add_dock(
                "Array curve",
                self.curve_area,
                Qt.DockWidgetArea.BottomDockWidgetArea,
                name="dock_array_curve",
            )
            self.curve_dock.hide()  # until the tab is shown (a saved layout may say else)
            self.curve_dock.visibilityChanged.connect(lambda _v: self._update_curve_button())
        col.addStretch(1)
        for edit in (self.band_start, self.band_stop, self.theta, self.phi, self.sheet):
            edit.returnPressed.connect(self._edited)

    def _label(self, text: str, buddy: QWidget) -> QLabel:
        """A row's label whose mnemonic (Alt + the underlined letter) focuses ``buddy``."""
        label = QLabel(text, self)
        label.setBuddy(buddy)
        return label

    # -- inputs ----------------------------------------------------------------------

    @property
    def mesh(self) -> TriMesh | None:
        result = self.model.result
        return None if result is None else result.mesh

    def inputs(self) -> ArrayInputs:
        """The fields as :class:`ArrayInputs`; ValueError naming the field if invalid."""
        a, b = self.band.band()
        theta = read_angle(self.theta.text(), "θ", 0.0, 90.0)
        phi = read_angle(self.phi.text(), "φ", -360.0, 360.0)
        zs = read_impedance(self.sheet.text())
        if self.stack_editor.error:
            raise ValueError(self.stack_editor.error)
        freqs = tuple(float(f) for f in np.linspace(a, b, self.points.value()))
        stack = self.stack_editor.stack
        return ArrayInputs(freqs, theta, phi, self.polarization.currentData(), zs, stack)

    def _reason(self, mesh: TriMesh | None) -> str:
        """Why the tab cannot sweep ``mesh`` ("" if it can)."""
        if mesh is None:
            return "No mesh on screen."
        try:
            lattice_vectors(mesh)
        except ValueError as exc:
            return f"{exc}."
        # no RWG table here (a big mesh's would hold the GUI thread at every change): a
        # cell without unknowns is refused by the solver in the worker, in one line
        return ""

    def _update_enabled(self) -> None:
        reason = self._reason(self.mesh)
        self.reason.setText(reason)
        self.reason.setVisible(bool(reason))
        self.inputs_box.setEnabled(not reason)
        self.stack_box.setEnabled(not reason)

    def _edited(self) -> None:
        try:
            self.inputs()
        except ValueError as exc:
            self.error.setText(str(exc))
            return
        self.error.clear()

    def _stack_changed(self, stack: Any) -> None:
        """A good new stack: Live sweeps again (as for a new mesh); otherwise the curve
        says it is for the previous stack."""
        live = self.engaged and self.live.isChecked() and self.mesh is not None
        if self.result is not None and self.result.inputs.stack != stack:
            self._stale(
                "Updating for the new stack…" if live else "This curve is for the previous stack."
            )
        if live and not self._reason(self.mesh):
            self.run()

    def _grade_toggled(self, _on: bool) -> None:
        """Live sweeps the other mesh at once; otherwise the curve says it is of the
        other one (its status line names the mesh solved)."""
        live = self.engaged and self.live.isChecked() and self.mesh is not None
        if self.result is not None:
            self._stale(
                "Updating for the other mesh…" if live else "This curve is for the other mesh."
            )
        if live and not self._reason(self.mesh):
            self.run()

    def _stale(self, text: str) -> None:
        """Say (in the tab and over the curve) that the curve shown is not for the inputs."""
        self.note.setText(text)
        self.curve_line.setStyleSheet("color: #555555;")
        self.curve_line.setText(text)

    # -- the curve's dock ------------------------------------------------------------

    def show_curve(self) -> None:
        """Open (and raise) the Array curve dock; the first time at a readable height."""
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
        if not self._shown_once:  # the tab is looked at: its curve comes with it
            self._shown_once = True
            self.show_curve()

    def _run_clicked(self) -> None:
        self.show_curve()
        self.run()

    # -- jobs ------------------------------------------------------------------------

    def run(self) -> bool:
        """Sweep the mesh on screen over the band (a worker); False and a message if the
        inputs or the mesh cannot be swept (the last good curve stays)."""
        mesh = self.mesh
        try:
            inputs = self.inputs()
            reason = self._reason(mesh)
            if reason:
                raise ValueError(reason)
        except ValueError as exc:
            self.error.setText(str(exc))
            return False
        assert mesh is not None  # _reason refuses no mesh
        self.error.clear()
        self.engaged = True
        self._cancel_running("array")
        self._tokens["array"] += 1
        token = self._tokens["array"]
        stop = self._cancel[token] = threading.Event()

        size, ratio = self.plot.request_size()
        result, graded = self.model.result, self.solver_grade.isChecked()
        circuit = self.circuit_box.isChecked()
        # the λ/10 rule at the band's top, λ in the densest layer (εr μr)
        densest = 1.0 if inputs.stack is None else inputs.stack.max_index**2

        def work(task: Task) -> tuple[ArraySweep, Picture, SolvedMesh, str, CircuitFit | None]:
            solved = (
                solver_mesh(result, inputs.frequencies[-1], densest)
                if graded
                else SolvedMesh(mesh, mesh)
            )
            sweep = sweep_array(
                solved.mesh,
                inputs,
                progress=task.report,
                cancel=stop.is_set,
            )
            fit = fit_circuit(sweep, solved.mesh) if circuit else None  # 20-30 ms: here
            return sweep, draw_curve(sweep, size, ratio, fit), solved, said(solved), fit

        n = len(inputs.frequencies)
        self.status.setText(f"Sweeping {n} frequencies…")
        self.jobs.submit(
            lambda task: run_job(token, mesh, "array", partial(work, task)),
            self._finished,
            with_task=True,
            on_progress=partial(self._progress, token),
        )
        return True

    def solve_at(self, hz: float) -> bool:
        """Solve the array at ``hz`` (a worker): the current, the orders table and drawing."""
        if self.result is None or self.result_mesh is None or self.result_mesh is not self.mesh:
            return False
        assert self.solved is not None  # set with the curve
        mesh, solved = self.result_mesh, self.solved.mesh  # the curve's: solved on ``solved``
        inputs = self.result.inputs
        self.plot.mark(hz)
        self._tokens["point"] += 1
        token = self._tokens["point"]
        size, ratio = self.drawing.request_size()

        def work() -> tuple[Any, Picture]:  # worker thread
            solution = solve_point(solved, hz, inputs)
            return solution, draw_orders(solution, size, ratio)

        self.status.setText(f"Solving at {hz / 1e9:.4g} GHz…")
        self.jobs.submit(lambda: run_job(token, mesh, "point", work), self._finished)
        return True

    def _redraw(self, kind: str) -> None:
        """Draw the curve or the orders again (in the worker) at their view's size; the
        curve with its circuit when the box is ticked (fitted there, if not yet)."""
        view = self.plot if kind == "curve" else self.drawing
        size, ratio = view.request_size()
        self._tokens[kind] += 1
        token = self._tokens[kind]
        if kind == "orders":
            point = self.point
            self.jobs.submit(
                lambda: run_job(token, None, kind, lambda: draw_orders(point, size, ratio)),
                self._finished,
            )
            return
        data, fit = self.result, self.circuit_fit
        mesh = None if self.solved is None else self.solved.mesh
        wanted = self.circuit_box.isChecked() and data is not None and mesh is not None
        if fit is not None and fit.sweep is not data:
            fit = None

        def work() -> tuple[Picture, CircuitFit | None]:  # worker thread
            found = (fit or fit_circuit(data, mesh)) if wanted else None
            return draw_curve(data, size, ratio, found), found

        self.jobs.submit(lambda: run_job(token, None, kind, work), self._finished)

    def _circuit_toggled(self, on: bool) -> None:
        """Draw the curve again with (fitting it) or without its circuit."""
        if not on:
            self.circuit_note.hide()
        elif self.result is None:
            self._say_circuit("The circuit is fitted to the next curve: Run.", "#555555")
        self._redraw("curve")

    def _say_circuit(self, text: str, colour: str) -> None:
        self.circuit_note.setStyleSheet(f"color: {colour};")
        self.circuit_note.setText(text)
        self.circuit_note.show()

    def _show_circuit(self, fit: CircuitFit | None) -> None:
        """The circuit's line: its values (grey), or why there is none (red); the fit is
        kept for redraws of the same curve."""
        if fit is not None:
            self.circuit_fit = fit
        if not self.circuit_box.isChecked() or fit is None:
            return
        self._say_circuit(fit.note(), "#555555" if fit.circuit is not None else "#d0021b")

    def _cancel_running(self, kind: str) -> None:
        token = self._tokens[kind]
        stop = self._cancel.pop(token, None)
        if stop is not None:
            stop.set()
            self.cancelled.append(token)

    def cancel(self) -> None:
        """Stop the running sweep before its next frequency; drop its result."""
        if self._cancel:
            self._cancel_running("array")
            self._tokens["array"] += 1
            self.status.setText("The array sweep was cancelled.")

    def _progress(self, token: int, done: int, total: int) -> None:
        if token == self._tokens["array"]:
            self.status.setText(f"Sweeping: {done} of {total} frequencies…")

    def _finished(self, outcome: Any) -> None:
        self.last_outcome = outcome
        self._cancel.pop(outcome.token, None) if outcome.kind == "array" else None
        if outcome.cancelled:
            self.stopped.append(outcome.token)
        if outcome.token != self._tokens[outcome.kind] or outcome.cancelled:
            log.debug("dropped a stale %s", outcome.kind)
            return
        if outcome.error is not None:
            self.status.clear()
            self.error.setText(
                f"The array {'sweep' if outcome.kind == 'array' else 'solve'} "
                f"failed: {outcome.error}"
            )
            return
        if outcome.kind == "orders":
            self.drawing.show_picture(outcome.result)
            return
        if outcome.kind == "curve":
            picture, fit = outcome.result
            self.plot.show_picture(picture)
            self._show_circuit(fit)
            return
        if outcome.mesh is not self.mesh:
            self.status.setText("The result was for a previous mesh: dropped.")
            return
        data, picture, *solved = outcome.result
        fit = None
        if outcome.kind == "array":
            self.solved, self.said, fit = solved
        self.status.setText(f"Done in {outcome.seconds:.2f} s, {self.said}.")
        if outcome.kind == "array":
            self.result, self.result_mesh = data, outcome.mesh
            self._tokens["curve"] += 1  # a redraw asked for before is older than this
            self.plot.show_picture(picture)
            self._show_circuit(fit)
            if (fit is not None) != self.circuit_box.isChecked():
                self._redraw("curve")  # the box was clicked while the sweep ran
            self._describe(data)
            self._show_warnings()
            self.swept.emit(data)
        else:
            self._tokens["orders"] += 1
            self.drawing.show_picture(picture)
            self._show_point(data, outcome.mesh)

    def _describe(self, r: ArraySweep) -> None:
        i = r.inputs
        self.note.setText(
            f"{i.polarization}, θ {i.theta:g}°, φ {i.phi:g}°"
            + (f", Z_s {i.sheet_impedance:g} Ω/sq" if i.sheet_impedance else "")
            + (f", on {i.stack.describe()}" if i.stack is not None else ", in vacuum")
            + ": click the curve for the orders"
        )
        lines = []
        if len(r.resonances):
            lines.append("Resonance: " + ", ".join(f"{f / 1e9:.4g} GHz" for f in r.resonances))
        for hz, orders in r.grating_lobe_onsets:
            names = ", ".join(f"({p},{q})" for p, q in orders)
            lines.append(f"Grating lobe {names} from {hz / 1e9:.4g} GHz")
        if len(r.zero_phase):
            lines.append(
                "In-phase reflection (∠R = 0): "
                + ", ".join(f"{f / 1e9:.4g} GHz" for f in r.zero_phase)
            )
        for hz, orders, layers in r.guided_onsets:
            names = ", ".join(f"({p},{q})" for p, q in orders)
            where = ", ".join(str(k + 1) for k in layers)
            lines.append(
                f"Guided in layer {where} (not a grating lobe): {names} from {hz / 1e9:.4g} GHz"
            )
        if not lines:
            lines.append("No resonance and no grating lobe in this band.")
        r_plane, t_plane = reference_plane_names(i.stack)
        lines.append(
            f"R is referred to {r_plane}"
            + (f", T to {t_plane}." if t_plane is not None else "; T = 0 (ground plane).")
        )
        self.summary.setText("\n".join(lines))

    def _show_warnings(self) -> None:
        """The solver's warnings of the curve (and of the solve at the clicked
        frequency), one per line, in the tab; their kinds over the curve."""
        found: dict[str, str] = {}  # kind -> sentence, one of each
        if self.result is not None:
            for text in self.result.warnings:
                found.setdefault(text.split(":")[0], text)
        if self.point is not None and self.point_mesh is self.result_mesh:
            at = f"at {self.point.frequency / 1e9:.5g} GHz, "
            for text in self.point.warnings:
                found.setdefault(text.split(":")[0], at + text)
        if not found:
            self.warnings.clear()
            self.warnings.hide()
            self.curve_line.setStyleSheet("color: #555555;")
            self.curve_line.setText(self.note.text())
            self.curve_line.setToolTip(self.summary.text())
            return
        lines = []
        for kind, text in found.items():
            head, _sep, rest = text.partition(kind)
            lines.append(f"⚠ {html.escape(head)}<b>{html.escape(kind)}</b>{html.escape(rest)}")
        self.warnings.setText("<br>".join(lines))
        self.warnings.show()
        self.curve_line.setStyleSheet("color: #a05000;")
        self.curve_line.setText(
            f"⚠ Do not trust this curve blindly: {'; '.join(found)} (the Array tab says why)"
        )
        self.curve_line.setToolTip("\n".join(found.values()))

    def _show_point(self, solution: Any, mesh: TriMesh | None) -> None:
        self.point, self.point_mesh = solution, mesh
        rows = orders_rows(solution)
        self.table.setRowCount(len(rows))
        for i, row in enumerate(rows):
            values = (
                str(row.p),
                str(row.q),
                f"{row.reflected:.3f}",
                f"{row.transmitted:.3f}",
                f"{row.power_r:.4f}",
                f"{row.power_t:.4f}",
                f"{row.theta:.1f}",
                f"{row.phi:.0f}",
            )
            for j, text in enumerate(values):
                item = QTableWidgetItem(text)
                item.setTextAlignment(Qt.AlignmentFlag.AlignCenter)
                self.table.setItem(i, j, item)
        total = solution.power_balance
        r, t = solution.co_polar()
        self.summary.setText(
            f"At {solution.frequency / 1e9:.5g} GHz: {len(rows)} propagating order"
            f"{'s' if len(rows) != 1 else ''}; co-polar |R| {abs(r):.4f}, |T| {abs(t):.4f}; "
            f"power balance {total:.5f}"
        )
        self.plot.mark(solution.frequency)
        self._show_warnings()
        # drawn on the mesh it was solved on (the solver-grade one, perhaps), not ``mesh``
        solved = self.solved.mesh if self.solved is not None else mesh
        self.show_current(solved, solution.current_density)

    # -- the mesh changed ------------------------------------------------------------

    def _mesh_changed(self, result: Any) -> None:
        self._update_enabled()
        mesh = result.mesh if result is not None else None
        if self.point is not None and self.point_mesh is not mesh:
            self.point = self.point_mesh = None
            self.table.setRowCount(0)
            self.plot.mark(None)
            self._redraw("orders")
            self.show_current(None, None)
        live = self.engaged and self.live.isChecked() and mesh is not None
        if self.result is not None and self.result_mesh is not mesh:
            self.result_mesh = None
            self._stale(
                "Updating for the new mesh…" if live else "This curve is for the previous mesh."
            )
        if live:
            if self._reason(mesh):
                self._cancel_running("array")
                return
            self.run()  # cancels the running sweep first

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
        return self.jobs.wait(msecs)

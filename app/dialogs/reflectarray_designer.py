"""The reflectarray designer: the Reflection phase tab's S-curve laid out over an aperture
(issue 33 §2, in the window).

A non-modal window, opened by **Design reflectarray…** in the Reflection phase tab once a
whole curve is solved. It takes the tab's library (a ``ReflectionLibrary`` of one
frequency, with its cell), the aperture N1 × N2, the feed's phase centre (x, y, z mm), the
beam (θ, φ degrees) and the phase quantisation (continuous, 1, 2 or 3 bits), and draws what
:func:`barymesh.reflectarray.design` makes of them
(:func:`barymesh.app.panels.reflectarray_figure.draw_design`): the layout coloured by the
parameter and by the phase error, and the gain in the beam's plane with the main beam's
direction, the side-lobe level and the quantisation loss against the textbook −3.9 / −0.9
/ −0.2 dB written over it.

Designing a 15 × 15 array takes a few tenths of a second (the pattern's grid, the simplex
search of the beam, the continuous design a quantised one is compared with), so the design
and its picture are made by a worker of the window's :class:`~barymesh.app.jobs.Jobs`; a
result older than the latest request is dropped by its token. A bad input is one red line
naming the field, and the last good design stays. **Open as cell** makes the whole array
one unit cell (:meth:`barymesh.reflectarray.Reflectarray.to_cell`, in a worker: a second
for 15 × 15 elements) and opens it in the window, where it is saved, meshed and exported
(DXF, GDSII, meshes) as any cell.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (
    QComboBox,
    QDialog,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from barymesh.app.jobs import Jobs
from barymesh.app.model.reflectarray_design import (
    BIT_CHOICES,
    DesignInputs,
    read_design_inputs,
    run_design,
)
from barymesh.app.panels.curve_tab_parts import GREY, add_messages
from barymesh.app.panels.infinite_array_panel import PictureView
from barymesh.app.panels.phase_figure import coverage_text
from barymesh.app.panels.reflectarray_figure import draw_design
from barymesh.app.panels.solve_panel import run_job

log = logging.getLogger(__name__)

#: The designer's first size (pixels): the picture's three panels readable.
DESIGNER_SIZE = (1040, 860)


class ReflectarrayDesigner(QDialog):
    """The reflectarray designer window (see module docstring).

    Parameters
    ----------
    open_cell : callable, optional
        ``open_cell(cell, message)``: the window opens a unit cell (the array's).
    parent : QWidget, optional
    """

    #: a design (a DesignResult) is shown
    designed = Signal(object)
    #: the design was opened in the window as this unit cell
    opened = Signal(object)

    def __init__(
        self, open_cell: Callable[[Any, str], None] | None = None, parent: QWidget | None = None
    ) -> None:
        super().__init__(parent)
        self.setWindowTitle("Reflectarray designer")
        self.setModal(False)
        self.open_cell = open_cell
        self.library: Any = None
        self.result: Any = None  # the DesignResult shown
        self.requested: DesignInputs | None = None
        self.jobs = Jobs(self, name="barymesh-reflectarray")
        self._tokens = {"design": 0, "draw": 0, "cell": 0}
        self._build()
        self.resize(*DESIGNER_SIZE)

    # -- layout ----------------------------------------------------------------------

    def _build(self) -> None:
        col = QVBoxLayout(self)
        self.library_line = QLabel("No library yet.", self)
        self.library_line.setWordWrap(True)
        self.library_line.setStyleSheet(GREY)
        col.addWidget(self.library_line)
        form = QFormLayout()
        form.setContentsMargins(0, 0, 0, 0)
        self.n1 = self._field("15", "Elements along the lattice's a1")
        self.n2 = self._field("15", "Elements along the lattice's a2")
        form.addRow(self._label("&Aperture", self.n1), self._row(self.n1, "×", self.n2))
        self.feed_x = self._field("0", "The feed's phase centre: x (mm), over the aperture")
        self.feed_y = self._field("0", "The feed's phase centre: y (mm)")
        self.feed_z = self._field("150", "The feed's height over the aperture (mm), > 0")
        form.addRow(
            self._label("&Feed x, y, z (mm)", self.feed_x),
            self._row(self.feed_x, ",", self.feed_y, ",", self.feed_z),
        )
        self.theta = self._field("20", "The beam's θ (degrees from the normal), 0 to 90")
        self.phi = self._field("0", "The beam's φ (degrees from x)")
        form.addRow(self._label("&Beam (°)", self.theta), self._row("θ", self.theta, "φ", self.phi))
        self.bits = QComboBox(self)
        for label, bits in BIT_CHOICES:
            self.bits.addItem(label, bits)
        self.bits.setToolTip(
            "Continuous: each element gets the phase it needs; 1, 2, 3 bits: 2, 4, 8 levels"
        )
        self.bits.activated.connect(lambda _i: self.design())
        self.design_button = QPushButton("&Design", self)
        self.design_button.setToolTip("Lay the array out and predict its pattern (or Enter)")
        self.design_button.clicked.connect(self.design)
        self.open_button = QPushButton("Open as &cell", self)
        self.open_button.setToolTip(
            "The whole array as one unit cell in the window: save, mesh and export it as "
            "any cell (File → Export…, Cell → Save cell…)"
        )
        self.open_button.setEnabled(False)
        self.open_button.clicked.connect(self.open_as_cell)
        for button in (self.design_button, self.open_button):
            button.setAutoDefault(False)  # Enter in a field designs, never opens a cell
        form.addRow(
            self._label("P&hases", self.bits),
            self._row(self.bits, self.design_button, self.open_button),
        )
        col.addLayout(form)
        shown = add_messages(self, col)
        self.error, self.status = shown.error, shown.status
        self.plot = PictureView(520, self, grow=True)
        self.plot.setToolTip(
            "The layout coloured by the parameter and by the phase error; the gain in the "
            "beam's plane"
        )
        self.plot.resized.connect(self._redraw)
        col.addWidget(self.plot, 1)
        for edit in (self.n1, self.n2, self.feed_x, self.feed_y, self.feed_z):
            edit.returnPressed.connect(self.design)
        for edit in (self.theta, self.phi):
            edit.returnPressed.connect(self.design)

    def _field(self, text: str, tip: str) -> QLineEdit:
        edit = QLineEdit(text, self)
        edit.setToolTip(tip)
        edit.setMaximumWidth(90)
        return edit

    def _label(self, text: str, buddy: QWidget) -> QLabel:
        label = QLabel(text, self)
        label.setBuddy(buddy)
        return label

    def _row(self, *items: Any) -> QHBoxLayout:
        row = QHBoxLayout()
        for item in items:
            row.addWidget(QLabel(item, self) if isinstance(item, str) else item)
        row.addStretch(1)
        return row

    # -- the library -----------------------------------------------------------------

    def set_library(self, library: Any) -> None:
        """Design from ``library`` (the tab's whole curve): at once when it is new."""
        if library is None or library is self.library:
            return
        self.library = library
        values = library.values
        phase = library.phase_deg[:, 0]
        covered = float(phase.max() - phase.min()) if len(phase) else 0.0
        self.library_line.setText(
            f"The Phase tab's curve: {library.parameter} from {values.min():g} to "
            f"{values.max():g} ({len(values)} values) at "
            f"{library.frequencies[0] / 1e9:.4g} GHz, {library.polarization}, "
            f"{coverage_text(covered)}."
        )
        self.design()

    def inputs(self) -> DesignInputs:
        """The fields as :class:`DesignInputs`; ValueError naming the field if invalid."""
        return read_design_inputs(
            self.n1.text(),
            self.n2.text(),
            (self.feed_x.text(), self.feed_y.text(), self.feed_z.text()),
            (self.theta.text(), self.phi.text()),
            self.bits.currentData(),
        )

    # -- jobs ------------------------------------------------------------------------

    def design(self) -> bool:
        """Lay the array out (a worker); False and one red line if the inputs are bad (the
        last good design stays)."""
        try:
            if self.library is None:
                raise ValueError("No library: solve a whole curve in the Phase tab")
            inputs = self.inputs()
        except ValueError as exc:
            self.error.setText(str(exc))
            return False
        self.error.clear()
        self.requested = inputs
        self._tokens["design"] += 1
        token = self._tokens["design"]
        library = self.library
        size, ratio = self.plot.request_size()

        def work() -> tuple[Any, Any]:  # numpy, scipy, Agg
            result = run_design(library, inputs)
            return result, draw_design(result, size, ratio)

        self.status.setText("Designing…")
        self.jobs.submit(lambda: run_job(token, None, "design", work), self._finished)
        return True

    def _redraw(self) -> None:
        """Draw the design shown again (a worker) at the view's size."""
        result = self.result
        size, ratio = self.plot.request_size()
        self._tokens["draw"] += 1
        token = self._tokens["draw"]

        def work() -> Any:
            if token != self._tokens["draw"]:  # a newer redraw is queued: skip this one
                return None
            return draw_design(result, size, ratio)

        self.jobs.submit(lambda: run_job(token, None, "draw", work), self._finished)

    def _finished(self, outcome: Any) -> None:
        if outcome.kind == "draw":
            if outcome.token == self._tokens["draw"] and outcome.result is not None:
                self.plot.show_picture(outcome.result)
            return
        if outcome.token != self._tokens["design"]:
            log.debug("dropped a stale design")
            return
        if outcome.error is not None:
            self.status.clear()
            self.error.setText(f"The design failed: {outcome.error}")
            return
        result, picture = outcome.result
        self.result = result
        self._tokens["draw"] += 1  # a redraw asked for before is older than this
        self.plot.show_picture(picture)
        self.open_button.setEnabled(True)
        self.status.setText(f"Designed in {outcome.seconds:.2f} s.")
        self.designed.emit(result)

    # -- the array as a cell -----------------------------------------------------------

    def open_as_cell(self) -> bool:
        """Open the design shown as one unit cell in the window: the cell is made by a
        worker (a second for 15 × 15 elements, each element's parameters checked), then
        opened; False if there is no design (a refusal comes as a red line)."""
        result = self.result
        if result is None or self.open_cell is None:
            return False
        self.error.clear()
        self._tokens["cell"] += 1
        token = self._tokens["cell"]
        array = result.array
        n1, n2 = array.aperture
        self.open_button.setEnabled(False)
        self.status.setText(f"Making the cell of {n1 * n2} elements…")
        self.jobs.submit(lambda: run_job(token, None, "cell", array.to_cell), self._cell_made)
        return True

    def _cell_made(self, outcome: Any) -> None:
        self.open_button.setEnabled(self.result is not None)
        if outcome.token != self._tokens["cell"] or self.open_cell is None:
            return
        if outcome.error is not None:
            self.status.clear()
            self.error.setText(f"Cannot open the array as a cell: {outcome.error}")
            return
        cell = outcome.result
        n = len(cell.elements)
        self.open_cell(cell, f"The reflectarray's {n} elements as one cell")
        self.status.setText(f"Opened as a cell of {n} elements: save or export it from the window.")
        self.opened.emit(cell)

    def keyPressEvent(self, event: Any) -> None:  # noqa: N802 - Qt's name
        # Enter in a field designs (its returnPressed); it must not close the dialog
        if event.key() in (Qt.Key.Key_Return, Qt.Key.Key_Enter):
            return
        super().keyPressEvent(event)

    def stop(self, msecs: int = 30_000) -> bool:
        """Drop the results to come and wait for the running job (the window is closing)."""
        for kind in self._tokens:
            self._tokens[kind] += 1
        return self.jobs.wait(msecs)

"""The Lattice panel: the cell's lattice (an undo step per edit) and the array preview's
n1 x n2 copies (a view setting, not part of the cell)."""

from __future__ import annotations

from PySide6.QtCore import Signal
from PySide6.QtWidgets import QComboBox, QFormLayout, QGroupBox, QLabel, QSpinBox, QWidget

from barymesh.app.model import AppModel, format_value, read_number
from barymesh.app.model.cell_document import LATTICE_KINDS, MAX_COPIES, CellState, lattice_periods
from barymesh.app.panels.controls import ValueField, decimal_point

KIND_TITLES = {
    "rectangular": "Rectangular",
    "hexagonal": "Hexagonal",
    "oblique": "Oblique (from the file)",
}


class LatticePanel(QGroupBox):
    """Kind, periods, the vectors they make, and the preview's copies n1 x n2."""

    #: (n1, n2): the preview's copies changed.
    copies_changed = Signal(int, int)

    def __init__(self, model: AppModel, parent: QWidget | None = None) -> None:
        super().__init__("Lattice and array preview", parent)
        self.model = model
        form = QFormLayout(self)
        self.kind = QComboBox(self)
        self.kind.setObjectName("lattice_kind")
        for kind in (*LATTICE_KINDS, "oblique"):
            self.kind.addItem(KIND_TITLES[kind], kind)
        self.kind.currentIndexChanged.connect(self._kind_chosen)
        self.period1 = ValueField(self)
        self.period1.setObjectName("lattice_period1")
        self.period1.setToolTip("Period along a1 (mm); the spacing of a hexagonal lattice")
        self.period2 = ValueField(self)
        self.period2.setObjectName("lattice_period2")
        self.period2.setToolTip("Period along a2 (mm) of a rectangular lattice")
        for field in (self.period1, self.period2):
            field.submitted.connect(self._periods_typed)
            field.reverted.connect(lambda: self.show_cell(self.model.cell_state))
        self.vectors = QLabel(self)
        self.vectors.setObjectName("lattice_vectors")
        self.vectors.setWordWrap(True)
        self.n1 = QSpinBox(self)
        self.n1.setObjectName("array_n1")
        self.n2 = QSpinBox(self)
        self.n2.setObjectName("array_n2")
        for box in (self.n1, self.n2):
            box.setRange(1, MAX_COPIES)
            box.setToolTip(
                "Copies drawn translucent around the cell (not meshed; "
                "Cell ▸ Export array mesh… welds them into one mesh)"
            )
            box.valueChanged.connect(lambda _v: self.copies_changed.emit(*self.copies))
        form.addRow("&Kind", self.kind)
        form.addRow("Period &1 (mm)", self.period1)
        form.addRow("Period &2 (mm)", self.period2)
        form.addRow("Vectors", self.vectors)
        form.addRow("Array preview n&1", self.n1)
        form.addRow("Array preview n&2", self.n2)
        model.cell_changed.connect(self.show_cell)
        self.show_cell(model.cell_state)

    @property
    def copies(self) -> tuple[int, int]:
        return self.n1.value(), self.n2.value()

    def set_copies(self, n1: int, n2: int) -> None:
        """Preview ``n1`` x ``n2`` copies (the command line's ``--array``)."""
        self.n1.setValue(n1)
        self.n2.setValue(n2)

    def _kind_chosen(self, _index: int) -> None:
        state = self.model.cell_state
        kind = self.kind.currentData()
        if state is None or kind not in LATTICE_KINDS:
            self.show_cell(state)
            return
        p1, p2 = lattice_periods(state.cell.lattice)
        if not self.model.edit_cell(lambda s: s.with_lattice(kind, p1, p2)):
            self.show_cell(state)

    def _periods_typed(self, _text: str) -> None:
        state = self.model.cell_state
        if state is None:
            return
        kind = self.kind.currentData()
        p1 = read_number(self.period1.text(), None, decimal_point()).value
        p2 = read_number(self.period2.text(), None, decimal_point()).value
        if not self.model.edit_cell(lambda s: s.with_lattice(kind, p1, p2)):
            for field in (self.period1, self.period2):
                field.setProperty("refused", True)

    def show_cell(self, state: CellState | None) -> None:
        self.setEnabled(state is not None)
        for field in (self.period1, self.period2):
            field.setProperty("refused", False)
        if state is None:
            self.vectors.setText("")
            return
        lat = state.cell.lattice
        self.kind.blockSignals(True)
        self.kind.setCurrentIndex(self.kind.findData(lat.kind))
        self.kind.blockSignals(False)
        p1, p2 = lattice_periods(lat)
        self.period1.show_text(format_value(round(p1, 12)))
        self.period2.show_text(format_value(round(p2, 12)))
        editable = lat.kind in LATTICE_KINDS
        self.period1.setEnabled(editable)
        self.period2.setEnabled(lat.kind == "rectangular")
        self.vectors.setText(
            f"a1 = ({format_value(round(lat.a1[0], 9))}, "
            f"{format_value(round(lat.a1[1], 9))}) mm, a2 = "
            f"({format_value(round(lat.a2[0], 9))}, "
            f"{format_value(round(lat.a2[1], 9))}) mm"
        )

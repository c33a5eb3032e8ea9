"""Per-element statistics of a unit cell under the Statistics panel's whole-cell rows."""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtWidgets import (
    QAbstractScrollArea,
    QHeaderView,
    QLabel,
    QSizePolicy,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from barymesh.app.model import MeshResult

RIGHT = Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter
#: Columns: title -> key of TriMesh.stats().
COLUMNS = {
    "Part": "name",
    "Triangles": "triangles",
    "Vertices": "vertices",
    "RWG unknowns": "interior_edges",
    "Patches": "patches",
}
#: The numbers shown per part (all of :data:`COLUMNS` but the part's name).
QUANTITIES = {title: key for title, key in COLUMNS.items() if key != "name"}


class CellStats(QWidget):
    """A table of the cell's parts, each alone (its own mesh before welding), the periodic
    match of the cell's sides, and the core's notes. Hidden for a structure.

    The parts are the table's columns and the quantities its rows (their names in the
    row header), so the table fits the narrow Statistics dock: two parts beside the
    names take about 250 px, where five quantity columns took 330 and pushed the whole
    panel, values and all, out of the dock's view. More parts scroll sideways under the
    row names, which stay.
    """

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        col = QVBoxLayout(self)
        col.setContentsMargins(0, 4, 0, 0)
        self.title = QLabel(self)
        self.title.setObjectName("cell_stats_title")
        self.title.setWordWrap(True)  # a long cell name must not widen the panel
        self.table = QTableWidget(len(QUANTITIES), 0, self)
        self.table.setObjectName("cell_part_stats")
        self.table.setVerticalHeaderLabels(list(QUANTITIES))
        self.table.setEditTriggers(QTableWidget.EditTrigger.NoEditTriggers)
        self.table.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        self.table.verticalHeader().setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        self.table.setVerticalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.table.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAsNeeded)
        self.table.setSizeAdjustPolicy(QAbstractScrollArea.SizeAdjustPolicy.AdjustIgnored)
        # as wide as the dock gives, never wider: many parts scroll instead
        self.table.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Fixed)
        self.periodic = QLabel(self)
        self.periodic.setObjectName("cell_periodic")
        self.periodic.setWordWrap(True)
        self.notes = QLabel(self)
        self.notes.setObjectName("cell_notes")
        self.notes.setWordWrap(True)
        self.notes.setStyleSheet("color: #a05a00;")
        for w in (self.title, self.table, self.periodic, self.notes):
            col.addWidget(w)
        self.hide()

    def show_result(self, result: MeshResult | None) -> None:
        stats = result.cell_stats if result is not None else {}
        self.setVisible(bool(stats))
        if not stats or result is None:
            return
        cell = result.cell
        assert cell is not None  # a cell's mesh has cell_stats
        self.title.setText(
            f"<b>Cell {cell.name}</b>: {cell.lattice.kind} lattice, "
            f"{cell.mode} mode; each part alone:"
        )
        parts = stats["parts"]
        # filled with fixed sections, then fitted once: ResizeToContents while filling
        # measured every column at each label and item (2.5 s for a 225-element array)
        header = self.table.horizontalHeader()
        header.setSectionResizeMode(QHeaderView.ResizeMode.Interactive)
        self.table.setColumnCount(len(parts))
        self.table.setHorizontalHeaderLabels([str(part["name"]) for part in parts])
        for c, part in enumerate(parts):
            for r, key in enumerate(QUANTITIES.values()):
                item = QTableWidgetItem(f"{part[key]:,}")
                item.setTextAlignment(RIGHT)
                self.table.setItem(r, c, item)
        header.setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        self.fit_height()
        pairs, unmatched = stats["periodic_edge_pairs"], stats["unmatched_periodic_edges"]
        self.periodic.setText(
            f"Periodic edge pairs across the cell's sides: {pairs:,}"
            + (f" ({unmatched:,} edges without a partner)" if unmatched else "")
        )
        self.notes.setText("\n".join(stats["notes"]))
        self.notes.setVisible(bool(stats["notes"]))

    def fit_height(self) -> None:
        """The table as tall as its header, every row and (when the parts do not fit the
        width) the scroll bar under them: no row is cut."""
        table = self.table
        height = table.horizontalHeader().sizeHint().height() + 2 * table.frameWidth()
        height += table.verticalHeader().length()
        width = table.verticalHeader().width() + table.horizontalHeader().length()
        if width + 2 * table.frameWidth() > table.width():
            height += table.horizontalScrollBar().sizeHint().height()
        if table.height() != height:
            table.setFixedHeight(height)

    def resizeEvent(self, event) -> None:  # noqa: ANN001, N802 - Qt's name
        super().resizeEvent(event)
        self.fit_height()  # the scroll bar comes and goes with the width

    def part_count(self) -> int:
        """How many parts the table shows (tests)."""
        return self.table.columnCount()

    def cell_text(self, row: int, column: str) -> str:
        """The text shown for part ``row`` under ``column`` (a title of :data:`COLUMNS`):
        tests, copy."""
        if COLUMNS[column] == "name":
            item = self.table.horizontalHeaderItem(row)
        else:
            item = self.table.item(list(QUANTITIES).index(column), row)
        assert item is not None, (row, column)
        return item.text()

"""Per-element statistics of a unit cell under the Statistics panel's whole-cell rows."""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtWidgets import (
    QHeaderView,
    QLabel,
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


class CellStats(QWidget):
    """A table with one row per part of the cell alone (its own mesh before welding),
    the periodic match of the cell's sides, and the core's notes. Hidden for a structure."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        col = QVBoxLayout(self)
        col.setContentsMargins(0, 4, 0, 0)
        self.title = QLabel(self)
        self.title.setObjectName("cell_stats_title")
        self.table = QTableWidget(0, len(COLUMNS), self)
        self.table.setObjectName("cell_part_stats")
        self.table.setHorizontalHeaderLabels(list(COLUMNS))
        self.table.verticalHeader().hide()
        self.table.setEditTriggers(QTableWidget.EditTrigger.NoEditTriggers)
        self.table.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        self.table.horizontalHeader().setStretchLastSection(True)
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
        if not stats:
            return
        cell = result.cell
        self.title.setText(
            f"<b>Cell {cell.name}</b>: {cell.lattice.kind} lattice, "
            f"{cell.mode} mode; each part alone:"
        )
        parts = stats["parts"]
        self.table.setRowCount(len(parts))
        for r, part in enumerate(parts):
            for c, key in enumerate(COLUMNS.values()):
                value = part[key]
                item = QTableWidgetItem(value if isinstance(value, str) else f"{value:,}")
                if not isinstance(value, str):
                    item.setTextAlignment(RIGHT)
                self.table.setItem(r, c, item)
        height = self.table.horizontalHeader().height() + 4
        height += sum(self.table.rowHeight(r) for r in range(len(parts)))
        self.table.setFixedHeight(min(height, 240))
        pairs, unmatched = stats["periodic_edge_pairs"], stats["unmatched_periodic_edges"]
        self.periodic.setText(
            f"Periodic edge pairs across the cell's sides: {pairs:,}"
            + (f" ({unmatched:,} edges without a partner)" if unmatched else "")
        )
        self.notes.setText("\n".join(stats["notes"]))
        self.notes.setVisible(bool(stats["notes"]))

    def cell_text(self, row: int, column: str) -> str:
        """The text of ``row`` under ``column`` (a title of :data:`COLUMNS`): tests, copy."""
        return self.table.item(row, list(COLUMNS).index(column)).text()

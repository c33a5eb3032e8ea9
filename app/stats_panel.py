"""The statistics panel: counts and quality of the mesh on screen, updated with every mesh."""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QFormLayout, QLabel, QWidget

from .edit.cell_stats import CellStats
from .model import STAT_LABELS, AppModel, MeshResult, stats_texts

TOOLTIPS = {
    "interior_edges": "Edges shared by exactly two triangles: one RWG basis function each",
    "boundary_edges": "Edges on one triangle: no RWG function",
    "junction_edges": "Edges on three or more triangles: not RWG-ready, check the mesh",
    "overlap_ratio": "1 − union area / sum of patch areas: how much paper-mode patches overlap",
    "mesh_time": "build_mesh plus the edge topology and statistics",
    "mom_memory": "A dense N × N complex128 impedance matrix, N = interior edges",
}


class StatsPanel(QWidget):
    """One ``label: value`` row per key of :data:`app.model.STAT_LABELS`."""

    def __init__(self, model: AppModel, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        form = QFormLayout(self)
        form.setContentsMargins(8, 6, 8, 6)
        form.setLabelAlignment(Qt.AlignmentFlag.AlignLeft)
        self.values: dict[str, QLabel] = {}
        for key, label in STAT_LABELS.items():
            value = QLabel("–", self)
            value.setObjectName(f"stat_{key}")
            value.setAlignment(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
            value.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
            name = QLabel(label, self)
            for w in (name, value):
                w.setToolTip(TOOLTIPS.get(key, ""))
            form.addRow(name, value)
            self.values[key] = value
        self.source = QLabel(self)
        self.source.setWordWrap(True)
        self.source.setStyleSheet("color: #555;")
        form.addRow(self.source)
        self.cell = CellStats(self)  # a unit cell: each element's rows
        form.addRow(self.cell)
        model.result_changed.connect(self.show_result)
        self.show_result(model.result)

    def show_result(self, result: MeshResult | None) -> None:
        for key, text in stats_texts(result).items():
            self.values[key].setText(text)
        junctions = result is not None and result.stats.get("junction_edges", 0) > 0
        self.values["junction_edges"].setStyleSheet(
            "color: #d0021b; font-weight: bold;" if junctions else ""
        )
        imported = result is not None and result.source != "parameters"
        self.source.setText(f"Mesh file: {result.source}" if imported else "")
        self.cell.show_result(result)

    def text(self, key: str) -> str:
        """The value shown for ``key`` (tests, copy)."""
        return self.values[key].text()

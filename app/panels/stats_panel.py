"""The statistics panel: counts and quality of the mesh on screen, updated with every mesh.

With a frequency, the mesh's sizing too: the subdivisions chosen, λ, the longest edge in
wavelengths, the largest area in λ² and whether every edge is within λ/10.
"""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QGridLayout, QLabel, QWidget

from barymesh.app.edit.cell_stats import CellStats
from barymesh.app.model import STAT_LABELS, AppModel, MeshResult, stats_texts

TOOLTIPS = {
    "interior_edges": "Edges shared by exactly two triangles: one RWG basis function each",
    "boundary_edges": "Edges on one triangle: no RWG function",
    "junction_edges": "Edges on three or more triangles: not RWG-ready, check the mesh",
    "overlap_ratio": "1 − union area / sum of patch areas: how much paper-mode patches overlap",
    "mesh_time": "build_mesh plus the edge topology and statistics",
    "mom_memory": "A dense N × N complex128 impedance matrix, N = interior edges",
    "subdivisions_chosen": "The smallest subdivisions whose edges all meet the frequency's "
    "λ / cells per wavelength or the largest edge",
    "wavelength": "λ = c0 / (f √εr) at the frequency, in the medium of εr",
    "max_edge_wavelengths": "Longest edge of the mesh in wavelengths (λ/10 = 0.1)",
    "max_area_wavelengths2": "Largest triangle area in square wavelengths (λ²/30 = 0.033)",
    "lambda_10_rule": "Whether every edge is at most a tenth of the wavelength",
}
#: Sizing rows (``TriMesh.stats()`` keys present when a frequency or largest edge is set).
SIZING_LABELS = {
    "subdivisions_chosen": "Subdivisions chosen",
    "wavelength": "Wavelength λ",
    "max_edge_wavelengths": "Longest edge / λ",
    "max_area_wavelengths2": "Largest area / λ²",
    "lambda_10_rule": "Edges ≤ λ/10",
}


def sizing_texts(result: MeshResult | None) -> dict[str, str]:
    """The sizing rows' text: "–" without a frequency (or a largest edge for the n)."""
    s = {} if result is None or result.mesh is None else result.stats
    out = dict.fromkeys(SIZING_LABELS, "–")
    if "subdivisions_chosen" in s:
        out["subdivisions_chosen"] = f"{s['subdivisions_chosen']}"
    if "wavelength" in s:
        out["wavelength"] = f"{s['wavelength']:.4g} mm"
        out["max_edge_wavelengths"] = f"{s['max_edge_wavelengths']:.4f} λ"
        out["max_area_wavelengths2"] = f"{s['max_area_wavelengths2']:.3g} λ²"
        out["lambda_10_rule"] = "yes" if s["lambda_10_rule"] else "no"
    return out


class StatsPanel(QWidget):
    """One ``label: value`` row per key of :data:`barymesh.app.model.STAT_LABELS`."""

    def __init__(self, model: AppModel, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        # a grid, not a form: a name wraps onto a second line when the dock is narrow and
        # its value is long (0.001917 mm, 101.121), so a value is never pushed off the
        # dock's edge and the dock never has to widen (which would resize the 3D view)
        grid = QGridLayout(self)
        grid.setContentsMargins(8, 6, 8, 6)
        grid.setHorizontalSpacing(10)
        grid.setVerticalSpacing(6)
        grid.setColumnStretch(0, 1)
        self.values: dict[str, QLabel] = {}
        self.names: dict[str, QLabel] = {}
        rows = {**STAT_LABELS, **SIZING_LABELS}
        for row, (key, label) in enumerate(rows.items()):
            value = QLabel("–", self)
            value.setObjectName(f"stat_{key}")
            value.setAlignment(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
            value.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
            name = QLabel(label, self)
            name.setWordWrap(True)
            for w in (name, value):
                w.setToolTip(TOOLTIPS.get(key, ""))
            grid.addWidget(name, row, 0)
            grid.addWidget(value, row, 1)
            self.values[key] = value
            self.names[key] = name
        self.source = QLabel(self)
        self.source.setWordWrap(True)
        self.source.setStyleSheet("color: #555;")
        grid.addWidget(self.source, len(rows), 0, 1, 2)
        self.cell = CellStats(self)  # a unit cell: each element's rows
        grid.addWidget(self.cell, len(rows) + 1, 0, 1, 2)
        grid.setRowStretch(len(rows) + 2, 1)
        model.result_changed.connect(self.show_result)
        self.show_result(model.result)

    def show_result(self, result: MeshResult | None) -> None:
        for key, text in {**stats_texts(result), **sizing_texts(result)}.items():
            self.values[key].setText(text)
        broken = result is not None and result.stats.get("lambda_10_rule") is False
        self.values["lambda_10_rule"].setStyleSheet(
            "color: #d0021b; font-weight: bold;" if broken else ""
        )
        junctions = result is not None and result.stats.get("junction_edges", 0) > 0
        self.values["junction_edges"].setStyleSheet(
            "color: #d0021b; font-weight: bold;" if junctions else ""
        )
        imported = result is not None and result.source != "parameters"
        self.source.setText(
            f"Mesh file: {result.source}" if result is not None and imported else ""
        )
        self.cell.show_result(result)

    def text(self, key: str) -> str:
        """The value shown for ``key`` (tests, copy)."""
        return self.values[key].text()

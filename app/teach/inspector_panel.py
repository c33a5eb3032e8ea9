"""The RWG inspector's panel (the view's click picking is
:class:`barymesh.app.view.picker.ViewPicker`).

:class:`InspectorPanel` keeps the selected edge, drives
:class:`barymesh.app.teach.inspector.InspectorOverlay` and shows the info box.
"""

from __future__ import annotations

import logging
from typing import Any

import numpy as np
from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from barymesh import TriMesh
from barymesh.app.teach.inspector import (
    DEFAULT_QUADRATURE,
    EdgeInfo,
    InspectorOverlay,
    edge_info,
    edge_midpoint,
    nearest_edge,
    nearest_edge_to_point,
    overlay_data,
    step_edge,
)

log = logging.getLogger(__name__)


class InspectorPanel(QWidget):
    """Edge selection, the info box and the overlay of the RWG inspector.

    ``edge_selected(edge)`` is emitted with every new selection (-1: none).
    """

    edge_selected = Signal(int)
    zoom_requested = Signal()

    def __init__(self, plotter: Any, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.plotter = plotter
        self.overlay = InspectorOverlay(plotter)
        self.mesh: TriMesh | None = None
        self.edge: int | None = None
        self.info: EdgeInfo | None = None
        self.active = False

        layout = QVBoxLayout(self)
        hint = QLabel(
            "Click an edge or a triangle in the 3D view. "
            "<b>N</b> / <b>P</b>: next / previous RWG unknown.",
            self,
        )
        hint.setWordWrap(True)
        layout.addWidget(hint)
        form = QFormLayout()
        self.edge_spin = QSpinBox(self)
        self.edge_spin.setRange(-1, 0)
        self.edge_spin.setSpecialValueText("none")
        self.edge_spin.setToolTip("Edge id (row of TriMesh.edges)")
        self.edge_spin.valueChanged.connect(self._spin_changed)
        self.quadrature = QSpinBox(self)
        self.quadrature.setRange(1, 8)
        self.quadrature.setValue(DEFAULT_QUADRATURE)
        self.quadrature.setToolTip(
            "f_n is drawn at the centroids of q² sub-triangles of T+ and T− (the quadrature points)"
        )
        self.quadrature.valueChanged.connect(lambda _q: self.refresh())
        form.addRow("&Edge", self.edge_spin)
        form.addRow("&Quadrature q (q² points)", self.quadrature)
        layout.addLayout(form)
        buttons = QHBoxLayout()
        self.prev_button = QPushButton("◀ Previous", self)
        self.next_button = QPushButton("Next ▶", self)
        self.prev_button.clicked.connect(self.previous_edge)
        self.next_button.clicked.connect(self.next_edge)
        self.zoom_button = QPushButton("Zoom to edge", self)
        self.zoom_button.setToolTip("Frame T+ and T− in the view (Z)")
        self.zoom_button.clicked.connect(self.zoom_requested.emit)
        buttons.addWidget(self.prev_button)
        buttons.addWidget(self.next_button)
        buttons.addWidget(self.zoom_button)
        layout.addLayout(buttons)
        self.info_label = QLabel(self)
        self.info_label.setWordWrap(True)
        self.info_label.setTextFormat(Qt.TextFormat.RichText)
        self.info_label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.info_label.setAlignment(Qt.AlignmentFlag.AlignTop | Qt.AlignmentFlag.AlignLeft)
        layout.addWidget(self.info_label)
        self.lines: list[QLabel] = []  # lines added by add_line, under the info
        legend = QLabel(
            "<small><span style='color:#b40426'>■</span> T+ (∇·f = +l/A+) &nbsp; "
            "<span style='color:#3b4cc0'>■</span> T− (∇·f = −l/A−)<br>"
            "<span style='background:#000000;color:#ffe000'>━━</span> the edge &nbsp; "
            "<span style='color:#00a651'>➜</span> ρ± and free vertices r± &nbsp; "
            "<b>➜</b> f_n at the quadrature points</small>",
            self,
        )
        legend.setWordWrap(True)
        layout.addWidget(legend)
        layout.addStretch(1)
        self._show_info()

    def add_line(self) -> QLabel:
        """A line of text under the edge's description, for another part of the window
        to fill (the Solve dock's I_n of the edge); selectable, wrapped."""
        line = QLabel(self)
        line.setWordWrap(True)
        line.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        layout = self.layout()
        assert isinstance(layout, QVBoxLayout)  # made in __init__
        layout.insertWidget(layout.indexOf(self.info_label) + 1 + len(self.lines), line)
        self.lines.append(line)
        return line

    # -- selection ----------------------------------------------------------------------

    def set_active(self, on: bool) -> None:
        """Show or hide the overlay (the panel itself is shown by its dock)."""
        self.active = bool(on)
        self.overlay.set_visible(self.active)
        if self.active and self.edge is None and self.mesh is not None:
            self.select_edge(step_edge(self.mesh, None, 1))
            return
        self.plotter.render()

    def set_mesh(self, mesh: TriMesh | None) -> None:
        """A new mesh: keep the selection at the same place (nearest edge midpoint)."""
        old, old_edge = self.mesh, self.edge
        self.mesh = mesh
        self.edge = None
        edges = len(mesh.edges) if mesh is not None else 0
        self.edge_spin.blockSignals(True)
        self.edge_spin.setRange(-1, max(edges - 1, -1))
        self.edge_spin.blockSignals(False)
        target = None
        if mesh is not None and old is not None and old_edge is not None:
            target = nearest_edge_to_point(mesh, edge_midpoint(old, old_edge))
        elif mesh is not None and self.active:
            target = step_edge(mesh, None, 1)
        self.select_edge(target, render=False)

    def select_edge(self, edge: int | None, render: bool = True) -> None:
        """Select ``edge`` (an id of ``mesh.edges``; ``None`` clears)."""
        mesh = self.mesh
        if mesh is None or edge is None or not 0 <= int(edge) < len(mesh.edges):
            edge = None
        self.edge = None if edge is None else int(edge)
        self.refresh(render)
        self.edge_selected.emit(-1 if self.edge is None else self.edge)

    def select_triangle(self, triangle: int, point: np.ndarray | None = None) -> None:
        """A click on ``triangle`` (at world ``point``): its nearest edge."""
        if self.mesh is None or not 0 <= int(triangle) < self.mesh.n_triangles:
            return
        self.select_edge(nearest_edge(self.mesh, int(triangle), point))

    def next_edge(self) -> None:
        if self.mesh is not None:
            self.select_edge(step_edge(self.mesh, self.edge, 1))

    def previous_edge(self) -> None:
        if self.mesh is not None:
            self.select_edge(step_edge(self.mesh, self.edge, -1))

    def refresh(self, render: bool = True) -> None:
        """Recompute the info and the overlay for the current edge."""
        self.info = None
        data = None
        if self.mesh is not None and self.edge is not None:
            try:
                self.info = edge_info(self.mesh, self.edge, self.quadrature.value())
                data = overlay_data(self.mesh, self.info)
            except Exception:  # noqa: BLE001 - the window keeps running whatever happens
                log.exception("inspecting edge %s failed", self.edge)
                self.info, data = None, None
        self.overlay.update(data)
        self.edge_spin.blockSignals(True)
        self.edge_spin.setValue(-1 if self.edge is None else self.edge)
        self.edge_spin.blockSignals(False)
        self._show_info()
        if render:
            self.plotter.render()

    def _spin_changed(self, value: int) -> None:
        self.select_edge(None if value < 0 else value)

    def _show_info(self) -> None:
        if self.info is None:
            self.info_label.setText("<i>No edge selected.</i>")
        else:
            self.info_label.setText(self.info.html())

    @property
    def status_text(self) -> str:
        """The sentence that says whether (and why not) the edge carries an RWG function."""
        return "" if self.info is None else self.info.status

"""The Infinite array tab's stack editor: dielectric layers around the sheet and a ground
plane, in a table, with a side view drawn to scale.

The table lists the layers top first with the sheet as a row among them (the layers above
that row lie between the incident wave and the sheet: ``Stack.above``; those below it,
``Stack.below``). A layer's thickness (mm, or typed with a unit: 35um, 30mil), εr, tan δ
and μr are typed into its cells; **Add layer**, **Remove**, **Up** and **Down** change the
rows (moving a layer past the sheet row moves it to the other side; the sheet row moves
too), and **Ground plane** puts a perfect conductor under the last layer.

Each committed edit is read whole (:func:`barymesh.app.model.stack_rows.read_stack`): a
good stack replaces the last and is announced with :attr:`StackEditor.changed`; a bad
value is said in one line under the table, its cell turns red, and the last good stack
stays (the curve computed with it too). :class:`StackSketch` draws the last good stack:
the layers as bands whose heights are their thicknesses to one scale (a scale bar on the
left), the sheet as a dashed line of metal, the ground plane as a hatched bar, and the
planes R and T are referred to (:func:`barymesh.app.model.stack_sketch.sketch_layout`).
"""

from __future__ import annotations

import math
from typing import Any

from PySide6.QtCore import QRectF, QSize, Qt, Signal
from PySide6.QtGui import QBrush, QColor, QFont, QPainter, QPen
from PySide6.QtWidgets import (
    QAbstractItemView,
    QCheckBox,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QSizePolicy,
    QTableWidget,
    QTableWidgetItem,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from barymesh.app.model.stack_rows import (
    COLUMNS,
    NEW_LAYER,
    LayerRow,
    layer_name,
    layer_row,
    read_column,
    read_stack,
)
from barymesh.app.model.stack_sketch import sketch_layout

#: The table's columns: the side, then the typed values (:data:`COLUMNS`).
HEADERS = ("side", "t (mm)", "εr", "tan δ", "μr")
HEADER_TIPS = (
    "Which side of the sheet the layer is on (move it past the sheet row to change)",
    "Thickness in mm (or type a unit: 35um, 30mil, 0.1in)",
    "Relative permittivity εr (> 0)",
    "Loss tangent tan δ (ε = εr (1 − j tan δ)); empty: 0",
    "Relative permeability μr (> 0); empty: 1",
)
#: The sheet's row in the table (a marker in :attr:`StackEditor.rows`).
SHEET = None
BAD_CELL = QColor("#f8d0d0")
SHEET_CELL = QColor("#e6e6e6")
R_COLOR, T_COLOR = QColor("#1f77b4"), QColor("#2ca02c")


class StackSketch(QWidget):
    """The side view of a stack, drawn to scale (see the module's docstring)."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.stack: Any = None
        self.setMinimumHeight(100)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Fixed)
        self.setToolTip(
            "The stack to scale (the vacuum above and below is not): the sheet (dashed), "
            "the layers, the ground plane (hatched) and the planes R and T are referred to"
        )

    def sizeHint(self) -> QSize:  # noqa: N802 - Qt's name
        return QSize(260, 110)

    def set_stack(self, stack: Any) -> None:
        self.stack = stack
        self.update()

    def layout_now(self) -> Any:
        """The :class:`barymesh.app.model.stack_sketch.Sketch` of the widget's height."""
        return sketch_layout(self.stack, float(self.height()))

    def paintEvent(self, _event: Any) -> None:  # noqa: N802 - Qt's name
        painter = QPainter(self)
        painter.setRenderHint(QPainter.RenderHint.Antialiasing, False)
        painter.fillRect(self.rect(), QColor("white"))
        sketch = self.layout_now()
        w = float(self.width())
        left, right = 34.0, w - 6.0
        font = QFont(self.font())
        font.setPointSizeF(max(font.pointSizeF() * 0.8, 6.0))
        painter.setFont(font)
        line = painter.fontMetrics().height()
        painter.setPen(QColor("#888888"))
        painter.drawText(QRectF(left + 4, 2, right - left, line), "vacuum  ↓ the wave")
        layers = self.stack.layers if self.stack is not None else ()
        for band in sketch.bands:
            layer = layers[band.index]
            rect = QRectF(left, band.top, right - left, band.bottom - band.top)
            painter.fillRect(rect, _layer_colour(layer.eps_r, layer.mu_r))
            painter.setPen(QPen(QColor("#7a6a50"), 1))
            painter.drawLine(round(left), round(band.top), round(right), round(band.top))
            painter.drawLine(round(left), round(band.bottom), round(right), round(band.bottom))
            if band.bottom - band.top >= line:
                painter.setPen(QColor("#3a3020"))
                painter.drawText(
                    rect.adjusted(4, 0, -4, 0),
                    int(Qt.AlignmentFlag.AlignVCenter | Qt.AlignmentFlag.AlignLeft),
                    f"{band.index + 1}: {band.label}",
                )
        if sketch.ground is not None:
            g0, g1 = sketch.ground
            rect = QRectF(left - 8, g0, right - left + 8, g1 - g0)
            painter.fillRect(rect, QColor("#b0b0b0"))
            painter.fillRect(rect, QBrush(QColor("#303030"), Qt.BrushStyle.BDiagPattern))
            painter.setPen(QPen(QColor("#303030"), 1))
            painter.drawRect(rect)
        # the sheet: the cell's metal, a dashed heavy line
        pen = QPen(QColor("#202020"), 3)
        pen.setDashPattern([4.0, 1.5])
        painter.setPen(pen)
        painter.drawLine(round(left), round(sketch.sheet), round(right), round(sketch.sheet))
        # the reference planes, labelled at the right
        planes = sketch.planes
        heights = self.stack.reference_planes if self.stack is not None else (0.0, 0.0)
        for (y, name), colour in zip(planes, (R_COLOR, T_COLOR), strict=False):
            pen = QPen(colour, 1)
            pen.setStyle(Qt.PenStyle.DashLine)
            painter.setPen(pen)
            painter.drawLine(round(left - 10), round(y), round(right), round(y))
            z = heights[0] if name.startswith("R") else heights[1]
            text = f"{name}, z = {z:.4g} mm".replace("-", "−")
            above = name.startswith("R") or y + line > self.height()
            box = QRectF(left, y - line - 1 if above else y + 1, right - left, line)
            painter.setPen(colour)
            painter.drawText(box, int(Qt.AlignmentFlag.AlignRight), text)
        self._scale_bar(painter, sketch, line)
        painter.end()

    def _scale_bar(self, painter: QPainter, sketch: Any, line: int) -> None:
        """A vertical bar of a round length (1, 2 or 5 × 10^k mm) on the left."""
        if not sketch.mm_per_pixel:
            return
        room = sketch.bottom_face - sketch.top_face
        span = room * sketch.mm_per_pixel
        length = _round_length(span * 0.6)
        pixels = length / sketch.mm_per_pixel
        x, y1 = 10, sketch.bottom_face
        painter.setPen(QPen(QColor("#404040"), 1))
        painter.drawLine(x, round(y1), x, round(y1 - pixels))
        painter.drawLine(x - 3, round(y1), x + 3, round(y1))
        painter.drawLine(x - 3, round(y1 - pixels), x + 3, round(y1 - pixels))
        painter.save()
        painter.translate(x + 12, y1 - pixels / 2)
        painter.rotate(-90)
        painter.drawText(
            QRectF(-40, -line, 80, line), int(Qt.AlignmentFlag.AlignCenter), f"{length:g} mm"
        )
        painter.restore()


def _round_length(x: float) -> float:
    """The largest 1, 2 or 5 × 10^k not above ``x`` (> 0)."""
    k = math.floor(math.log10(x))
    for m in (5.0, 2.0, 1.0):
        if m * 10.0**k <= x:
            return m * 10.0**k
    return 10.0**k


def _layer_colour(eps_r: float, mu_r: float) -> QColor:
    """Pale for vacuum, warmer the denser the layer (log of its index)."""
    index = math.sqrt(eps_r * mu_r)
    t = min(math.log(max(index, 1.0)) / math.log(4.0), 1.0)
    c0, c1 = (245, 245, 240), (236, 188, 110)
    return QColor(*(round(a + (b - a) * t) for a, b in zip(c0, c1, strict=True)))


class StackEditor(QWidget):
    """Layers and a ground plane in a table, with the side view (see the module)."""

    #: the new good stack (a barymesh.mom.Stack; None: the sheet alone in vacuum)
    changed = Signal(object)
    #: after every edit, good or bad (:attr:`error` says which)
    edited = Signal()

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        #: the rows top first: a LayerRow each, SHEET for the sheet's row
        self.rows: list[LayerRow | None] = [SHEET]
        self.stack: Any = None  # the last good stack
        self.error = ""
        self._filling = False
        col = QVBoxLayout(self)
        col.setContentsMargins(0, 0, 0, 0)
        self.table = QTableWidget(0, len(HEADERS), self)
        self.table.setHorizontalHeaderLabels(list(HEADERS))
        for column, tip in enumerate(HEADER_TIPS):
            header_item = self.table.horizontalHeaderItem(column)
            assert header_item is not None  # made by the labels above
            header_item.setToolTip(tip)
        header = self.table.horizontalHeader()
        header.setSectionResizeMode(0, QHeaderView.ResizeMode.ResizeToContents)
        for column in range(1, len(HEADERS)):
            header.setSectionResizeMode(column, QHeaderView.ResizeMode.Stretch)
        header.setMinimumSectionSize(20)
        self.table.verticalHeader().setDefaultSectionSize(22)
        font = self.table.font()  # as the orders' table: five columns in a 300 px dock
        font.setPointSizeF(font.pointSizeF() * 0.85)
        self.table.setFont(font)
        self.table.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectItems)
        self.table.setSelectionMode(QAbstractItemView.SelectionMode.SingleSelection)
        self.table.setEditTriggers(
            QAbstractItemView.EditTrigger.DoubleClicked
            | QAbstractItemView.EditTrigger.EditKeyPressed
            | QAbstractItemView.EditTrigger.AnyKeyPressed
        )
        self.table.setVerticalScrollMode(QAbstractItemView.ScrollMode.ScrollPerPixel)
        self.table.itemChanged.connect(self._cell_edited)
        self.table.currentCellChanged.connect(lambda *_: self._update_buttons())
        col.addWidget(self.table)
        row = QHBoxLayout()
        self.add_button = self._button("&Add layer", "A new layer under the selected row", row)
        self.remove_button = self._button("Remove", "Remove the selected layer", row)
        self.up_button = self._button(
            "↑", "Move the selected row up (a layer moved past the sheet changes sides)", row
        )
        self.down_button = self._button("↓", "Move the selected row down", row)
        self.add_button.clicked.connect(self.add_layer)
        self.remove_button.clicked.connect(self.remove_layer)
        self.up_button.clicked.connect(lambda: self.move(-1))
        self.down_button.clicked.connect(lambda: self.move(1))
        col.addLayout(row)
        self.ground = QCheckBox("&Ground plane under the last layer", self)
        self.ground.setToolTip(
            "A perfectly conducting plane under the bottom layer: T = 0, R is the whole story"
        )
        self.ground.toggled.connect(lambda _on: self._apply())
        col.addWidget(self.ground)
        self.message = QLabel(self)
        self.message.setWordWrap(True)
        self.message.setStyleSheet("color: #d0021b;")
        self.message.hide()
        col.addWidget(self.message)
        self.sketch = StackSketch(self)
        col.addWidget(self.sketch)
        self._fill()

    def _button(self, text: str, tip: str, row: QHBoxLayout) -> QToolButton:
        button = QToolButton(self)  # narrower than push buttons: the dock is 300 px wide
        button.setText(text)
        button.setToolTip(tip)
        button.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Fixed)
        row.addWidget(button)
        return button

    # -- what the rows say -------------------------------------------------------------

    @property
    def sheet_row(self) -> int:
        return self.rows.index(SHEET)

    def layer_rows(self) -> list[LayerRow]:
        return [r for r in self.rows if r is not SHEET]

    def set_stack(self, stack: Any) -> None:
        """Show ``stack`` (None: no layers, no ground) and make it the good stack.

        The stack is taken as it is, not read back from the rows it fills: it is good
        already, and reading it would import :mod:`barymesh.mom` on the GUI thread (most
        of a second), which the window's start-up must not wait for when the Reflection
        phase tab copies the Infinite array tab's stack.
        """
        above = [layer_row(x) for x in stack.above] if stack is not None else []
        below = [layer_row(x) for x in stack.below] if stack is not None else []
        self.rows = [*above, SHEET, *below]
        self._fill()
        self.ground.blockSignals(True)
        self.ground.setChecked(bool(stack is not None and stack.ground))
        self.ground.blockSignals(False)
        self._mark_bad_cells(self.sheet_row)
        self.error = ""
        self.message.clear()
        self.message.hide()
        kept = None if stack is None or stack.is_free_standing else stack
        if kept != self.stack:
            self.stack = kept
            self.sketch.set_stack(kept)
            self.changed.emit(kept)
        self.edited.emit()

    # -- the table ---------------------------------------------------------------------

    def _fill(self) -> None:
        """Copy :attr:`rows` into the table (no edit signals)."""
        self._filling = True
        try:
            table = self.table
            table.clearSpans()
            table.setRowCount(len(self.rows))
            sheet = self.sheet_row
            names, n = [], 0
            for i, row in enumerate(self.rows):
                if row is SHEET:
                    names.append("")
                    self._sheet_cells(i)
                    continue
                n += 1
                names.append(str(n))
                side = QTableWidgetItem("above" if i < sheet else "below")
                side.setFlags(Qt.ItemFlag.ItemIsEnabled | Qt.ItemFlag.ItemIsSelectable)
                side.setForeground(QColor("#666666"))
                table.setItem(i, 0, side)
                for j, column in enumerate(COLUMNS, start=1):
                    item = QTableWidgetItem(getattr(row, column))
                    item.setTextAlignment(Qt.AlignmentFlag.AlignCenter)
                    table.setItem(i, j, item)
            table.setVerticalHeaderLabels(names)
            visible = min(max(len(self.rows), 2), 6)
            height = (
                table.horizontalHeader().height()
                + visible * table.verticalHeader().defaultSectionSize()
                + 2 * table.frameWidth()
                + 2
            )
            table.setFixedHeight(height)
        finally:
            self._filling = False
        self._update_buttons()

    def _sheet_cells(self, i: int) -> None:
        table = self.table
        marker = QTableWidgetItem("sheet")
        font = marker.font()
        font.setBold(True)
        marker.setFont(font)
        text = QTableWidgetItem("━━ the sheet ━━")
        text.setTextAlignment(Qt.AlignmentFlag.AlignCenter)
        text.setToolTip("Layers above this row are above the sheet, those below it below")
        for j, item in ((0, marker), (1, text)):
            item.setFlags(Qt.ItemFlag.ItemIsEnabled | Qt.ItemFlag.ItemIsSelectable)
            item.setBackground(SHEET_CELL)
            table.setItem(i, j, item)
        for j in range(2, len(HEADERS)):
            blank = QTableWidgetItem("")
            table.setItem(i, j, blank)
            blank.setFlags(Qt.ItemFlag.ItemIsEnabled)
        table.setSpan(i, 1, 1, len(HEADERS) - 1)

    def cell_rect(self, row: int, column: str) -> Any:
        """The viewport rectangle of a layer's cell (``row`` in the table, ``column`` one
        of :data:`barymesh.app.model.stack_rows.COLUMNS`): where a user double-clicks."""
        j = COLUMNS.index(column) + 1
        return self.table.visualRect(self.table.model().index(row, j))

    def _cell_edited(self, item: QTableWidgetItem) -> None:
        if self._filling:
            return
        i, j = item.row(), item.column()
        row = self.rows[i]
        if row is SHEET or j == 0:
            return
        values = {c: getattr(row, c) for c in COLUMNS}
        values[COLUMNS[j - 1]] = item.text()
        self.rows[i] = LayerRow(**values)
        self._apply()

    def _update_buttons(self) -> None:
        i = self.table.currentRow()
        chosen = 0 <= i < len(self.rows)
        self.remove_button.setEnabled(chosen and self.rows[i] is not SHEET)
        self.up_button.setEnabled(chosen and i > 0)
        self.down_button.setEnabled(chosen and i < len(self.rows) - 1)

    def add_layer(self) -> None:
        """A new layer (:data:`NEW_LAYER`) under the selected row (at the bottom if none)."""
        i = self.table.currentRow()
        at = i + 1 if 0 <= i < len(self.rows) else len(self.rows)
        self.rows.insert(at, LayerRow(*NEW_LAYER))
        self._fill()
        self.table.setCurrentCell(at, 1)
        self._apply()

    def remove_layer(self) -> None:
        i = self.table.currentRow()
        if not 0 <= i < len(self.rows) or self.rows[i] is SHEET:
            return
        del self.rows[i]
        self._fill()
        self.table.setCurrentCell(min(i, len(self.rows) - 1), 1)
        self._apply()

    def move(self, step: int) -> None:  # type: ignore[override]  # over QWidget.move(), its own
        """Move the selected row ``step`` (±1) rows; a layer moved past the sheet row
        changes sides."""
        i = self.table.currentRow()
        j = i + step
        if not (0 <= i < len(self.rows) and 0 <= j < len(self.rows)):
            return
        self.rows[i], self.rows[j] = self.rows[j], self.rows[i]
        column = max(self.table.currentColumn(), 1)
        self._fill()
        self.table.setCurrentCell(j, column)
        self._apply()

    # -- reading it --------------------------------------------------------------------

    def _apply(self) -> None:
        """Read the rows: a good stack replaces the last (``changed``); a bad value is
        said under the table and its cell marked, the last good stack kept."""
        sheet = self.sheet_row
        layers = self.layer_rows()
        self._mark_bad_cells(sheet)
        try:
            stack = read_stack(layers, sheet, self.ground.isChecked())
        except ValueError as exc:
            self.error = str(exc)
            self.message.setText(self.error)
            self.message.show()
            self.edited.emit()
            return
        self.error = ""
        self.message.clear()
        self.message.hide()
        kept = None if stack.is_free_standing else stack
        if kept != self.stack:
            self.stack = kept
            self.sketch.set_stack(kept)
            self.changed.emit(kept)
        self.edited.emit()

    def _mark_bad_cells(self, sheet: int) -> None:
        self._filling = True
        try:
            n = 0
            for i, row in enumerate(self.rows):
                if row is SHEET:
                    continue
                where = layer_name(n, i < sheet)
                n += 1
                for j, column in enumerate(COLUMNS, start=1):
                    try:
                        read_column(column, getattr(row, column), where)
                        bad = False
                    except ValueError:
                        bad = True
                    item = self.table.item(i, j)
                    if item is not None:
                        item.setBackground(BAD_CELL if bad else QBrush())
        finally:
            self._filling = False

"""The Elements panel: the cell's elements in a list, and the buttons that edit it.

Every widget translates one user action into one :meth:`barymesh.app.model.AppModel.edit_cell`
(an undo step) or :meth:`~barymesh.app.model.AppModel.select_element` call, and the list is
copied back from the model's ``cell_changed`` event. A refusal of the core (a name
already taken, every element hidden, overlapping elements in conforming mode) is shown
under the list; the cell and its mesh stay as they were.
"""

from __future__ import annotations

import math
from typing import Any, cast

from PySide6.QtCore import QEvent, QObject, Qt, QTimer
from PySide6.QtGui import QAction, QKeyEvent, QKeySequence
from PySide6.QtWidgets import (
    QAbstractItemView,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QMenu,
    QToolButton,
    QTreeWidget,
    QTreeWidgetItem,
    QVBoxLayout,
    QWidget,
)

from barymesh import MeshParams
from barymesh.app.model import STRUCTURE_TITLES, AppModel, format_value, read_number, read_points
from barymesh.app.model.cell_document import CellState
from barymesh.app.panels.controls import ERROR_COLOUR, ERROR_STYLE, ValueField, decimal_point

#: The grid (mm) a dragged element's position snaps to, until the user types another.
DEFAULT_SNAP = 0.5


def structure_presets() -> dict[str, str]:
    """Structure presets (name -> description) the Add menu offers; none if unreadable."""
    try:
        from barymesh.presets import preset_descriptions

        return preset_descriptions()
    except Exception:  # noqa: BLE001 - a broken preset file must not stop the panel
        return {}


class ElementsPanel(QWidget):
    """List (name, structure; the check box shows the element), Add ▾, Duplicate, Delete,
    Up, Down, and the selected element's position and rotation."""

    def __init__(self, model: AppModel, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.model = model
        col = QVBoxLayout(self)
        col.setContentsMargins(6, 6, 6, 6)
        self.hint = QLabel(
            "No unit cell is open. File ▸ Open cell…, Cell ▸ Cell presets, or "
            "Cell ▸ New cell from this structure.",
            self,
        )
        self.hint.setWordWrap(True)
        col.addWidget(self.hint)

        self.list = QTreeWidget(self)
        self.list.setObjectName("element_list")
        self.list.setColumnCount(2)
        self.list.setHeaderLabels(["Element", "Structure"])
        self.list.setRootIsDecorated(False)
        self.list.setSelectionMode(QAbstractItemView.SelectionMode.SingleSelection)
        self.list.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.list.setToolTip(
            "Check box: the element is meshed (unchecked: hidden). "
            "Double-click a name to rename the element."
        )
        self.list.currentItemChanged.connect(self._current_changed)
        self.list.itemChanged.connect(self._item_changed)
        self.list.itemDoubleClicked.connect(self._double_clicked)
        self.list.installEventFilter(self)
        row_height = self.list.fontMetrics().height() + 4
        self.list.setMinimumHeight(5 * row_height + 8)  # the header and 4 rows
        self.list.setMaximumHeight(7 * row_height + 8)
        col.addWidget(self.list)

        row = QHBoxLayout()
        self.add_button = QToolButton(self)
        self.add_button.setText("Add")
        self.add_button.setObjectName("add_element")
        self.add_button.setPopupMode(QToolButton.ToolButtonPopupMode.InstantPopup)
        self.add_menu = QMenu(self.add_button)
        for structure, title in STRUCTURE_TITLES.items():
            act = self.add_menu.addAction(title)
            act.triggered.connect(lambda _=False, s=structure: self.add_structure(s))
        presets = structure_presets()
        if presets:
            sub = self.add_menu.addMenu("From a preset")
            sub.setToolTipsVisible(True)
            for name, description in presets.items():
                act = sub.addAction(name)
                act.setToolTip(description)
                act.triggered.connect(lambda _=False, n=name: self.add_preset(n))
        self.add_button.setMenu(self.add_menu)
        row.addWidget(self.add_button)
        self.act_duplicate = self._button(
            row, "Duplicate", "Ctrl+D", self.duplicate, "Copy the selected element (Ctrl+D)"
        )
        self.act_delete = self._button(
            row,
            "Delete",
            QKeySequence.StandardKey.Delete,
            self.delete,
            "Remove the selected element (Del)",
        )
        self.act_up = self._button(
            row, "Up", "Alt+Up", lambda: self.move(-1), "Move the element up the list (Alt+↑)"
        )
        self.act_down = self._button(
            row, "Down", "Alt+Down", lambda: self.move(1), "Move the element down the list (Alt+↓)"
        )
        row.addStretch(1)
        col.addLayout(row)

        form = QFormLayout()
        self.position = ValueField(self)
        self.position.setObjectName("element_position")
        self.position.setToolTip("Where the element's own origin goes in the cell: x, y (mm)")
        self.position.submitted.connect(self._position_typed)
        self.position.reverted.connect(self._show_selected)
        self.rotation = ValueField(self)
        self.rotation.setObjectName("element_rotation")
        self.rotation.setToolTip("Counter-clockwise turn about the element's own origin (°)")
        self.rotation.submitted.connect(self._rotation_typed)
        self.rotation.reverted.connect(self._show_selected)
        self.snap = ValueField(self)
        self.snap.setObjectName("snap_grid")
        self.snap.setToolTip(
            "Cell ▸ Drag elements puts positions on multiples of this (mm); empty or 0: no snapping"
        )
        self.snap.submitted.connect(self._snap_typed)
        self.snap.reverted.connect(lambda: self.snap.show_text(format_value(self.snap_grid)))
        self.snap_grid: float | None = DEFAULT_SNAP
        self.snap.show_text(format_value(self.snap_grid))
        form.addRow("&Position x, y (mm)", self.position)
        form.addRow("&Rotation (°)", self.rotation)
        form.addRow("Drag &snap grid (mm)", self.snap)
        col.addLayout(form)

        self.error = QLabel(self)
        self.error.setObjectName("cell_error")
        self.error.setWordWrap(True)
        self.error.setStyleSheet(f"color: {ERROR_COLOUR};")
        self.error.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.error.hide()
        col.addWidget(self.error)

        self._rows: tuple[Any, ...] | None = ()
        model.cell_changed.connect(self.show_cell)
        model.cell_error_changed.connect(self.show_error)
        self.show_cell(model.cell_state)

    def _button(self, row: QHBoxLayout, text: str, key: Any, slot: Any, tip: str) -> QAction:
        act = QAction(text, self)
        act.setShortcut(QKeySequence(key))
        act.setShortcutContext(Qt.ShortcutContext.WidgetWithChildrenShortcut)
        act.setToolTip(tip)
        act.triggered.connect(slot)
        self.addAction(act)
        button = QToolButton(self)
        button.setDefaultAction(act)
        button.setObjectName(f"element_{text.lower()}")
        row.addWidget(button)
        return act

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:  # noqa: N802 - Qt's name
        """Keys typed into the list: Del deletes, Alt+↑/↓ move the selected element."""
        if watched is self.list and event.type() == QEvent.Type.KeyPress:
            event = cast(QKeyEvent, event)
            alt = event.modifiers() == Qt.KeyboardModifier.AltModifier
            if event.key() == Qt.Key.Key_Delete and not event.modifiers():
                self.delete()
                return True
            if alt and event.key() in (Qt.Key.Key_Up, Qt.Key.Key_Down):
                self.move(-1 if event.key() == Qt.Key.Key_Up else 1)
                return True
        return super().eventFilter(watched, event)

    # -- user -> model -------------------------------------------------------------------

    @property
    def state(self) -> CellState | None:
        return self.model.cell_state

    def _selected(self) -> int | None:
        return None if self.state is None else self.state.selected

    def add_structure(self, structure: str) -> bool:
        """Add ``structure`` with its default parameters at the cell's centre."""
        return self.model.edit_cell(lambda s: s.added(MeshParams(structure=structure)))

    def add_preset(self, name: str) -> bool:
        """Add the structure of preset ``name`` at the cell's centre."""
        from barymesh.presets import load_preset

        def edit(s: CellState) -> CellState:
            params, _description = load_preset(name)
            return s.added(params, name=params.structure)

        return self.model.edit_cell(edit)

    def duplicate(self) -> bool:
        k = self._selected()
        return k is not None and self.model.edit_cell(lambda s: s.duplicated(k))

    def delete(self) -> bool:
        k = self._selected()
        return k is not None and self.model.edit_cell(lambda s: s.deleted(k))

    def move(self, step: int) -> bool:  # type: ignore[override]  # over QWidget.move(), its own
        k = self._selected()
        return k is not None and self.model.edit_cell(lambda s: s.moved(k, step))

    def _current_changed(self, item: QTreeWidgetItem | None, _previous: Any) -> None:
        if item is not None:
            self.model.select_element(self.list.indexOfTopLevelItem(item))

    def _double_clicked(self, item: QTreeWidgetItem, _column: int) -> None:
        self.list.editItem(item, 0)  # the name only; the structure is the Parameters'

    def _item_changed(self, item: QTreeWidgetItem, column: int) -> None:
        # the model's cell_changed comes back before Qt is done with ``item``: refilling
        # the list then would delete the item under the view's hands (a crash)
        self._changing_item = True
        try:
            self._apply_item(item, column)
        finally:
            self._changing_item = False

    def _apply_item(self, item: QTreeWidgetItem, column: int) -> None:
        state = self.state
        k = self.list.indexOfTopLevelItem(item)
        if state is None or column != 0 or not 0 <= k < len(state.elements):
            return
        hide = item.checkState(0) != Qt.CheckState.Checked
        if hide != state.hidden[k]:
            if not self.model.edit_cell(lambda s: s.with_hidden(k, hide)):
                self._refill_later()
            return
        name = item.text(0)
        if name != state.elements[k].name:
            if not self.model.edit_cell(lambda s: s.renamed(k, name)):
                self._refill_later()

    def _refill_later(self) -> None:
        """A refused check or name: the items show the cell again, once the view is done
        with the item it is changing (never from inside its signal)."""
        self._rows = ("stale",)
        QTimer.singleShot(0, lambda: self.show_cell(self.model.cell_state))

    def _position_typed(self, text: str) -> None:
        k = self._selected()
        if k is None:
            return
        value = read_points(text, 1, decimal_point()).value
        if not self.model.edit_cell(lambda s: s.placed(k, position=value)):
            self._keep_typed(self.position, text)

    def _rotation_typed(self, text: str) -> None:
        k = self._selected()
        if k is None:
            return
        value = read_number(text, None, decimal_point()).value
        if not self.model.edit_cell(lambda s: s.placed(k, rotation=value)):
            self._keep_typed(self.rotation, text)

    def _snap_typed(self, text: str) -> None:
        value = read_number(text, None, decimal_point()).value
        if text.strip() in ("", "0") or value == 0:
            self.snap_grid = None
            self.snap.show_text("")
            self.snap.setProperty("refused", False)
            self.snap.setStyleSheet("")
            self.show_error(None)
        elif isinstance(value, float) and math.isfinite(value) and value > 0:
            self.snap_grid = value
            self.snap.show_text(format_value(value))
            self.snap.setProperty("refused", False)
            self.snap.setStyleSheet("")
            self.show_error(None)
        else:
            self.show_error(
                f"snap grid={text.strip()!r} is invalid; expected a length > 0 mm, "
                "or empty for no snapping"
            )
            self._keep_typed(self.snap, text)

    def _keep_typed(self, field: ValueField, text: str) -> None:
        """A refused value stays as typed, framed red, until corrected or Esc."""
        field.show_text(text)
        field.setProperty("refused", True)
        field.setStyleSheet(f"QLineEdit {{{ERROR_STYLE}}}")

    # -- model -> widgets ----------------------------------------------------------------

    def show_cell(self, state: CellState | None) -> None:
        if getattr(self, "_changing_item", False):  # from inside itemChanged: after it
            QTimer.singleShot(0, lambda: self.show_cell(self.model.cell_state))
            return
        self.hint.setVisible(state is None)
        self.list.blockSignals(True)
        rows = (
            None
            if state is None
            else tuple(
                (el.name, el.params.structure, h)
                for el, h in zip(state.elements, state.hidden, strict=True)
            )
        )
        if rows != self._rows:  # a new selection alone keeps the items (and a double click)
            self._rows = rows
            self._fill(state)
        if state is not None and state.selected is not None:
            item = self.list.topLevelItem(state.selected)
            assert item is not None  # _fill made a row per element
            self.list.setCurrentItem(item)
        self.list.blockSignals(False)
        has = state is not None
        index = state.selected if state is not None else None
        count = len(state.elements) if state is not None else 0
        selected = index is not None
        for w in (self.list, self.add_button):
            w.setEnabled(has)
        for act in (self.act_duplicate, self.act_delete):
            act.setEnabled(selected)
        self.act_up.setEnabled(index is not None and index > 0)
        self.act_down.setEnabled(index is not None and index < count - 1)
        self.position.setEnabled(selected)
        self.rotation.setEnabled(selected)
        self._show_selected()

    def _fill(self, state: CellState | None) -> None:
        self.list.clear()
        if state is None:
            return
        for el, hidden in zip(state.elements, state.hidden, strict=True):
            item = QTreeWidgetItem(
                [el.name, STRUCTURE_TITLES.get(el.params.structure, el.params.structure)]
            )
            item.setFlags(
                item.flags() | Qt.ItemFlag.ItemIsEditable | Qt.ItemFlag.ItemIsUserCheckable
            )
            item.setCheckState(0, Qt.CheckState.Unchecked if hidden else Qt.CheckState.Checked)
            if hidden:
                for c in (0, 1):
                    item.setForeground(c, Qt.GlobalColor.gray)
                item.setToolTip(0, "Hidden: not meshed")
            self.list.addTopLevelItem(item)
        self.list.resizeColumnToContents(0)

    def _show_selected(self) -> None:
        state = self.state
        el = None
        if state is not None and state.selected is not None:
            el = state.elements[state.selected]
        for field in (self.position, self.rotation):
            field.setProperty("refused", False)
            field.setStyleSheet("")
        self.position.show_text("" if el is None else format_value(el.position))
        self.rotation.show_text("" if el is None else format_value(el.rotation))

    def show_error(self, message: str | None) -> None:
        self.error.setText(message or "")
        self.error.setVisible(bool(message))

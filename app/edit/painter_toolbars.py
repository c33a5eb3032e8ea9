"""The pixel painter's two toolbars, Paint and Grid: its actions, their keys, and its fields.

:class:`PainterToolbars` makes them on the painter's window (Qt widgets only, no VTK). The
actions call the painter's public edits (:class:`PainterSlots`); the window connects the
symmetry box and the grid fields to its own handlers, which read them back.
"""

from __future__ import annotations

from typing import Any, Protocol

from PySide6.QtGui import QAction, QActionGroup
from PySide6.QtWidgets import (
    QComboBox,
    QDoubleSpinBox,
    QLabel,
    QMainWindow,
    QSpinBox,
    QToolBar,
)

from barymesh.app.actions import make_action
from barymesh.app.model import pixels
from barymesh.cell import SYMMETRIES

#: Symmetry keys: 0 none, X mirror x, Y mirror y, 4 four-fold, 8 eight-fold.
SYMMETRY_KEYS = {"none": "0", "mirror_x": "X", "mirror_y": "Y", "4-fold": "4", "8-fold": "8"}


class PainterSlots(Protocol):
    """What the toolbars' actions call: the painter's edits, files and view."""

    def invert(self) -> bool: ...
    def clear(self) -> bool: ...
    def random_fill(self) -> bool: ...
    def undo(self) -> None: ...
    def redo(self) -> None: ...
    def open_dialog(self) -> None: ...
    def save_dialog(self) -> None: ...
    def reset_view(self) -> None: ...


class PainterToolbars:
    """The Paint and Grid toolbars, added to ``parent`` (the painter's window), with the
    actions (each with its key, in the window) and the fields they hold.

    Parameters
    ----------
    parent : QMainWindow
        The painter's window: the parent of every action, field and toolbar.
    slots : PainterSlots
        What the actions call (the painter itself).
    """

    def __init__(self, parent: QMainWindow, slots: PainterSlots) -> None:
        def a(
            text: str, slot: Any, shortcut: Any = None, tip: str = "", checkable: bool = False
        ) -> QAction:
            return make_action(parent, text, slot, shortcut, tip, checkable, keys_in_tip=True)

        tools = QActionGroup(parent)
        self.act_pen = a(
            "Pen",
            lambda: None,
            "P",
            "Left button paints, right button erases; a drag is one stroke",
            checkable=True,
        )
        self.act_fill = a(
            "Fill",
            lambda: None,
            "F",
            "Click fills the connected region (4-neighbours) with metal, right click with none",
            checkable=True,
        )
        for act in (self.act_pen, self.act_fill):
            tools.addAction(act)
        self.act_pen.setChecked(True)
        self.act_erase = a("Erase", lambda: None, "E", "The left button erases too", checkable=True)
        self.act_invert = a(
            "Invert", slots.invert, "I", "Babinet complement: metal where there was none"
        )
        self.act_clear = a("Clear", slots.clear, "Ctrl+Backspace", "No metal anywhere")
        self.act_random = a(
            "Random", slots.random_fill, "G", "Random pixels under the symmetry, from the seed"
        )
        self.act_undo = a("Undo", slots.undo, "Ctrl+Z", "Undo the last stroke or edit")
        self.act_redo = a("Redo", slots.redo, ["Ctrl+Shift+Z", "Ctrl+Y"], "Redo")
        self.act_open = a("Open cell…", slots.open_dialog, "Ctrl+O", "Edit a *.cell.json file")
        self.act_save = a(
            "Save cell…", slots.save_dialog, "Ctrl+S", "Write the cell as a *.cell.json file"
        )
        self.act_view = a("Reset view", slots.reset_view, "R", "Frame the cell from above")

        self.symmetry_box = QComboBox(parent)
        for mode in SYMMETRIES:
            self.symmetry_box.addItem(pixels.SYMMETRY_TITLES[mode], mode)
        self.symmetry_box.setToolTip(
            "Symmetry of every edit about the grid's centre (keys 0, X, Y, 4, 8)"
        )
        for mode, key in SYMMETRY_KEYS.items():
            a(
                f"Symmetry {pixels.SYMMETRY_TITLES[mode]}",
                lambda _=False, m=mode: self.symmetry_box.setCurrentIndex(
                    self.symmetry_box.findData(m)
                ),
                key,
                "Symmetry mode",
            )

        self.seed_box = QSpinBox(parent)
        self.seed_box.setRange(0, 2**31 - 1)
        self.seed_box.setMaximumWidth(110)
        self.seed_box.setToolTip("Seed of the random fill (the same seed, the same pixels)")
        self.density_box = QSpinBox(parent)
        self.density_box.setRange(0, 100)
        self.density_box.setValue(50)
        self.density_box.setSuffix(" %")
        self.density_box.setToolTip("Share of metal in the random fill")
        self.rows_box: QSpinBox = QSpinBox(parent)
        self.cols_box: QSpinBox = QSpinBox(parent)
        for box, what in ((self.rows_box, "Rows"), (self.cols_box, "Columns")):
            box.setRange(1, pixels.MAX_SIDE)
            box.setKeyboardTracking(False)
            box.setToolTip(f"{what} of the grid (resized about its centre)")
        self.size_box: QDoubleSpinBox = QDoubleSpinBox(parent)
        self.size_box.setDecimals(4)
        self.size_box.setRange(1e-4, 1e4)
        self.size_box.setSuffix(" mm")
        self.size_box.setKeyboardTracking(False)
        self.size_box.setToolTip("Side of a pixel; the grid keeps its centre")

        edit = QToolBar("Paint", parent)
        edit.setObjectName("paint_toolbar")
        edit.addActions([self.act_pen, self.act_fill, self.act_erase])
        edit.addSeparator()
        edit.addWidget(QLabel(" Symmetry ", parent))
        edit.addWidget(self.symmetry_box)
        edit.addSeparator()
        edit.addActions([self.act_invert, self.act_clear, self.act_random])
        edit.addWidget(QLabel(" seed ", parent))
        edit.addWidget(self.seed_box)
        edit.addWidget(QLabel(" metal ", parent))
        edit.addWidget(self.density_box)
        parent.addToolBar(edit)
        parent.addToolBarBreak()
        grid = QToolBar("Grid", parent)
        grid.setObjectName("grid_toolbar")
        grid.addActions([self.act_undo, self.act_redo])
        grid.addSeparator()
        grid.addWidget(QLabel(" Rows ", parent))
        grid.addWidget(self.rows_box)
        grid.addWidget(QLabel(" Columns ", parent))
        grid.addWidget(self.cols_box)
        grid.addWidget(QLabel(" Pixel ", parent))
        grid.addWidget(self.size_box)
        grid.addSeparator()
        grid.addActions([self.act_view, self.act_open, self.act_save])
        parent.addToolBar(grid)

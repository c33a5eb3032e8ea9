"""The parameters panel: choice boxes, a slider with a typed field per number, Advanced.

Widgets only translate: a slider move becomes one ``AppModel.set_value`` call, a typed
field one ``AppModel.set_text`` call (on Enter or when focus leaves it), Esc in a field one
``AppModel.revert``; the model's ``draft_changed`` / ``error_changed`` / ``result_changed``
events are copied back into the widgets with their signals blocked.

A field takes what is typed exactly: the core accepts it, or refuses it and the field
keeps the text, framed red, with the core's message under it, until it is corrected or
Esc puts the accepted value back. Nothing is clamped, rounded or read through a locale
without saying so.

A length's or an angle step's slider spans a decade each side of the value
(:meth:`barymesh.app.model.ParamSpec.around`), not 0.01 mm to 10 m: a drag of a few pixels is a
small change. It is centred again when the drag ends, when a key steps it to an end, when
a typed value (or Undo) lies outside it, and whenever a whole new set of parameters comes
(a preset, a parameter file, Reset).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, cast

from PySide6.QtCore import QEvent, QLocale, Qt, Signal
from PySide6.QtGui import QKeyEvent
from PySide6.QtWidgets import (
    QComboBox,
    QFormLayout,
    QGridLayout,
    QGroupBox,
    QLabel,
    QLineEdit,
    QPushButton,
    QSlider,
    QVBoxLayout,
    QWidget,
)

from barymesh.app.model import (
    ADVANCED_SPECS,
    CHOICES,
    PARAM_SPECS,
    POINT_PARAMS,
    AppModel,
    MeshResult,
    ParamError,
    ParamSpec,
    applies,
    format_value,
    read_number,
    subdivisions_limit,
)

ERROR_COLOUR = "#d0021b"
ERROR_STYLE = f"border: 2px solid {ERROR_COLOUR}; border-radius: 3px;"


def decimal_point() -> str:
    """The system locale's decimal separator (a dot is always accepted as well)."""
    return QLocale().decimalPoint()


def _is_undo_key(event: QKeyEvent) -> bool:
    """Ctrl+Z, Ctrl+Shift+Z or Ctrl+Y (the window's Undo and Redo)."""
    mods = event.modifiers() & ~Qt.KeyboardModifier.KeypadModifier
    ctrl = Qt.KeyboardModifier.ControlModifier
    shift = Qt.KeyboardModifier.ShiftModifier
    if event.key() == Qt.Key.Key_Z:
        return mods in (ctrl, ctrl | shift)
    return event.key() == Qt.Key.Key_Y and mods == ctrl


class ValueField(QLineEdit):
    """A line edit for one typed value.

    ``submitted(text)`` on Enter or when focus leaves after an edit, ``reverted()`` on Esc,
    ``stepped(steps)`` on ↑/↓ (±1) and PgUp/PgDn (±10), which move the paired slider.
    """

    submitted = Signal(str)
    reverted = Signal()
    stepped = Signal(int)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self._shown = ""
        self.editingFinished.connect(self._finished)

    def show_text(self, text: str) -> None:
        """Display ``text`` without submitting it."""
        self._shown = text
        if self.text() != text:
            self.setText(text)
            self.setCursorPosition(0)

    def _finished(self) -> None:
        if self.text() != self._shown or self.property("refused"):
            self._shown = self.text()
            self.submitted.emit(self.text())

    def event(self, event: QEvent) -> bool:
        # Esc belongs to the field while it holds an edit or a refused value, not to a
        # window shortcut (such as cancelling a build).
        if (
            event.type() == QEvent.Type.ShortcutOverride
            and cast(QKeyEvent, event).key() == Qt.Key.Key_Escape
            and (self.property("refused") or self.text() != self._shown)
        ):
            event.accept()
            return True
        # Ctrl+Z / redo in a field showing the accepted value is the window's Undo of the
        # parameter change (the line edit's own text undo put back a text that was not
        # the value, and submitted nothing); with an edit under way it undoes typing
        if (
            event.type() == QEvent.Type.ShortcutOverride
            and _is_undo_key(cast(QKeyEvent, event))
            and self.text() == self._shown
            and not self.property("refused")
        ):
            event.ignore()
            return True
        return super().event(event)

    def keyPressEvent(self, event: QKeyEvent) -> None:  # noqa: N802 - Qt's name
        steps: dict[int, int] = {  # by key code (event.key() is an int)
            Qt.Key.Key_Up: 1,
            Qt.Key.Key_Down: -1,
            Qt.Key.Key_PageUp: 10,
            Qt.Key.Key_PageDown: -10,
        }
        if event.key() == Qt.Key.Key_Escape:
            self.reverted.emit()
            event.accept()
        elif event.key() in steps:
            self.stepped.emit(steps[event.key()])
            event.accept()
        else:
            super().keyPressEvent(event)

    # The old spin boxes' API, for scripts: ``setValue`` submits as if typed.

    def setValue(self, value: Any) -> None:  # noqa: N802 - QSpinBox's name
        self.setText(format_value(value))
        self._finished()

    def value(self) -> Any:
        return read_number(self.text(), None, decimal_point()).value


def _message_label(parent: QWidget, name: str, colour: str) -> QLabel:
    label = QLabel(parent)
    label.setObjectName(name)
    label.setWordWrap(True)
    label.setStyleSheet(f"color: {colour};")
    label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
    label.hide()
    return label


class FieldRow:
    """Label, optional slider, typed field and unit, with an error line and a note line."""

    def __init__(
        self,
        name: str,
        label: str,
        grid: QGridLayout,
        row: int,
        parent: QWidget,
        spec: ParamSpec | None = None,
        tooltip: str = "",
        placeholder: str = "",
    ) -> None:
        self.name = name
        self.spec = spec
        self.typed: str | None = None  # the text last typed, kept while it is refused
        self.label = QLabel(label, parent)
        self.slider: QSlider | None = None
        #: the slider's own spec: ``spec`` around the value for a windowed one
        self.slider_spec: ParamSpec | None = spec
        if spec is not None and spec.slider:
            self.slider = QSlider(Qt.Orientation.Horizontal, parent)
            self.slider.setObjectName(f"slider_{name}")
            self.slider.setRange(0, spec.slider_max)
            self.slider.setSingleStep(1)
            self.slider.setPageStep(max(1, spec.slider_max // 20))
            self.slider.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        self.field = ValueField(parent)
        self.field.setObjectName(f"field_{name}")
        self.field.setMinimumWidth(96)
        self.field.setAlignment(Qt.AlignmentFlag.AlignRight)
        self.field.setPlaceholderText(placeholder)
        unit = spec.unit if spec is not None else "mm"
        self.unit = QLabel(unit, parent)
        self.error = _message_label(parent, f"error_{name}", ERROR_COLOUR)
        self.note = _message_label(parent, f"note_{name}", "#555")
        tip = tooltip + (f" ({unit})" if unit else "")
        for w in (self.label, self.slider, self.field):
            if w is not None:
                w.setToolTip(tip)
        self.label.setBuddy(self.field)
        grid.addWidget(self.label, 3 * row, 0)
        if self.slider is not None:
            grid.addWidget(self.slider, 3 * row, 1)
            grid.addWidget(self.field, 3 * row, 2)
        else:
            grid.addWidget(self.field, 3 * row, 1, 1, 2)
        grid.addWidget(self.unit, 3 * row, 3)
        grid.addWidget(self.error, 3 * row + 1, 0, 1, 4)
        grid.addWidget(self.note, 3 * row + 2, 0, 1, 4)

    @property
    def spin(self) -> ValueField:
        """The field (the name the spin boxes had)."""
        return self.field

    def widgets(self) -> tuple[QWidget, ...]:
        return tuple(w for w in (self.label, self.slider, self.field, self.unit) if w is not None)

    def recentre(self, value: Any) -> None:
        """Centre a windowed slider on ``value`` (its range and the handle follow)."""
        if self.slider is None or self.spec is None or not self.spec.windowed:
            return
        spec = self.spec.around(value)
        if spec == self.slider_spec:
            return
        self.slider_spec = spec
        self.slider.blockSignals(True)
        self.slider.setRange(0, spec.slider_max)
        self.slider.setPageStep(max(1, spec.slider_max // 20))
        self.slider.setValue(spec.to_slider(value))
        self.slider.blockSignals(False)

    def show_value(self, value: Any, refused: bool, fallback: Any, centre: Any = None) -> None:
        """Show ``value``; a refused one keeps the text as typed. A windowed slider is
        centred again if the value lies outside it (on ``centre`` while it is None)."""
        if not refused:
            self.typed = None
        typed = refused and self.typed is not None
        shown = value
        if self.spec is not None and self.spec.scale != 1 and isinstance(value, (int, float)):
            shown = value / self.spec.scale  # Hz shown in GHz
        self.field.show_text(
            self.typed if typed and self.typed is not None else format_value(shown)
        )
        if self.slider is not None:  # a refused typed value leaves the slider where it was
            assert self.spec is not None and self.slider_spec is not None  # a slider's
            on_slider = fallback if typed else value
            if self.spec.windowed and not self.slider.isSliderDown():
                target = on_slider if on_slider is not None else centre
                if self.slider_spec is self.spec or (
                    target is not None and not self.slider_spec.holds(target)
                ):
                    self.recentre(target)
            self.slider.blockSignals(True)
            self.slider.setValue(self.slider_spec.to_slider(on_slider))
            self.slider.blockSignals(False)

    def set_enabled(self, on: bool) -> None:
        for w in self.widgets():
            w.setEnabled(on)

    def set_error(self, message: str | None) -> None:
        self.field.setProperty("refused", message is not None)
        self.field.setStyleSheet("" if message is None else f"QLineEdit {{{ERROR_STYLE}}}")
        self.error.setText(message or "")
        self.error.setVisible(message is not None)

    def set_note(self, note: str | None) -> None:
        self.note.setText(note or "")
        self.note.setVisible(bool(note))


class ControlsPanel(QWidget):
    """A file banner, the choices, every numeric parameter and the Advanced group."""

    def __init__(self, model: AppModel, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.model = model
        layout = QVBoxLayout(self)
        layout.setContentsMargins(6, 6, 6, 6)

        self.file_box = QGroupBox("Mesh file on screen", self)
        self.file_box.setObjectName("file_box")
        box = QVBoxLayout(self.file_box)
        self.file_label = QLabel(self.file_box)
        self.file_label.setObjectName("file_label")
        self.file_label.setWordWrap(True)
        self.back_button = QPushButton("&Back to the parametric mesh", self.file_box)
        self.back_button.setObjectName("back_to_parameters")
        self.back_button.setToolTip("Mesh the parameters below again (the file stays on disk)")
        self.back_button.clicked.connect(model.return_to_parameters)
        box.addWidget(self.file_label)
        box.addWidget(self.back_button)
        self.file_box.hide()
        layout.addWidget(self.file_box)

        self.choices_box = QGroupBox("Structure", self)
        form = QFormLayout(self.choices_box)
        self.combos: dict[str, QComboBox] = {}
        for name, (label, titles) in CHOICES.items():
            combo = QComboBox(self.choices_box)
            combo.setObjectName(f"combo_{name}")
            for value, title in titles.items():
                combo.addItem(title, value)
            combo.currentIndexChanged.connect(
                lambda _i, n=name, c=combo: self.model.set_value(n, c.currentData())
            )
            form.addRow(f"&{label}", combo)
            self.combos[name] = combo
        self.choice_error = _message_label(self.choices_box, "error_choice", ERROR_COLOUR)
        form.addRow(self.choice_error)
        layout.addWidget(self.choices_box)

        self.rows: dict[str, FieldRow] = {}
        self.numbers_box = self._group("Dimensions and discretisation", PARAM_SPECS, {})
        self.advanced_box = self._group("Advanced", ADVANCED_SPECS, POINT_PARAMS)
        layout.addWidget(self.numbers_box)
        layout.addWidget(self.advanced_box)
        layout.addStretch(1)

        model.draft_changed.connect(self.show_draft)
        model.params_replaced.connect(self.recentre_sliders)
        model.error_changed.connect(self.show_error)
        model.result_changed.connect(self.show_source)
        model.result_changed.connect(self._show_chosen)
        self.show_draft(model.draft)
        self.show_error(model.error)

    def _group(
        self,
        title: str,
        specs: tuple[ParamSpec, ...],
        points: dict[str, tuple[str, tuple[str, ...]]],
    ) -> QGroupBox:
        group = QGroupBox(title, self)
        grid = QGridLayout(group)
        grid.setColumnStretch(1, 1)
        grid.setVerticalSpacing(2)
        grid.setHorizontalSpacing(8)
        i = 0
        for spec in specs:
            row = FieldRow(
                spec.name,
                spec.label,
                grid,
                i,
                group,
                spec,
                spec.tooltip,
                spec.empty_text if spec.optional else "",
            )
            self._wire(row)
            i += 1
        tips = {
            "origin": "x, y: the lower-left corner A of a patch, the first vertex of a "
            "triangle; for rings the point their patches turn about. Paper "
            "mode puts each patch's lower-left corner at origin + r (cos θ, "
            "sin θ), as the paper does, so a paper ring's centre is at origin "
            "+ (s/2, s/2), s the patch size; conforming rings and square "
            "rings are centred on the origin",
            "triangle_vertices": "Three vertices x, y; x, y; x, y of the triangle "
            "structure; empty = equilateral of side patch size",
        }
        for name, (label, _structures) in points.items():
            row = FieldRow(
                name,
                label,
                grid,
                i,
                group,
                None,
                tips[name],
                "equilateral" if name == "triangle_vertices" else "",
            )
            self._wire(row)
            i += 1
        return group

    def _wire(self, row: FieldRow) -> None:
        row.field.submitted.connect(lambda text, r=row: self._typed(r, text))
        row.field.reverted.connect(lambda n=row.name: self.model.revert(n))
        if row.slider is not None:
            row.slider.valueChanged.connect(lambda pos, r=row: self._slider_moved(r, pos))
            row.slider.sliderReleased.connect(lambda r=row: self._slider_released(r))
            row.field.stepped.connect(
                lambda k, s=row.slider: s.setValue(s.value() + k)
            )  # ↑/↓ in the field
        self.rows[row.name] = row

    # -- user -> model -------------------------------------------------------------------

    def _slider_moved(self, row: FieldRow, pos: int) -> None:
        row.typed = None
        assert row.slider is not None and row.slider_spec is not None  # it moved
        down = row.slider.isSliderDown()
        self.model.set_value(row.name, row.slider_spec.from_slider(pos), merge=down)
        if not down and pos in (row.slider.minimum(), row.slider.maximum()):
            row.recentre(self.model.draft.get(row.name))  # a key at an end: room again

    def _slider_released(self, row: FieldRow) -> None:
        """The drag ended: the slider is centred on the value it reached."""
        self.model.end_merge()
        if row.name not in self.model.refused:
            row.recentre(self.model.draft.get(row.name))

    def _typed(self, row: FieldRow, text: str) -> None:
        row.typed = text
        self.model.set_text(row.name, text, decimal_point())

    # -- model -> widgets ----------------------------------------------------------------

    def recentre_sliders(self, _params: Any = None) -> None:
        """A whole new set of parameters (a preset, a parameter file, Reset, a study's
        design): every windowed slider is centred on its value, so that a drag has the
        same room both ways (a value inside the last window used to keep its off-centre
        handle: 82 of 96 after Fig. 12(d) then Fig. 12(a), and a drag hit the end)."""
        draft = self.model.draft
        for name, row in self.rows.items():
            if row.slider is None or row.slider.isSliderDown() or name in self.model.refused:
                continue
            value = draft.get(name)
            row.recentre(value if value is not None else draft.get("patch_size"))

    def show_draft(self, draft: dict[str, Any]) -> None:
        structure: str = draft.get("structure", "")  # "" as None: applies to nothing
        for name, combo in self.combos.items():
            index = combo.findData(draft.get(name))
            combo.blockSignals(True)
            if index >= 0:
                combo.setCurrentIndex(index)
            combo.blockSignals(False)
            combo.setEnabled(applies(name, structure))
        scheme = draft.get("scheme", "uniform")
        sub = self.rows["subdivisions"].slider
        assert sub is not None  # the subdivisions have a slider
        top = subdivisions_limit(scheme if scheme in ("uniform", "barycentric") else "uniform")
        if sub.maximum() != top - 1:
            sub.blockSignals(True)
            sub.setRange(0, top - 1)
            sub.blockSignals(False)
        committed = self.model.params.to_dict()
        sized = self.model.params.sized
        for name, row in self.rows.items():
            row.show_value(
                draft.get(name),
                name in self.model.refused,
                committed.get(name),
                centre=draft.get("patch_size"),
            )
            row.set_enabled(applies(name, structure) and not (sized and name == "subdivisions"))
            row.set_note(self.model.notes.get(name))
        self._show_chosen()

    def _show_chosen(self, _result: MeshResult | None = None) -> None:
        if self.model.params.sized:
            self.rows["subdivisions"].set_note(self._chosen_note())

    def _chosen_note(self) -> str:
        """Under the greyed subdivisions: the n the sizing chose for the mesh on screen."""
        result = self.model.result
        chosen = None if result is None else result.stats.get("subdivisions_chosen")
        if result is None or chosen is None or result.params != self.model.params:
            return "chosen by the mesher from the frequency or the largest edge"
        what = "levels" if self.model.params.scheme == "barycentric" else "n"
        return (
            f"chosen by the mesher: {what} = {chosen} (edges ≤ "
            f"{result.stats['target_edge']:.4g} mm)"
        )

    def show_error(self, _error: ParamError | None) -> None:
        errors = self.model.errors
        for name, row in self.rows.items():
            row.set_error(errors[name].message if name in errors else None)
        others = [e for name, e in errors.items() if name not in self.rows]
        self.choice_error.setText("\n".join(e.message for e in others))
        self.choice_error.setVisible(bool(others))
        for name, combo in self.combos.items():
            combo.setStyleSheet(f"QComboBox {{{ERROR_STYLE}}}" if name in errors else "")

    def show_source(self, result: MeshResult | None) -> None:
        """A mesh file on screen: say which, and keep the parameters out of reach."""
        path = self.model.file_source
        in_file = path is not None
        if path is not None:
            assert result is not None  # the file's mesh is on screen
            s = result.stats
            self.file_label.setText(
                f"<b>{Path(path).name}</b><br>{s['triangles']:,} triangles · "
                f"{s['vertices']:,} vertices · {s['interior_edges']:,} RWG unknowns<br>"
                "The parameters below are not this mesh's; they apply again when you go "
                "back to the parametric mesh."
            )
            self.file_label.setToolTip(path)
        self.file_box.setVisible(in_file)
        for group in (self.choices_box, self.numbers_box, self.advanced_box):
            group.setEnabled(not in_file)

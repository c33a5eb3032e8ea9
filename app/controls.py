"""The parameters panel: choice boxes and, per numeric parameter, a slider with a spin box.

Widgets only translate: a user action becomes one ``AppModel.set_value`` call, and the
model's ``draft_changed`` / ``error_changed`` / ``params_changed`` events are copied back
into the widgets with their signals blocked.
"""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import Qt
from PySide6.QtWidgets import (
    QAbstractSpinBox,
    QComboBox,
    QDoubleSpinBox,
    QFormLayout,
    QGridLayout,
    QGroupBox,
    QLabel,
    QSlider,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from .model import CHOICES, PARAM_SPECS, AppModel, ParamError, ParamSpec, applies
from .model import subdivisions_limit as _subdivisions_limit

ERROR_STYLE = "border: 2px solid #d0021b; border-radius: 3px;"


class ParamRow:
    """Label, slider, spin box (value + unit) and an error line for one parameter."""

    def __init__(self, spec: ParamSpec, grid: QGridLayout, row: int, parent: QWidget) -> None:
        self.spec = spec
        self.label = QLabel(spec.label, parent)
        self.slider = QSlider(Qt.Orientation.Horizontal, parent)
        self.slider.setObjectName(f"slider_{spec.name}")
        self.slider.setRange(0, spec.slider_max)
        self.slider.setSingleStep(1)
        self.slider.setPageStep(max(1, spec.slider_max // 20))
        self.slider.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        if spec.integer:
            self.spin: QSpinBox | QDoubleSpinBox = QSpinBox(parent)
            self.spin.setRange(int(spec.minimum), int(spec.maximum))
        else:
            self.spin = QDoubleSpinBox(parent)
            self.spin.setDecimals(spec.decimals)
            lo = 0.0 if spec.optional else spec.minimum
            self.spin.setRange(lo, spec.maximum)
            self.spin.setSingleStep(spec.step if spec.step > 0 else spec.minimum * 1e3)
            if spec.optional:
                self.spin.setSpecialValueText("auto")
                self.spin.setStepType(QAbstractSpinBox.StepType.AdaptiveDecimalStepType)
        self.spin.setObjectName(f"spin_{spec.name}")
        self.spin.setKeyboardTracking(False)  # typed values count on Enter / focus out
        self.spin.setAccelerated(True)
        if spec.unit:
            self.spin.setSuffix(f" {spec.unit}")
        self.spin.setMinimumWidth(110)
        self.spin.setAlignment(Qt.AlignmentFlag.AlignRight)
        self.error = QLabel(parent)
        self.error.setObjectName(f"error_{spec.name}")
        self.error.setWordWrap(True)
        self.error.setStyleSheet("color: #d0021b;")
        self.error.hide()
        tip = spec.tooltip + (f" ({spec.unit})" if spec.unit else "")
        for w in (self.label, self.slider, self.spin):
            w.setToolTip(tip)
        self.label.setBuddy(self.spin)
        grid.addWidget(self.label, 2 * row, 0)
        grid.addWidget(self.slider, 2 * row, 1)
        grid.addWidget(self.spin, 2 * row, 2)
        grid.addWidget(self.error, 2 * row + 1, 0, 1, 3)

    def show_value(self, value: Any) -> None:
        for w in (self.slider, self.spin):
            w.blockSignals(True)
        try:
            self.slider.setValue(self.spec.to_slider(value))
            self.spin.setValue(0 if value is None else value)
        finally:
            for w in (self.slider, self.spin):
                w.blockSignals(False)

    def set_enabled(self, on: bool) -> None:
        for w in (self.label, self.slider, self.spin):
            w.setEnabled(on)

    def set_error(self, message: str | None) -> None:
        self.spin.setStyleSheet("" if message is None else f"QAbstractSpinBox {{{ERROR_STYLE}}}")
        self.error.setText(message or "")
        self.error.setVisible(message is not None)


class ControlsPanel(QWidget):
    """Structure, mode, diagonal, scheme and every numeric parameter of :data:`PARAM_SPECS`."""

    def __init__(self, model: AppModel, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.model = model
        layout = QVBoxLayout(self)
        layout.setContentsMargins(6, 6, 6, 6)

        choices = QGroupBox("Structure", self)
        form = QFormLayout(choices)
        self.combos: dict[str, QComboBox] = {}
        for name, (label, titles) in CHOICES.items():
            combo = QComboBox(choices)
            combo.setObjectName(f"combo_{name}")
            for value, title in titles.items():
                combo.addItem(title, value)
            combo.currentIndexChanged.connect(
                lambda _i, n=name, c=combo: self.model.set_value(n, c.currentData())
            )
            form.addRow(f"&{label}", combo)
            self.combos[name] = combo
        self.choice_error = QLabel(choices)
        self.choice_error.setObjectName("error_choice")
        self.choice_error.setWordWrap(True)
        self.choice_error.setStyleSheet("color: #d0021b;")
        self.choice_error.hide()
        form.addRow(self.choice_error)
        layout.addWidget(choices)

        numbers = QGroupBox("Dimensions and discretisation", self)
        grid = QGridLayout(numbers)
        grid.setColumnStretch(1, 1)
        grid.setVerticalSpacing(2)
        self.rows: dict[str, ParamRow] = {}
        for i, spec in enumerate(PARAM_SPECS):
            row = ParamRow(spec, grid, i, numbers)
            row.slider.valueChanged.connect(lambda pos, r=row: self._slider_moved(r, pos))
            row.slider.sliderReleased.connect(self.model.end_merge)
            row.spin.valueChanged.connect(lambda v, r=row: self._spin_changed(r, v))
            self.rows[spec.name] = row
        layout.addWidget(numbers)
        layout.addStretch(1)

        model.draft_changed.connect(self.show_draft)
        model.error_changed.connect(self.show_error)
        self.show_draft(model.draft)

    # -- user -> model -------------------------------------------------------------------

    def _slider_moved(self, row: ParamRow, pos: int) -> None:
        value = row.spec.from_slider(pos)
        row.spin.blockSignals(True)
        row.spin.setValue(0 if value is None else value)
        row.spin.blockSignals(False)
        self.model.set_value(row.spec.name, value, merge=row.slider.isSliderDown())

    def _spin_changed(self, row: ParamRow, value: float) -> None:
        if row.spec.optional and value <= 0:
            value = None
        row.slider.blockSignals(True)
        row.slider.setValue(row.spec.to_slider(value))
        row.slider.blockSignals(False)
        self.model.set_value(row.spec.name, value)

    # -- model -> widgets ----------------------------------------------------------------

    def show_draft(self, draft: dict[str, Any]) -> None:
        structure = draft.get("structure")
        for name, combo in self.combos.items():
            index = combo.findData(draft.get(name))
            combo.blockSignals(True)
            if index >= 0:
                combo.setCurrentIndex(index)
            combo.blockSignals(False)
            combo.setEnabled(applies(name, structure))
        scheme = draft.get("scheme", "uniform")
        sub = self.rows["subdivisions"]
        top = _subdivisions_limit(scheme if scheme in ("uniform", "barycentric") else "uniform")
        if sub.spin.maximum() != top:
            for w in (sub.slider, sub.spin):
                w.blockSignals(True)
            sub.slider.setRange(0, top - 1)
            sub.spin.setRange(1, top)
            for w in (sub.slider, sub.spin):
                w.blockSignals(False)
        for name, row in self.rows.items():
            row.show_value(draft.get(name))
            row.set_enabled(applies(name, structure))

    def show_error(self, error: ParamError | None) -> None:
        for name, row in self.rows.items():
            row.set_error(error.message if error is not None and error.name == name else None)
        choice = error is not None and error.name not in self.rows
        self.choice_error.setText(error.message if choice else "")
        self.choice_error.setVisible(choice)
        for name, combo in self.combos.items():
            marked = choice and error.name == name
            combo.setStyleSheet(f"QComboBox {{{ERROR_STYLE}}}" if marked else "")

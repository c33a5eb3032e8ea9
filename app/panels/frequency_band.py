"""A frequency band typed as start, stop and a unit: the Sweep tab's range and the
Infinite array tab's band are this one widget."""

from __future__ import annotations

from PySide6.QtWidgets import QComboBox, QHBoxLayout, QLabel, QLineEdit, QWidget

from barymesh.app.model.solve_inputs import UNITS, format_frequency, read_band


class FrequencyBand(QWidget):
    """Two fields and a unit box in a row: "3 to 12 GHz".

    Parameters
    ----------
    start, stop : str
        The fields' first text, in ``unit``.
    name : str
        What a refusal calls the band ("Band", "Sweep range").
    parent : QWidget, optional
    unit : str
        One of :data:`~barymesh.app.model.solve_inputs.UNITS`.
    """

    def __init__(
        self,
        start: str,
        stop: str,
        name: str = "Band",
        parent: QWidget | None = None,
        unit: str = "GHz",
    ) -> None:
        super().__init__(parent)
        self.name = name
        self.start = QLineEdit(start, self)
        self.stop = QLineEdit(stop, self)
        self.unit = QComboBox(self)
        for u in UNITS:
            self.unit.addItem(u, u)
        self.unit.setCurrentText(unit)
        row = QHBoxLayout(self)
        row.setContentsMargins(0, 0, 0, 0)
        row.addWidget(self.start, 1)
        row.addWidget(QLabel("to", self))
        row.addWidget(self.stop, 1)
        row.addWidget(self.unit)
        self.setFocusProxy(self.start)

    def band(self) -> tuple[float, float]:
        """(start, stop) in Hz; ValueError naming the band or the field otherwise."""
        return read_band(self.start.text(), self.stop.text(), self.unit.currentText(), self.name)

    def set_band(self, start_hz: float, stop_hz: float) -> None:
        """Show a band (Hz) in the unit of its top."""
        number, unit = format_frequency(stop_hz)
        scale = UNITS[unit]
        self.unit.setCurrentText(unit)
        self.start.setText(f"{start_hz / scale:.6g}")
        self.stop.setText(number)

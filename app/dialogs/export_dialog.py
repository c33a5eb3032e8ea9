"""File → Export mesh: the file, the format its extension picks, and the length unit."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from PySide6.QtCore import QSettings
from PySide6.QtWidgets import (
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QFileDialog,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QWidget,
)


class ExportDialog(QDialog):
    """File → Export mesh: the file (its extension picks the format) and the length unit.

    Parameters
    ----------
    parent : QWidget
    settings : QSettings
        Where the last path (``paths/export``) and unit (``export/unit``) are remembered.
    start_export : callable
        ``start_export(path, unit, done=callback) -> bool``: start writing in the
        background; ``done(ok)`` is called when the file is written or failed.
    status : callable
        ``status() -> str``: the message that says why an export failed.
    """

    def __init__(
        self,
        parent: QWidget,
        settings: QSettings,
        start_export: Callable[..., bool],
        status: Callable[[], str],
    ) -> None:
        super().__init__(parent)
        from barymesh.io import EXPORT_FORMATS, UNITS

        self.settings = settings
        self.start_export, self.status = start_export, status
        self.formats = EXPORT_FORMATS
        self.setWindowTitle("Export mesh")
        form = QFormLayout(self)
        self.path = QLineEdit(str(settings.value("paths/export", "barymesh.msh")), self)
        self.path.setMinimumWidth(360)
        browse = QPushButton("Browse…", self)
        browse.clicked.connect(self._browse)
        row = QHBoxLayout()
        row.addWidget(self.path, 1)
        row.addWidget(browse)
        label = QLabel("&File", self)
        label.setBuddy(self.path)
        form.addRow(label, row)
        self.format_label = QLabel(self)
        form.addRow("Format", self.format_label)
        self.unit = QComboBox(self)
        self.unit.addItem("the format's default", None)
        names = {
            "m": "m (metres)",
            "mm": "mm (millimetres, the mesher's unit)",
            "um": "µm (micrometres)",
        }
        for unit in UNITS:
            self.unit.addItem(names.get(unit, unit), unit)
        saved = settings.value("export/unit", "")
        self.unit.setCurrentIndex(max(self.unit.findData(saved), 0) if saved else 0)
        form.addRow("Length &unit", self.unit)
        self.error = QLabel(self)
        self.error.setStyleSheet("color: #d0021b;")
        self.error.setWordWrap(True)
        form.addRow(self.error)
        buttons = QDialogButtonBox(self)
        self.export_button = buttons.addButton("Export", QDialogButtonBox.ButtonRole.AcceptRole)
        buttons.addButton(QDialogButtonBox.StandardButton.Cancel)
        buttons.accepted.connect(self._export)
        buttons.rejected.connect(self.reject)
        form.addRow(buttons)
        self.path.textChanged.connect(self._describe)
        self.unit.currentIndexChanged.connect(self._describe)
        self._describe()

    def _describe(self) -> None:
        from barymesh.io import describe_export

        try:
            text = describe_export(Path(self.path.text()).name, self.unit.currentData())
            self.format_label.setText(text.split(" (", 1)[1].rstrip(")"))
            self.export_button.setEnabled(True)
        except ValueError as exc:
            self.format_label.setText(str(exc))
            self.export_button.setEnabled(False)

    def _browse(self) -> None:
        from barymesh.io import export_filters, filter_extension

        path, chosen = QFileDialog.getSaveFileName(
            self, "Export mesh", self.path.text(), ";;".join(export_filters())
        )
        if path:
            if not Path(path).suffix:
                path += filter_extension(chosen) or ".msh"
            self.path.setText(path)

    def _export(self) -> None:
        path = self.path.text().strip()
        unit = self.unit.currentData()
        self.settings.setValue("export/unit", unit or "")
        self.settings.setValue("paths/export", path)
        self.error.setText("")
        if self.start_export(path, unit, done=self._finished):
            self.export_button.setEnabled(False)  # until this one is written or cancelled
        else:
            self._finished(False)

    def _finished(self, ok: bool) -> None:
        if ok:
            self.accept()
            return
        self.error.setText(self.status())
        self._describe()

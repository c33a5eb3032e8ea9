"""The layers panel: a visibility check box per layer, the face colouring and the
level of detail."""

from __future__ import annotations

from PySide6.QtCore import QSize
from PySide6.QtGui import QColor, QIcon, QPainter, QPixmap
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QFormLayout,
    QLabel,
    QVBoxLayout,
    QWidget,
)

from barymesh.app.model import AppModel, MeshResult
from barymesh.app.model.layers import (
    COLOR_BY_TITLES,
    DETAIL_MODES,
    LABEL_LIMIT,
    LAYER_TITLES,
    LAYERS,
)
from barymesh.app.view.scene_data import COLORS, full_detail_warning


def swatch(color: str, size: int = 11) -> QIcon:
    """A square of ``color`` with a grey border: the layer's colour beside its check box
    (the box itself keeps the style's tick, so a checked layer reads as checked)."""
    pixmap = QPixmap(size, size)
    pixmap.fill(QColor("#444444"))
    inner = QPixmap(size - 2, size - 2)
    inner.fill(QColor(color))
    painter = QPainter(pixmap)
    painter.drawPixmap(1, 1, inner)
    painter.end()
    return QIcon(pixmap)


class LayersPanel(QWidget):
    """Check boxes bound to ``AppModel.layers`` and a combo bound to ``AppModel.color_by``."""

    def __init__(self, model: AppModel, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.model = model
        layout = QVBoxLayout(self)
        layout.setContentsMargins(8, 3, 8, 3)
        layout.setSpacing(0)
        self.boxes: dict[str, QCheckBox] = {}
        for i, name in enumerate(LAYERS):
            box = QCheckBox(LAYER_TITLES[name], self)
            box.setObjectName(f"layer_{name}")
            box.setChecked(model.layers[name])
            box.setIcon(swatch(COLORS[name]))  # the layer's colour, after the tick
            box.setIconSize(QSize(11, 11))
            # the style's own box and tick, only as small as the swatches it replaced
            # (the panel, and the window, keep their height)
            box.setStyleSheet("QCheckBox::indicator { width: 11px; height: 11px; }")
            box.setToolTip(f"Show or hide {LAYER_TITLES[name].lower()} (Ctrl+{i + 1})")
            box.toggled.connect(lambda on, n=name: self.model.set_layer_visible(n, on))
            layout.addWidget(box)
            self.boxes[name] = box
        form = QFormLayout()
        form.setContentsMargins(0, 3, 0, 0)
        form.setVerticalSpacing(2)
        self.color_by = QComboBox(self)
        self.color_by.setObjectName("combo_color_by")
        for key, title in COLOR_BY_TITLES.items():
            self.color_by.addItem(title, key)
        self.color_by.setCurrentIndex(self.color_by.findData(model.color_by))
        self.color_by.currentIndexChanged.connect(
            lambda _i: self.model.set_color_by(self.color_by.currentData())
        )
        form.addRow("&Colour faces by", self.color_by)
        self.detail = QComboBox(self)
        self.detail.setObjectName("combo_detail")
        for key, title in DETAIL_MODES.items():
            self.detail.addItem(title, key)
        self.detail.setCurrentIndex(self.detail.findData(model.detail))
        self.detail.setToolTip(
            "Automatic: triangle edges and centroids are left out below 4 px per triangle "
            "and dense meshes are drawn as an image. Always full: every triangle, edge "
            "and centroid at any zoom (slow above about 1M triangles)."
        )
        self.detail.currentIndexChanged.connect(
            lambda _i: self.model.set_detail(self.detail.currentData())
        )
        form.addRow("&Detail", self.detail)
        layout.addLayout(form)
        self.warning = QLabel(self)
        self.warning.setObjectName("detail_warning")
        self.warning.setWordWrap(True)
        self.warning.setStyleSheet("color: #a04000;")
        self.warning.hide()
        layout.addWidget(self.warning)
        layout.addStretch(1)
        model.layer_changed.connect(self._layer_changed)
        model.color_by_changed.connect(self._color_by_changed)
        model.detail_changed.connect(self._detail_changed)
        model.result_changed.connect(self._result_changed)

    def _layer_changed(self, name: str, visible: bool) -> None:
        box = self.boxes[name]
        if box.isChecked() != visible:
            box.blockSignals(True)
            box.setChecked(visible)
            box.blockSignals(False)

    def _color_by_changed(self, key: str) -> None:
        self.color_by.blockSignals(True)
        self.color_by.setCurrentIndex(self.color_by.findData(key))
        self.color_by.blockSignals(False)

    def _detail_changed(self, mode: str) -> None:
        self.detail.blockSignals(True)
        self.detail.setCurrentIndex(self.detail.findData(mode))
        self.detail.blockSignals(False)
        self._show_warning()

    def _show_warning(self) -> None:
        result = self.model.result
        n = result.mesh.n_triangles if result is not None and result.mesh is not None else 0
        text = full_detail_warning(n, self.model.detail)
        self.warning.setText(text)
        self.warning.setVisible(bool(text))

    def _result_changed(self, result: MeshResult) -> None:
        assert result.mesh is not None  # result_changed brings a mesh (AppModel.set_result)
        self._show_warning()
        small = result.mesh is not None and result.mesh.n_triangles <= LABEL_LIMIT
        box = self.boxes["labels"]
        box.setEnabled(small)
        box.setToolTip(
            "Triangle numbers at the centroids"
            if small
            else f"Switched off above {LABEL_LIMIT} triangles (unreadable); "
            f"this mesh has {result.mesh.n_triangles:,}"
        )

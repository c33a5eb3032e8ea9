"""The layers panel: a visibility check box per layer and the face colouring."""

from __future__ import annotations

from PySide6.QtWidgets import QCheckBox, QComboBox, QFormLayout, QVBoxLayout, QWidget

from app.model import AppModel, MeshResult
from app.view.layers import COLOR_BY_TITLES, LABEL_LIMIT, LAYER_TITLES, LAYERS
from app.view.scene import COLORS


class LayersPanel(QWidget):
    """Check boxes bound to ``AppModel.layers`` and a combo bound to ``AppModel.color_by``."""

    def __init__(self, model: AppModel, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.model = model
        layout = QVBoxLayout(self)
        layout.setContentsMargins(8, 6, 8, 6)
        layout.setSpacing(2)
        self.boxes: dict[str, QCheckBox] = {}
        for i, name in enumerate(LAYERS):
            box = QCheckBox(LAYER_TITLES[name], self)
            box.setObjectName(f"layer_{name}")
            box.setChecked(model.layers[name])
            if name != "faces":  # a swatch of the layer's colour
                box.setStyleSheet(
                    f"QCheckBox::indicator:checked {{ background: {COLORS[name]};"
                    " border: 1px solid #444; }"
                )
            box.setToolTip(f"Show or hide {LAYER_TITLES[name].lower()} (Ctrl+{i + 1})")
            box.toggled.connect(lambda on, n=name: self.model.set_layer_visible(n, on))
            layout.addWidget(box)
            self.boxes[name] = box
        form = QFormLayout()
        self.color_by = QComboBox(self)
        self.color_by.setObjectName("combo_color_by")
        for key, title in COLOR_BY_TITLES.items():
            self.color_by.addItem(title, key)
        self.color_by.setCurrentIndex(self.color_by.findData(model.color_by))
        self.color_by.currentIndexChanged.connect(
            lambda _i: self.model.set_color_by(self.color_by.currentData())
        )
        form.addRow("&Colour faces by", self.color_by)
        layout.addLayout(form)
        layout.addStretch(1)
        model.layer_changed.connect(self._layer_changed)
        model.color_by_changed.connect(self._color_by_changed)
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

    def _result_changed(self, result: MeshResult) -> None:
        small = result.mesh is not None and result.mesh.n_triangles <= LABEL_LIMIT
        box = self.boxes["labels"]
        box.setEnabled(small)
        box.setToolTip(
            "Triangle numbers at the centroids"
            if small
            else f"Switched off above {LABEL_LIMIT} triangles (unreadable); "
                 f"this mesh has {result.mesh.n_triangles:,}"
        )

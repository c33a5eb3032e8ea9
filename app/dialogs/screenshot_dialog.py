"""File → Export screenshot: the scale and the background of a grab of the 3D view."""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, cast

import numpy as np
from PySide6.QtCore import QObject, QSettings
from PySide6.QtWidgets import (
    QCheckBox,
    QDialog,
    QDialogButtonBox,
    QFileDialog,
    QFormLayout,
    QLabel,
    QSpinBox,
    QWidget,
)

from barymesh.app.dialogs.step_progress import thread_steps


class ScreenshotCancelled(Exception):
    """A screenshot's writing was cancelled: no file was left."""


def write_png(
    path: str | Path,
    image: np.ndarray,
    cancelled: Callable[[], bool] | None = None,
) -> None:
    """Encode ``image`` (h, w, 3 or 4) uint8 as a PNG and write it to ``path`` at once
    (through a temporary file): never a partial file. Numpy and files only, so a worker
    thread may call it; when ``cancelled()`` turns true before the file is in place,
    :class:`ScreenshotCancelled` is raised and nothing is written."""
    import imageio.v3 as iio

    from barymesh.io import atomic_path

    data = iio.imwrite("<bytes>", np.ascontiguousarray(image), extension=".png")
    if cancelled is not None and cancelled():
        raise ScreenshotCancelled(f"{path}: cancelled")
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
        if cancelled is not None and cancelled():
            raise ScreenshotCancelled(f"{path}: cancelled")


def png_steps(shot: Any, path: str | Path, owner: QObject) -> Iterator[Any]:
    """Steps of :func:`~barymesh.app.dialogs.step_progress.run_in_steps`: ``shot`` (a
    :class:`~barymesh.app.view.scaled_shot.ScaledShot`) drawn, one render a step, then
    written to ``path`` as a PNG in a worker thread (:func:`write_png`); closed early
    (Cancel), they leave no file."""
    yield from shot.steps()
    cancelled = threading.Event()
    yield 1.0, f"writing {Path(path).name}"
    try:
        yield from thread_steps(lambda: write_png(path, shot.image, cancelled.is_set), owner)
    except GeneratorExit:
        cancelled.set()
        raise


class ScreenshotDialog(QDialog):
    """Scale (1–4×) and transparency for File → Export screenshot; save or copy.

    Parameters
    ----------
    parent : QWidget
    settings : QSettings
        Where the scale, the transparency and the last path are remembered.
    view_size : (2,) int
        The 3D view's width and height in pixels (the image is that times the scale).
    save : callable
        ``save(path, scale, transparent) -> bool``: write the PNG; whether it was written.
    copy : callable
        ``copy(scale, transparent)``: put the image on the clipboard.
    """

    def __init__(
        self,
        parent: QWidget,
        settings: QSettings,
        view_size: tuple[int, int],
        save: Callable[[str, int, bool], bool],
        copy: Callable[[int, bool], None],
    ) -> None:
        super().__init__(parent)
        self.settings = settings
        self.save_png, self.copy_image = save, copy
        self.setWindowTitle("Export screenshot")
        form = QFormLayout(self)
        self.scale = QSpinBox(self)
        self.scale.setRange(1, 4)
        self.scale.setSuffix(" ×")
        self.scale.setValue(int(cast("int | str", settings.value("screenshot/scale", 2))))
        self.transparent = QCheckBox("Transparent background", self)
        self.transparent.setChecked(
            settings.value("screenshot/transparent", "false") in (True, "true")
        )
        w, h = view_size
        self.size_label = QLabel(self)
        self.scale.valueChanged.connect(lambda s: self.size_label.setText(f"{w * s} × {h * s} px"))
        self.size_label.setText(f"{w * self.scale.value()} × {h * self.scale.value()} px")
        form.addRow("&Scale", self.scale)
        form.addRow("Size", self.size_label)
        form.addRow(self.transparent)
        buttons = QDialogButtonBox(self)
        save_button = buttons.addButton("Save PNG…", QDialogButtonBox.ButtonRole.AcceptRole)
        copy_button = buttons.addButton("Copy to clipboard", QDialogButtonBox.ButtonRole.ActionRole)
        buttons.addButton(QDialogButtonBox.StandardButton.Close)
        save_button.clicked.connect(self._save)
        copy_button.clicked.connect(self._copy)
        buttons.rejected.connect(self.reject)
        form.addRow(buttons)

    def _remember(self) -> None:
        self.settings.setValue("screenshot/scale", self.scale.value())
        self.settings.setValue("screenshot/transparent", self.transparent.isChecked())

    def _save(self) -> None:
        self._remember()
        start = str(self.settings.value("paths/screenshot", "barymesh.png"))
        path, _ = QFileDialog.getSaveFileName(self, "Export screenshot", start, "PNG (*.png)")
        if path:
            if not path.lower().endswith(".png"):
                path += ".png"
            self.settings.setValue("paths/screenshot", path)
            if self.save_png(path, self.scale.value(), self.transparent.isChecked()):
                self.accept()

    def _copy(self) -> None:
        self._remember()
        self.copy_image(self.scale.value(), self.transparent.isChecked())
        self.accept()

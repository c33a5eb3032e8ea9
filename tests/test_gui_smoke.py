"""Smoke test of the GUI stack: PySide6 (xcb) + pyvistaqt + VTK/Mesa in a real X window."""

import imageio.v3 as iio
import numpy as np
import pytest

pytest.importorskip("pyvistaqt")

import pyvista as pv  # noqa: E402
from PySide6.QtWidgets import QApplication, QMainWindow  # noqa: E402
from pyvistaqt import QtInteractor  # noqa: E402

BACKGROUND = (255, 255, 255)
MESH = (255, 0, 0)


def _has_colour(img: np.ndarray, rgb: tuple[int, int, int], tol: int = 40) -> bool:
    return bool((np.abs(img[..., :3].astype(int) - rgb).max(axis=-1) <= tol).any())


def test_qtinteractor_renders_plane_in_window(qtbot, tmp_path):
    assert QApplication.platformName() == "xcb"  # a real X window, see conftest.py
    window = QMainWindow()
    qtbot.addWidget(window)
    interactor = QtInteractor(window, off_screen=False)
    try:
        window.setCentralWidget(interactor)
        window.resize(640, 480)
        interactor.set_background(BACKGROUND)
        # Unlit, so the plane is exactly MESH-coloured whatever the camera angle.
        interactor.add_mesh(pv.Plane(i_size=1, j_size=1), color=MESH, lighting=False)
        interactor.view_xy()
        window.show()
        qtbot.waitExposed(window)
        interactor.render()

        shot = interactor.screenshot()
        w, h = interactor.width(), interactor.height()
        ratio = interactor.devicePixelRatioF()
        assert shot.shape == (round(h * ratio), round(w * ratio), 3)
        assert _has_colour(shot, BACKGROUND) and _has_colour(shot, MESH)

        png = tmp_path / "window.png"
        assert window.grab().save(str(png))
        grabbed = iio.imread(png)
        assert grabbed.shape[:2] == (round(window.height() * ratio), round(window.width() * ratio))
        assert _has_colour(grabbed, BACKGROUND) and _has_colour(grabbed, MESH)
    finally:
        # Release the VTK render window and its GL context while the Qt widget and the X
        # connection still exist, rather than relying on teardown/garbage-collection order.
        interactor.close()

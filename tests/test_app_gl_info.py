"""app/view/gl_info.py: the renderer asked once, and every view's samples set before its
first frame (no MSAA on Mesa's llvmpipe, which the suite runs on under Xvfb)."""

import pytest

pytest.importorskip("pyvistaqt")

from PySide6.QtGui import QOpenGLContext  # noqa: E402

from barymesh.app.view import gl_info  # noqa: E402


def test_the_renderer_is_asked_once_and_left_current_nowhere(qapp):
    name = gl_info.renderer_name()
    assert "llvmpipe" in name  # Xvfb + Mesa: the software rasteriser
    assert QOpenGLContext.currentContext() is None
    assert gl_info.renderer_name() is name  # cached: one context per process


def test_samples_follow_the_renderer_unless_asked(qapp, monkeypatch, caplog):
    monkeypatch.delenv("BARYMESH_MSAA", raising=False)
    assert gl_info.multi_samples() == 0  # llvmpipe
    monkeypatch.setenv("BARYMESH_MSAA", "2")
    assert gl_info.multi_samples() == 2
    monkeypatch.setenv("BARYMESH_MSAA", "-3")
    assert gl_info.multi_samples() == 0
    monkeypatch.setenv("BARYMESH_MSAA", "many")
    assert gl_info.multi_samples() == 0  # the renderer's choice, and a warning
    assert "BARYMESH_MSAA='many' is not a whole number" in caplog.text


def test_views_get_their_samples_before_their_first_frame(qtbot, monkeypatch):
    from barymesh import MeshParams
    from barymesh.app.edit.painter import PixelPainterWindow
    from barymesh.app.window import MainWindow

    monkeypatch.setenv("BARYMESH_MSAA", "2")  # not the construction default of either
    win = MainWindow(MeshParams(angle_step=30.0, subdivisions=1), scripted=True)
    qtbot.addWidget(win)
    painter = PixelPainterWindow()
    qtbot.addWidget(painter)
    assert not win.isVisible() and not painter.isVisible()  # never shown, never painted
    assert win.plotter.ren_win.GetMultiSamples() == 2
    assert painter.plotter.ren_win.GetMultiSamples() == 2
    win.close()
    painter.close()

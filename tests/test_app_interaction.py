"""What a mouse drag, a wheel step or a slider drag costs the GUI thread (issue 30,
section 1, item 13), asserted as structure, never as time (``benchmarks/latency.py
--interaction`` measures the times): one render a frame, rulers rebuilt once the camera
rests, no element lookup built for meshes a slider only passes through. In the real
window (Xvfb), driven by QTest mouse and wheel events as a user's."""

import numpy as np
import pytest

pytest.importorskip("pyvistaqt")

from app_user import drag_slider_by  # noqa: E402
from PySide6.QtCore import QEvent, QPoint, QPointF, Qt, QTimer  # noqa: E402
from PySide6.QtGui import QMouseEvent, QWheelEvent  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

import barymesh.app.view.view_tools as view_tools  # noqa: E402
from barymesh import MeshParams  # noqa: E402

FIG12A = MeshParams()  # 23,040 triangles, drawn in full
KINDS = ("triangle", "edge", "vertex")  # what the readout names under the cursor


@pytest.fixture
def window_params():
    return FIG12A


class Renders:
    """Counts the view's renders (the render window's EndEvent)."""

    def __init__(self, plotter) -> None:
        self.count = 0
        self.window = plotter.ren_win
        self.tag = self.window.AddObserver("EndEvent", self._rendered)

    def _rendered(self, *_args) -> None:
        self.count += 1

    def close(self) -> None:
        self.window.RemoveObserver(self.tag)


def _wheel(plotter, notches: int = 1) -> None:
    centre = QPoint(plotter.width() // 2, plotter.height() // 2)
    event = QWheelEvent(
        QPointF(centre),
        QPointF(plotter.mapToGlobal(centre)),
        QPoint(0, 0),
        QPoint(0, 120 * notches),
        Qt.MouseButton.NoButton,
        Qt.KeyboardModifier.NoModifier,
        Qt.ScrollPhase.NoScrollPhase,
        False,
    )
    QApplication.sendEvent(plotter, event)


def _mouse(widget, kind, pos, button, buttons) -> None:
    event = QMouseEvent(
        kind,
        QPointF(pos),
        QPointF(widget.mapToGlobal(pos)),
        button,
        buttons,
        Qt.KeyboardModifier.NoModifier,
    )
    QApplication.sendEvent(widget, event)


@pytest.fixture
def shown(window, qtbot):
    qtbot.waitUntil(lambda: window.model.result is not None, timeout=30_000)
    qtbot.waitUntil(lambda: not window.controller.busy, timeout=30_000)
    qtbot.wait(300)
    return window


def test_a_wheel_step_is_drawn_once_and_the_rulers_follow_at_rest(shown, qtbot):
    """A wheel step was drawn twice (VTK's style rendered in the event, the widget again
    in its paint) and rebuilt the rulers' labels with each step (about 100 ms of the GUI
    thread under load): now one render a step, the rulers as they were (in mm, they zoom
    along) until the camera rests, then placed along the part in view."""
    window = shown
    plotter, scene = window.plotter, window.scene
    renders = Renders(plotter)
    settled = []  # the render count when the camera came to rest
    real_settle = scene.settle

    def settle():
        settled.append(renders.count)
        return real_settle()

    scene.settle = settle
    # (a rest 2 s after the camera's last move, not 0.25 s: a loaded machine's slow
    # paints would let it come between the steps)
    window.presenter.rest_timer.setInterval(2000)
    try:
        before = tuple(scene.axes.bounds)
        scale = plotter.camera.parallel_scale
        for _ in range(3):
            _wheel(plotter)
            QApplication.processEvents()
            qtbot.wait(30)  # less than the rest timer: the camera still moves
        assert plotter.camera.parallel_scale < 0.6 * scale  # zoomed in
        assert renders.count <= 3  # one render a step at most (there were 6)
        assert tuple(scene.axes.bounds) == before  # the rulers wait for the rest
        qtbot.waitUntil(lambda: tuple(scene.axes.bounds) != before, timeout=10_000)
        rested = settled[0]
        qtbot.waitUntil(lambda: renders.count > rested, timeout=5_000)  # drawn once more
        x0, x1, y0, y1 = scene.view_rect()
        bx0, bx1, by0, by1 = tuple(scene.axes.bounds)[:4]
        assert x0 <= bx0 < bx1 <= x1 and y0 <= by0 < by1 <= y1  # along the part in view
    finally:
        renders.close()
    plotter.render()
    window.grab().save("/tmp/wb/shots/wheel_rest_rulers.png")


def test_a_rotating_drag_draws_at_most_one_frame_a_paint(shown, qtbot):
    """Each mouse move of a rotation was rendered in VTK's handler and again in the
    widget's paint; now the moves only ask for a paint, which renders once (moves that
    come between two paints make one frame)."""
    window = shown
    plotter = window.plotter
    renders = Renders(plotter)
    paints = window.paint_counter.paints
    asked = plotter.renders_asked
    left, none = Qt.MouseButton.LeftButton, Qt.MouseButton.NoButton
    at = QPoint(plotter.width() // 2, plotter.height() // 2)
    try:
        up = plotter.camera.up
        _mouse(plotter, QEvent.Type.MouseButtonPress, at, left, left)
        for i in range(1, 9):
            _mouse(plotter, QEvent.Type.MouseMove, at + QPoint(8 * i, 3 * i), none, left)
            if i % 2 == 0:
                QApplication.processEvents()
        _mouse(plotter, QEvent.Type.MouseButtonRelease, at + QPoint(64, 24), left, none)
        qtbot.wait(100)
        assert not np.allclose(plotter.camera.up, up)  # the camera turned
        assert plotter.renders_asked - asked >= 8  # VTK asked for a render with each move
        # ...and the view rendered only when painted, no more than once a paint
        assert 1 <= renders.count <= window.paint_counter.paints - paints
    finally:
        renders.close()


def test_a_slider_drag_builds_no_element_lookup(shown, qtbot, monkeypatch):
    """Each mesh of a slider drag built the hover readout's element lookup (a k-d tree
    of the centroids, 30–70 ms of the GUI thread at 23,040 triangles) though the pointer
    was on the slider. It is built when the pointer comes over the view."""
    window = shown
    built = []
    real = view_tools.MeshLocator

    class Counting(real):
        def __init__(self, mesh):
            built.append(mesh.n_triangles)
            super().__init__(mesh)

    monkeypatch.setattr(view_tools, "MeshLocator", Counting)
    shown_meshes = []
    window.model.result_changed.connect(lambda r: shown_meshes.append(r.mesh.n_triangles))
    for dx in (6, 6, -9):  # three short drags of the handle, each a new mesh
        drag_slider_by(window.controls.rows["inner_radius"].slider, dx, steps=3)
        window.controller.flush()
        qtbot.waitUntil(lambda: not window.controller.busy, timeout=30_000)
        qtbot.wait(100)
    assert len(shown_meshes) >= 2  # new meshes came, each drawn
    assert built == []
    # the pointer over the view: the lookup, and the readout
    from gui_helpers import hover_world

    mesh = window.model.result.mesh
    hover_world(qtbot, window.plotter, mesh.centroids[5])
    qtbot.waitUntil(
        lambda: any(f"{kind} " in window.view_tools.readout.text() for kind in KINDS),
        timeout=10_000,
    )
    assert built == [mesh.n_triangles]


def test_a_new_mesh_and_its_first_render_are_two_passes_of_the_event_loop(shown, qtbot):
    """A slider's new mesh was copied into the view's datasets and rendered in one go
    (about 60 + 50 ms of the GUI thread at 23,040 triangles, one block); the render now
    comes from a timer, so the event loop (another timer here) runs between the two."""
    window = shown
    ticks = []
    ticker = QTimer()
    ticker.setInterval(1)
    ticker.timeout.connect(lambda: ticks.append(1))
    marks = []
    real_show = window._show_result

    def show(result):
        real_show(result)
        marks.append(("shown", len(ticks), window.paint_counter.paints))

    window.model.result_changed.disconnect(window._show_result)
    window.model.result_changed.connect(show)
    real_paint = window.plotter.paintGL

    def paint():
        marks.append(("paint", len(ticks), window.paint_counter.paints))
        real_paint()

    window.plotter.paintGL = paint
    ticker.start()
    try:
        for value in (4.2, 4.4, 4.6):
            marks.clear()
            window.model.set_params(FIG12A.replace(inner_radius=value))
            qtbot.waitUntil(lambda: any(m[0] == "paint" for m in marks), timeout=30_000)
            shown_at = next(m for m in marks if m[0] == "shown")
            painted_at = next(m for m in marks if m[0] == "paint")
            assert painted_at[1] > shown_at[1], marks  # the ticker ran in between
            assert painted_at[2] == shown_at[2] + 1  # the first paint after the new mesh
    finally:
        ticker.stop()
        del window.plotter.paintGL


def test_a_full_collection_waits_for_the_end_of_a_drag(shown, qtbot, monkeypatch):
    """The window runs Python's cyclic collector on the GUI thread; a full collection
    (generation 2, about 300,000 objects here: 100-200 ms under load) came in the middle
    of drags. While a mouse button is held (here on the slider's handle, as QTest presses
    it), a due full collection is a generation-1 one; after the release, the full one."""
    import gc

    from app_user import _handle_rect
    from PySide6.QtGui import QGuiApplication
    from PySide6.QtTest import QTest

    from barymesh.app import gui_gc

    collector = gui_gc.collect_in_gui_thread()
    collector.timer.stop()  # (its own timer would collect in between)
    collector.postponed_since = None  # no full collection waiting yet
    collected = []
    monkeypatch.setattr(gc, "get_count", lambda: (701, 11, 11))  # every generation due
    monkeypatch.setattr(gc, "collect", lambda generation=2: collected.append(generation))
    slider = shown.controls.rows["inner_radius"].slider
    handle, _groove = _handle_rect(slider)
    # pressed through the window system (the top-level QWindow), as a mouse does, so
    # that Qt's own record of the held buttons follows
    window = shown.windowHandle()
    at = slider.mapTo(shown, handle.center())
    left, plain = Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier
    try:
        QTest.mousePress(window, left, plain, at)
        try:
            assert QGuiApplication.mouseButtons() == left
            collector.collect()
        finally:
            QTest.mouseRelease(window, left, plain, at)
        assert QGuiApplication.mouseButtons() == Qt.MouseButton.NoButton
        collector.collect()
    finally:
        collector.timer.start()
    assert collected == [1, 2]

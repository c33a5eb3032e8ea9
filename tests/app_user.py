"""Driving the window as a user does (keys into fields, mouse on slider handles, combo keys),
and the counts a mesh of separate patches must have (closed forms in n)."""

import contextlib
import gc

from PySide6.QtCore import QEvent, QPoint, QPointF, Qt
from PySide6.QtGui import QMouseEvent
from PySide6.QtTest import QTest
from PySide6.QtWidgets import (
    QApplication,
    QComboBox,
    QFileDialog,
    QLineEdit,
    QPushButton,
    QSlider,
    QStyle,
    QStyleOptionButton,
    QStyleOptionSlider,
)


@contextlib.contextmanager
def session_heap_frozen():
    """The objects the test session made so far out of the cyclic collector's reach.

    The window runs Python's full collection in its GUI thread (``app/gui_gc.py``); late
    in ``make test`` one scans the heap of thousands of tests before, not a window's (a
    1.09 s gap of the GUI thread's CPU time was seen). A heartbeat measured inside this
    block sees the collections a user's window would.
    """
    gc.collect()
    gc.freeze()
    try:
        yield
    finally:
        gc.unfreeze()


def type_into(field: QLineEdit, text: str, key=Qt.Key.Key_Return) -> None:
    """Select all in ``field``, delete it, type ``text`` and press Enter (or ``key``)."""
    QTest.keyClick(field, Qt.Key.Key_A, Qt.KeyboardModifier.ControlModifier)
    QTest.keyClick(field, Qt.Key.Key_Backspace)
    QTest.keyClicks(field, text)
    if key is not None:
        QTest.keyClick(field, key)


def _handle_rect(slider: QSlider):
    opt = QStyleOptionSlider()
    slider.initStyleOption(opt)
    style = slider.style()
    handle = style.subControlRect(
        QStyle.ComplexControl.CC_Slider, opt, QStyle.SubControl.SC_SliderHandle, slider
    )
    groove = style.subControlRect(
        QStyle.ComplexControl.CC_Slider, opt, QStyle.SubControl.SC_SliderGroove, slider
    )
    return handle, groove


def _mouse(widget, kind, point: QPoint, buttons) -> None:
    local = QPointF(point)
    button = Qt.MouseButton.LeftButton if kind != QEvent.Type.MouseMove else Qt.MouseButton.NoButton
    event = QMouseEvent(
        kind,
        local,
        QPointF(widget.mapToGlobal(point)),
        button,
        buttons,
        Qt.KeyboardModifier.NoModifier,
    )
    QApplication.sendEvent(widget, event)


def slider_x(slider: QSlider, position: int) -> int:
    """The x pixel of the handle's centre when ``slider`` is at ``position``."""
    handle, groove = _handle_rect(slider)
    span = groove.width() - handle.width()
    offset = QStyle.sliderPositionFromValue(slider.minimum(), slider.maximum(), position, span)
    return groove.x() + handle.width() // 2 + offset


def drag_slider(slider: QSlider, position: int, steps: int = 6) -> None:
    """Press the handle, move in ``steps`` to ``position`` (beyond the end for the ends),
    release: as a mouse does."""
    handle, _groove = _handle_rect(slider)
    start = handle.center()
    if position >= slider.maximum():
        end_x = slider.width() + 40
    elif position <= slider.minimum():
        end_x = -40
    else:
        end_x = slider_x(slider, position)
    left = Qt.MouseButton.LeftButton
    _mouse(slider, QEvent.Type.MouseButtonPress, start, left)
    for i in range(1, steps + 1):
        x = start.x() + (end_x - start.x()) * i // steps
        _mouse(slider, QEvent.Type.MouseMove, QPoint(x, start.y()), left)
    _mouse(
        slider, QEvent.Type.MouseButtonRelease, QPoint(end_x, start.y()), Qt.MouseButton.NoButton
    )


def choose(combo: QComboBox, data) -> None:
    """Pick the item holding ``data`` with ↑/↓ on the closed combo box."""
    target = combo.findData(data)
    assert target >= 0, data
    for _ in range(combo.count()):
        if combo.currentIndex() == target:
            return
        key = Qt.Key.Key_Down if combo.currentIndex() < target else Qt.Key.Key_Up
        QTest.keyClick(combo, key)
    assert combo.currentIndex() == target


def answer_file_dialogs(monkeypatch):
    """File dialogs return what ``answer(path, chosen_filter)`` set last (what a user picks),
    or nothing (Cancel) when no answer is pending."""
    picked = {}

    def answer(path, chosen=""):
        picked["path"], picked["filter"] = str(path), chosen

    def dialog(*_args, **_kwargs):
        return picked.pop("path", ""), picked.pop("filter", "")

    monkeypatch.setattr(QFileDialog, "getOpenFileName", dialog)
    monkeypatch.setattr(QFileDialog, "getSaveFileName", dialog)
    return answer


def export_through_dialog(window) -> bool:
    """File → Export mesh as a user does it: the action, Browse… (the patched file dialog
    answers), then Export. Returns whether the dialog closed (the export succeeded)."""
    window.act_export.trigger()
    dialog = window.export_dialog
    browse = next(b for b in dialog.findChildren(QPushButton) if b.text().startswith("Browse"))
    QTest.mouseClick(browse, Qt.MouseButton.LeftButton)
    QTest.mouseClick(dialog.export_button, Qt.MouseButton.LeftButton)
    wait_for_export(window)
    closed = not dialog.isVisible()
    dialog.close()
    return closed


def wait_for_export(window, timeout: float = 120.0) -> None:
    """Let the event loop run until the window's export (a worker thread) has finished."""
    import time

    from PySide6.QtCore import QCoreApplication

    deadline = time.monotonic() + timeout
    while window.export_job is not None:
        assert time.monotonic() < deadline, "the export did not finish"
        QCoreApplication.processEvents()
        time.sleep(0.005)


def settle(window, qtbot) -> None:
    """Start the pending build and wait until no build runs (worker builds included)."""
    window.controller.flush()
    qtbot.waitUntil(lambda: not window.controller.busy, timeout=60_000)


def patch_counts(patches: int, n: int) -> dict:
    """Counts of ``patches`` separate square patches, each split along one diagonal into two
    primary triangles subdivided uniformly n × n: per patch (n + 1)² vertices, 2n²
    triangles, 3n² + 2n edges of which 4n on the boundary (n = 4: the paper's 32 triangles).
    """
    return {
        "patches": patches,
        "vertices": patches * (n + 1) ** 2,
        "triangles": patches * 2 * n * n,
        "edges": patches * (3 * n * n + 2 * n),
        "interior_edges": patches * (3 * n * n - 2 * n),
        "boundary_edges": patches * 4 * n,
        "junction_edges": 0,
    }


def shown_counts(window) -> dict:
    """The statistics panel's counts as integers."""
    keys = (
        "patches",
        "vertices",
        "triangles",
        "edges",
        "interior_edges",
        "boundary_edges",
        "junction_edges",
    )
    return {k: int(window.stats.text(k).replace(",", "")) for k in keys}


def click_check_box(box) -> None:
    """Click a check box on its indicator."""
    opt = QStyleOptionButton()
    box.initStyleOption(opt)
    rect = box.style().subElementRect(QStyle.SubElement.SE_CheckBoxIndicator, opt, box)
    QTest.mouseClick(box, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, rect.center())


def drag_slider_by(slider: QSlider, dx: int, steps: int = 8) -> None:
    """Press the handle, move it ``dx`` pixels (in ``steps`` moves) and release, as a mouse
    does."""
    handle, _groove = _handle_rect(slider)
    start = handle.center()
    left = Qt.MouseButton.LeftButton
    _mouse(slider, QEvent.Type.MouseButtonPress, start, left)
    for i in range(1, steps + 1):
        _mouse(slider, QEvent.Type.MouseMove, QPoint(start.x() + dx * i // steps, start.y()), left)
    _mouse(
        slider,
        QEvent.Type.MouseButtonRelease,
        QPoint(start.x() + dx, start.y()),
        Qt.MouseButton.NoButton,
    )

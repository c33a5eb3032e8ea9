"""What the window benchmarks share: the event loop, memory, the heartbeat, a user's input.

``benchmarks/latency.py`` and ``benchmarks/array_live.py`` drive the real window as a user
does (QTest key clicks, mouse events on a slider's handle) and watch the event loop with
a 10 ms heartbeat timer. They run as scripts, so this module is imported from the
``benchmarks`` folder (``from window_tools import ...``); Qt is imported inside each
function, after the script has chosen its platform and display.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from typing import Any


def wait_until(condition: Callable[[], bool], timeout: float) -> bool:
    """Run the event loop until ``condition()`` (polled every ms) or ``timeout`` (s).

    An event loop rather than a ``processEvents()`` busy loop: PySide6 6.12 under
    CPython 3.11 loses a reference to None with every call of a void method, and a busy
    loop makes millions of them.
    """
    from PySide6.QtCore import QEventLoop, QTimer

    if condition():
        return True
    loop = QEventLoop()
    deadline = time.perf_counter() + timeout
    poll = QTimer()
    poll.setInterval(1)

    def check() -> None:
        if condition() or time.perf_counter() > deadline:
            poll.stop()
            loop.quit()

    poll.timeout.connect(check)
    poll.start()
    loop.exec()
    return condition()


def rss(pid: int | str = "self") -> int:
    """Resident set size of process ``pid`` (bytes; Linux; 0 elsewhere)."""
    try:
        with open(f"/proc/{pid}/statm") as f:
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except OSError:  # pragma: no cover - not Linux, or the process is gone
        return 0


def children_rss() -> int:
    """RSS of this process's child processes (the window's solver process), 0 if none."""
    import multiprocessing

    return sum(rss(p.pid) for p in multiprocessing.active_children())


class Heartbeat:
    """A 10 ms timer; ``gaps`` are the times between its beats (s): the event loop's blocks.

    ``thread_gaps`` are the GUI thread's CPU seconds in each gap (``time.thread_time``):
    on a loaded machine a block's wall time grows with the other processes' share of the
    cores, its CPU time does not (what llvmpipe's own threads render is not in it).
    ``process_gaps`` are the whole process's CPU seconds in each gap
    (``time.process_time``: the GUI thread, llvmpipe's render threads, and any worker
    thread busy meanwhile). ``ends`` are the ``time.perf_counter()`` of each beat.
    """

    def __init__(self) -> None:
        from PySide6.QtCore import QTimer

        self.reset()
        self.timer = QTimer()
        self.timer.setInterval(10)
        self.timer.timeout.connect(self._beat)
        self.timer.start()

    def _beat(self) -> None:
        now, cpu, process = time.perf_counter(), time.thread_time(), time.process_time()
        self.gaps.append(now - self.last)
        self.thread_gaps.append(cpu - self.last_cpu)
        self.process_gaps.append(process - self.last_process)
        self.ends.append(now)
        self.last, self.last_cpu, self.last_process = now, cpu, process

    def reset(self) -> None:
        self.gaps: list[float] = []
        self.thread_gaps: list[float] = []
        self.process_gaps: list[float] = []
        self.ends: list[float] = []
        self.last, self.last_cpu = time.perf_counter(), time.thread_time()
        self.last_process = time.process_time()

    @property
    def longest(self) -> float:
        """Wall seconds of the longest gap since the last reset."""
        return max(self.gaps, default=0.0)

    @property
    def longest_cpu(self) -> float:
        """The GUI thread's CPU seconds in its busiest gap."""
        return max(self.thread_gaps, default=0.0)

    def longest_block_process(self) -> float:
        """The whole process's CPU seconds in the longest gap since the last reset."""
        if not self.gaps:
            return 0.0
        i = max(range(len(self.gaps)), key=self.gaps.__getitem__)
        return self.process_gaps[i]

    def longest_block(self) -> tuple[float, float, float]:
        """(wall, GUI-thread CPU) seconds of the longest gap since the last reset, and the
        ``time.perf_counter()`` its end came at."""
        if not self.gaps:
            return 0.0, 0.0, self.last
        i = max(range(len(self.gaps)), key=self.gaps.__getitem__)
        return self.gaps[i], self.thread_gaps[i], self.ends[i]


def type_into(field: Any, text: str) -> None:
    """Select all in ``field``, type ``text`` and press Enter, as a user does."""
    from PySide6.QtCore import Qt
    from PySide6.QtTest import QTest

    QTest.keyClick(field, Qt.Key.Key_A, Qt.KeyboardModifier.ControlModifier)
    QTest.keyClick(field, Qt.Key.Key_Backspace)
    QTest.keyClicks(field, text)
    QTest.keyClick(field, Qt.Key.Key_Return)


def click(widget: Any, pos: Any = None) -> None:
    """A left click on ``widget`` (at ``pos``, default its centre)."""
    from PySide6.QtCore import Qt
    from PySide6.QtTest import QTest

    if pos is None:
        QTest.mouseClick(widget, Qt.MouseButton.LeftButton)
    else:
        QTest.mouseClick(widget, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, pos)


def click_check_box(box: Any) -> None:
    """A click on a check box's indicator."""
    from PySide6.QtWidgets import QStyle, QStyleOptionButton

    opt = QStyleOptionButton()
    box.initStyleOption(opt)
    rect = box.style().subElementRect(QStyle.SubElement.SE_CheckBoxIndicator, opt, box)
    click(box, rect.center())


def slider_rects(slider: Any) -> tuple[Any, Any]:
    """The handle's and the groove's rectangles of ``slider`` (its style's)."""
    from PySide6.QtWidgets import QStyle, QStyleOptionSlider

    opt = QStyleOptionSlider()
    slider.initStyleOption(opt)
    style = slider.style()
    cc, sc = QStyle.ComplexControl.CC_Slider, QStyle.SubControl
    return (
        style.subControlRect(cc, opt, sc.SC_SliderHandle, slider),
        style.subControlRect(cc, opt, sc.SC_SliderGroove, slider),
    )


def slider_x(slider: Any, position: int) -> int:
    """The x pixel of the handle's centre when ``slider`` is at ``position``."""
    from PySide6.QtWidgets import QStyle

    handle, groove = slider_rects(slider)
    span = groove.width() - handle.width()
    offset = QStyle.sliderPositionFromValue(slider.minimum(), slider.maximum(), position, span)
    return groove.x() + handle.width() // 2 + offset


def mouse(widget: Any, kind: Any, x: int, y: int, button: Any, buttons: Any) -> None:
    """Send ``widget`` one mouse event of ``kind`` at (x, y), as the window system does."""
    from PySide6.QtCore import QPoint, QPointF, Qt
    from PySide6.QtGui import QMouseEvent
    from PySide6.QtWidgets import QApplication

    point = QPointF(QPoint(x, y))
    event = QMouseEvent(
        kind,
        point,
        QPointF(widget.mapToGlobal(point)),
        button,
        buttons,
        Qt.KeyboardModifier.NoModifier,
    )
    QApplication.sendEvent(widget, event)

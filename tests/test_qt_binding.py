"""The Qt binding keeps Python's reference counts right.

PySide6 6.12.0 on CPython 3.11 dropped one reference to ``None`` on every call of a void
Qt method made from Python (``processEvents``, ``update``, ...). A long session then ends
in "Fatal Python error: none_dealloc". pyproject pins a version without that bug; this
test fails if a future version brings it back.
"""

import sys

import pytest

pytest.importorskip("PySide6")

from PySide6.QtWidgets import QApplication  # noqa: E402


def test_void_qt_calls_leave_the_refcount_of_none_alone(qapp):
    calls = 2000
    before = sys.getrefcount(None)
    for _ in range(calls):
        QApplication.processEvents()
    # other code running meanwhile may take or drop a few references, never one per call
    assert abs(sys.getrefcount(None) - before) < calls // 10

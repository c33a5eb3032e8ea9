"""A spinner with the elapsed time on stderr for long command-line work (a terminal only)."""

from __future__ import annotations

import contextlib
import sys
import threading
import time
from collections.abc import Iterator
from typing import TextIO

#: Work longer than this (seconds) shows a spinner when stderr is a terminal.
PROGRESS_DELAY = 1.0


@contextlib.contextmanager
def progress(what: str, stream: TextIO | None = None) -> Iterator[None]:
    """Show ``what`` with a spinner and the elapsed time on ``stream`` (stderr).

    Only when the stream is a terminal and the work takes longer than
    ``PROGRESS_DELAY`` seconds; the line is cleared when the work ends.
    """
    stream = sys.stderr if stream is None else stream
    try:
        tty = stream.isatty()
    except (AttributeError, ValueError):
        tty = False
    if not tty:
        yield
        return
    done = threading.Event()
    shown = threading.Event()
    start = time.monotonic()

    def spin() -> None:
        if done.wait(PROGRESS_DELAY):
            return
        frames = "|/-\\"
        k = 0
        while not done.is_set():
            shown.set()
            stream.write(f"\r{frames[k % 4]} {what} … {time.monotonic() - start:5.1f} s")
            stream.flush()
            k += 1
            done.wait(0.1)

    thread = threading.Thread(target=spin, daemon=True)
    thread.start()
    try:
        yield
    finally:
        done.set()
        thread.join()
        if shown.is_set():
            stream.write("\r\033[K")
            stream.flush()

"""Progress of long command-line work on stderr: a spinner on a terminal, lines in a log.

On a terminal, a spinner with the elapsed time (and ``done/total`` when the work counts
its steps) replaces itself on one line, and is cleared when the work ends. Anywhere else
(a pipe, a file, a CI log, a batch job) nothing is redrawn: work that lasts longer than
``LOG_DELAY`` seconds writes one line then, one every ``LOG_EVERY`` seconds while it runs,
and one when it ends, each with the elapsed time, the steps done and the time left at
the rate so far::

    solving 21 frequencies, N = 8,720: 3/21 after 1m32s, about 9m12s left
    solving 21 frequencies, N = 8,720: done, 21/21 in 10m40s

Quick work prints nothing at all, on a terminal or off it.
"""

from __future__ import annotations

import contextlib
import sys
import threading
import time
from collections.abc import Callable, Iterator
from typing import TextIO

#: Work longer than this (seconds) shows a spinner when stderr is a terminal.
PROGRESS_DELAY = 1.0
#: Off a terminal, work longer than this (seconds) writes its first line.
LOG_DELAY = 10.0
#: Off a terminal, the seconds between two lines of the same work.
LOG_EVERY = 60.0

#: ``report(done, total)``: what ``progress`` yields, for the work to count its steps.
Report = Callable[[int, int], None]


def is_terminal(stream: TextIO) -> bool:
    """Whether ``stream`` is a terminal (False for anything that cannot say)."""
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):
        return False


def duration(seconds: float) -> str:
    """``"42s"``, ``"3m20s"``, ``"1h05m"``.

    >>> duration(42.4), duration(200), duration(3900)
    ('42s', '3m20s', '1h05m')
    """
    s = int(round(seconds))
    if s >= 3600:
        return f"{s // 3600}h{s % 3600 // 60:02d}m"
    if s >= 60:
        return f"{s // 60}m{s % 60:02d}s"
    return f"{s}s"


class _Steps:
    """The steps a piece of work reported, and the time it started."""

    def __init__(self) -> None:
        self.start = time.monotonic()
        self.done = 0
        self.total = 0

    def __call__(self, done: int, total: int) -> None:
        self.done, self.total = int(done), int(total)

    def elapsed(self) -> float:
        return time.monotonic() - self.start

    def counted(self) -> str:
        return f" ({self.done}/{self.total})" if self.total else ""

    def log_line(self, what: str, finished: bool = False, stopped: bool = False) -> str:
        spent = duration(self.elapsed())
        if stopped:
            return f"{what}: stopped after {spent}"
        if finished:
            steps = f", {self.done}/{self.total}" if self.total else ""
            return f"{what}: done{steps} in {spent}"
        if not self.total:
            return f"{what}: running for {spent}"
        line = f"{what}: {self.done}/{self.total} after {spent}"
        if 0 < self.done < self.total:
            left = self.elapsed() / self.done * (self.total - self.done)
            line += f", about {duration(left)} left"
        return line


@contextlib.contextmanager
def progress(what: str, stream: TextIO | None = None) -> Iterator[Report]:
    """Show the progress of ``what`` on ``stream`` (stderr) while the block runs.

    Yields ``report(done, total)``, which the work may call after each step (a sweep's
    ``progress=``); the lines then show the steps and the time left.
    """
    stream = sys.stderr if stream is None else stream
    steps = _Steps()
    done = threading.Event()
    shown = threading.Event()
    tty = is_terminal(stream)

    def spin() -> None:
        if done.wait(PROGRESS_DELAY):
            return
        frames = "|/-\\"
        k = 0
        while not done.is_set():
            shown.set()
            stream.write(f"\r{frames[k % 4]} {what} … {steps.elapsed():5.1f} s{steps.counted()}")
            stream.flush()
            k += 1
            done.wait(0.1)

    def log() -> None:
        wait = LOG_DELAY
        while not done.wait(wait):
            shown.set()
            stream.write(steps.log_line(what) + "\n")
            stream.flush()
            wait = LOG_EVERY

    thread = threading.Thread(target=spin if tty else log, daemon=True)
    thread.start()
    failed = False
    try:
        yield steps
    except BaseException:
        failed = True
        raise
    finally:
        done.set()
        thread.join()
        if shown.is_set():
            end = steps.log_line(what, finished=True, stopped=failed) + "\n"
            stream.write("\r\033[K" if tty else end)
            stream.flush()

"""Atomic file writes: a temporary file in the target folder, then one rename.

A failed or interrupted write (an exception, Ctrl-C, SIGTERM) leaves no
half-written file under the target name, removes its temporary file and keeps
any existing file as it was. A SIGKILL cannot be caught: the next write to the
same target removes what the killed one left (see
:func:`remove_stale_temp_files`).
"""

from __future__ import annotations

import contextlib
import logging
import os
import re
import signal
import tempfile
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path

log = logging.getLogger(__name__)


class ExportError(OSError):
    """A mesh file could not be written; the message names the path and the reason."""


class ExportCancelled(ExportError):
    """The export was cancelled: its temporary files were removed, no target touched."""


#: Temporary files of ours are named ``.NAME.barymesh-PID-RANDOM.tmpSUFFIX``.
TEMP_MARK = ".barymesh-"
_STARTED = time.time()


def _temp_pattern(target: Path) -> re.Pattern[str]:
    return re.compile(re.escape(f".{target.name}{TEMP_MARK}") + r"(\d+)-[^.]*\.tmp")


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # e.g. another user's process: alive
        return True
    return True


def remove_stale_temp_files(target: str | Path) -> list[Path]:
    """Remove temporary files a killed export to ``target`` left behind.

    Only files named as ours for this target (``.NAME.barymesh-PID-….tmp…``)
    whose process is no longer running and that are older than this process
    are removed; an export in flight in another process is left alone.
    Returns the removed paths.
    """
    target = Path(target)
    pattern = _temp_pattern(target)
    removed: list[Path] = []
    try:
        entries = list(os.scandir(target.parent))
    except OSError:
        return removed
    for entry in entries:
        match = pattern.match(entry.name)
        if not match or _alive(int(match.group(1))):
            continue
        with contextlib.suppress(OSError):
            if entry.stat(follow_symlinks=False).st_mtime < _STARTED:
                os.unlink(entry.path)
                removed.append(Path(entry.path))
                log.info("removed %s, left by an interrupted export", entry.path)
    return removed


class Terminated(SystemExit):
    """SIGTERM arrived during a write (exit code 143, as the default action gives)."""


@contextlib.contextmanager
def _sigterm_raises() -> Iterator[None]:
    """While writing, SIGTERM raises :class:`Terminated` (cleanup runs) like SIGINT does."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    try:
        previous = signal.getsignal(signal.SIGTERM)
    except (ValueError, AttributeError):
        yield
        return
    if previous not in (signal.SIG_DFL, None):
        yield  # someone else handles SIGTERM (e.g. an application): leave it to them
        return

    def terminate(signum: int, frame: object) -> None:
        raise Terminated(128 + signum)

    signal.signal(signal.SIGTERM, terminate)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def _real_target(target: Path) -> Path:
    """Where a write of ``target`` goes: through symbolic links, to the file they name."""
    if target.is_symlink():
        return Path(os.path.realpath(target))
    return target


def _new_temp(target: Path, suffix: str) -> Path:
    folder = target.parent
    if not folder.is_dir():
        what = "is not a folder" if folder.exists() else "does not exist"
        raise ExportError(f"cannot write {target}: the folder {folder} {what}")
    remove_stale_temp_files(target)
    try:
        fd, tmp_name = tempfile.mkstemp(
            prefix=f".{target.name}{TEMP_MARK}{os.getpid()}-", suffix=f".tmp{suffix}", dir=folder
        )
    except OSError as exc:
        raise ExportError(f"cannot write {target}: {exc.strerror or exc}") from None
    os.close(fd)
    return Path(tmp_name)


@contextlib.contextmanager
def atomic_paths(targets: list[str | Path], suffix: str | None = None) -> Iterator[list[Path]]:
    """Temporary paths next to ``targets`` that replace all of them only if all are written.

    Every temporary file keeps its target's extension (or ``suffix``) so writers
    that pick the format from the name still work; a target that is a symbolic
    link is written through (the file it names is replaced, the link stays).
    On any exception, or SIGINT/SIGTERM, every temporary file is removed, no
    target is touched, and the exception is re-raised (as
    :class:`ExportError` naming the first target, except interrupts).
    Temporary files that a killed export to the same targets left behind
    are removed first.
    """
    named = [Path(t) for t in targets]
    real = [_real_target(t) for t in named]
    tmps: list[Path] = []
    try:
        with _sigterm_raises():
            for shown, target in zip(named, real, strict=True):
                tmps.append(_new_temp(target, target.suffix if suffix is None else suffix))
                if shown != target and not target.parent.is_dir():
                    raise ExportError(f"cannot write {shown}: it links to a missing folder")
            yield tmps
            for tmp, target in zip(tmps, real, strict=True):
                _keep_mode(target, tmp)
            for tmp, target in zip(tmps, real, strict=True):
                os.replace(tmp, target)
    except BaseException as exc:
        for tmp in tmps:
            with contextlib.suppress(OSError):
                tmp.unlink()
        if isinstance(exc, ExportError | KeyboardInterrupt | SystemExit):
            raise
        if isinstance(exc, OSError):
            reason = exc.strerror or str(exc)
        else:
            reason = str(exc) or type(exc).__name__
        raise ExportError(f"cannot write {named[0]}: {reason}") from exc


@contextlib.contextmanager
def atomic_path(target: str | Path, suffix: str | None = None) -> Iterator[Path]:
    """A temporary path next to ``target`` that replaces ``target`` on success.

    See :func:`atomic_paths` (this is its one-file form).
    """
    with atomic_paths([target], suffix) as (tmp,):
        yield tmp


def _keep_mode(target: Path, tmp: Path) -> None:
    """Give the new file the existing file's permissions, or the usual umask ones."""
    try:
        mode = target.stat().st_mode & 0o7777
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        mode = 0o666 & ~umask
    os.chmod(tmp, mode)


def atomic_write(target: str | Path, write: Callable[[Path], object]) -> None:
    """Call ``write(tmp_path)`` and move the result to ``target`` atomically."""
    with atomic_path(target) as tmp:
        write(tmp)


def atomic_write_bytes(target: str | Path, data: bytes) -> None:
    """Write ``data`` to ``target`` atomically."""
    atomic_write(target, lambda tmp: tmp.write_bytes(data))


def atomic_write_text(target: str | Path, text: str) -> None:
    """Write UTF-8 ``text`` to ``target`` atomically."""
    atomic_write(target, lambda tmp: tmp.write_text(text, encoding="utf-8"))

"""Atomic file writes: a temporary file in the target folder, then one rename.

A failed or interrupted write leaves no half-written file under the target
name, removes its temporary file and keeps any existing file as it was.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path


class ExportError(OSError):
    """A mesh file could not be written; the message names the path and the reason."""


@contextlib.contextmanager
def atomic_path(target: str | Path, suffix: str | None = None) -> Iterator[Path]:
    """A temporary path next to ``target`` that replaces ``target`` on success.

    The temporary file keeps ``target``'s extension (or ``suffix``) so writers
    that pick the format from the name still work. On any exception the
    temporary file is removed and the exception is re-raised as
    :class:`ExportError` naming ``target``.
    """
    target = Path(target)
    folder = target.parent
    suffix = target.suffix if suffix is None else suffix
    if not folder.is_dir():
        what = "is not a folder" if folder.exists() else "does not exist"
        raise ExportError(f"cannot write {target}: the folder {folder} {what}")
    try:
        fd, tmp_name = tempfile.mkstemp(
            prefix=f".{target.stem}.", suffix=f".tmp{suffix}", dir=folder
        )
    except OSError as exc:
        raise ExportError(f"cannot write {target}: {exc.strerror or exc}") from None
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        yield tmp
        _keep_mode(target, tmp)
        os.replace(tmp, target)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            tmp.unlink()
        if isinstance(exc, ExportError | KeyboardInterrupt | SystemExit):
            raise
        if isinstance(exc, OSError):
            reason = exc.strerror or str(exc)
        else:
            reason = str(exc) or type(exc).__name__
        raise ExportError(f"cannot write {target}: {reason}") from exc


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

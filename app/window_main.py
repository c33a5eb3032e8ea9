"""Opening the window from the command line: ``barymesh [options]`` without a verb.

:func:`main` reads the window's options with the command line's own checks
(:mod:`barymesh.app.cli_options`), makes the application and the
:class:`~barymesh.app.window.MainWindow`, and, for ``--screenshot``/``--quit``, drives a
scripted run (:class:`ScriptedRun`).
"""

from __future__ import annotations

import logging
import os
import sys
import time
import traceback
from pathlib import Path
from typing import Any, cast

from PySide6.QtCore import QTimer
from PySide6.QtGui import QIcon
from PySide6.QtWidgets import QApplication

from barymesh.app.cli_options import (
    UsageError,
    build_window_parser,
    check_cell_usage,
    check_preset,
)
from barymesh.app.window import ICON, MainWindow
from barymesh.app.window_settings import APPLICATION, ORGANIZATION

log = logging.getLogger(__name__)


def _install_excepthook() -> None:
    """Exceptions in Qt slots go to the log and the status bar, never a crash or dialog."""

    def hook(kind: type[BaseException], exc: BaseException, tb: Any) -> None:
        if issubclass(kind, KeyboardInterrupt):
            QApplication.quit()
            return
        log.error("unexpected error:\n%s", "".join(traceback.format_exception(kind, exc, tb)))
        for widget in QApplication.topLevelWidgets():
            if isinstance(widget, MainWindow):
                widget.statusBar().showMessage(f"Internal error: {kind.__name__}: {exc}")

    sys.excepthook = hook


def _has_display() -> bool:
    if sys.platform != "linux" or os.environ.get("QT_QPA_PLATFORM"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def main(argv: list[str] | None = None) -> int:
    """Run the window; returns the exit code (0, 1 bad input or failure, 2 bad usage).

    ``barymesh [--preset NAME] [--params FILE] [--set name=value ...] [--screenshot PNG]
    [--quit]``: with ``--screenshot PNG --quit`` the window renders, saves a grab of the
    whole window and exits. ``--cell FILE`` or ``--cell-preset NAME`` (with
    ``--array N1xN2`` for the preview) open a unit cell instead of one structure.
    """
    parser = build_window_parser()
    try:
        args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    except SystemExit as exc:
        return int(exc.code or 0)
    params = None
    cell = None
    try:  # the command line's checks, in its words
        check_preset(args, None)
        check_cell_usage(args, None)
    except UsageError as exc:
        print(f"barymesh: error: {exc} (see barymesh --help)", file=sys.stderr)
        return 2
    if args.cell is not None or args.cell_preset is not None:
        from barymesh.cell import load_cell, load_cell_preset

        try:
            cell = (
                load_cell(args.cell)
                if args.cell is not None
                else load_cell_preset(args.cell_preset)
            )
        except (ValueError, TypeError, OSError) as exc:
            print(f"barymesh: error: {exc}", file=sys.stderr)
            return 1
    elif args.array is not None:
        print(
            "barymesh: error: --array previews copies of a unit cell: give --cell or "
            "--cell-preset too (see barymesh --help)",
            file=sys.stderr,
        )
        return 2
    elif args.preset or args.params or args.sets:
        from barymesh.presets import resolve_params

        try:
            params = resolve_params(args.preset, args.params, args.sets)
        except (ValueError, TypeError, OSError) as exc:
            print(f"barymesh: error: {exc}", file=sys.stderr)
            return 1
    if not _has_display():
        print(
            "barymesh: error: no display (DISPLAY is not set). The window needs one; "
            "use `xvfb-run -a barymesh ...`, or `barymesh mesh --screenshot out.png` "
            "to render without a window.",
            file=sys.stderr,
        )
        return 1
    if os.environ.get("DISPLAY") and sys.platform == "linux":
        os.environ.setdefault("QT_QPA_PLATFORM", "xcb")  # VTK's GL widget needs X, not Wayland
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    # a window's application, when there is one, is a QApplication (instance() says less)
    app = cast("QApplication | None", QApplication.instance()) or QApplication(
        [sys.argv[0] if sys.argv else "barymesh"]
    )
    app.setOrganizationName(ORGANIZATION)
    app.setApplicationName(APPLICATION)
    app.setWindowIcon(QIcon(str(ICON)))
    _install_excepthook()
    scripted = bool(args.quit or args.screenshot)
    window = MainWindow(params, scripted=scripted, cell=cell)
    if args.array is not None:
        window.cell_tools.lattice.set_copies(*args.array)
    window.show()
    if scripted:
        window.scripted_run = ScriptedRun(window, args.screenshot, args.quit)  # keep alive
        window.scripted_run.start()
    return int(app.exec())


class ScriptedRun:
    """``--screenshot`` / ``--quit``: wait for the first mesh's first paint, grab, save,
    maybe exit."""

    def __init__(self, window: MainWindow, screenshot: str | None, quit_after: bool) -> None:
        self.window, self.path, self.quit_after = window, screenshot, quit_after
        self.deadline = time.monotonic() + 120
        self.timer = QTimer(window)
        self.timer.setInterval(50)
        self.timer.timeout.connect(self._poll)

    def start(self) -> None:
        self.timer.start()

    def _poll(self) -> None:
        w = self.window
        result = w.model.result
        ready = (
            result is not None
            and not w.controller.busy
            and w.isVisible()
            # the view has painted this mesh (--quit after the first frame, not before it)
            and w.presenter.shown_scene is result.scene
            and not w.presenter.paint_pending
            and w.paint_counter.paints > 0
        )
        if not ready and time.monotonic() < self.deadline:
            return
        self.timer.stop()
        code = 0
        if not ready:
            print("barymesh: error: the mesh was not ready in time", file=sys.stderr)
            code = 1
        elif self.path:
            QApplication.processEvents()
            w.plotter.render()
            path = Path(self.path)
            if not w.grab().save(str(path), "PNG"):
                print(f"barymesh: error: could not write {path}", file=sys.stderr)
                code = 1
        if self.quit_after or code:
            w.close()
            QApplication.exit(code)

"""Shared pytest configuration.

GUI tests run in a real X11 window: pytest-xvfb starts Xvfb (size and depth are set in
pyproject.toml) and exports DISPLAY, Qt draws through its xcb platform plugin, and VTK renders
into Qt's GLX context with Mesa's software rasteriser (llvmpipe). The Debian packages this
needs are installed by scripts/system-deps.sh (run by `make test`).
"""

import os
import sys

# Before anything imports Qt: use Xvfb's X server, not Wayland (if the session has one) nor
# the `offscreen` platform, which would not exercise a real window. An explicit choice wins.
os.environ.setdefault("QT_QPA_PLATFORM", "xcb")


import pytest  # noqa: E402


@pytest.fixture(autouse=True)
def private_settings(tmp_path, monkeypatch):
    """GUI tests never read or write the user's QSettings."""
    if "PySide6.QtCore" not in sys.modules:
        return
    from PySide6.QtCore import QSettings

    QSettings.setPath(QSettings.Format.IniFormat, QSettings.Scope.UserScope, str(tmp_path))
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path))


@pytest.fixture
def window_params():
    """Parameters the ``window`` fixture opens on (override per module).

    By default a Fig. 12-like double ring of a few hundred triangles: fast to mesh and render.
    """
    from core import MeshParams

    return MeshParams(angle_step=15.0, subdivisions=2)


@pytest.fixture
def window(qtbot, window_params):
    """The main window on ``window_params``, shown in the real (Xvfb) X display."""
    pytest.importorskip("pyvistaqt")
    from app.window import MainWindow

    win = MainWindow(window_params, scripted=True)
    qtbot.addWidget(win)
    win.resize(1300, 800)
    win.show()
    qtbot.waitExposed(win)
    win.controller.flush()
    yield win
    win.close()


# -- a deterministic end of the test process ---------------------------------------------
#
# pytest-xvfb stops the X server in an atexit handler, before Python finalizes the modules
# that still hold Qt and VTK objects connected to it; that teardown then aborted the
# process now and then ("corrupted double-linked list", exit 134) after every test had
# passed. So once pytest has reported, close the windows while the X server is alive, stop
# it, and leave with pytest's own exit status without finalizing Qt and VTK.

_EXIT_STATUS = pytest.StashKey[int]()


def pytest_sessionfinish(session, exitstatus):
    session.config.stash[_EXIT_STATUS] = int(exitstatus)


@pytest.hookimpl(trylast=True)
def pytest_unconfigure(config):
    status = config.stash.get(_EXIT_STATUS, None)
    if status is None or "PySide6.QtWidgets" not in sys.modules:
        return
    from PySide6.QtWidgets import QApplication

    app = QApplication.instance()
    if app is not None:
        for widget in app.topLevelWidgets():
            widget.close()
        app.processEvents()
    sys.stdout.flush()
    sys.stderr.flush()
    try:
        import pytest_xvfb

        pytest_xvfb.shutdown_xvfb()
    except Exception:  # noqa: BLE001 - the X server is gone anyway
        pass
    os._exit(status)

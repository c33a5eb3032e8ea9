"""Shared pytest configuration.

GUI tests run in a real X11 window: pytest-xvfb starts Xvfb (size and depth are set in
pyproject.toml) and exports DISPLAY, Qt draws through its xcb platform plugin, and VTK renders
into Qt's GLX context with Mesa's software rasteriser (llvmpipe). The Debian packages this
needs are installed by scripts/system-deps.sh (run by `make test`).
"""

import os
import sys
import tempfile

# Before anything imports Qt: use Xvfb's X server, not Wayland (if the session has one) nor
# the `offscreen` platform, which would not exercise a real window. An explicit choice wins.
os.environ.setdefault("QT_QPA_PLATFORM", "xcb")


import pytest  # noqa: E402
from hypothesis import HealthCheck, settings  # noqa: E402

# -- one package: the suite imports `barymesh` only -------------------------------------------
#
# `python -m pytest` puts the checkout on sys.path, where core/ and app/ are importable under
# their folders' names; a test that did so would load a second copy of every module under
# another name. pytest_sessionfinish fails the run if any test imported them.
FOLDER_NAMES = ("core", "app")

UNDER_MUTMUT = os.environ.get("MUTANT_UNDER_TEST") is not None

if UNDER_MUTMUT:  # pragma: no cover - only under `make mutate`
    # mutmut runs the tests inside its copy of the checkout (mutants/, the working
    # directory), whose core/ holds the mutated code, and it names each function by its
    # file's path (core.topology.x). So there the mesher is imported as `core`, from that
    # copy, and every `barymesh.X` the tests import is the same module object as `core.X`.
    import importlib
    import importlib.abc
    import importlib.util

    class _Alias(importlib.abc.Loader):
        def __init__(self, real: str) -> None:
            self.real = real

        def create_module(self, spec):
            return importlib.import_module(self.real)

        def exec_module(self, module) -> None:
            pass

    class _CoreAsBarymesh(importlib.abc.MetaPathFinder):
        def find_spec(self, fullname, path=None, target=None):
            top, _, rest = fullname.partition(".")
            if top != "barymesh" or rest == "app" or rest.startswith("app."):
                return None
            real = "core" + fullname[len("barymesh") :]
            return importlib.util.spec_from_loader(fullname, _Alias(real))

    sys.path.insert(0, os.getcwd())
    sys.meta_path.insert(0, _CoreAsBarymesh())

# -- hypothesis: the same examples on every run, nothing written into the checkout ---------
#
# "repeatable" (the default) derives its examples from each test's name, so a run in CI and
# on a laptop try the same cases and a failure reproduces by running the test again; no
# example database, and no timing checks (the machines are shared and noisy). "fuzz"
# (HYPOTHESIS_PROFILE=fuzz) draws fresh random examples on every run and prints the
# @reproduce_failure blob of a failure. A test's own @settings (max_examples, ...) wins over
# the profile for what it sets.

settings.register_profile(
    "repeatable",
    derandomize=True,
    database=None,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile(
    "fuzz",
    derandomize=False,
    database=None,
    deadline=None,
    print_blob=True,
    max_examples=50_000,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))

# Hypothesis also caches constants and character maps in its storage directory (./.hypothesis
# unless told otherwise): keep them in one folder of the system's temporary directory, reused
# by every run (and by the forked runs of `make mutate`, which never reach pytest's cleanup).
os.environ.setdefault(
    "HYPOTHESIS_STORAGE_DIRECTORY",
    os.path.join(tempfile.gettempdir(), f"barymesh-hypothesis-{getattr(os, 'getuid', str)()}"),
)


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
    from barymesh import MeshParams

    return MeshParams(angle_step=15.0, subdivisions=2)


@pytest.fixture
def window(qtbot, window_params):
    """The main window on ``window_params``, shown in the real (Xvfb) X display."""
    pytest.importorskip("pyvistaqt")
    from barymesh.app.window import MainWindow

    win = MainWindow(window_params, scripted=True)
    qtbot.addWidget(win)
    win.resize(1300, 800)
    win.show()
    qtbot.waitExposed(win)
    win.controller.flush()
    yield win
    win.close()


# -- VTK and Qt go before the X server -----------------------------------------------------
#
# pytest-xvfb stops Xvfb in an atexit handler. Every window a test opened used to outlive the
# test (pytest-qt's deleteLater only runs in an event loop, and closed windows stay alive as
# top-level widgets), so the interpreter's final cleanup destroyed Qt widgets holding VTK
# OpenGL render windows after their X server was gone, and aborted now and then ("corrupted
# double-linked list", exit 134) although every test had passed. Now windows are deleted
# after each test, and at the end of the session every VTK render window is finalized and
# every widget deleted while the X server is still there.


def _flush_deleted_widgets():
    from PySide6.QtCore import QCoreApplication, QEvent

    QCoreApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete)


@pytest.fixture(autouse=True)
def delete_closed_windows():
    """After each test, delete the windows pytest-qt closed (it only schedules deletion)."""
    yield
    if "PySide6.QtWidgets" not in sys.modules:
        return
    from PySide6.QtWidgets import QApplication

    if QApplication.instance() is not None:
        _flush_deleted_widgets()


def release_gui():
    """Finalize VTK render windows and interactors, then delete every top-level widget."""
    if "PySide6.QtWidgets" not in sys.modules:
        return
    from PySide6.QtWidgets import QApplication

    app = QApplication.instance()
    if app is None:
        return
    if "pyvistaqt" in sys.modules:
        from pyvistaqt import QtInteractor

        for widget in app.allWidgets():
            if isinstance(widget, QtInteractor):
                widget.close()  # Finalize()s the render window (idempotent)
    for widget in app.topLevelWidgets():
        widget.close()
        widget.deleteLater()
    _flush_deleted_widgets()
    app.processEvents()
    if "pyvista" in sys.modules:
        import pyvista

        pyvista.close_all()  # off-screen plotters a test left open
    from barymesh.app.gui_gc import collect

    collect()  # with no GL context current (see barymesh.app.gui_gc)


def pytest_sessionfinish(session, exitstatus):
    if UNDER_MUTMUT:  # pragma: no cover - there, `core` is the mutated copy on purpose
        return
    loaded = sorted(name for name in sys.modules if name.split(".")[0] in FOLDER_NAMES)
    if loaded:
        print(
            f"\nerror: the run imported {', '.join(loaded[:5])}: import barymesh, never the "
            f"folders core/ or app/ (a module would be loaded twice)",
            file=sys.stderr,
        )
        session.exitstatus = pytest.ExitCode.TESTS_FAILED


def pytest_unconfigure(config):
    release_gui()

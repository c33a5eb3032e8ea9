"""Start-up stays light: what ``import barymesh`` and the command load, in fresh processes.

Issue "Start-up", part 2: scipy's submodules, meshio, shtab and the window's libraries are
imported where they are used, not at module level, so that the mesher, ``barymesh --help``
and ``barymesh mesh`` start in a fraction of a second. Timings are not asserted here (the
machines are shared); ``benchmarks/startup.py`` measures them.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

#: Top-level packages none of the cases below may import (scipy counts by its submodules:
#: ``scipy`` itself is light, ``scipy.sparse``, ``scipy.spatial`` or ``scipy.constants`` are not).
HEAVY = (
    "scipy.sparse",
    "scipy.spatial",
    "scipy.constants",
    "scipy.linalg",
    "scipy.special",
    "scipy.io",
    "scipy.interpolate",
    "scipy.ndimage",
    "meshio",
    "shtab",
    "PySide6",
    "pyvista",
    "pyvistaqt",
    "vtk",
    "vtkmodules",
    "matplotlib",
    "dask",
    "distributed",
    "xarray",
    "pandas",
    "numba",  # the solver's compiled fill imports it on the first fill only
    "llvmlite",
)

#: Prints the heavy modules loaded after running the code it is given (as JSON, on stdout).
REPORT = """
import json, sys
heavy = {heavy!r}
found = sorted(m for m in sys.modules if any(m == h or m.startswith(h + ".") for h in heavy))
sys.stdout = sys.__stdout__
print(json.dumps(found))
"""


def heavy_modules(code: str) -> list[str]:
    """The modules of :data:`HEAVY` that a fresh Python has loaded after running ``code``."""
    env = dict(os.environ)
    env.pop("DISPLAY", None)
    script = f"{code}\n{REPORT.format(heavy=HEAVY)}"
    out = subprocess.run(
        [sys.executable, "-c", script],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout.strip().splitlines()[-1])


def command(*args: str) -> str:
    """Code that runs ``barymesh ARGS`` in-process, its output swallowed, its exit caught."""
    return (
        "import io, sys\n"
        "from barymesh.app.launch import main\n"
        "sys.stdout = io.StringIO()\n"
        "try:\n"
        f"    code = main({list(args)!r})\n"
        "except SystemExit as stop:\n"
        "    code = stop.code\n"
        "assert code in (0, None), code\n"
    )


def test_import_barymesh_loads_no_heavy_module():
    assert heavy_modules("import barymesh") == []


def test_the_mesher_api_loads_no_heavy_module():
    # the names of barymesh.__all__ (imported when asked for) and the constants
    code = (
        "from barymesh import MeshParams, TriMesh, build_mesh, EdgeTopology, RWGTable\n"
        "from barymesh.constants import SPEED_OF_LIGHT, wavelength\n"
    )
    assert heavy_modules(code) == []


def test_a_small_mesh_and_its_statistics_load_no_heavy_module():
    code = (
        "from barymesh import MeshParams, build_mesh\n"
        "mesh = build_mesh(MeshParams(structure='patch'))\n"
        "assert mesh.stats()['triangles'] == 32\n"
    )
    assert heavy_modules(code) == []


@pytest.mark.parametrize(
    "args",
    [
        ("--help",),
        ("mesh", "--help"),
        ("solve", "--help"),
        ("study", "--help"),
        ("library", "--help"),
        ("--version",),
        ("presets",),
        ("mesh", "--preset", "paper-fig10", "--stats-json", "-"),
    ],
    ids=" ".join,
)
def test_the_command_loads_no_heavy_module(args):
    assert heavy_modules(command(*args)) == []


def test_the_heavy_modules_still_come_when_used():
    # the guard sees imports made inside functions: the connectivity matrix is scipy's
    code = (
        "from barymesh import MeshParams, build_mesh\n"
        "build_mesh(MeshParams(structure='patch')).connectivity\n"
        "from barymesh.constants import ETA0\n"
    )
    found = heavy_modules(code)
    assert "scipy.sparse" in found and "scipy.constants" in found
    assert heavy_modules(command("--print-completion", "bash")) == ["shtab"]


def test_the_scene_data_that_worker_threads_make_imports_no_vtk():
    """Worker threads make the view's layers (``barymesh.app.view.scene_data``); VTK
    objects made or freed off the GUI thread corrupt the heap, so that module (and what
    it imports) must not even import VTK or pyvista."""
    code = (
        "import sys, barymesh.app.view.scene_data as s, barymesh.app.worker;"
        "print(sorted(m for m in sys.modules if m.split('.')[0] in ('vtk', 'vtkmodules',"
        " 'pyvista', 'pyvistaqt')))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True
    )
    assert out.stdout.strip() == "[]", out.stdout


def test_importing_the_window_leaves_matplotlib_for_later():
    """The connectivity matrix (matplotlib) is made when its dock is first shown: the
    window's import, on the way to its first frame, does not pay for matplotlib."""
    code = "import sys, barymesh.app.window; print('matplotlib' in sys.modules)"
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True
    )
    assert out.stdout.strip() == "False", out.stdout


def test_importing_the_window_loads_no_scipy_submodule():
    """The window's first frame needs none of scipy: the element lookup's k-d tree and the
    pixel painter's region labels import theirs when first used (a third of a second of a
    start-up whose target is two)."""
    found = heavy_modules("import barymesh.app.window_main")
    assert [m for m in found if m.startswith("scipy.")] == []
    assert "PySide6" in found  # the guard sees what the window does import


def test_copying_a_stack_into_an_editor_leaves_the_solver_for_later():
    """The Reflection phase tab copies the Infinite array tab's stack while the window is
    built: showing a good stack must not read it back through barymesh.mom (0.7 s on the
    GUI thread, which had pushed the first frame from 1.8 s to 2.5 s)."""
    code = (
        "import os, sys\n"
        "from types import SimpleNamespace as NS\n"
        "os.environ['QT_QPA_PLATFORM'] = 'offscreen'\n"
        "from PySide6.QtWidgets import QApplication\n"
        "app = QApplication([])\n"
        "from barymesh.app.panels.stack_editor import StackEditor\n"
        "editor = StackEditor()\n"
        "layer = NS(thickness=1.575, eps_r=2.2, loss_tangent=0.0009, mu_r=1.0)\n"
        "stack = NS(above=(), below=(layer,), ground=True, is_free_standing=False)\n"
        "editor.set_stack(stack)\n"
        "assert editor.stack is stack and not editor.error\n"
        "assert editor.table.item(1, 1).text() == '1.575'\n"
        "print('barymesh.mom' in sys.modules)\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=False
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == "False", out.stdout

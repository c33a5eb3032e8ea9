"""The window's Qt-free pieces and its module boundaries (issue 18, points 4 and 5).

Nothing here imports Qt, VTK or pyvista: the models (click tools, undo history, the
build of a structure or a cell) run as plain Python, and the boundaries between the
window's modules are read from their source (imports, private members, the tool host).
"""

import ast
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from helpers import imports_of
from hypothesis import given
from hypothesis import strategies as st

from barymesh import MeshParams, build_mesh
from barymesh.app import cli_options
from barymesh.app.model import (
    CLICK_TOOLS,
    ClickTools,
    UndoHistory,
    ViewSelection,
    compute,
    compute_cell,
)
from barymesh.app.model.cell_document import CellTarget
from barymesh.cell import Element, Lattice, UnitCell

APP = Path(__file__).resolve().parents[1] / "app"
#: The window's tools (issue 18, point 4): none may import MainWindow or reach into it.
TOOL_MODULES = (
    "edit/cell_tools.py",
    "edit/drag_tool.py",
    "edit/painter.py",
    "edit/painter_opener.py",
    "edit/painter_scene.py",
    "edit/painter_toolbars.py",
    "teach/teaching_tools.py",
    "teach/teaching_windows.py",
    "view/view_tools.py",
    "dialogs/export_dialog.py",
    "dialogs/screenshot_dialog.py",
    "dialogs/help_dialog.py",
)
#: What left window.py (issue 31, point 2): the scene presenter and the File actions get
#: the plotter, the scene and the model (the File actions the tool host too), never the
#: window.
WINDOW_ROOMS = ("view/scene_presenter.py", "file_actions.py")
#: Panels and dialogs get a narrow interface too (issue 31): the host and what else they
#: need, passed in, never the window.
PANEL_MODULES = tuple(
    str(p.relative_to(APP))
    for folder in ("panels", "dialogs")
    for p in sorted((APP / folder).glob("*.py"))
    if p.name != "__init__.py"
)
GUI_MODULES = ("PySide6", "vtk", "vtkmodules", "pyvista", "pyvistaqt")
#: The paper's square patch at n = 4: 2 primary triangles x 4² = 32 sub-triangles.
PATCH = MeshParams(structure="patch", subdivisions=4)


def _tree(relative: str) -> ast.Module:
    return ast.parse((APP / relative).read_text(encoding="utf-8"))


def _others_private_members(tree: ast.Module) -> list[str]:
    """``x._name`` where ``x`` is not ``self`` or ``cls`` (dunders aside)."""
    found = []
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.Attribute)
            and node.attr.startswith("_")
            and not node.attr.startswith("__")
            and not (isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"))
        ):
            found.append(f"line {node.lineno}: {ast.unparse(node)}")
    return found


# -- the click tools ------------------------------------------------------------------


@pytest.mark.parametrize(
    ("on", "goes_to"),
    [
        ((), "select"),
        (("drag",), "select"),  # a press off an element goes on to the view
        (("inspector",), "picker"),
        (("matrix",), "picker"),
        (("inspector", "matrix"), "picker"),
        (("measure",), "measure"),
        (("inspector", "measure"), "measure"),  # measuring takes the clicks from the picker
        (("matrix", "measure", "drag"), "measure"),
    ],
)
def test_a_click_goes_to_measure_then_the_picker_then_the_selection(on, goes_to):
    clicks = ClickTools()
    for tool in on:
        assert clicks.set_on(tool, True)
    assert clicks.click_goes_to() == goes_to
    assert clicks.picking == bool({"inspector", "matrix"} & set(on))
    assert clicks.measuring == ("measure" in on)
    assert {t for t in CLICK_TOOLS if clicks.is_on(t)} == set(on)


def test_click_tools_announce_each_change_once():
    clicks, heard = ClickTools(), []
    clicks.changed.connect(lambda tool, on: heard.append((tool, on)))
    assert clicks.set_on("measure", 1) and not clicks.set_on("measure", True)
    assert clicks.set_on("measure", False)
    assert heard == [("measure", True), ("measure", False)]


def test_an_unknown_click_tool_is_named():
    with pytest.raises(ValueError, match=r"tool='zoom' is unknown; expected one of inspector"):
        ClickTools().set_on("zoom", True)


# -- the view's selection --------------------------------------------------------------


class _Hit:
    def __init__(self, triangle):
        self.triangle = triangle


def test_zoom_frames_a_measurement_then_the_teach_tools_then_a_click():
    """On the paper's n = 4 patch (32 triangles): each source gives its own corners."""
    mesh = build_mesh(PATCH)
    selection, heard = ViewSelection(), []
    selection.changed.connect(heard.append)
    assert selection.points(mesh) is None and selection.points(None, taught=[1]) is None
    hit = _Hit(5)
    selection.click(hit)
    selection.click(hit)  # the same element again: no news
    assert heard == [hit]
    np.testing.assert_array_equal(selection.points(mesh), mesh.points[mesh.triangles[5]])
    taught = selection.points(mesh, taught=[3, 9])
    np.testing.assert_array_equal(taught, mesh.points[mesh.triangles[[3, 9]]].reshape(6, 3))
    measured = selection.points(None, measured=[(0, 0, 0), (2.5, 1, 0)], taught=[3])
    assert measured.shape == (2, 3) and measured.dtype == np.float64 and measured[1, 0] == 2.5
    selection.clear()
    assert selection.clicked is None and selection.points(mesh) is None


# -- the undo history -----------------------------------------------------------------

OPS = st.lists(
    st.one_of(st.tuples(st.just("push"), st.integers(0, 3)), st.sampled_from(["undo", "redo"])),
    max_size=40,
)


@given(OPS)
def test_undo_history_matches_a_list_and_a_position(ops):
    """Against the plainest reference: done = states[:k + 1], a push truncates the rest."""
    history, states, k = UndoHistory(0), [0], 0
    for op in ops:
        if op == "undo":
            expected = states[k - 1] if k > 0 else None
            k = max(k - 1, 0)
            assert history.undo() == expected
        elif op == "redo":
            expected = states[k + 1] if k < len(states) - 1 else None
            k = min(k + 1, len(states) - 1)
            assert history.redo() == expected
        else:
            value = op[1]
            changed = value != states[k]
            if changed:
                states, k = [*states[: k + 1], value], k + 1
            assert history.push(value) == changed
        assert history.states == states and history.position == k
        assert history.current == states[k] and len(history) == len(states)
        assert history.can_undo == (k > 0) and history.can_redo == (k < len(states) - 1)
        assert history.previous == (states[k - 1] if k > 0 else None)


def test_undo_history_reset_starts_a_new_document():
    history = UndoHistory("a")
    history.push("b")
    history.reset("z")
    assert history.states == ["z"] and not history.can_undo and history.undo() is None


# -- one build path for a structure and a cell ----------------------------------------


def test_a_structure_and_the_same_structure_as_a_cell_build_alike():
    """The paper's n = 4 patch: 2 primary triangles x 16 = 32, as a structure and as the
    one element of a cell (the same stages timed, the cell's extras only for the cell)."""
    cell = UnitCell(Lattice.rectangular(20), (Element(PATCH, name="a"),))
    alone, inside = compute(PATCH, 7), compute(CellTarget(cell), 7)
    assert alone.stats["triangles"] == inside.stats["triangles"] == 32
    assert alone.stats["interior_edges"] == inside.stats["interior_edges"]
    assert (alone.params, alone.cell, alone.cell_mesh, alone.cell_stats) == (PATCH, None, None, {})
    assert inside.params is None and inside.cell is cell and inside.cell_mesh is not None
    assert inside.cell_stats["parts"][0]["triangles"] == 32
    assert alone.generation == inside.generation == 7
    assert set(alone.timings) == set(inside.timings) == {"build", "statistics"}
    assert alone.target == PATCH and inside.target == CellTarget(cell)


def test_a_scene_is_prepared_and_timed_on_both_paths():
    cell = UnitCell(Lattice.rectangular(20), (Element(PATCH, name="a"),))
    for target in (PATCH, CellTarget(cell)):
        result = compute(target, prepare=lambda mesh: mesh.n_triangles)
        assert result.scene == 32 and "scene" in result.timings


def test_a_cancelled_build_says_so_on_both_paths():
    """The core checks ``cancel`` between its own stages (a structure stops inside the
    build); a cell's build does not take it, so it stops right after."""
    cell = UnitCell(Lattice.rectangular(20), (Element(PATCH, name="a"),))
    for result, params, made_of, timed in (
        (compute(PATCH, 3, cancel=lambda: True), PATCH, None, []),
        (compute_cell(cell, 3, cancel=lambda: True), None, cell, ["build"]),
    ):
        assert result.cancelled and result.error == "cancelled" and result.mesh is None
        assert (result.generation, result.params, result.cell) == (3, params, made_of)
        assert list(result.timings) == timed


def test_a_refused_cell_names_itself_and_a_failed_structure_says_meshing_failed(monkeypatch):
    both = (Element(PATCH, name="a"), Element(PATCH, name="b"))
    cell = UnitCell(Lattice.rectangular(20), both, mode="conforming", name="twins")
    refused = compute_cell(cell)
    assert refused.error.startswith("cell 'twins': element 'a' (elements[0]) and element 'b'")
    assert refused.cell is cell and refused.mesh is None and not refused.cancelled

    import barymesh.app.model.build as build

    def broken(params, cancel=None):
        raise ValueError("the weld found no vertices")

    monkeypatch.setattr(build, "build_mesh", broken)
    failed = compute(PATCH)
    assert failed.error == "meshing failed: the weld found no vertices"
    assert failed.params == PATCH and failed.cell is None and failed.mesh is None


# -- the command line: one parser for the window --------------------------------------


def test_the_window_options_are_parsed_by_one_parser():
    args = cli_options.build_window_parser().parse_args(
        ["--cell-preset", "x", "--array", "3x2", "--set", "a=1", "b=2", "--quit"]
    )
    assert (args.cell_preset, args.array, args.sets, args.quit) == (
        "x",
        (3, 2),
        ["a=1", "b=2"],
        True,
    )
    with pytest.raises(SystemExit) as bad:
        cli_options.build_window_parser().parse_args(["--array", "0x2"])
    assert bad.value.code == 2
    # the window builds no parser of its own, and the two command-line modules share theirs
    for relative in ("window.py", "cli_solve.py"):
        calls = [
            ast.unparse(node.func)
            for node in ast.walk(_tree(relative))
            if isinstance(node, ast.Call) and ast.unparse(node.func).endswith("ArgumentParser")
        ]
        assert calls == [], relative


# -- module boundaries ----------------------------------------------------------------


@pytest.mark.parametrize("relative", sorted(set(TOOL_MODULES + PANEL_MODULES + WINDOW_ROOMS)))
def test_no_tool_imports_the_main_window_or_reaches_into_another_object(relative):
    tree = _tree(relative)
    imported = [
        node.module
        for node in ast.walk(tree)
        if isinstance(node, ast.ImportFrom) and node.module == "barymesh.app.window"
    ]
    assert imported == []
    assert _others_private_members(tree) == []
    # and none is handed the window itself: a parameter named window is one
    given_window = [
        f"line {node.lineno}: {node.name}"
        for node in ast.walk(tree)
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)
        and any(a.arg in ("window", "main_window") for a in node.args.args + node.args.kwonlyargs)
    ]
    assert given_window == []


def test_no_app_module_imports_a_private_name_of_another():
    imports = []
    for path in sorted(APP.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("barymesh"):
                imports += [
                    f"{path.relative_to(APP)}: {node.module}.{alias.name}"
                    for alias in node.names
                    if alias.name.startswith("_") and not alias.name.startswith("__")
                ]
    assert imports == []


def test_the_main_window_implements_the_whole_tool_host():
    def members(tree: ast.Module, name: str) -> set[str]:
        cls = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == name)
        return {n.name for n in cls.body if isinstance(n, ast.FunctionDef)}

    wanted = members(_tree("tool_host.py"), "ToolHost")
    assert {"add_action", "add_dock", "show_status", "request_render", "file_error"} <= wanted
    assert {"setting", "set_setting"} <= wanted
    assert wanted <= members(_tree("window.py"), "MainWindow")


def test_the_models_import_nothing_of_the_window_above_them():
    # the model knows nothing of the widgets, the view or the editors (napari's
    # components/ and _qt/): what it shares with them lives in app/model
    found = []
    for path in sorted((APP / "model").rglob("*.py")):
        for _, names in imports_of(ast.parse(path.read_text(encoding="utf-8"))):
            found += [
                f"{path.relative_to(APP)}: {name}"
                for name in names
                if name.startswith("barymesh.app.") and not name.startswith("barymesh.app.model")
            ]
    assert found == []


@pytest.mark.parametrize(
    "modules",
    [
        "barymesh.app.model, barymesh.app.cli, barymesh.app.cli_options",
        # what the pixel painter's worker thread builds: numpy arrays only (style rule 17)
        "barymesh.app.edit.painter_preview",
    ],
)
def test_the_models_the_command_line_and_the_painters_worker_side_import_no_qt_or_vtk(modules):
    code = (
        f"import sys, {modules}; "
        f"print(sorted({{m.split('.')[0] for m in sys.modules}} & set({GUI_MODULES!r})))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120
    )
    assert out.stdout.strip() == "[]"

"""Unit cells in the real window (Xvfb): cell files and presets, the Elements panel, the
lattice and the array preview, driven as a user does; every mesh is compared with
core.cell.build_cell of the cell the user should have made."""

import json
import os
import subprocess
import sys

import imageio.v3 as iio
import numpy as np
import pytest

pytest.importorskip("pyvistaqt")

from PySide6.QtCore import Qt  # noqa: E402
from PySide6.QtTest import QTest  # noqa: E402

from app.window import file_error_sentence  # noqa: E402
from core import MeshParams  # noqa: E402
from core.cell import (  # noqa: E402
    build_cell,
    cell_to_dict,
    load_cell,
    load_cell_preset,
)
from tests.app_user import answer_file_dialogs, settle, shown_counts  # noqa: E402

COARSE = MeshParams(angle_step=15.0, subdivisions=2)  # = conftest's window_params


def open_preset(window, qtbot, name):
    """Cell ▸ Cell presets ▸ ``name``, then wait for the mesh."""
    window.cell_tools.preset_actions[name].trigger()
    settle(window, qtbot)


def assert_shows(window, cell):
    """The mesh on screen is build_cell(cell): counts, and every part's row."""
    expected = build_cell(cell)
    result = window.model.result
    assert result.error is None and result.cell == cell
    assert result.mesh.n_triangles == expected.mesh.n_triangles
    assert np.array_equal(result.mesh.triangles, expected.mesh.triangles)
    assert np.allclose(result.mesh.points, expected.mesh.points)
    s = expected.mesh.stats()
    shown = shown_counts(window)
    for key in ("patches", "vertices", "triangles", "edges", "interior_edges"):
        assert shown[key] == s[key], key
    table = window.stats.cell
    assert table.table.rowCount() == len(expected.part_meshes)
    for row, part in enumerate(expected.part_stats()):
        assert table.cell_text(row, "Part") == part["name"]
        assert table.cell_text(row, "Triangles") == f"{part['triangles']:,}"
        assert table.cell_text(row, "RWG unknowns") == f"{part['interior_edges']:,}"
    pairs = len(expected.periodic_pairs.edges)
    assert table.periodic.text().startswith(
        f"Periodic edge pairs across the cell's sides: {pairs:,}")


def list_click(window, row, column=0, double=False):
    """A left click (or double click) on the Elements list's ``row``."""
    tree = window.cell_tools.elements.list
    rect = tree.visualItemRect(tree.topLevelItem(row))
    pos = rect.center()
    if column == 0:
        pos.setX(rect.left() + tree.columnWidth(0) // 2 + 10)
    click = QTest.mouseDClick if double else QTest.mouseClick
    click(tree.viewport(), Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, pos)


def check_box_click(window, row):
    """A click on the check box of ``row`` (shown = checked)."""
    from PySide6.QtWidgets import QStyle, QStyleOptionViewItem

    tree = window.cell_tools.elements.list
    item = tree.topLevelItem(row)
    index = tree.indexFromItem(item, 0)
    opt = QStyleOptionViewItem()
    opt.initFrom(tree)
    opt.rect = tree.visualRect(index)
    opt.features |= QStyleOptionViewItem.ViewItemFeature.HasCheckIndicator
    check = tree.style().subElementRect(QStyle.SubElement.SE_ItemViewItemCheckIndicator, opt, tree)
    QTest.mouseClick(tree.viewport(), Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier,
                     check.center())


# -- files, presets, command line ------------------------------------------------------


@pytest.mark.parametrize("name", ["double-ring-patch", "split-ring-pair", "hexagonal-rings",
                                  "coding-16x16"])
def test_each_cell_preset_shows_its_cell_and_undo_returns(window, qtbot, name):
    open_preset(window, qtbot, name)
    cell = load_cell_preset(name)
    assert_shows(window, cell)
    assert window.windowTitle() == f"barymesh – cell {cell.name}"
    elements = window.cell_tools.elements.list
    assert elements.topLevelItemCount() == len(cell.elements)
    # a pixel-only cell has no element for the Parameters panel to edit
    assert window.controls.isEnabled() is bool(cell.elements)
    window.act_undo.trigger()
    settle(window, qtbot)
    assert window.model.cell is None and window.model.params == COARSE
    assert window.model.result.cell is None and shown_counts(window)["triangles"] == 384
    assert not window.stats.cell.isVisibleTo(window.stats)
    window.act_redo.trigger()
    settle(window, qtbot)
    assert_shows(window, cell)


def test_open_and_save_cell_files(window, qtbot, tmp_path, monkeypatch):
    answer = answer_file_dialogs(monkeypatch)
    cell = load_cell_preset("split-ring-pair")
    good = tmp_path / "pair.cell.json"
    good.write_text(json.dumps(cell_to_dict(cell)))
    answer(good)
    window.cell_tools.act_open.trigger()
    settle(window, qtbot)
    assert_shows(window, cell)

    # a bad document: one sentence naming the file and the place in it; the cell stays
    data = cell_to_dict(cell)
    data["elements"][1]["inner_radius"] = -2
    bad = tmp_path / "bad.cell.json"
    bad.write_text(json.dumps(data))
    with pytest.raises(ValueError) as refusal:
        load_cell(bad)
    answer(bad)
    window.cell_tools.act_open.trigger()
    settle(window, qtbot)
    message = window.statusBar().currentMessage()
    assert message == file_error_sentence("Could not open bad.cell.json", refusal.value, bad)
    assert message.startswith("Could not open bad.cell.json: elements[1].inner_radius: ")
    assert str(tmp_path) not in message
    assert window.model.cell == cell and window.model.result.cell == cell

    # File ▸ Save cell writes what load_cell reads back, hidden elements included
    window.cell_tools.elements.list.setFocus()
    check_box_click(window, 0)
    settle(window, qtbot)
    assert window.model.cell_state.hidden == (True, False)
    saved = tmp_path / "saved"
    answer(saved)
    window.cell_tools.act_save.trigger()
    assert load_cell(tmp_path / "saved.cell.json") == cell


def test_command_line_opens_the_window_on_a_cell(tmp_path):
    out = tmp_path / "cell.png"
    env = dict(os.environ, XDG_CONFIG_HOME=str(tmp_path))
    proc = subprocess.run(
        [sys.executable, "-m", "app", "--cell-preset", "hexagonal-rings", "--screenshot",
         str(out), "--quit"], env=env, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    image = iio.imread(out)
    assert image.shape[0] > 300 and len(np.unique(image[..., :3].reshape(-1, 3), axis=0)) > 10
    bad = subprocess.run(
        [sys.executable, "-m", "app", "--cell-preset", "hexagonal-rings", "--preset",
         "paper-fig10", "--quit"], env=env, capture_output=True, text=True, timeout=60)
    assert bad.returncode == 2
    assert bad.stderr.strip().splitlines() == [
        "barymesh: error: --preset cannot go with --cell-preset: a cell holds its own "
        "elements and their parameters (see barymesh --help)"]
    nofile = subprocess.run([sys.executable, "-m", "app", "--cell", str(tmp_path / "no.cell.json"),
                             "--quit"], env=env, capture_output=True, text=True, timeout=60)
    assert nofile.returncode == 1 and "no.cell.json" in nofile.stderr
    assert "Traceback" not in nofile.stderr


def test_main_cli_passes_cell_options_to_the_window(monkeypatch):
    import app.window
    from app import cli

    seen = []
    monkeypatch.setattr(app.window, "main", lambda argv: seen.append(argv) or 0)
    assert cli.main(["--cell-preset", "coding-16x16"]) == 0
    assert seen == [["--cell-preset", "coding-16x16"]]

"""Unit cells in the real window (Xvfb): cell files and presets, the Elements panel, the
lattice and the array preview, driven as a user does; every mesh is compared with
barymesh.cell.build_cell of the cell the user should have made."""

import json
import os
import subprocess
import sys

import imageio.v3 as iio
import numpy as np
import pytest

pytest.importorskip("pyvistaqt")

from app_user import (  # noqa: E402
    answer_file_dialogs,
    choose,
    settle,
    shown_counts,
    type_into,
    wait_for_export,
)
from PySide6.QtCore import Qt  # noqa: E402
from PySide6.QtTest import QTest  # noqa: E402

from barymesh import MeshParams  # noqa: E402
from barymesh.app.edit.painter_opener import cell_menu  # noqa: E402
from barymesh.app.window import file_error_sentence  # noqa: E402
from barymesh.cell import (  # noqa: E402
    Element,
    Lattice,
    build_cell,
    cell_to_dict,
    load_cell,
    load_cell_preset,
    tile,
)

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
    assert table.part_count() == len(expected.part_meshes)
    for row, part in enumerate(expected.part_stats()):
        assert table.cell_text(row, "Part") == part["name"]
        assert table.cell_text(row, "Triangles") == f"{part['triangles']:,}"
        assert table.cell_text(row, "RWG unknowns") == f"{part['interior_edges']:,}"
    pairs = len(expected.periodic_pairs.edges)
    assert table.periodic.text().startswith(
        f"Periodic edge pairs across the cell's sides: {pairs:,}"
    )


def list_click(window, row, column=0, double=False):
    """A left click (or double click) on the Elements list's ``row``."""
    tree = window.cell_tools.elements.list
    rect = tree.visualItemRect(tree.topLevelItem(row))
    pos = rect.center()
    if column == 0:
        pos.setX(rect.left() + tree.columnWidth(0) // 2 + 10)
    left, none = Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier
    QTest.mouseClick(tree.viewport(), left, none, pos)
    if double:  # a double click is a click, then the second press (a double-click event)
        QTest.mouseDClick(tree.viewport(), left, none, pos)


def rename(window, row, text):
    """Double-click the name of ``row``, type ``text`` and Enter into the editor it opens."""
    from PySide6.QtWidgets import QApplication, QLineEdit

    list_click(window, row, double=True)
    editors = window.cell_tools.elements.list.findChildren(QLineEdit)
    assert len(editors) == 1
    type_into(editors[0], text)
    QApplication.processEvents()  # the view commits the editor's text in a queued call
    QApplication.processEvents()  # and a refused name is put back in the next round


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
    QTest.mouseClick(
        tree.viewport(), Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, check.center()
    )


# -- files, presets, command line ------------------------------------------------------


@pytest.mark.parametrize(
    "name", ["double-ring-patch", "split-ring-pair", "hexagonal-rings", "coding-16x16"]
)
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
        [
            sys.executable,
            "-m",
            "barymesh.app",
            "--cell-preset",
            "hexagonal-rings",
            "--screenshot",
            str(out),
            "--quit",
        ],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    image = iio.imread(out)
    assert image.shape[0] > 300 and len(np.unique(image[..., :3].reshape(-1, 3), axis=0)) > 10
    bad = subprocess.run(
        [
            sys.executable,
            "-m",
            "barymesh.app",
            "--cell-preset",
            "hexagonal-rings",
            "--preset",
            "paper-fig10",
            "--quit",
        ],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert bad.returncode == 2
    assert bad.stderr.strip().splitlines() == [
        "barymesh: error: --preset sets the parameters of one structure; a cell "
        "(--cell-preset) holds its own elements: edit its file instead (see barymesh --help)"
    ]
    nofile = subprocess.run(
        [sys.executable, "-m", "barymesh.app", "--cell", str(tmp_path / "no.cell.json"), "--quit"],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert nofile.returncode == 1 and "no.cell.json" in nofile.stderr
    assert "Traceback" not in nofile.stderr


def test_main_cli_passes_cell_options_to_the_window(monkeypatch):
    import barymesh.app.window_main
    from barymesh.app import cli

    seen = []
    monkeypatch.setattr(barymesh.app.window_main, "main", lambda argv: seen.append(argv) or 0)
    assert cli.main(["--cell-preset", "coding-16x16"]) == 0
    assert seen == [["--cell-preset", "coding-16x16"]]


# -- the Elements panel ----------------------------------------------------------------


def replaced(cell, k, **changes):
    """``cell`` with element ``k`` changed (params fields, or position/rotation/name)."""
    el = cell.elements[k]
    own = {key: changes.pop(key) for key in ("position", "rotation", "name") if key in changes}
    params = el.params.replace(**changes) if changes else el.params
    new = Element(
        params,
        own.get("position", el.position),
        own.get("rotation", el.rotation),
        own.get("name", el.name),
    )
    return cell.replace(elements=cell.elements[:k] + (new,) + cell.elements[k + 1 :])


def test_selected_element_is_edited_by_the_parameters_and_its_fields(window, qtbot):
    open_preset(window, qtbot, "double-ring-patch")
    cell = load_cell_preset("double-ring-patch")
    panel = window.cell_tools.elements
    list_click(window, 1)
    assert window.model.cell_state.selected == 1
    assert window.controls.combos["structure"].currentData() == "patch"
    assert window.controls.rows["patch_size"].field.text() == "3"
    assert panel.position.text() == "-1.5, -1.5"
    assert window.parameters_dock.windowTitle() == "Parameters – element centre patch"
    steps = len(window.model.undo_stack)

    type_into(window.controls.rows["patch_size"].field, "4")
    settle(window, qtbot)
    edited = replaced(cell, 1, patch_size=4.0)
    assert_shows(window, edited)
    type_into(panel.position, "-2, -2")
    settle(window, qtbot)
    edited = replaced(edited, 1, position=(-2.0, -2.0))
    assert_shows(window, edited)
    type_into(panel.rotation, "45")
    settle(window, qtbot)
    edited = replaced(edited, 1, rotation=45.0)
    assert_shows(window, edited)
    assert len(window.model.undo_stack) == steps + 3  # one undo step per edit

    # a value the element refuses: the field says why, the cell and its mesh stay
    shown = window.model.result
    type_into(panel.position, "left")
    settle(window, qtbot)
    assert window.model.result is shown and window.model.cell == edited
    assert panel.error.text() == "position='left' is invalid; expected two numbers (x, y) in mm"
    assert panel.position.text() == "left" and "border" in panel.position.styleSheet()

    # the first element again: the Parameters panel shows the rings
    list_click(window, 0)
    assert window.controls.rows["inner_radius"].field.text() == "5"
    assert window.model.cell_state.selected == 0
    for _ in range(3):
        window.act_undo.trigger()
    settle(window, qtbot)
    assert_shows(window, cell)
    assert window.model.cell_state.selected == 1  # the selection of that step


def test_add_duplicate_delete_move_hide_rename(window, qtbot):
    open_preset(window, qtbot, "double-ring-patch")
    cell = load_cell_preset("double-ring-patch")
    panel = window.cell_tools.elements
    steps = len(window.model.undo_stack)
    ring = Element(MeshParams(structure="ring"), name="ring")

    add = next(a for a in panel.add_menu.actions() if a.text() == "Ring")
    add.trigger()  # Add ▸ Ring (a worker build: 11,520 triangles)
    settle(window, qtbot)
    expected = cell.replace(elements=cell.elements + (ring,))
    assert_shows(window, expected)
    assert window.model.cell_state.selected == 2

    QTest.mouseClick(
        panel.findChild(type(panel.add_button), "element_duplicate"), Qt.MouseButton.LeftButton
    )
    settle(window, qtbot)
    twin = Element(ring.params, name="ring 2")
    assert_shows(window, cell.replace(elements=cell.elements + (ring, twin)))

    panel.list.setFocus()
    QTest.keyClick(panel.list, Qt.Key.Key_Delete)  # the selected copy
    settle(window, qtbot)
    assert_shows(window, expected)

    QTest.keyClick(panel.list, Qt.Key.Key_Up, Qt.KeyboardModifier.AltModifier)
    settle(window, qtbot)
    moved = cell.replace(elements=(cell.elements[0], ring, cell.elements[1]))
    assert_shows(window, moved)
    assert [panel.list.topLevelItem(k).text(0) for k in range(3)] == [
        "rings",
        "ring",
        "centre patch",
    ]

    check_box_click(window, 0)  # hide the rings: not meshed, still in the cell
    settle(window, qtbot)
    assert window.model.cell == moved
    assert_shows(window, moved.replace(elements=moved.elements[1:]))

    rename(window, 2, "disc")  # the centre patch
    settle(window, qtbot)
    renamed = replaced(moved, 2, name="disc")
    assert window.model.cell == renamed
    assert_shows(window, renamed.replace(elements=renamed.elements[1:]))

    # a name already taken is refused with the core's words; nothing changes
    rename(window, 2, "ring")
    settle(window, qtbot)
    assert window.model.cell == renamed and panel.list.topLevelItem(2).text(0) == "disc"
    assert panel.error.text() == (
        "elements[2].name='ring' is already the name of elements[1]; element names must be unique"
    )

    assert len(window.model.undo_stack) == steps + 6  # add, duplicate, delete, move, hide, rename
    for _ in range(6):
        window.act_undo.trigger()
    settle(window, qtbot)
    assert_shows(window, cell)


def test_hiding_every_element_is_refused(window, qtbot):
    open_preset(window, qtbot, "hexagonal-rings")
    shown = window.model.result
    check_box_click(window, 0)
    settle(window, qtbot)
    assert window.model.result is shown and window.model.cell_state.hidden == (False,)
    assert window.cell_tools.elements.error.text() == (
        "every element is hidden: the cell would have no metal to mesh"
    )
    tree = window.cell_tools.elements.list
    qtbot.waitUntil(lambda: tree.topLevelItem(0).checkState(0) == Qt.CheckState.Checked)


def test_conforming_overlap_is_refused_naming_both_and_the_mesh_stays(window, qtbot):
    open_preset(window, qtbot, "hexagonal-rings")
    cell = load_cell_preset("hexagonal-rings")
    panel = window.cell_tools.elements
    next(a for a in panel.add_menu.actions() if a.text() == "Square patch").trigger()
    settle(window, qtbot)
    patch = Element(MeshParams(structure="patch", mode="conforming"), name="patch")
    with_patch = cell.replace(elements=cell.elements + (patch,))  # inside the ring's hole
    assert_shows(window, with_patch)
    shown = window.model.result
    steps = len(window.model.undo_stack)

    type_into(panel.position, "2.5, 0")  # onto the ring's track
    settle(window, qtbot)
    with pytest.raises(ValueError) as refusal:
        build_cell(replaced(with_patch, 1, position=(2.5, 0.0)))
    assert "element 'ring' (elements[0]) and element 'patch' (elements[1]) overlap" in str(
        refusal.value
    )
    assert panel.error.text() == f"cell 'hexagonal-rings': {refusal.value}"
    assert not panel.error.isHidden()
    assert window.model.result is shown and window.model.cell == with_patch
    assert panel.position.text() == "0, 0"
    assert len(window.model.undo_stack) == steps  # the refused edit left no undo step
    assert "(the last good mesh stays on screen)" in window.statusBar().currentMessage()

    type_into(panel.position, "-0.5, -0.5")  # a good place clears the message
    settle(window, qtbot)
    assert_shows(window, replaced(with_patch, 1, position=(-0.5, -0.5)))
    assert panel.error.isHidden()


# -- the lattice and the array preview -------------------------------------------------


def test_lattice_kind_and_periods(window, qtbot):
    open_preset(window, qtbot, "double-ring-patch")
    cell = load_cell_preset("double-ring-patch")
    lattice = window.cell_tools.lattice
    steps = len(window.model.undo_stack)
    choose(lattice.kind, "hexagonal")
    settle(window, qtbot)
    assert_shows(window, cell.replace(lattice=Lattice.hexagonal(20.0)))
    assert not lattice.period2.isEnabled()
    assert lattice.vectors.text() == "a1 = (20, 0) mm, a2 = (10, 17.320508076) mm"
    type_into(lattice.period1, "25")
    settle(window, qtbot)
    assert_shows(window, cell.replace(lattice=Lattice.hexagonal(25.0)))
    choose(lattice.kind, "rectangular")
    type_into(lattice.period2, "30")
    settle(window, qtbot)
    assert_shows(window, cell.replace(lattice=Lattice.rectangular(25.0, 30.0)))
    assert len(window.model.undo_stack) == steps + 4

    shown = window.model.result
    type_into(lattice.period1, "-1")
    settle(window, qtbot)
    assert window.model.result is shown
    assert window.cell_tools.elements.error.text() == (
        "px=-1.0 is invalid; expected a finite length > 0 mm"
    )
    for _ in range(4):
        window.act_undo.trigger()
    settle(window, qtbot)
    assert_shows(window, cell)


def spin_to(box, value):
    """Type ``value`` into a spin box and press Enter."""
    type_into(box.lineEdit(), str(value))


def test_array_preview_draws_copies_without_meshing_them(window, qtbot, tmp_path, monkeypatch):
    from gui_helpers import near, pixel, rendered

    from barymesh.io import read_mesh

    open_preset(window, qtbot, "double-ring-patch")
    cell = load_cell_preset("double-ring-patch")
    lattice = window.cell_tools.lattice
    preview = window.cell_tools.preview
    assert preview.ghost_triangles == 0 and "cell_outline" in window.plotter.actors
    spin_to(lattice.n1, 3)
    spin_to(lattice.n2, 2)
    assert lattice.copies == (3, 2)
    one = build_cell(cell).mesh
    assert preview.ghost_triangles == 5 * one.n_triangles  # drawn, the cell itself not again
    assert_shows(window, cell)  # the mesh is still the one cell
    ghosts = window.plotter.actors["cell_ghosts"].mapper.dataset
    assert ghosts.n_cells == 5 * one.n_triangles
    lo, hi = one.points[:, :2].min(axis=0), one.points[:, :2].max(axis=0)
    assert np.allclose(ghosts.bounds[:4], (lo[0] - 20, hi[0] + 20, lo[1], hi[1] + 20))
    assert window.plotter.actors["cell_copy_outlines"].mapper.dataset.n_lines == 5
    assert preview.bounds == (-30.0, 30.0, -10.0, 30.0)  # the copies framed, all in view

    image = rendered(window.plotter)
    # a copy's empty corner (on the left: the overlap look's colour bar stands on the right)
    background = pixel(image, window.plotter, (-27.0, 7.0, 0.0))
    assert near(background, "#ffffff", tol=10)
    for centre in ((20.0, 0.0), (-20.0, 20.0)):  # the centre patch of two copies
        assert not near(pixel(image, window.plotter, (*centre, 0.0)), "#ffffff", tol=10)

    # Cell ▸ Export array mesh: the copies welded into one mesh, as tile() makes it
    answer = answer_file_dialogs(monkeypatch)
    answer(tmp_path / "array.msh")
    window.cell_tools.act_export_array.trigger()
    wait_for_export(window)  # written in a worker thread
    written = read_mesh(tmp_path / "array.msh")
    array = tile(cell, 3, 2).mesh
    assert (written.n_triangles, written.n_vertices) == (array.n_triangles, array.n_vertices)
    assert written.n_triangles == 6 * one.n_triangles

    spin_to(lattice.n1, 1)
    spin_to(lattice.n2, 1)
    assert preview.ghost_triangles == 0 and "cell_ghosts" not in window.plotter.actors
    window.act_undo.trigger()  # back to the structure: no outline
    settle(window, qtbot)
    assert "cell_outline" not in window.plotter.actors


def test_window_command_line_previews_an_array(tmp_path):
    out = tmp_path / "array.png"
    env = dict(os.environ, XDG_CONFIG_HOME=str(tmp_path))
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "barymesh.app",
            "--cell-preset",
            "coding-16x16",
            "--array",
            "3x3",
            "--screenshot",
            str(out),
            "--quit",
        ],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    assert iio.imread(out).shape[0] > 300
    alone = subprocess.run(
        [sys.executable, "-m", "barymesh.app", "--array", "3x3", "--quit"],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert alone.returncode == 2 and "--array previews copies of a unit cell" in alone.stderr


def test_mode_of_an_element_is_the_cells(window, qtbot):
    open_preset(window, qtbot, "double-ring-patch")
    cell = load_cell_preset("double-ring-patch")
    choose(window.controls.combos["mode"], "conforming")
    settle(window, qtbot)
    conforming = cell.replace(mode="conforming")
    assert_shows(window, conforming)
    assert {el.params.mode for el in window.model.cell.elements} == {"conforming"}
    window.act_undo.trigger()
    settle(window, qtbot)
    assert_shows(window, cell)


def test_new_cell_from_the_structure_on_screen(window, qtbot):
    window.cell_tools.act_new.trigger()
    settle(window, qtbot)
    cell = window.model.cell
    assert [el.params for el in cell.elements] == [COARSE]
    # COARSE's outer patches (1 mm) are centred on r = 9 mm: the one at 0° reaches
    # x = 9.5, a 19 mm box, centred; the cell is 1.25 times that
    points = window.model.result.mesh.points[:, :2]
    assert np.allclose(points.min(axis=0), -9.5) and np.allclose(points.max(axis=0), 9.5)
    assert cell.lattice == Lattice.rectangular(23.75)
    assert_shows(window, cell)
    assert shown_counts(window)["triangles"] == 384  # the structure's own mesh, one copy
    assert window.cell_menu.title() == "&Cell" and cell_menu(window) is window.cell_menu


# -- dragging in the view --------------------------------------------------------------


def mouse(window, kind, world, buttons):
    """A mouse event of ``kind`` on the 3D view where ``world`` (x, y mm) is drawn."""
    from gui_helpers import widget_pos
    from PySide6.QtCore import QEvent, QPointF
    from PySide6.QtGui import QMouseEvent
    from PySide6.QtWidgets import QApplication

    plotter = window.plotter
    pos = widget_pos(plotter, (*world, 0.0))
    button = Qt.MouseButton.NoButton if kind == QEvent.Type.MouseMove else Qt.MouseButton.LeftButton
    event = QMouseEvent(
        kind,
        QPointF(pos),
        QPointF(plotter.mapToGlobal(pos)),
        button,
        buttons,
        Qt.KeyboardModifier.NoModifier,
    )
    QApplication.sendEvent(plotter, event)


def drag(window, path):
    """Press at ``path[0]``, move through the rest with the button held, release at the end."""
    from PySide6.QtCore import QEvent

    left = Qt.MouseButton.LeftButton
    mouse(window, QEvent.Type.MouseButtonPress, path[0], left)
    for point in path[1:]:
        mouse(window, QEvent.Type.MouseMove, point, left)
    mouse(window, QEvent.Type.MouseButtonRelease, path[-1], Qt.MouseButton.NoButton)


def test_drag_an_element_in_the_view_snaps_to_the_grid(window, qtbot):
    from PySide6.QtCore import QEvent

    open_preset(window, qtbot, "double-ring-patch")
    cell = load_cell_preset("double-ring-patch")
    tool = window.cell_tools.dragger
    assert tool.act.shortcut().toString() == "G"
    tool.act.trigger()
    assert tool.active and window.cell_tools.elements.snap_grid == 0.5
    steps = len(window.model.undo_stack)

    # press on the centre patch (its centre is the origin), move: it follows, on the grid
    left = Qt.MouseButton.LeftButton
    mouse(window, QEvent.Type.MouseButtonPress, (0.0, 0.0), left)
    assert tool.dragging == 1 and window.model.cell_state.selected == 1
    mouse(window, QEvent.Type.MouseMove, (1.4, 0.9), left)
    assert tool.target == (0.0, -0.5)  # (-1.5, -1.5) + (1.4, 0.9) on the 0.5 mm grid
    ghost = window.plotter.actors["element_drag"]
    assert ghost.GetPosition() == (1.5, 1.0, 0.0)
    mouse(window, QEvent.Type.MouseMove, (3.5, 2.0), left)
    mouse(window, QEvent.Type.MouseButtonRelease, (3.5, 2.0), Qt.MouseButton.NoButton)
    settle(window, qtbot)
    moved = replaced(cell, 1, position=(2.0, 0.5))
    assert_shows(window, moved)
    assert "element_drag" not in window.plotter.actors
    assert len(window.model.undo_stack) == steps + 1  # the whole drag: one undo step
    assert window.cell_tools.elements.position.text() == "2, 0.5"

    # a grid must be a length; without one the position follows the pointer (to a pixel)
    type_into(window.cell_tools.elements.snap, "-1")
    assert window.cell_tools.elements.snap_grid == 0.5
    assert window.cell_tools.elements.error.text() == (
        "snap grid='-1' is invalid; expected a length > 0 mm, or empty for no snapping"
    )
    type_into(window.cell_tools.elements.snap, "")
    assert window.cell_tools.elements.snap_grid is None
    drag(window, [(2.0 + 1.5, 0.5 + 1.5), (2.0 + 1.5 - 1.13, 0.5 + 1.5 + 0.61)])
    settle(window, qtbot)
    x, y = window.model.cell.elements[1].position
    pixel_mm = 60.0 / window.plotter.width()  # the view spans more than 20 mm: generous
    assert abs(x - 0.87) < pixel_mm and abs(y - 1.11) < pixel_mm

    # a press off the metal is the camera's: nothing moves
    before = window.model.cell
    drag(window, [(9.0, 9.0), (5.0, 5.0)])
    settle(window, qtbot)
    assert window.model.cell == before and tool.dragging is None

    tool.act.trigger()  # off: a press on an element no longer moves it
    assert not tool.active
    drag(window, [(0.0, 8.5), (3.0, 8.5)])
    settle(window, qtbot)
    assert window.model.cell == before
    window.act_undo.trigger()
    window.act_undo.trigger()
    settle(window, qtbot)
    assert_shows(window, cell)


# -- refusals on opening, cancelling, and the model without a window -------------------


def overlapping_cell():
    """A conforming cell whose two elements overlap (build_cell refuses it)."""
    from barymesh.cell import UnitCell

    ring = Element(
        MeshParams(structure="ring", mode="conforming", inner_radius=3.0, angle_step=10.0),
        name="ring",
    )
    patch = Element(MeshParams(structure="patch", mode="conforming"), (2.5, 0.0), name="bar")
    return UnitCell(Lattice.rectangular(12.0), (ring, patch), mode="conforming", name="clash")


def test_opening_a_cell_the_core_refuses_keeps_the_structure(window, qtbot, tmp_path, monkeypatch):
    from barymesh.cell import save_cell

    path = tmp_path / "clash.cell.json"
    save_cell(overlapping_cell(), path)
    shown = window.model.result
    answer = answer_file_dialogs(monkeypatch)
    answer(path)
    window.cell_tools.act_open.trigger()
    settle(window, qtbot)
    with pytest.raises(ValueError) as refusal:
        build_cell(overlapping_cell())
    assert "element 'ring' (elements[0]) and element 'bar' (elements[1]) overlap" in str(
        refusal.value
    )
    assert window.model.result is shown and window.model.cell is None
    assert window.model.params == COARSE and not window.model.undo_stack
    assert window.cell_tools.elements.error.text() == f"cell 'clash': {refusal.value}"
    assert window.statusBar().currentMessage() == (
        f"cell 'clash': {refusal.value} (the last good mesh stays on screen)"
    )


def test_cancel_returns_to_the_cell_on_screen(window, qtbot):
    open_preset(window, qtbot, "double-ring-patch")
    cell = load_cell_preset("double-ring-patch")
    window.controller.sync_triangles = 0  # every build in the worker
    list_click(window, 1)
    type_into(window.cell_tools.elements.position, "4, 4")
    window.controller.flush()
    assert window.controller.busy
    window.cancel_build()  # before the worker's result is delivered
    assert window.model.cell == cell and not window.controller.busy
    qtbot.wait(200)  # the abandoned build's result arrives and is dropped
    assert_shows(window, cell)
    assert window.cell_tools.elements.position.text() == "-1.5, -1.5"


def test_model_cell_undo_and_refusals_without_qt():
    from barymesh.app.model import AppModel, compute
    from barymesh.app.model.cell_document import CellState, CellTarget, predicted_triangles

    cell = load_cell_preset("split-ring-pair")
    model = AppModel(COARSE)
    model.set_cell(cell)
    assert model.build_target() == CellTarget(cell) and model.params == cell.elements[0].params
    assert predicted_triangles(cell) == build_cell(cell).mesh.n_triangles
    result = compute(model.build_target(), model.generation)
    assert model.set_result(result) and result.cell_stats["parts"][1]["name"] == "right ring"

    assert model.set_value("gap_width", 0.5)  # the selected element's parameter
    assert model.cell.elements[0].params.gap_width == 0.5
    assert model.cell.elements[1] == cell.elements[1]
    assert not model.edit_cell(lambda s: s.renamed(0, "right ring"))
    assert model.cell_error.endswith("element names must be unique")
    assert model.edit_cell(lambda s: s.placed(1, rotation=90))
    model.select_element(1)
    assert model.params == cell.elements[1].params and model.cell_state.selected == 1
    model.undo()
    assert model.cell.elements[1].rotation == cell.elements[1].rotation
    model.undo()
    assert model.cell == cell
    model.undo()
    assert model.cell is None and model.params == COARSE
    model.redo()
    assert model.cell == cell and isinstance(model.undo_stack[-1], MeshParams)

    # a structure preset leaves the cell (undoable), like a parameter file
    model.set_params(MeshParams(structure="patch"))
    assert model.cell is None and isinstance(model.undo_stack[-1], CellState)

    # a failed cell build: back to the cell on screen, the edit gone from the history
    model.undo()
    result = compute(model.build_target(), model.generation)
    model.set_result(result)
    steps = len(model.undo_stack)
    assert model.edit_cell(lambda s: s.placed(1, position=(-2.0, 0.0)))
    failed = compute(model.build_target(), model.generation)
    failed = type(failed)(model.generation, None, error="cell 'x': refused", cell=failed.cell)
    assert not model.set_result(failed)
    assert model.cell == cell and len(model.undo_stack) == steps
    assert model.cell_error == "cell 'x': refused"


@pytest.mark.parametrize(
    "module",
    [
        "barymesh.app.model.cell_document",
        "barymesh.app.edit.array_preview",
        "barymesh.app.edit.drag_tool",
        "barymesh.app.cli_options",  # parse_copies, the preview's N1xN2, was lattice_panel's
    ],
)
def test_docstring_examples(module):
    """The examples in the cell editor's docstrings (app/ is not in the doctest paths)."""
    import doctest
    import importlib

    result = doctest.testmod(importlib.import_module(module))
    assert result.attempted > 0 and result.failed == 0


def test_drag_snaps_a_side_onto_another_elements_side(window, qtbot):
    from barymesh.app.edit.drag_tool import EDGE_SNAP_PX
    from barymesh.app.view.framing import pixels_per_mm

    open_preset(window, qtbot, "double-ring-patch")
    cell = load_cell_preset("double-ring-patch")
    rings = build_cell(cell).part_meshes[0].points[:, :2]
    right = float(rings[:, 0].max())  # 8.5: the ring patch at 0° reaches r + 1 mm
    window.cell_tools.dragger.act.trigger()
    type_into(window.cell_tools.elements.snap, "")  # no grid: only the sides snap
    reach = EDGE_SNAP_PX / pixels_per_mm(window.plotter)
    assert 0.2 < reach < 1.0  # a few tenths of a mm at this zoom
    # the patch's left side (x = -1.5 at the press on its centre) dragged to 0.2 mm right
    # of the rings' right side: it lands on it; y follows the pointer
    drag(window, [(0.0, 0.0), (4.0, 1.0), (right + 0.2 + 1.5, 1.75)])
    settle(window, qtbot)
    x, y = window.model.cell.elements[1].position
    assert x == right
    assert abs(y - 0.25) < 60.0 / window.plotter.width()
    assert_shows(window, replaced(cell, 1, position=(x, y)))


@pytest.mark.parametrize("name", ["hexagonal-rings", "coding-16x16"])
def test_teaching_tools_work_on_a_cell(window, qtbot, name):
    """Issue 13: the RWG inspector and the connectivity matrix act on the cell on screen,
    as on a structure's mesh: a click on an interior edge of the cell's welded mesh shows
    its T+ and T-, and the matrix holds 2 ones per interior edge of build_cell's mesh."""
    from test_app_inspector import click_world

    open_preset(window, qtbot, name)
    cell = load_cell_preset(name)
    assert_shows(window, cell)
    mesh = window.model.result.mesh
    expected = build_cell(cell).mesh
    with qtbot.waitActive(window):
        window.activateWindow()
    window.plotter.setFocus()
    qtbot.keyClick(window.plotter, Qt.Key.Key_I)  # Teach → RWG basis inspector
    assert window.teaching.inspector_active
    qtbot.wait(50)
    window.plotter.render()
    rwg = mesh.rwg
    row = len(rwg.edge) // 3
    edge = int(rwg.edge[row])
    tri = mesh.triangles[rwg.t_plus[row]]
    assert np.array_equal(tri, expected.triangles[expected.rwg.t_plus[row]])
    # zoom onto the edge so that a click lands on it whatever the cell's size
    a, b = mesh.points[mesh.edges[edge]]
    window.plotter.camera.focal_point = (*(0.5 * (a + b))[:2], 0.0)
    window.plotter.camera.position = (*(0.5 * (a + b))[:2], 10.0)
    window.plotter.camera.parallel_scale = 3 * float(np.linalg.norm(b - a))
    window.plotter.render()
    target = 0.5 * (a + b) + 0.02 * (mesh.centroids[rwg.t_plus[row]] - 0.5 * (a + b))
    click_world(window, qtbot, target)
    panel = window.teaching.inspector
    assert panel.edge == edge
    s = panel.info.sample
    assert (s.t_plus, s.t_minus) == (rwg.t_plus[row], rwg.t_minus[row])
    assert panel.overlay.datasets["triangles"].n_cells == 2

    qtbot.keyClick(window.plotter, Qt.Key.Key_M)  # Teach → Connectivity matrix
    view = window.teaching.matrix
    qtbot.waitUntil(lambda: not view.stale and view.matrix is not None, timeout=20_000)
    assert view.matrix.shape == (expected.n_triangles,) * 2
    assert view.nonzeros() == 2 * len(expected.interior_edges)


def test_construction_window_follows_the_selected_element(window, qtbot):
    """In a cell the Parameters panel edits the selected element, and the construction
    window (F7) shows that element's construction; selecting another element follows."""
    open_preset(window, qtbot, "double-ring-patch")
    cell = load_cell_preset("double-ring-patch")
    with qtbot.waitActive(window):
        window.activateWindow()
    window.plotter.setFocus()
    qtbot.keyClick(window.plotter, Qt.Key.Key_F7)  # Teach → Construction step by step
    view = window.teaching_windows.construction
    assert view is not None and view.isVisible()
    for row, element in enumerate(cell.elements):
        list_click(window, row)
        settle(window, qtbot)
        assert window.model.cell_state.selected == row
        assert view.params.structure == element.params.structure
        assert view.params.subdivisions == element.params.subdivisions


def test_export_array_offers_only_what_it_can_write(window, qtbot, tmp_path, monkeypatch):
    """Cell ▸ Export array mesh offered .nas and .ply, then said "cannot write .nas": every
    extension it offers now writes a file that reads back as the welded array."""
    import re

    from PySide6.QtWidgets import QFileDialog

    from barymesh.io import EXPORT_EXTENSIONS, IMPORT_EXTENSIONS, read_mesh

    open_preset(window, qtbot, "double-ring-patch")
    cell = load_cell_preset("double-ring-patch")
    spin_to(window.cell_tools.lattice.n1, 2)
    array = tile(cell, 2, 1).mesh
    offered = {}

    def save_dialog(_parent, _title, start, filters):
        offered["filters"] = filters.split(";;")
        return offered.pop("answer", ("", ""))

    monkeypatch.setattr(QFileDialog, "getSaveFileName", save_dialog)
    window.cell_tools.act_export_array.trigger()  # Cancel: look at what it offers
    extensions = [ext for f in offered["filters"] for ext in re.findall(r"\*(\.\w+)", f)]
    assert sorted(extensions) == sorted(EXPORT_EXTENSIONS)
    assert ".nas" not in extensions and ".ply" not in extensions
    for chosen, ext in zip(offered["filters"], extensions, strict=True):
        # typed without an extension: the chosen filter's is added
        offered["answer"] = (str(tmp_path / f"array-{ext[1:]}"), chosen)
        window.cell_tools.act_export_array.trigger()
        wait_for_export(window)
        path = tmp_path / f"array-{ext[1:]}{ext}"
        assert path.exists(), window.statusBar().currentMessage()
        assert "Wrote the 2 x 1 array" in window.statusBar().currentMessage()
        if ext in IMPORT_EXTENSIONS:
            back = read_mesh(path)
            assert (back.n_triangles, back.n_vertices) == (array.n_triangles, array.n_vertices)
        elif ext == ".npz":
            with np.load(path) as table:
                assert table["triangles"].shape == (array.n_triangles, 3)
                assert len(table["edge"]) == len(array.interior_edges)
        else:  # .csv: the RWG table, one row per interior edge under a header
            lines = path.read_text(encoding="utf-8").splitlines()
            rows = [line for line in lines if line and not line.startswith("#")]
            assert len(rows) == len(array.interior_edges) + 1


def test_the_cell_looks_the_same_whichever_element_is_selected(window, qtbot):
    open_preset(window, qtbot, "double-ring-patch")
    scene = window.scene

    def look():
        return (
            {n: scene.shows(n) for n in scene.actors},
            scene.shown_color_by,
            scene.light,
            scene.note.GetInput(),
            bool(scene.scalar_bar.GetVisibility()),
            round(float(window.plotter.camera.parallel_scale), 9),
        )

    tree = window.cell_tools.elements.list
    looks = []
    for row in range(tree.topLevelItemCount()):
        list_click(window, row)
        assert window.model.cell_state.selected == row
        settle(window, qtbot)
        looks.append(look())
    assert len(looks) >= 2 and all(v == looks[0] for v in looks)
    shown, *_ = looks[0]
    # and it is the paper's drawing of the whole cell (its triangles are > 4 px)
    for layer in ("triangle_edges", "shared_edges", "boundary_edges", "centroids"):
        assert shown[layer], layer
    assert scene.datasets["shared_edges"].n_cells == len(window.model.result.mesh.interior_edges)


def test_array_copies_are_one_pale_shade_not_darker_where_patches_overlap(window, qtbot):
    from gui_helpers import hex_rgb, near, pixel, rendered

    from barymesh.app.edit.array_preview import ghost_shade
    from barymesh.app.view.overview import overlap_counts_at
    from barymesh.app.view.scene_data import COLORS

    open_preset(window, qtbot, "double-ring-patch")
    mesh = window.model.result.mesh
    assert mesh.mode == "paper" and mesh.overlap_ratio > 0.2  # its patches overlap
    lattice = window.cell_tools.lattice
    spin_to(lattice.n1, 3)
    spin_to(lattice.n2, 1)
    ghosts = window.plotter.actors["cell_ghosts"]
    assert ghosts.GetProperty().GetOpacity() == 1.0
    for name in ("triangle_edges", "shared_edges", "boundary_edges", "centroids"):
        window.model.set_layer_visible(name, False)  # faces only (the copies have no lines)
    image = rendered(window.plotter)
    v = mesh.n_vertices
    points = ghosts.mapper.dataset.points
    shifts = points[::v][:, :2] - mesh.points[0, :2]  # one per copy
    assert len(shifts) == 2
    counts = overlap_counts_at(np.asarray(mesh.patch_rects), mesh.centroids)
    cents = np.asarray(mesh.centroids)
    single, stacked = cents[counts == 1], cents[counts >= 3]
    assert len(single) and len(stacked)
    shade = ghost_shade()
    for shift in shifts:  # the same shade over one patch and over three or more
        for c in (single[len(single) // 2], stacked[len(stacked) // 2]):
            got = pixel(image, window.plotter, (c[0] + shift[0], c[1] + shift[1], 0.0))
            assert near(got, shade, tol=4), (c, got, shade)
    # and no darker than the cell's own faces
    assert sum(hex_rgb(shade)) >= sum(hex_rgb(COLORS["faces"]))


def assert_stats_readable(window):
    """Every value of the Statistics panel is inside the dock's view (visible, not pushed
    off its right edge), and the per-part table shows every row whole."""
    from PySide6.QtCore import QPoint

    area = window.statistics_dock.widget()  # the dock's scroll area
    viewport = area.viewport()
    panel = window.stats
    for key, label in panel.values.items():
        right = label.mapTo(viewport, QPoint(label.width(), 0)).x()
        assert right <= viewport.width(), (key, right, viewport.width())
        inside = label.mapTo(panel, label.rect().center())
        assert panel.rect().contains(inside), key
    assert panel.text("triangles") == f"{window.model.result.mesh.n_triangles:,}"
    # the table: no row cut, all parts reachable (beside each other, or by the scroll bar)
    table = panel.cell.table
    assert table.viewport().height() >= table.verticalHeader().length()
    wide = table.horizontalHeader().length() > table.viewport().width()
    assert table.horizontalScrollBar().isVisible() == wide
    # shown on screen: the triangle count's label is drawn within the dock
    area.ensureWidgetVisible(panel.values["triangles"])
    assert not panel.values["triangles"].visibleRegion().isEmpty()


def test_statistics_of_a_cell_show_their_values_and_the_whole_part_table(window, qtbot, tmp_path):
    """Issue 30, 1.6: with a cell open the Statistics panel showed its labels but no
    values (the per-part table and the cell's title, 444 px wide, pushed the value column
    off the 306 px dock), and the table under it was squeezed and clipped."""
    window.resize(1400, 860)
    open_preset(window, qtbot, "split-ring-pair")
    window.statistics_dock.raise_()
    qtbot.wait(50)
    assert_stats_readable(window)
    assert window.stats.cell.cell_text(1, "Part") == "right ring"
    window.statistics_dock.grab().save(str(tmp_path / "stats-2-parts.png"))
    # four parts, wider than the dock: the table scrolls sideways, rows still whole
    panel = window.cell_tools.elements
    duplicate = panel.findChild(type(panel.add_button), "element_duplicate")
    assert duplicate is not None
    for _ in range(2):
        QTest.mouseClick(duplicate, Qt.MouseButton.LeftButton)
        settle(window, qtbot)
    assert window.stats.cell.part_count() == 4
    qtbot.wait(50)
    assert_stats_readable(window)
    assert window.stats.cell.table.horizontalScrollBar().isVisible()
    area = window.statistics_dock.widget()
    area.verticalScrollBar().setValue(area.verticalScrollBar().maximum())
    window.statistics_dock.grab().save(str(tmp_path / "stats-4-parts.png"))
    # long values ("0.001917 mm", "101.121") widen the dock rather than go off its edge
    open_preset(window, qtbot, "hexagonal-rings")
    type_into(window.controls.rows["inner_radius"].field, "0.011")
    settle(window, qtbot)
    qtbot.wait(50)
    assert window.stats.text("min_edge").endswith(" mm")
    assert len(window.stats.text("min_edge")) >= 11, window.stats.text("min_edge")
    assert_stats_readable(window)
    window.statistics_dock.grab().save(str(tmp_path / "stats-long-values.png"))


def dark_share(window, box):
    """Share of the 3D view's pixels inside ``box`` (x0, x1, y0, y1 mm) that are as dark
    as the triangle numbers (#202020)."""
    from gui_helpers import display_point, rendered

    image = rendered(window.plotter)
    h = image.shape[0]
    (xa, ya), (xb, yb) = (display_point(window.plotter, (x, y, 0.0)) for x, y in box_corners(box))
    rows = slice(max(int(h - 1 - max(ya, yb)), 0), int(h - 1 - min(ya, yb)) + 1)
    cols = slice(max(int(min(xa, xb)), 0), int(max(xa, xb)) + 1)
    part = image[rows, cols].astype(int)
    dark = (np.abs(part - 0x20).max(axis=-1) <= 40).sum()
    return dark / max(part.shape[0] * part.shape[1], 1)


def box_corners(box):
    x0, x1, y0, y1 = box
    return (x0, y0), (x1, y1)


def wheel_in(window, world, steps=1):
    """Wheel steps forward (zoom in) with the pointer over ``world``, as a mouse does."""
    from gui_helpers import widget_pos
    from PySide6.QtCore import QPoint, QPointF
    from PySide6.QtGui import QWheelEvent
    from PySide6.QtWidgets import QApplication

    plotter = window.plotter
    pos = widget_pos(plotter, world)
    for _ in range(steps):
        event = QWheelEvent(
            QPointF(pos),
            QPointF(plotter.mapToGlobal(pos)),
            QPoint(0, 0),
            QPoint(0, 120),
            Qt.MouseButton.NoButton,
            Qt.KeyboardModifier.NoModifier,
            Qt.ScrollPhase.NoScrollPhase,
            False,
        )
        QApplication.sendEvent(plotter, event)


def test_triangle_numbers_stay_off_until_they_can_be_read(window, qtbot, tmp_path):
    """Issue 30, 1.8: after a live drag in the array preview took a cell's ring below 300
    triangles, its triangle numbers came on by themselves and drew a black smudge (216
    labels over a ring 70 px wide). They are drawn only where the triangles are large
    enough on screen to hold them; the note says so; zooming in brings them."""
    from app_user import drag_slider_by

    from barymesh.app.model.layers import LABEL_LIMIT

    window.resize(1400, 860)
    open_preset(window, qtbot, "hexagonal-rings")
    type_into(window.controls.rows["subdivisions"].field, "3")
    settle(window, qtbot)
    lattice = window.cell_tools.lattice
    for box in (lattice.n1, lattice.n2):
        type_into(box.lineEdit(), "3")
    settle(window, qtbot)
    assert window.cell_tools.preview.copies == (3, 3)
    assert window.model.result.mesh.n_triangles > LABEL_LIMIT  # 390: no numbers asked
    row = window.controls.rows["inner_radius"]
    drag_slider_by(row.slider, -25)  # the ring's hole shrinks: fewer sectors
    settle(window, qtbot)
    qtbot.wait(50)
    mesh = window.model.result.mesh
    assert mesh.n_triangles <= LABEL_LIMIT, mesh.n_triangles
    scene = window.scene
    assert scene.visible["labels"]  # the layer is on (the default) ...
    assert not scene.drawn("labels") and not scene.actors["labels"].GetVisibility()
    assert "Triangle numbers hidden" in scene.note_text(), scene.note_text()
    x0, y0 = mesh.points[:, :2].min(axis=0)
    x1, y1 = mesh.points[:, :2].max(axis=0)
    ring = (x0, x1, y0, y1)
    assert dark_share(window, ring) < 0.05  # ... and no smudge over the ring
    window.grab().save(str(tmp_path / "numbers-hidden.png"))
    # zoomed in on the ring, its triangles get large enough: the numbers come
    centre = (0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.0)
    for _ in range(60):
        if scene.drawn("labels"):
            break
        wheel_in(window, centre)
        qtbot.wait(10)
    assert scene.drawn("labels") and scene.actors["labels"].GetVisibility()
    assert "Triangle numbers hidden" not in scene.note_text()
    window.grab().save(str(tmp_path / "numbers-shown.png"))

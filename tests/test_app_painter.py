"""Cell → Paint pixels, in a real window under Xvfb (see conftest.py): the painter driven
with the mouse at pixel centres computed from its camera, under every symmetry mode."""

import numpy as np
import pytest

pytest.importorskip("pyvistaqt")

from app_user import answer_file_dialogs, choose  # noqa: E402
from gui_helpers import near, pixel, rendered, type_into, widget_pos  # noqa: E402
from PySide6.QtCore import QPoint, Qt  # noqa: E402
from PySide6.QtTest import QTest  # noqa: E402
from test_edit_pixels import transforms  # noqa: E402

from barymesh.app.edit.painter import PixelPainterWindow  # noqa: E402
from barymesh.app.model import pixels  # noqa: E402
from barymesh.cell import SYMMETRIES, load_cell, load_cell_preset  # noqa: E402

N = 4  # subdivisions of a pixel patch: 2 n² = 32 triangles (the paper's count)
LEFT, RIGHT = Qt.MouseButton.LeftButton, Qt.MouseButton.RightButton
NONE = Qt.KeyboardModifier.NoModifier


def wait_built(qtbot, painter):
    qtbot.waitUntil(
        lambda: not painter.busy and painter.shown_generation == painter.generation, timeout=60_000
    )


def click_action(painter, action):
    """Click the toolbar button of ``action``."""
    for bar in painter.findChildren(type(painter.addToolBar("probe"))):
        button = bar.widgetForAction(action)
        if button is not None:
            QTest.mouseClick(button, LEFT)
            return
    raise AssertionError(f"no button for {action.text()}")


def at(painter, row, col):
    """Widget position of the centre of pixel (row, col)."""
    return widget_pos(painter.plotter, painter.pixel_centre(row, col))


def drag(painter, path, button=LEFT):
    """Press on the first pixel of ``path``, move over the others, release on the last."""
    plotter = painter.plotter
    QTest.mousePress(plotter, button, NONE, at(painter, *path[0]))
    for rc in path[1:]:
        QTest.mouseMove(plotter, at(painter, *rc))
    QTest.mouseRelease(plotter, button, NONE, at(painter, *path[-1]))


def expected_mask(shape, strokes, mode):
    """Pixels set by ``strokes`` [(value, [(r, c), ...]), ...] under the geometric maps of
    ``mode`` (written out in tests/test_edit_pixels.py, independent of app/model/pixels.py)."""
    mask = np.zeros(shape, bool)
    for value, path in strokes:
        for r, c in path:
            for g in transforms(mode):
                mask[g(r, c, *shape)] = value
    return mask


def welded_counts(mask, n=N):
    """Vertices and edges of the pixels of ``mask`` meshed n x n and welded, counted from
    the points and sides themselves (a Python set), not from the mesher."""
    points = set()
    for r, c in np.argwhere(mask):
        for a in range(n + 1):
            for b in range(n + 1):
                points.add((c * n + a, r * n + b))
    side_pairs = int((mask[:, 1:] & mask[:, :-1]).sum() + (mask[1:] & mask[:-1]).sum())
    k = int(mask.sum())
    # per patch 3n² + 2n edges; two pixels sharing a side share its n edges
    return len(points), k * (3 * n * n + 2 * n) - n * side_pairs


def assert_mesh_of(painter, mask):
    wait_built(painter.qtbot, painter)
    assert np.array_equal(painter.cell().pixels.mask, mask)
    mesh = painter.cell_mesh.mesh
    k = int(mask.sum())
    vertices, edges = welded_counts(mask)
    assert mesh.n_triangles == 32 * k
    assert mesh.n_vertices == vertices
    assert len(mesh.edges) == edges
    assert len(mesh.junction_edges) == 0
    assert painter.scene.datasets["faces"].n_cells == 32 * k  # what is drawn is that mesh
    assert f"Triangles <b>{32 * k:,}</b>" in painter.stats_label.text()


@pytest.fixture
def painter(qtbot):
    win = PixelPainterWindow(load_cell_preset("coding-16x16"))
    win.qtbot = qtbot
    qtbot.addWidget(win)
    win.resize(1000, 820)
    win.show()
    qtbot.waitExposed(win)
    wait_built(qtbot, win)
    qtbot.wait(50)
    win.reset_view()
    yield win
    win.close()


def clear(painter):
    click_action(painter, painter.toolbars.act_clear)
    wait_built(painter.qtbot, painter)
    assert not painter.mask.any()


def test_opens_on_the_coding_cell_in_its_4_fold_symmetry(painter):
    preset = load_cell_preset("coding-16x16")
    assert painter.symmetry == "4-fold"
    assert_mesh_of(painter, preset.pixels.mask)
    assert painter.cell().lattice == preset.lattice


@pytest.mark.parametrize("mode", SYMMETRIES)
def test_a_drag_paints_one_stroke_under_each_symmetry(painter, mode):
    clear(painter)
    choose(painter.toolbars.symmetry_box, mode)
    assert painter.symmetry == mode
    before = len(painter.history)
    stroke = [(1, 2), (1, 3), (2, 3), (2, 4)]
    drag(painter, stroke)
    expected = expected_mask((16, 16), [(True, stroke)], mode)
    assert len(painter.history) == before + 1  # the whole drag is one undo step
    assert_mesh_of(painter, expected)
    # the right button erases, under the same symmetry
    drag(painter, [(2, 4)], RIGHT)
    expected = expected_mask((16, 16), [(True, stroke), (False, [(2, 4)])], mode)
    assert_mesh_of(painter, expected)
    # undo restores each step, redo brings it back
    click_action(painter, painter.toolbars.act_undo)
    assert_mesh_of(painter, expected_mask((16, 16), [(True, stroke)], mode))
    click_action(painter, painter.toolbars.act_undo)
    assert not painter.mask.any()
    click_action(painter, painter.toolbars.act_redo)
    click_action(painter, painter.toolbars.act_redo)
    assert_mesh_of(painter, expected)


def test_a_fast_drag_leaves_no_gap(painter):
    clear(painter)
    choose(painter.toolbars.symmetry_box, "none")
    drag(painter, [(5, 1), (5, 9)])  # one mouse move over eight pixels
    expected = np.zeros((16, 16), bool)
    expected[5, 1:10] = True
    assert_mesh_of(painter, expected)


def test_erase_toggle_and_fill_tool(painter, qtbot):
    clear(painter)
    choose(painter.toolbars.symmetry_box, "none")
    click_action(painter, painter.toolbars.act_fill)
    QTest.mouseClick(painter.plotter, LEFT, NONE, at(painter, 7, 7))
    assert_mesh_of(painter, np.ones((16, 16), bool))
    click_action(painter, painter.toolbars.act_pen)
    click_action(painter, painter.toolbars.act_erase)
    ring = (
        [(4, c) for c in range(4, 12)]
        + [(11, c) for c in range(4, 12)]
        + [(r, 4) for r in range(5, 11)]
        + [(r, 11) for r in range(5, 11)]
    )
    for r, c in ring:
        QTest.mouseClick(painter.plotter, LEFT, NONE, at(painter, r, c))
    expected = np.ones((16, 16), bool)
    for r, c in ring:
        expected[r, c] = False
    assert_mesh_of(painter, expected)
    click_action(painter, painter.toolbars.act_erase)
    click_action(painter, painter.toolbars.act_fill)
    # a right click fills the island inside the ring with nothing (4-neighbours: the
    # ring's corners do not leak)
    QTest.mouseClick(painter.plotter, RIGHT, NONE, at(painter, 7, 7))
    expected[5:11, 5:11] = False
    assert_mesh_of(painter, expected)


def test_invert_is_the_babinet_complement_and_twice_the_identity(painter):
    mask = painter.mask.copy()
    click_action(painter, painter.toolbars.act_invert)
    assert_mesh_of(painter, ~mask)
    click_action(painter, painter.toolbars.act_invert)
    assert_mesh_of(painter, mask)


@pytest.mark.parametrize("mode", ["8-fold", "mirror_y"])
def test_random_fill_from_the_seed_field(painter, qtbot, mode):
    choose(painter.toolbars.symmetry_box, mode)
    type_into(qtbot, painter.toolbars.seed_box, "1234")
    click_action(painter, painter.toolbars.act_random)
    mask = painter.mask.copy()
    assert np.array_equal(mask, pixels.random_mask((16, 16), 1234, mode, 0.5))
    assert all(
        np.array_equal(mask, np.zeros((16, 16), bool) | _image(mask, g)) for g in transforms(mode)
    )
    assert_mesh_of(painter, mask)
    clear(painter)
    click_action(painter, painter.toolbars.act_random)  # the same seed: the same cell
    assert_mesh_of(painter, mask)


def _image(mask, g):
    out = np.zeros_like(mask)
    for r, c in np.argwhere(mask):
        out[g(r, c, *mask.shape)] = True
    return out


def test_grid_fields_resize_about_the_centre_and_the_lattice_follows(painter, qtbot):
    mask = painter.mask.copy()
    type_into(qtbot, painter.toolbars.rows_box, "20")
    type_into(qtbot, painter.toolbars.cols_box, "20")
    assert painter.mask.shape == (20, 20)
    assert np.array_equal(painter.mask[2:18, 2:18], mask) and painter.mask.sum() == mask.sum()
    assert painter.symmetry == "4-fold"  # kept: the change is even
    assert pixels.is_invariant(painter.mask, "4-fold")
    cell = painter.cell()
    assert cell.lattice.a1 == (10.0, 0.0) and cell.lattice.a2 == (0.0, 10.0)
    assert cell.pixels.origin == (-5.0, -5.0)
    assert_mesh_of(painter, painter.mask)
    type_into(qtbot, painter.toolbars.cols_box, "21")  # not square: no 4-fold any more
    assert painter.symmetry == "none"
    type_into(qtbot, painter.toolbars.size_box, "0.25")
    cell = painter.cell()
    assert cell.pixels.pixel_size == 0.25
    assert cell.lattice.a1 == (5.25, 0.0) and cell.lattice.a2 == (0.0, 5.0)
    assert_mesh_of(painter, painter.mask)
    assert painter.cell_mesh.periodic_pairs.matched
    assert len(painter.history) == 5  # rows, columns, columns, pixel size: one step each
    for _ in range(4):
        click_action(painter, painter.toolbars.act_undo)
    assert not painter.toolbars.act_undo.isEnabled()
    assert painter.cell().lattice == load_cell_preset("coding-16x16").lattice
    assert painter.cell().pixels == load_cell_preset("coding-16x16").pixels


def test_4_fold_refused_on_a_grid_that_is_not_square(painter, qtbot):
    type_into(qtbot, painter.toolbars.rows_box, "12")
    choose(painter.toolbars.symmetry_box, "mirror_y")
    QTest.keyClick(painter.toolbars.symmetry_box, Qt.Key.Key_Down)  # to 4-fold: refused
    assert painter.symmetry == "mirror_y"
    assert "square" in painter.statusBar().currentMessage()


def test_corner_contacts_are_marked(painter):
    clear(painter)
    choose(painter.toolbars.symmetry_box, "none")
    drag(painter, [(3, 3)])
    drag(painter, [(4, 4)])
    wait_built(painter.qtbot, painter)
    contacts = painter.scene.datasets["contacts"]
    assert contacts.n_points == 1
    assert np.allclose(contacts.points[0, :2], (-4 + 4 * 0.5, -4 + 4 * 0.5))
    assert "1</b> corner-only contact" in painter.stats_label.text()
    assert any("corner only" in note for note in painter.cell_mesh.notes)
    drag(painter, [(3, 4)])  # the pinch filled: no contact
    wait_built(painter.qtbot, painter)
    assert painter.scene.datasets["contacts"].n_points == 0
    assert "corner-only" not in painter.stats_label.text()


def test_save_and_reload_equal(painter, qtbot, monkeypatch, tmp_path):
    answer = answer_file_dialogs(monkeypatch)
    choose(painter.toolbars.symmetry_box, "8-fold")
    drag(painter, [(0, 0), (1, 1)])
    wait_built(qtbot, painter)
    answer(tmp_path / "painted")  # the suffix is added
    click_action(painter, painter.toolbars.act_save)
    path = tmp_path / "painted.cell.json"
    assert path.exists(), painter.statusBar().currentMessage()
    loaded = load_cell(path)
    assert loaded == painter.cell()
    clear(painter)
    answer(path)
    click_action(painter, painter.toolbars.act_open)
    assert np.array_equal(painter.mask, loaded.pixels.mask)
    assert len(painter.history) == 1  # a new document


def test_an_empty_cell_is_not_saved(painter, monkeypatch, tmp_path):
    answer = answer_file_dialogs(monkeypatch)
    clear(painter)
    answer(tmp_path / "empty.cell.json")
    click_action(painter, painter.toolbars.act_save)
    assert not (tmp_path / "empty.cell.json").exists()
    assert "no metal" in painter.statusBar().currentMessage()
    assert painter.scene.datasets["faces"].n_cells == 0


def test_a_64_by_64_grid_is_built_in_the_worker(painter, qtbot):
    type_into(qtbot, painter.toolbars.rows_box, "64")
    type_into(qtbot, painter.toolbars.cols_box, "64")
    click_action(painter, painter.toolbars.act_invert)
    assert painter.busy or painter.shown_generation == painter.generation
    wait_built(qtbot, painter)
    k = int(painter.mask.sum())
    assert k == 64 * 64 - load_cell_preset("coding-16x16").pixels.mask.sum()
    assert painter.cell_mesh.mesh.n_triangles == 32 * k
    drag(painter, [(0, 0), (0, 5)], RIGHT)  # strokes still land while it builds
    assert not painter.mask[0, :6].any()
    wait_built(qtbot, painter)
    mesh = painter.cell_mesh.mesh
    k = int(painter.mask.sum())
    assert mesh.n_triangles == 32 * k
    # drawn as one square per pixel, no triangle edges at this size on screen
    assert painter.scene.datasets["faces"].n_cells == k
    assert np.isclose(painter.scene.datasets["faces"].area, k * 0.25)
    assert not painter.scene.actors["edges"].GetVisibility()
    # the wheel zooms in on the middle: the triangle edges come, those in view only
    centre = at(painter, 32, 32)
    for _ in range(8):
        wheel(painter.plotter, centre, 120)
        qtbot.wait(20)
    qtbot.waitUntil(lambda: painter.scene.actors["edges"].GetVisibility(), timeout=10_000)
    x0, x1, y0, y1 = painter.scene.view_rect(margin=0.5)
    mid = 0.5 * (mesh.points[mesh.edges[:, 0], :2] + mesh.points[mesh.edges[:, 1], :2])
    inside = (mid[:, 0] >= x0) & (mid[:, 0] <= x1) & (mid[:, 1] >= y0) & (mid[:, 1] <= y1)
    drawn = painter.scene.datasets["edges"]
    assert 0 < drawn.n_cells == inside.sum() < len(mesh.edges)


def wheel(widget, pos, delta):
    """One notch of the mouse wheel over ``widget`` at ``pos`` (positive: away, zoom in)."""
    from PySide6.QtCore import QPointF
    from PySide6.QtGui import QWheelEvent
    from PySide6.QtWidgets import QApplication

    event = QWheelEvent(
        QPointF(pos),
        QPointF(widget.mapToGlobal(pos)),
        QPoint(0, 0),
        QPoint(0, delta),
        Qt.MouseButton.NoButton,
        NONE,
        Qt.ScrollPhase.NoScrollPhase,
        False,
    )
    QApplication.sendEvent(widget, event)


def test_screenshot_metal_where_set_background_where_not(painter, tmp_path):
    import imageio.v3 as iio

    from barymesh.app.edit.painter_scene import COLORS

    image = rendered(painter.plotter)
    iio.imwrite(tmp_path / "painter.png", image)
    mask = painter.mask
    # the metal is graded toward the painted outline: in each metal pixel the incentre of its
    # fattest triangle is the point furthest from the drawn edges
    mesh = painter.cell_mesh.mesh
    corners = mesh.points[mesh.triangles][:, :, :2]
    sides = np.linalg.norm(np.roll(corners, -1, axis=1) - np.roll(corners, 1, axis=1), axis=2)
    incentres = np.einsum("ti,tij->tj", sides, corners) / sides.sum(axis=1, keepdims=True)
    inradius = 2 * mesh.areas / sides.sum(axis=1)
    half = 0.5 * painter.cell().pixels.pixel_size
    for r in range(16):
        for c in range(16):
            x, y, _ = painter.pixel_centre(r, c)
            p = (x + 0.03, y - 0.07, 0.0)  # background: off the grid lines
            if mask[r, c]:
                inside = np.flatnonzero(np.all(np.abs(incentres - (x, y)) < half, axis=1))
                p = (*incentres[inside[np.argmax(inradius[inside])]], 0.0)
            rgb = pixel(image, painter.plotter, p)
            assert near(rgb, COLORS["metal"] if mask[r, c] else COLORS["background"], 30), (
                r,
                c,
                rgb,
            )


def test_opened_from_the_cell_menu(window, qtbot):
    menus = {m.title(): m for m in window.menuBar().findChildren(type(window.teach_menu))}
    opener = window.painter_opener
    assert opener.act_paint in menus["&Cell"].actions()
    with qtbot.waitActive(window):
        window.activateWindow()
    qtbot.keyClick(
        window,
        Qt.Key.Key_P,
        Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.ShiftModifier,
    )
    painter = opener.painter
    assert painter is not None and painter.isVisible()
    wait_built(qtbot, painter)
    assert painter.cell_mesh.mesh.n_triangles == 32 * int(painter.mask.sum())
    window.close()
    assert painter._closed


def test_the_mouse_over_a_pixel_outlines_its_orbit(painter):
    for mode, order in (("none", 1), ("mirror_x", 2), ("4-fold", 4), ("8-fold", 8)):
        choose(painter.toolbars.symmetry_box, mode)
        QTest.mouseMove(painter.plotter, at(painter, 2, 5))  # on no mirror line
        assert painter.scene.datasets["hover"].n_cells == order, mode
        QTest.mouseMove(painter.plotter, at(painter, 3, 5))
        assert painter.scene.datasets["hover"].n_cells == order, mode
    # the outlined squares are the pixel's images under the eight maps of the square
    centres = painter.scene.datasets["hover"].cell_centers().points[:, :2]
    images = {g(3, 5, 16, 16) for g in transforms("8-fold")}
    expected = np.array([painter.pixel_centre(r, c)[:2] for r, c in images])
    assert len(centres) == len(expected) == 8
    assert {tuple(p) for p in np.round(centres, 6)} == {tuple(p) for p in np.round(expected, 6)}
    QTest.mouseMove(painter.plotter, QPoint(2, 2))  # off the grid: no outline
    assert painter.scene.datasets["hover"].n_cells == 0


def test_keys_of_the_painter(painter, qtbot):
    with qtbot.waitActive(painter):
        painter.activateWindow()
    painter.plotter.setFocus()
    mask = painter.mask.copy()
    for key, mode in (
        (Qt.Key.Key_8, "8-fold"),
        (Qt.Key.Key_X, "mirror_x"),
        (Qt.Key.Key_Y, "mirror_y"),
        (Qt.Key.Key_0, "none"),
        (Qt.Key.Key_4, "4-fold"),
    ):
        QTest.keyClick(painter.plotter, key)
        assert painter.symmetry == mode
    QTest.keyClick(painter.plotter, Qt.Key.Key_I)
    assert np.array_equal(painter.mask, ~mask)
    QTest.keyClick(painter.plotter, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert np.array_equal(painter.mask, mask)
    QTest.keyClick(painter.plotter, Qt.Key.Key_Y, Qt.KeyboardModifier.ControlModifier)
    assert np.array_equal(painter.mask, ~mask)
    QTest.keyClick(painter.plotter, Qt.Key.Key_E)
    assert painter.toolbars.act_erase.isChecked()
    QTest.keyClick(painter.plotter, Qt.Key.Key_F)
    assert painter.toolbars.act_fill.isChecked()
    QTest.keyClick(painter.plotter, Qt.Key.Key_P)
    assert painter.toolbars.act_pen.isChecked()
    QTest.keyClick(painter.plotter, Qt.Key.Key_W)  # VTK's wireframe key does nothing here
    assert painter.scene.actors["faces"].GetProperty().GetRepresentation() == 2  # surface


def test_a_cell_the_core_refuses_keeps_the_last_mesh(qtbot):
    """Conforming mode refuses a pixel over an element: the message is shown, the last
    good mesh stays, and undo goes back to a cell that meshes."""
    from barymesh import MeshParams
    from barymesh.cell import Element, Lattice, PixelGrid, UnitCell

    patch = Element(
        MeshParams(structure="patch", patch_size=1.0), position=(2.0, 2.0), name="patch"
    )
    grid = PixelGrid(np.zeros((16, 16), bool), 0.5, (-4.0, -4.0))
    win = PixelPainterWindow(UnitCell(Lattice.rectangular(8.0), (patch,), grid, mode="conforming"))
    win.qtbot = qtbot
    qtbot.addWidget(win)
    win.resize(900, 800)
    win.show()
    qtbot.waitExposed(win)
    wait_built(qtbot, win)
    win.reset_view()
    assert win.cell_mesh.mesh.n_triangles == 32  # the element alone
    drag(win, [(0, 0)])
    wait_built(qtbot, win)
    assert win.cell_mesh.mesh.n_triangles == 64
    drag(win, [(12, 12)])  # under the element [2, 3] x [2, 3] mm
    wait_built(qtbot, win)
    assert "overlap" in win.statusBar().currentMessage()
    assert "pixel (row 12, column 12)" in win.statusBar().currentMessage()
    assert win.cell_mesh.mesh.n_triangles == 64 and win.scene.datasets["faces"].n_cells == 64
    click_action(win, win.toolbars.act_undo)
    wait_built(qtbot, win)
    assert win.cell_mesh.mesh.n_triangles == 64 and not win.mask[12, 12]
    win.close()


def test_a_cell_without_a_grid_gets_one_over_the_cell(qtbot):
    import doctest

    from barymesh import MeshParams
    from barymesh.app.model import painter_document as module
    from barymesh.cell import Element, Lattice, UnitCell

    finder = doctest.DocTestFinder()
    runner = doctest.DocTestRunner()
    for test in finder.find(module.blank_grid, "blank_grid", globs=vars(module)):
        runner.run(test)
    assert runner.tries >= 2 and runner.failures == 0
    ring = Element(MeshParams(angle_step=15.0, subdivisions=2), name="rings")
    win = PixelPainterWindow(UnitCell(Lattice.rectangular(24.0, 12.0), (ring,)))
    qtbot.addWidget(win)
    win.show()
    qtbot.waitExposed(win)
    wait_built(qtbot, win)
    assert win.mask.shape == (8, 16) and not win.mask.any()
    assert win.grid.pixel_size == 1.5 and win.grid.origin == (-12.0, -6.0)
    rings = win.cell_mesh.mesh.n_triangles
    assert rings > 0 and win.cell_mesh.mesh.n_triangles == win.scene.datasets["faces"].n_cells
    win.close()


def test_a_pixel_size_finer_than_the_field_survives_a_resize(qtbot):
    from barymesh.cell import Lattice, PixelGrid, UnitCell

    grid = PixelGrid(np.eye(4, dtype=bool), 0.123456, (-0.246912, -0.246912))
    win = PixelPainterWindow(UnitCell(Lattice.rectangular(4 * 0.123456), pixels=grid))
    qtbot.addWidget(win)
    win.show()
    qtbot.waitExposed(win)
    type_into(qtbot, win.toolbars.rows_box, "6")
    type_into(qtbot, win.toolbars.size_box, "0.1235")  # what the field shows: no change
    assert win.mask.shape == (6, 4) and win.grid.pixel_size == 0.123456
    assert len(win.history) == 2
    type_into(qtbot, win.toolbars.size_box, "0.2")
    assert win.grid.pixel_size == 0.2 and len(win.history) == 3
    win.close()


def test_the_cell_menu_is_shared_with_whoever_made_it(qtbot):
    from PySide6.QtWidgets import QMainWindow

    from barymesh.app.edit.painter_opener import cell_menu

    win = QMainWindow()
    qtbot.addWidget(win)
    made = win.menuBar().addMenu("&Cell")
    assert cell_menu(win) is made
    other = QMainWindow()
    qtbot.addWidget(other)
    new = cell_menu(other)
    assert new.title() == "&Cell" and cell_menu(other) is new


def test_status_messages_have_their_own_line_and_go_when_untrue(painter, qtbot):
    """A status message ran into the statistics (both in the status bar, the message cut
    under them), and "The grid is not square" stayed after the grid was square again."""
    choose(painter.toolbars.symmetry_box, "4-fold")
    assert painter.symmetry == "4-fold"
    type_into(qtbot, painter.toolbars.rows_box, "12")
    assert painter.grid.shape == (12, 16) and painter.symmetry == "none"
    bar = painter.statusBar()
    message = bar.currentMessage()
    assert message.startswith("The grid is not square")
    # the statistics are outside the status bar, so the message has its whole width
    stats = painter.stats_label
    assert not bar.isAncestorOf(stats) and stats.isVisible()
    top_left = stats.mapTo(painter, stats.rect().topLeft())
    assert top_left.y() + stats.height() <= bar.mapTo(painter, bar.rect().topLeft()).y()
    assert bar.fontMetrics().horizontalAdvance(message) < bar.width()
    assert "Pixels" in stats.text()
    type_into(qtbot, painter.toolbars.rows_box, "16")  # square again: the symmetry comes back
    assert painter.grid.shape == (16, 16) and painter.symmetry == "4-fold"
    assert "not square" not in bar.currentMessage()
    assert "square again" in bar.currentMessage()
    click_action(painter, painter.toolbars.act_undo)  # not square again, then square by redo
    assert "not square" in bar.currentMessage()
    click_action(painter, painter.toolbars.act_redo)
    assert "not square" not in bar.currentMessage()

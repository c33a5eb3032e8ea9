"""The Infinite array tab's stack editor in the real window (Xvfb), as a user drives it
(issue 29, Window): layer values typed into the table's cells, rows moved and added with
the mouse, the ground plane ticked with a click; the live curve follows, and every curve
is checked against barymesh.mom.periodic_solve run directly with the same Stack. Bad
values are said in one line and keep the last curve; the event loop keeps ticking while a
stack edit's sweep runs; the curve is whole and unscrolled at the window's default size.

The cell is the coarse conforming double ring of tests/test_gui_infinite_array.py (a
couple of hundred unknowns on a 12 mm square lattice), swept at three frequencies.
"""

import time

import numpy as np
import pytest

pytest.importorskip("pyvistaqt")
pytest.importorskip("matplotlib")

from app_user import click_check_box, type_into  # noqa: E402
from PySide6.QtCore import Qt, QTimer  # noqa: E402
from PySide6.QtWidgets import QAbstractItemView, QLineEdit  # noqa: E402
from test_gui_infinite_array import (  # noqa: E402
    HEARTBEAT_GAP,
    RING,
    open_array_tab,
    run_and_wait,
    save_shot,
    type_band,
)

from barymesh.app.model.stack_rows import COLUMNS  # noqa: E402
from barymesh.app.panels.stack_editor import BAD_CELL  # noqa: E402
from barymesh.app.window import SCRIPTED_SIZE  # noqa: E402
from barymesh.mom import Layer, PlaneWave, Stack, periodic_solve  # noqa: E402

TE = PlaneWave.from_angles(0.0, 0.0, 90.0)
MIL62 = 62 * 0.0254  # a 62 mil board, typed as "62mil"


@pytest.fixture
def window_params():
    return RING


def type_cell(qtbot, editor, row, column, text):
    """Double-click a layer's cell, type ``text`` into its editor and press Enter."""
    rect = editor.cell_rect(row, column)
    # a double click as the mouse sends it: press, release, then the second press (QTest's
    # mouseDClick sends only the last, which a view ignores without the first)
    viewport, left = editor.table.viewport(), Qt.MouseButton.LeftButton
    qtbot.mouseClick(viewport, left, pos=rect.center())
    qtbot.mouseDClick(viewport, left, pos=rect.center())
    assert editor.table.state() == QAbstractItemView.State.EditingState
    (field,) = [w for w in editor.table.viewport().findChildren(QLineEdit) if w.isVisible()]
    type_into(field, text)
    # the view commits a cell's Enter through the event loop
    qtbot.waitUntil(lambda: editor.table.state() != QAbstractItemView.State.EditingState)


def click_row(qtbot, editor, row):
    rect = editor.table.visualRect(editor.table.model().index(row, 0))
    qtbot.mouseClick(editor.table.viewport(), Qt.MouseButton.LeftButton, pos=rect.center())


def click(qtbot, button):
    qtbot.mouseClick(button, Qt.MouseButton.LeftButton)


def wait_for_stack(qtbot, tab, stack):
    """Wait for the live curve swept with ``stack``."""
    qtbot.waitUntil(
        lambda: tab.result is not None and tab.result.inputs.stack == stack, timeout=180_000
    )
    qtbot.wait(100)  # its picture shown
    return tab.result


def assert_curve_is_the_direct_solve(tab, mesh, stack):
    result = tab.result
    for i in (0, 2):
        r, t = periodic_solve(mesh, result.frequencies[i], TE, stack=stack).co_polar()
        assert abs(result.reflection[i] - r) < 1e-6 and abs(result.transmission[i] - t) < 1e-6
    mag, phase = tab.plot.figure.axes[:2]
    with np.errstate(divide="ignore"):
        np.testing.assert_allclose(mag.lines[0].get_ydata(), 20 * np.log10(abs(result.reflection)))
    np.testing.assert_allclose(phase.lines[0].get_ydata(), np.degrees(np.angle(result.reflection)))
    return result


def test_typed_layers_and_a_clicked_ground_plane_drive_the_live_curve(window, qtbot):
    tab = open_array_tab(window, qtbot)
    # the mesh as drawn: its coarse-mesh warning in the slab is part of what is checked
    # (the solver-grade mesh would be within λ/10 there)
    click_check_box(tab.solver_grade)
    assert not tab.solver_grade.isChecked()
    editor = tab.stack_editor
    mesh = window.model.result.mesh
    type_band(qtbot, tab, "10", "20", 3)
    free = run_and_wait(qtbot, tab)
    phase_axis = tab.plot.figure.axes[1]
    assert phase_axis.get_ylabel() == "∠R, ∠T (°) at the sheet,\nz = 0 mm"
    assert free.inputs.stack is None and not tab.warnings.isVisible()

    # a layer under the sheet, its values typed (62 mil, lossless), then a ground plane
    click(qtbot, editor.add_button)
    assert editor.rows[1] is not None and editor.sheet_row == 0  # added under the sheet
    type_cell(qtbot, editor, 1, "thickness", "62mil")
    type_cell(qtbot, editor, 1, "eps_r", "2.2")
    type_cell(qtbot, editor, 1, "loss_tangent", "0")
    assert editor.error == "" and editor.stack == Stack(below=(Layer(MIL62, 2.2),))
    click_check_box(editor.ground)
    grounded = Stack(below=(Layer(MIL62, 2.2),), ground=True)
    result = wait_for_stack(qtbot, tab, grounded)
    assert_curve_is_the_direct_solve(tab, mesh, grounded)
    # a lossless grounded slab under the ring: all the power comes back (one propagating
    # order below the 25 GHz onset), none goes through
    np.testing.assert_allclose(abs(result.reflection), 1.0, atol=2e-3)
    assert np.all(result.transmission == 0)
    mag, phase_axis = tab.plot.figure.axes[:2]
    assert phase_axis.get_ylabel() == "∠R (°) at the sheet,\nz = 0 mm"
    assert [line.get_label() for line in mag.lines if not line.get_label().startswith("_")] == [
        "|R|"
    ]
    # the slab's first guided order, c / (P sqrt(2.2)) = 16.8 GHz, is marked as such
    assert [o for _f, o, _l in result.guided_onsets][0] == ((-1, 0), (0, -1), (0, 1), (1, 0))
    assert "Guided in layer 1 (not a grating lobe): (-1,0)" in tab.summary.text()
    # the ring's edges are long for the wavelength in the slab at 20 GHz: said, not hidden
    assert tab.warnings.isVisible() and "<b>coarse mesh</b>" in tab.warnings.text()
    assert tab.curve_line.text().startswith("⚠ Do not trust this curve blindly: coarse mesh")
    save_shot(window, "array_stack_grounded")

    # the layer moved above the sheet (↑ on its row): a ground plane with nothing under
    # the sheet is refused in a line, and the last curve stays
    click_row(qtbot, editor, 1)
    click(qtbot, editor.up_button)
    assert editor.sheet_row == 1
    assert editor.error.startswith("Ground plane: it needs a layer of non-zero thickness")
    assert editor.message.isVisible() and editor.message.text() == editor.error
    assert tab.result is result and editor.stack == grounded
    # the sheet's row selected, Add layer: a new layer under the sheet (RT/duroid 5880)
    click_row(qtbot, editor, 1)
    click(qtbot, editor.add_button)
    two = Stack(above=(Layer(MIL62, 2.2),), below=(Layer(1.575, 2.2, 0.0009),), ground=True)
    wait_for_stack(qtbot, tab, two)
    assert not editor.message.isVisible()
    assert_curve_is_the_direct_solve(tab, mesh, two)
    assert tab.plot.figure.axes[1].get_ylabel() == "∠R (°) at the top face,\nz = 1.575 mm"
    assert "R is referred to the top face, z = 1.575 mm; T = 0 (ground plane)." in (
        tab.summary.text()
    )
    # the side view: both bands to one scale, the ground's hatched bar, the sheet between
    sketch = editor.sketch.layout_now()
    heights = [b.bottom - b.top for b in sketch.bands]
    assert heights[0] / heights[1] == pytest.approx(MIL62 / 1.575, rel=1e-9)
    image = editor.sketch.grab().toImage()
    g0, g1 = sketch.ground
    row = [image.pixelColor(x, round((g0 + g1) / 2)).lightness() for x in range(40, 200)]
    assert min(row) < 80 and max(row) > 150  # hatched: dark lines on a light bar
    assert image.pixelColor(120, round(sketch.sheet)).lightness() < 60  # the metal
    save_shot(editor, "array_stack_editor")

    # ground off by a click: T comes back, referred to the bottom face
    click_check_box(editor.ground)
    open_ = Stack(above=(Layer(MIL62, 2.2),), below=(Layer(1.575, 2.2, 0.0009),))
    result = wait_for_stack(qtbot, tab, open_)
    assert_curve_is_the_direct_solve(tab, mesh, open_)
    assert np.all(abs(result.transmission) > 0.05)
    phase_axis = tab.plot.figure.axes[1]
    assert [line.get_label() for line in phase_axis.lines[:2]] == [
        "∠R",
        "∠T at the bottom face, z = −1.575 mm",
    ]


def test_bad_layer_values_are_said_in_a_line_and_keep_the_last_curve(window, qtbot):
    tab = open_array_tab(window, qtbot)
    editor = tab.stack_editor
    type_band(qtbot, tab, "10", "20", 3)
    run_and_wait(qtbot, tab)
    click(qtbot, editor.add_button)  # a good stack: swept live
    substrate = Stack(below=(Layer(1.575, 2.2, 0.0009),))
    good = wait_for_stack(qtbot, tab, substrate)
    line = tab.plot.figure.axes[0].lines[0].get_ydata().copy()
    sweeps = tab._tokens["array"]
    for column, text, message in (
        ("thickness", "-1", "Layer 1 (below the sheet): thickness '-1' is invalid; expected"),
        ("eps_r", "0", "Layer 1 (below the sheet): εr '0' is invalid; expected a number, 0 <"),
        ("mu_r", "abc", "Layer 1 (below the sheet): μr 'abc' is invalid"),
        ("loss_tangent", "-0.01", "Layer 1 (below the sheet): tan δ '-0.01' is invalid"),
    ):
        j = 1 + COLUMNS.index(column)
        keep = editor.table.item(1, j).text()
        type_cell(qtbot, editor, 1, column, text)
        assert editor.message.isVisible() and editor.message.text().startswith(message)
        assert editor.table.item(1, j).background().color() == BAD_CELL
        assert not tab.run()  # Run refuses it too, naming it
        assert tab.error.text().startswith(message)
        assert tab.result is good and tab._tokens["array"] == sweeps  # no sweep started
        np.testing.assert_allclose(tab.plot.figure.axes[0].lines[0].get_ydata(), line)
        assert editor.stack == substrate and editor.sketch.stack == substrate
        type_cell(qtbot, editor, 1, column, keep)
        assert not editor.message.isVisible() and tab.error.text() == ""
        assert editor.table.item(1, j).background().color() != BAD_CELL
    save_shot(tab, "array_stack_refused")
    # no layer left and a ground plane ticked: refused, the last curve stays
    click_row(qtbot, editor, 1)
    click(qtbot, editor.remove_button)
    qtbot.waitUntil(
        lambda: tab.result is not good and tab.result.inputs.stack is None, timeout=180_000
    )
    last = tab.result
    click_check_box(editor.ground)
    assert editor.message.text().startswith(
        "Ground plane: it needs a layer of non-zero thickness below the sheet"
    )
    assert not tab.run() and tab.result is last


def test_a_stack_edit_sweeps_live_and_the_event_loop_keeps_ticking(window, qtbot):
    tab = open_array_tab(window, qtbot)
    editor = tab.stack_editor
    type_band(qtbot, tab, "10", "20", 3)
    run_and_wait(qtbot, tab)
    click(qtbot, editor.add_button)
    wait_for_stack(qtbot, tab, Stack(below=(Layer(1.575, 2.2, 0.0009),)))
    beats = []
    timer = QTimer()
    timer.setInterval(10)
    timer.timeout.connect(lambda: beats.append(time.perf_counter()))
    type_cell(qtbot, editor, 1, "eps_r", "4.4")  # FR-4
    timer.start()
    try:
        fr4 = Stack(below=(Layer(1.575, 4.4, 0.0009),))
        wait_for_stack(qtbot, tab, fr4)
        qtbot.wait(200)  # the new curve painted
    finally:
        timer.stop()
    gaps = np.diff(beats)
    assert len(gaps) > 10 and gaps.max() < HEARTBEAT_GAP, gaps.max()
    # the solver-grade mesh, the ring's edges within λ/10 at 20 GHz in the FR-4
    assert tab.solved.graded and tab.solved.shown is window.model.result.mesh
    r, t = periodic_solve(tab.solved.mesh, 15e9, TE, stack=fr4).co_polar()
    assert abs(tab.result.reflection[1] - r) < 1e-6 and abs(tab.result.transmission[1] - t) < 1e-6


def test_the_curve_is_whole_and_unscrolled_at_the_default_size(window, qtbot):
    window.resize(*SCRIPTED_SIZE)
    qtbot.wait(50)
    tab = open_array_tab(window, qtbot)
    qtbot.waitUntil(lambda: tab.plot.picture is not None, timeout=60_000)
    qtbot.wait(400)  # a redraw at the laid-out size
    for view in (tab.plot, tab.drawing):
        assert view.isVisible()
        # nothing of it is clipped (by a scroll area, a dock's edge or the window's)
        assert view.visibleRegion().boundingRect() == view.rect()
        # and its picture is drawn for its size (it was drawn 100 px wide before a redraw)
        qtbot.waitUntil(
            lambda v=view: abs(v.picture.rgba.shape[1] / v.picture.ratio - v.width()) <= 2,
            timeout=60_000,
        )
    assert tab.plot.width() >= 400 and tab.plot.height() >= 250
    # the inputs and Run stay where they were: in the Solve dock, above its fold
    assert tab.run_button.visibleRegion().boundingRect() == tab.run_button.rect()
    save_shot(window, "array_default_size")
    # closed (what its title bar's × does), the dock comes back with Show the curve
    assert not tab.show_curve_button.isVisible()
    tab.curve_dock.close()
    qtbot.waitUntil(tab.show_curve_button.isVisible)
    click(qtbot, tab.show_curve_button)
    qtbot.waitUntil(tab.plot.isVisible)
    assert not tab.show_curve_button.isVisible()


def test_a_picture_drawn_for_another_size_is_drawn_again(qtbot):
    """The tab's first (empty) curve was drawn before the layout, 100 px wide, and stayed
    so: a resize before a picture exists asked for no redraw, and none came after."""
    from barymesh.app.panels.array_figures import draw_curve
    from barymesh.app.panels.infinite_array_panel import PictureView

    view = PictureView(200, grow=True)
    qtbot.addWidget(view)
    view.resize(420, 240)
    view.show()
    qtbot.waitExposed(view)
    (w, h), ratio = view.request_size()
    with qtbot.waitSignal(view.resized, timeout=2_000):
        view.show_picture(draw_curve(None, (100, h), ratio))  # drawn for the old size
    with qtbot.assertNotEmitted(view.resized, wait=400):
        view.show_picture(draw_curve(None, (w, h), ratio))  # drawn for its size: done

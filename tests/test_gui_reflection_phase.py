"""The Solve dock's "Reflection phase" tab in the real window (Xvfb), driven as a user does
(issue 33 §1, Window): a cell preset opened, the parameter chosen with the keys, its range,
the frequency and the angle typed, the stack's layer and ground plane added with the mouse,
Run clicked; every curve against barymesh.mom.reflection_library called directly with the
same inputs. The preview (every 4th value) comes before the whole curve; a stack edit, a
typed frequency and a slider re-solve it live while the event loop keeps ticking; a click
on the curve loads that cell; a bad range is said in one line and the curve stays.

The cell is the hexagonal-rings preset made coarse (two subdivisions, 20° steps: 144
triangles), its ring's inner radius swept over 7 values at 10 GHz over a grounded
RT/duroid board: the curve crosses the ring's resonance, about 330° of phase, in a second
or two of solves.
"""

import os
import shutil
import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pyvistaqt")
pytest.importorskip("matplotlib")

from app_user import (  # noqa: E402
    choose,
    click_check_box,
    drag_slider,
    session_heap_frozen,
    settle,
    type_into,
)
from PySide6.QtCore import Qt, QTimer  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402
from test_gui_array_stack import type_cell  # noqa: E402

from barymesh.app.panels.phase_curve import curve_key  # noqa: E402
from barymesh.mom import Layer, Stack, reflection_library  # noqa: E402

PATH = "elements[0].inner_radius"
VALUES = np.linspace(1.0, 4.0, 7)  # the ring (1 mm wide) stays inside its cell
BOARD = Stack(below=(Layer(1.575, 2.2, 0.0009),), ground=True)  # the editor's new layer
#: The longest gap the event loop may show while a live curve is solved and drawn: only
#: gross blocking (a solve on the GUI thread) fails it on a loaded machine.
HEARTBEAT_GAP = 1.0
TIMEOUT = 180_000


def save_shot(widget, tmp_path, name):
    """Save a picture to ``tmp_path`` (and to BARYMESH_TEST_SHOTS if it names a folder)."""
    for _ in range(3):
        QApplication.processEvents()
    target = tmp_path / f"{name}.png"
    assert widget.grab().save(str(target))
    folder = os.environ.get("BARYMESH_TEST_SHOTS")
    if folder:
        shutil.copy(target, Path(folder) / target.name)
    return target


def open_phase_tab(window, qtbot):
    """Open the coarse hexagonal-rings cell, raise the Solve dock's Reflection phase tab."""
    assert window.cell_tools.load_cell_preset("hexagonal-rings")
    settle(window, qtbot)
    assert window.model.set_value("subdivisions", 2)
    assert window.model.set_value("angle_step", 20.0)
    settle(window, qtbot)
    assert window.model.result.mesh.n_triangles == 144
    window.solve_dock.raise_()
    window.solve_panel.tabs.setCurrentWidget(window.phase_panel)
    tab = window.phase_panel
    qtbot.waitUntil(tab.plot.isVisible)
    assert tab.inputs_box.isEnabled() and not tab.reason.isVisible()
    return tab


def add_board(qtbot, tab):
    """A layer under the sheet (the editor's RT/duroid 5880) and a ground plane, by mouse."""
    editor = tab.stack_editor
    qtbot.mouseClick(editor.add_button, Qt.MouseButton.LeftButton)
    click_check_box(editor.ground)
    assert editor.stack == BOARD


def type_inputs(qtbot, tab, start="1", stop="4", points=7, ghz="10", theta="0", phi="0"):
    choose(tab.parameter, PATH)
    type_into(tab.start, start)
    type_into(tab.stop_edit, stop)
    type_into(tab.points.lineEdit(), str(points))
    type_into(tab.frequency, ghz)
    type_into(tab.theta, theta)
    type_into(tab.phi, phi)


def run_and_wait(qtbot, tab):
    """Click Run; the preview's and the curve's libraries in the order they came."""
    seen = []
    tab.preview.connect(lambda lib: seen.append(("preview", lib)))
    tab.swept.connect(lambda lib: seen.append(("curve", lib)))
    with qtbot.waitSignal(tab.swept, timeout=TIMEOUT):
        qtbot.mouseClick(tab.run_button, Qt.MouseButton.LeftButton)
    return seen


def direct(window, stack, frequency=10e9, pol="TM", theta=0.0):
    cell = window.model.shown_state.visible
    incidence = {"theta": theta, "phi": 0.0, "pol": pol}
    return reflection_library(cell, PATH, VALUES, frequency, incidence=incidence, stack=stack)


def curve_key_of(tab):
    """What the curve shown depends on in its cell (all but the parameter)."""
    return None if tab.curve_for is None else tab.curve_for[0]


def curve_key_of_screen(tab):
    return curve_key(tab.cell, PATH)


def phase_line(tab):
    return tab.plot.figure.axes[0].lines[0]


def test_tab_is_disabled_with_a_reason_without_a_lattice(window, qtbot):
    settle(window, qtbot)  # the plain double ring: a structure, no lattice
    tab = window.phase_panel
    assert window.model.result.mesh.lattice is None
    assert not tab.inputs_box.isEnabled()
    assert tab.reason.text().startswith("The mesh on screen has no lattice")
    assert not tab.run()


def test_typed_inputs_give_reflection_library_curve_preview_first(window, qtbot, tmp_path):
    tab = open_phase_tab(window, qtbot)
    # the cell's parameters a study's axis takes, its structure's sizes first
    paths = [tab.parameter.itemData(i) for i in range(tab.parameter.count())]
    assert paths == [
        "elements[0].inner_radius",
        "elements[0].patch_size",
        "elements[0].position[0]",
        "elements[0].position[1]",
        "elements[0].rotation",
        "lattice.hexagonal",
    ]
    add_board(qtbot, tab)
    type_inputs(qtbot, tab)
    assert tab.error.text() == ""
    seen = run_and_wait(qtbot, tab)
    # the preview (every 4th value and the last) came first, then the whole curve
    assert [kind for kind, _lib in seen] == ["preview", "curve"]
    preview, lib = seen[0][1], seen[1][1]
    np.testing.assert_allclose(preview.values, VALUES[[0, 4, 6]])
    np.testing.assert_allclose(lib.values, VALUES)
    want = direct(window, BOARD)
    np.testing.assert_allclose(lib.phase_deg, want.phase_deg, atol=1e-6)
    np.testing.assert_allclose(lib.magnitude, want.magnitude, atol=1e-6)
    np.testing.assert_allclose(lib.reflection, want.reflection, atol=1e-9)
    np.testing.assert_allclose(preview.reflection, want.reflection[[0, 4, 6]], atol=1e-9)
    # the ring's resonance is in the range: more than 300° of phase (about 330°)
    span = float(np.ptp(want.phase_deg[:, 0]))
    assert 300.0 < span < 360.0
    # what is drawn is that curve, the cell's 3 mm marked on it
    np.testing.assert_allclose(phase_line(tab).get_xdata(), VALUES)
    np.testing.assert_allclose(phase_line(tab).get_ydata(), want.phase_deg[:, 0], atol=1e-6)
    np.testing.assert_allclose(
        tab.plot.figure.axes[1].lines[0].get_ydata(), want.magnitude[:, 0], atol=1e-6
    )
    assert tab.marked == 3.0
    dashed = [ln for ln in tab.plot.figure.axes[0].lines if ln.get_linestyle() == "--"]
    assert [ln.get_xdata()[0] for ln in dashed] == [3.0]
    texts = [t.get_text() for t in tab.plot.figure.texts]
    assert f"covers {span:.0f}° of 360°" in texts[0]
    assert texts[1] == "∠R referred to the sheet, z = 0 mm"  # the board is under the sheet
    assert "this cell: 3 mm" in tab.plot.figure.axes[0].texts[0].get_text()
    # the Infinite array tab shows the same stack (one stack for the two)
    assert window.array_panel.stack_editor.stack == BOARD
    window.phase_panel.curve_dock.raise_()
    shot = save_shot(window, tmp_path, "reflection_phase_window")
    assert shot.stat().st_size > 10_000
    save_shot(tab.curve_area, tmp_path, "reflection_phase_curve")


def test_a_layer_above_moves_the_reference_plane_and_it_is_written(window, qtbot):
    tab = open_phase_tab(window, qtbot)
    add_board(qtbot, tab)
    # a 0.5 mm cover over the sheet (set whole: typing into the table is tested below)
    cover = Stack(above=(Layer(0.5, 3.0),), below=BOARD.below, ground=True)
    tab.stack_editor.set_stack(cover)
    assert window.array_panel.stack_editor.stack == cover
    type_inputs(qtbot, tab, points=3)
    run_and_wait(qtbot, tab)
    assert tab.library.reference_plane == 0.5
    texts = [t.get_text() for t in tab.plot.figure.texts]
    assert texts[1] == "∠R referred to the stack's top face, z = 0.5 mm"


def test_live_stack_edit_and_frequency_re_solve_and_the_loop_keeps_ticking(window, qtbot):
    tab = open_phase_tab(window, qtbot)
    add_board(qtbot, tab)
    type_inputs(qtbot, tab)
    run_and_wait(qtbot, tab)
    first = tab.library
    # εr 2.2 -> 3.0 typed into the layer's cell: the curve follows (Live)
    with qtbot.waitSignal(tab.swept, timeout=TIMEOUT):
        type_cell(qtbot, tab.stack_editor, 1, "eps_r", "3")
    thicker = Stack(below=(Layer(1.575, 3.0, 0.0009),), ground=True)
    assert tab.library.stack == thicker
    want = direct(window, thicker)
    np.testing.assert_allclose(tab.library.phase_deg, want.phase_deg, atol=1e-6)
    assert np.max(np.abs(want.phase_deg - first.phase_deg)) > 5.0  # it moved
    np.testing.assert_allclose(phase_line(tab).get_ydata(), want.phase_deg[:, 0], atol=1e-6)
    # a typed frequency while a 10 ms heartbeat runs: no gross block of the event loop
    beats = []
    timer = QTimer()
    timer.setInterval(10)
    timer.timeout.connect(lambda: beats.append(time.perf_counter()))
    previews = []
    tab.preview.connect(previews.append)
    with session_heap_frozen():  # a full collection scans a window's heap, not the session's
        timer.start()
        try:
            with qtbot.waitSignal(tab.swept, timeout=TIMEOUT):
                type_into(tab.frequency, "11")
            qtbot.wait(300)  # the curve shown, the loop still beating
        finally:
            timer.stop()
    assert len(previews) == 1 and len(previews[0].values) == 3
    gaps = np.diff(beats)
    assert len(gaps) > 20 and gaps.max() < HEARTBEAT_GAP, gaps.max()
    want = direct(window, thicker, frequency=11e9)
    np.testing.assert_allclose(tab.library.phase_deg, want.phase_deg, atol=1e-6)


def test_a_slider_re_solves_and_a_click_loads_that_cell(window, qtbot, tmp_path):
    tab = open_phase_tab(window, qtbot)
    add_board(qtbot, tab)
    type_inputs(qtbot, tab)
    run_and_wait(qtbot, tab)
    # another value of the cell (the ring's width, its slider dragged by mouse): live
    row = window.controls.rows["patch_size"]
    with qtbot.waitSignal(tab.swept, timeout=TIMEOUT):
        drag_slider(row.slider, row.slider_spec.to_slider(1.5))
        settle(window, qtbot)
    width = window.model.cell.elements[0].params.patch_size
    assert 1.3 < width < 1.7  # 1 mm before
    qtbot.waitUntil(lambda: curve_key_of(tab) == curve_key_of_screen(tab), timeout=TIMEOUT)
    want = direct(window, BOARD)
    np.testing.assert_allclose(tab.library.phase_deg, want.phase_deg, atol=1e-6)
    # a click on the curve's 3.5 mm point: that cell is the one on screen
    solved = tab._tokens["curve"]
    point = tab.plot.data_to_widget(3.5)
    qtbot.mouseClick(tab.plot, Qt.MouseButton.LeftButton, pos=point)
    qtbot.waitUntil(lambda: window.model.cell.elements[0].params.inner_radius == 3.5)
    settle(window, qtbot)
    mesh = window.model.result.mesh
    assert window.model.shown_state.visible.elements[0].params.inner_radius == 3.5
    assert mesh.n_triangles > 0
    # the curve stays (the parameter itself changed) and the mark moves to 3.5 mm
    qtbot.waitUntil(lambda: tab.marked == 3.5)
    qtbot.waitUntil(
        lambda: (
            [
                ln.get_xdata()[0]
                for ln in tab.plot.figure.axes[0].lines
                if ln.get_linestyle() == "--"
            ]
            == [3.5]
        ),
        timeout=60_000,
    )
    assert tab._tokens["curve"] == solved  # not solved again
    assert window.model.can_undo  # one undo step, as an edit of the cell
    save_shot(tab.curve_area, tmp_path, "reflection_phase_clicked")


def test_bad_range_is_said_in_a_line_and_the_curve_stays(window, qtbot):
    tab = open_phase_tab(window, qtbot)
    type_inputs(qtbot, tab, points=2)
    good = run_and_wait(qtbot, tab)[-1][1]
    line = phase_line(tab).get_ydata().copy()
    token = tab._tokens["curve"]
    for field, text, message in (
        (tab.stop_edit, "five", "Range stop 'five' is not a number"),
        (tab.stop_edit, "1", "Range 1 to 1: the stop must differ from the start"),
        (tab.start, "-1", f"{PATH} = -1: the cell refuses it"),
        (tab.frequency, "0", "Frequency '0' GHz is invalid; expected a positive number"),
        (tab.theta, "95", "θ '95' is out of range"),
    ):
        keep = field.text()
        type_into(field, text)  # Enter: said at once (Live would solve a good one)
        assert tab.error.text().startswith(message), tab.error.text()
        assert not tab.run()
        assert tab.error.text().startswith(message), tab.error.text()
        assert "\n" not in tab.error.text() and "Traceback" not in tab.error.text()
        assert tab.library is good
        np.testing.assert_allclose(phase_line(tab).get_ydata(), line)
        type_into(field, keep)  # the curve's inputs again: nothing to solve
        assert tab.error.text() == "" and tab.library is good
        assert tab._tokens["curve"] == token  # no solve was started


def test_a_new_input_cancels_the_running_curve_and_its_result_is_dropped(window, qtbot):
    tab = open_phase_tab(window, qtbot)
    type_inputs(qtbot, tab, points=41)  # a long curve: 82 solves
    qtbot.mouseClick(tab.run_button, Qt.MouseButton.LeftButton)
    running = tab._tokens["curve"]
    # 7 values at 11 GHz typed while it runs (Live): the long one is told to stop
    with qtbot.waitSignal(tab.swept, timeout=TIMEOUT):
        type_into(tab.points.lineEdit(), "7")
        type_into(tab.frequency, "11")
    assert running in tab.cancelled
    qtbot.waitUntil(lambda: running in tab.stopped, timeout=TIMEOUT)  # it stopped early
    assert len(tab.library.values) == 7 and tab.library.frequencies[0] == 11e9
    want = direct(window, None, frequency=11e9)
    np.testing.assert_allclose(tab.library.phase_deg, want.phase_deg, atol=1e-6)

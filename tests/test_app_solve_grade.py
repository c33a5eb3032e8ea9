"""The window solves the solver-grade mesh by default (issue 29 §2), driven as a user does.

The Solve dock and the Infinite array tab have a "Solver-grade mesh" box, on by default: a
uniform patch on screen is solved on its graded mesh (more unknowns), the result names
both meshes' unknowns and the Surface current is drawn on the mesh solved; off, the mesh
on screen is solved. A frequency beyond the λ/10 rule's reach is refused in one line and
the last good curve stays. Every count is computed here, independently, through
barymesh.solver_grade and the builders.
"""

import os
import threading
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pyvistaqt")
pytest.importorskip("matplotlib")

from app_user import click_check_box, settle, type_into  # noqa: E402
from PySide6.QtCore import Qt  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

from barymesh import MeshParams, build_mesh  # noqa: E402
from barymesh.cell import Element, Lattice, UnitCell, build_cell  # noqa: E402
from barymesh.mom import PlaneWave, periodic_solve, solve  # noqa: E402
from barymesh.solver_grade import solver_cell, solver_params  # noqa: E402

#: A 100 mm square patch, n = 4: 40 RWG unknowns on screen (3n² − 2n), uniform.
PATCH = MeshParams(structure="patch", patch_size=100.0, subdivisions=4)
#: An 8 mm patch, n = 5 (65 unknowns), on a 12 mm square lattice (no metal on the cell's
#: sides; n = 4's triangles are too large for the periodic solver's cell).
CELL_PATCH = MeshParams(structure="patch", patch_size=8.0, subdivisions=5)
P = 12.0


@pytest.fixture
def window_params():
    return PATCH


def click(qtbot, widget, **kw):
    qtbot.mouseClick(widget, Qt.MouseButton.LeftButton, **kw)


def shot(widget, name):
    """Keep a picture when BARYMESH_TEST_SHOTS names a folder (to look at)."""
    folder = os.environ.get("BARYMESH_TEST_SHOTS")
    if folder:
        for _ in range(3):
            QApplication.processEvents()
        widget.grab().save(str(Path(folder) / f"{name}.png"))


def open_solve(window, qtbot):
    settle(window, qtbot)
    window.solve_dock.raise_()
    qtbot.waitUntil(window.solve_panel.isVisible)
    return window.solve_panel


def solve_by_mouse(qtbot, panel):
    before = panel.last_outcome
    click(qtbot, panel.solve_button)
    qtbot.waitUntil(lambda: panel.last_outcome is not before, timeout=120_000)
    return panel.last_outcome


def test_solve_dock_solves_the_solver_grade_mesh_and_draws_the_current_on_it(window, qtbot):
    panel = open_solve(window, qtbot)
    assert panel.solver_grade.isChecked()  # the default
    drawn = window.model.result.mesh
    assert len(drawn.rwg) == 40
    type_into(panel.frequency, "1")
    assert panel.solution is None  # a solver-grade mesh is solved when asked
    outcome = solve_by_mouse(qtbot, panel)
    assert outcome.thread != threading.get_ident()  # built and solved in the worker
    graded = build_mesh(solver_params(PATCH, frequency=1e9))  # n = 16, graded: 736
    assert len(graded.rwg) == 3 * 16**2 - 2 * 16 == 736
    solution = panel.solution
    assert len(solution.coefficients) == len(graded.rwg)
    np.testing.assert_allclose(solution.coefficients, solve(graded, 1e9).coefficients, rtol=1e-9)
    text = panel.summary.text()
    assert (
        "Solved on the solver-grade mesh: 736 unknowns (the view shows the mesh as drawn, "
        "40 unknowns)" in text
    ), text
    # the view still shows the drawn mesh; the current is drawn on the mesh solved
    assert window.model.result.mesh is drawn
    layer = panel.layer
    assert layer.mesh is panel.solved_mesh and layer.mesh.n_triangles == graded.n_triangles
    assert layer.current.shape == (graded.n_triangles, 3)
    assert layer.surface.n_cells == graded.n_triangles
    np.testing.assert_array_equal(layer.mesh.triangles, graded.triangles)
    shot(panel, "solve_dock_solver_grade")


def test_solve_dock_box_off_solves_the_mesh_as_drawn(window, qtbot):
    panel = open_solve(window, qtbot)
    click_check_box(panel.solver_grade)
    assert not panel.solver_grade.isChecked()
    drawn = window.model.result.mesh
    type_into(panel.frequency, "1")  # 40 unknowns as drawn: auto-solved at once
    click(qtbot, panel.solve_button)
    assert len(panel.solution.coefficients) == len(drawn.rwg) == 40
    assert panel.layer.mesh is drawn and panel.solved_mesh is drawn
    assert "Solved on the mesh as drawn: 40 unknowns" in panel.summary.text()
    # on again, by a click: the current on screen was of the drawn mesh, now another input
    click_check_box(panel.solver_grade)
    assert panel.solution is None and panel.stale.isVisible()


def test_solve_dock_refuses_a_frequency_beyond_lambda_over_10_in_a_line(window, qtbot):
    panel = open_solve(window, qtbot)
    type_into(panel.frequency, "1")
    solve_by_mouse(qtbot, panel)
    assert len(panel.solution.coefficients) == 736
    # the Sweep tab's curve, then a sweep whose top the λ/10 rule cannot reach
    panel.tabs.setCurrentIndex(1)
    type_into(panel.sweep_from, "1")
    type_into(panel.sweep_to, "2")
    panel.sweep_count.setValue(3)
    click(qtbot, panel.sweep_button)
    qtbot.waitUntil(lambda: panel.sweep_result is not None, timeout=120_000)
    good = panel.sweep_result
    assert len(good.frequencies) == 3
    assert "Solved on the solver-grade mesh: 736 unknowns" in panel.resonance_label.text()
    type_into(panel.sweep_to, "1000")
    before = panel.last_outcome
    click(qtbot, panel.sweep_button)
    qtbot.waitUntil(lambda: panel.last_outcome is not before, timeout=60_000)
    message = panel.status.text()
    assert message.startswith("The sweep failed: the solver-grade mesh of the patch"), message
    assert "untick “Solver-grade mesh”" in message
    assert "\n" not in message and "Traceback" not in message
    assert panel.sweep_result is good and panel.plot.result is good  # the last curve stays
    # and the Solve tab: the same refusal in one line
    panel.tabs.setCurrentIndex(0)
    type_into(panel.frequency, "1000")
    before = panel.last_outcome
    click(qtbot, panel.solve_button)
    qtbot.waitUntil(lambda: panel.last_outcome is not before, timeout=60_000)
    message = panel.status.text()
    assert message.startswith("The solve failed: the solver-grade mesh of the patch"), message
    assert "\n" not in message and "Traceback" not in message
    shot(panel, "solve_dock_refused")


# -- the Infinite array tab --------------------------------------------------------------


def open_cell(window, qtbot):
    # the patch's corner at the origin: centred in the cell, as barymesh periodic does
    centred = Element(CELL_PATCH, position=(-4.0, -4.0))
    cell = UnitCell(Lattice.rectangular(P), (centred,), name="patch")
    window.cell_tools.open_cell(cell, "test cell")
    settle(window, qtbot)
    window.solve_dock.raise_()
    window.solve_panel.tabs.setCurrentWidget(window.array_panel)
    tab = window.array_panel
    qtbot.waitUntil(tab.plot.isVisible)
    type_into(tab.band_start, "10")
    type_into(tab.band_stop, "20")
    type_into(tab.points.lineEdit(), "2")
    return cell, tab


def run(qtbot, tab):
    before = tab.last_outcome
    click(qtbot, tab.run_button)
    qtbot.waitUntil(
        lambda: tab.last_outcome is not before and tab.last_outcome.kind == "array",
        timeout=120_000,
    )


def test_array_tab_solves_the_solver_grade_cell_and_draws_the_current_on_it(window, qtbot):
    cell, tab = open_cell(window, qtbot)
    assert tab.solver_grade.isChecked()
    drawn = window.model.result.mesh
    assert len(drawn.rwg) == 65
    run(qtbot, tab)
    assert tab.last_outcome.thread != threading.get_ident()
    graded = build_cell(solver_cell(cell, frequency=20e9)).mesh  # the band's top
    assert len(graded.rwg) == 736
    assert tab.solved.mesh.n_triangles == graded.n_triangles
    np.testing.assert_array_equal(tab.solved.mesh.triangles, graded.triangles)
    assert (
        "solved on the solver-grade mesh: 736 unknowns (the view shows the mesh as drawn, "
        "65 unknowns)" in tab.status.text()
    ), tab.status.text()
    wave = PlaneWave.from_angles(0.0, 0.0, 90.0)
    r, t = periodic_solve(graded, 20e9, wave).co_polar()
    assert abs(tab.result.reflection[-1] - r) < 1e-6 and abs(tab.result.transmission[-1] - t) < 1e-6
    # a click on the curve: the cell's current, drawn on the mesh solved
    click(qtbot, tab.plot, pos=tab.plot.data_to_widget(15e9))
    qtbot.waitUntil(lambda: tab.point is not None, timeout=120_000)
    layer = window.solve_panel.layer
    assert layer.mesh is tab.solved.mesh and layer.current.shape == (graded.n_triangles, 3)
    direct = periodic_solve(graded, tab.point.frequency, wave)
    np.testing.assert_allclose(layer.current, direct.current_density, rtol=1e-6, atol=1e-9)
    shot(tab, "array_tab_solver_grade")


def test_array_tab_box_off_solves_the_mesh_as_drawn(window, qtbot):
    _cell, tab = open_cell(window, qtbot)
    click_check_box(tab.solver_grade)
    assert not tab.solver_grade.isChecked()
    run(qtbot, tab)
    drawn = window.model.result.mesh
    assert tab.solved.mesh is drawn and not tab.solved.graded
    assert "solved on the mesh as drawn: 65 unknowns" in tab.status.text()
    r, _t = periodic_solve(drawn, 10e9, PlaneWave.from_angles(0.0, 0.0, 90.0)).co_polar()
    assert abs(tab.result.reflection[0] - r) < 1e-6


def test_array_tab_refuses_a_band_beyond_lambda_over_10_and_keeps_the_curve(window, qtbot):
    _cell, tab = open_cell(window, qtbot)
    run(qtbot, tab)
    good = tab.result
    line = tab.plot.figure.axes[0].lines[0].get_ydata().copy()
    type_into(tab.band_stop, "2000")
    click(qtbot, tab.run_button)
    qtbot.waitUntil(lambda: tab.error.text() != "", timeout=60_000)
    message = tab.error.text()
    assert message.startswith("The array sweep failed: the solver-grade mesh of the patch"), message
    assert "untick “Solver-grade mesh”" in message
    assert "\n" not in message and "Traceback" not in message
    assert tab.result is good
    np.testing.assert_allclose(tab.plot.figure.axes[0].lines[0].get_ydata(), line)
    shot(tab, "array_tab_refused")

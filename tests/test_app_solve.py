"""The Solve dock and the Surface current layer, driven as a user does (issue 11).

Numbers are checked against ``barymesh.mom`` run directly on the same mesh and against
Makarov's published plate current (0.01853 A/m at 300 MHz, his chapter-2 code).
"""

import threading

import numpy as np
import pytest
import pyvista as pv

pytest.importorskip("pyvistaqt")
pytest.importorskip("matplotlib")

from app_user import choose, click_check_box, drag_slider, settle, type_into  # noqa: E402
from PySide6.QtCore import QPoint, Qt  # noqa: E402
from PySide6.QtTest import QTest  # noqa: E402

from barymesh import MeshParams  # noqa: E402
from barymesh.app.panels.solve_panel import AUTO_SOLVE_UNKNOWNS  # noqa: E402
from barymesh.app.view.current_layer import BAR_TITLE, CHARGE, CHARGE_TITLE, MAGNITUDE  # noqa: E402
from barymesh.mom import PlaneWave, solve, sweep  # noqa: E402

#: Makarov's chapter-2 code on platefine, plane wave along −z, E along x, 1 V/m, 300 MHz.
MAKAROV_PLATEFINE_JMAX = 0.01853


@pytest.fixture
def window_params():
    """A 100 mm square patch, n = 4: 40 RWG unknowns (3n² − 2n), solved on the GUI thread."""
    return MeshParams(structure="patch", patch_size=100.0, subdivisions=4)


def open_solve(window, qtbot, as_drawn=True):
    """The Solve dock raised; ``as_drawn``: its Solver-grade mesh box clicked off, as these
    tests are of the dock's workings on the mesh on screen, checked against direct solves
    of that mesh (tests/test_app_solve_grade.py has the solver-grade default)."""
    settle(window, qtbot)
    window.solve_dock.raise_()  # the dock's tab, as a user clicks it
    qtbot.waitUntil(window.solve_panel.isVisible)
    panel = window.solve_panel
    if as_drawn:
        click_check_box(panel.solver_grade)
        assert not panel.solver_grade.isChecked()
    return panel


def largest_j(solution):
    return float(np.linalg.norm(np.abs(solution.current_density), axis=1).max())


def click(qtbot, button):
    qtbot.mouseClick(button, Qt.MouseButton.LeftButton)


def test_makarov_plate_current_in_the_layer(window, qtbot):
    menu = next(a.menu() for a in window.menuBar().actions() if "Presets" in a.text())
    next(a for a in menu.actions() if a.text() == "makarov-platefine").trigger()
    panel = open_solve(window, qtbot)
    mesh = window.model.result.mesh
    assert len(mesh.rwg) == 736 > AUTO_SOLVE_UNKNOWNS
    type_into(panel.frequency, "300")
    choose(panel.unit, "MHz")
    assert panel.solution is None  # 736 unknowns: not solved without asking
    click(qtbot, panel.solve_button)
    assert panel.cancel_button.isEnabled() and panel.progress.isVisible()
    qtbot.waitUntil(lambda: panel.solution is not None, timeout=120_000)
    outcome = panel.last_outcome
    assert outcome.thread != threading.get_ident()  # solved off the GUI thread
    assert not panel.progress.isVisible() and not panel.cancel_button.isEnabled()

    direct = solve(mesh, 300e6, PlaneWave(direction=(0, 0, -1), polarization=(1, 0, 0)))
    jmax = largest_j(direct)
    layer = panel.layer
    shown = np.asarray(layer.surface.cell_data[MAGNITUDE])
    assert shown.max() == pytest.approx(jmax, rel=1e-12)
    assert int(np.argmax(shown)) == int(
        np.argmax(np.linalg.norm(np.abs(direct.current_density), axis=1))
    )
    assert abs(shown.max() / MAKAROV_PLATEFINE_JMAX - 1) < 0.015
    assert panel.solution.frequency == 300e6
    assert f"{jmax:.5g}" in panel.summary.text()
    assert layer._surface_actor.GetVisibility() and layer._arrow_actor.GetVisibility()


def test_small_mesh_auto_solves_and_follows_the_mesh(window, qtbot):
    panel = open_solve(window, qtbot)
    mesh = window.model.result.mesh
    assert len(mesh.rwg) == 40
    assert panel.solution is None  # the window opens without a current
    assert "surface_current" not in window.plotter.renderer.actors
    type_into(panel.frequency, "1.2")  # GHz: solved at once on the GUI thread
    assert panel.solution is not None
    assert panel.last_outcome.thread == threading.get_ident()
    direct = solve(mesh, 1.2e9)
    np.testing.assert_allclose(panel.solution.coefficients, direct.coefficients, rtol=1e-12)
    actor = panel.layer._surface_actor
    type_into(panel.frequency, "1.3")  # the same mesh: its actors are updated in place
    assert panel.layer._surface_actor is actor
    assert panel.layer.magnitude.max() == pytest.approx(largest_j(solve(mesh, 1.3e9)), rel=1e-12)
    np.testing.assert_allclose(panel.layer.surface.cell_data[MAGNITUDE], panel.layer.magnitude)
    assert actor.GetMapper().GetScalarRange()[1] == pytest.approx(panel.layer.magnitude.max())
    type_into(panel.frequency, "1.2")
    assert panel.layer.magnitude.max() == pytest.approx(largest_j(direct), rel=1e-12)
    assert panel.solution.extinction_cross_section == pytest.approx(
        direct.extinction_cross_section, rel=1e-12
    )

    # a new mesh (n = 5: 3·25 − 10 = 65 unknowns) is solved again, not shown with old data
    type_into(window.controls.rows["subdivisions"].field, "5")
    window.controller.flush()
    new = window.model.result.mesh
    assert len(new.rwg) == 65
    assert panel.layer.mesh is new and panel.solution_mesh is new
    assert panel.layer.magnitude.shape == (len(new.triangles),)
    assert panel.layer.magnitude.max() == pytest.approx(largest_j(solve(new, 1.2e9)), rel=1e-12)


def test_result_is_invalidated_visibly(window, qtbot):
    panel = open_solve(window, qtbot)
    type_into(panel.frequency, "1")
    assert panel.solution is not None and panel.layer.shown
    names = {"surface_current", "surface_current_arrows"}
    assert names <= set(window.plotter.renderer.actors)
    assert BAR_TITLE in window.plotter.scalar_bars
    panel.auto.click()  # no auto-solve: a change leaves the view without a result
    assert not panel.auto.isChecked()
    type_into(panel.frequency, "2")
    assert panel.solution is None and panel.layer.current is None
    assert panel.stale.isVisible() and "other inputs" in panel.stale.text()
    assert not names & set(window.plotter.renderer.actors)  # |J| surface and arrows gone
    assert BAR_TITLE not in window.plotter.scalar_bars
    click(qtbot, panel.solve_button)
    assert panel.solution.frequency == 2e9 and not panel.stale.isVisible()

    type_into(window.controls.rows["patch_size"].field, "80")
    window.controller.flush()
    assert panel.solution is None and panel.layer.current is None
    assert "previous mesh" in panel.stale.text() and panel.stale.isVisible()


def test_bad_inputs_are_refused_in_words(window, qtbot):
    panel = open_solve(window, qtbot)
    type_into(panel.frequency, "1")
    good = panel.solution
    type_into(panel.frequency, "abc")
    assert "Frequency 'abc' is not a number" in panel.error.text()
    type_into(panel.frequency, "1")
    panel.polarization.lineEdit().setFocus()
    type_into(panel.polarization.lineEdit(), "0, 0, 1")  # along the direction of travel
    click(qtbot, panel.solve_button)
    assert "not perpendicular" in panel.error.text()
    assert panel.solution is good  # the last good result stays, like the last good mesh


def test_phase_slider_turns_the_arrows(window, qtbot):
    panel = open_solve(window, qtbot)
    type_into(panel.frequency, "1.5")
    layer = panel.layer
    current = panel.solution.current_density
    np.testing.assert_allclose(layer.vectors, current.real)
    before = np.asarray(layer.arrows.points).copy()
    drag_slider(panel.phase, 90)
    phi = panel.phase.value()
    assert 80 <= phi <= 100 and panel.phase_label.text() == f"{phi}°"
    np.testing.assert_allclose(layer.vectors, np.real(current * np.exp(1j * np.deg2rad(phi))))
    assert not np.allclose(np.asarray(layer.arrows.points), before)
    window.plotter.render()
    drawn = pv.wrap(layer._arrow_actor.GetMapper().GetInput())  # what was drawn
    np.testing.assert_allclose(np.asarray(drawn.points), np.asarray(layer.arrows.points))
    drag_slider(panel.phase, 180)  # half a period later every arrow points the other way
    if panel.phase.value() == 180:
        np.testing.assert_allclose(layer.vectors, -current.real, atol=1e-15)
    choose(panel.scale, "log")
    assert layer.scale == "log" and layer.surface is not None
    assert f"{BAR_TITLE}, log scale" in window.plotter.scalar_bars

    # charge density ρ_s = j ∇·J / ω, signed, turning with the phase
    choose(panel.quantity, "charge")
    assert CHARGE_TITLE in window.plotter.scalar_bars and not panel.scale.isEnabled()
    drag_slider(panel.phase, 45)
    phi = panel.phase.value()
    rho = panel.solution.charge_density
    window.plotter.render()
    shown = pv.wrap(layer._surface_actor.GetMapper().GetInput())  # what was drawn
    np.testing.assert_allclose(
        np.asarray(shown.cell_data[CHARGE]), np.real(rho * np.exp(1j * np.deg2rad(phi)))
    )
    assert shown.active_scalars_name == CHARGE
    # charge is conserved: the total over the plate vanishes (each RWG function's ±l/A)
    total = np.sum(rho * window.model.result.mesh.areas)
    assert abs(total) < 1e-9 * np.sum(np.abs(rho) * window.model.result.mesh.areas)


def test_sweep_marks_the_resonance_and_a_click_solves_there(window, qtbot):
    panel = open_solve(window, qtbot)
    panel.tabs.setCurrentIndex(1)
    type_into(panel.sweep_from, "0.8")
    type_into(panel.sweep_to, "2.4")
    panel.sweep_count.lineEdit().selectAll()
    QTest.keyClicks(panel.sweep_count.lineEdit(), "17")
    click(qtbot, panel.sweep_button)
    qtbot.waitUntil(lambda: panel.sweep_result is not None, timeout=120_000)
    assert panel.last_outcome.thread != threading.get_ident()
    mesh = window.model.result.mesh
    freqs = np.linspace(0.8e9, 2.4e9, 17)
    direct = sweep(mesh, freqs, PlaneWave(), scattering=False)
    np.testing.assert_allclose(
        panel.sweep_result.extinction_cross_section, direct.extinction_cross_section, rtol=1e-12
    )
    # a 100 mm plate: its first resonance lies near c / (2 · 100 mm) = 1.5 GHz
    assert len(direct.resonances) >= 1
    np.testing.assert_allclose(panel.sweep_result.resonances, direct.resonances)
    f0 = direct.resonances[0]
    assert 1.0e9 < f0 < 2.0e9
    assert f"{f0 / 1e9:.4g} GHz" in panel.resonance_label.text()
    lines = [line for line in panel.plot.axes.lines if line.get_linestyle() == "--"]
    assert any(line.get_xdata()[0] == pytest.approx(f0 / 1e9) for line in lines)

    panel.plot.canvas.draw()
    x, y = panel.plot.data_to_widget(2.0e9)
    qtbot.mouseClick(panel.plot.canvas, Qt.MouseButton.LeftButton, pos=QPoint(x, y))
    qtbot.waitUntil(lambda: panel.solution is not None, timeout=60_000)
    hz = panel.solution.frequency
    assert hz == pytest.approx(2.0e9, rel=0.02)  # within a pixel or two of the click
    assert panel.unit.currentText() == "GHz"
    assert float(panel.frequency.text()) * 1e9 == pytest.approx(hz)


def test_cancel_drops_a_running_solve(window, qtbot):
    menu = next(a.menu() for a in window.menuBar().actions() if "Presets" in a.text())
    next(a for a in menu.actions() if a.text() == "srr-openmodes").trigger()
    panel = open_solve(window, qtbot)
    assert len(window.model.result.mesh.rwg) == 448  # 90 sectors of 2 x 1 cells
    type_into(panel.frequency, "6")
    click(qtbot, panel.solve_button)
    assert panel.cancel_button.isEnabled()
    click(qtbot, panel.cancel_button)
    assert "cancelled" in panel.status.text()
    assert not panel.progress.isVisible()
    assert panel.jobs.wait(120_000)
    qtbot.wait(50)  # the dropped result arrives through the event loop
    assert panel.solution is None and panel.layer.current is None


def test_rwg_inspector_shows_the_coefficient(window, qtbot):
    panel = open_solve(window, qtbot)
    type_into(panel.frequency, "1.5")
    with qtbot.waitActive(window):  # shortcuts (I, N) need the active window
        window.activateWindow()
    window.plotter.setFocus()
    QTest.keyClick(window.plotter, Qt.Key.Key_I)  # Teach → RWG basis inspector
    inspector = window.teaching.inspector
    qtbot.waitUntil(lambda: inspector.edge is not None)
    QTest.keyClick(window.plotter, Qt.Key.Key_N)
    QTest.keyClick(window.plotter, Qt.Key.Key_N)  # the third RWG function
    mesh = window.model.result.mesh
    rows = np.asarray(mesh.rwg.edge)
    assert inspector.edge == rows[2]
    c = complex(solve(mesh, 1.5e9).coefficients[2])
    text = panel.coefficient_label.text()
    assert text.startswith(f"I_2 = {c.real:.4g} ")
    assert f"|I_n| {abs(c):.4g} A" in text and "1.5 GHz" in text
    panel.auto.click()
    type_into(panel.frequency, "2")  # no current for these inputs: said so, not a stale I_n
    assert "no current" in panel.coefficient_label.text()


def test_closing_the_window_during_a_solve_waits_for_it(window, qtbot):
    menu = next(a.menu() for a in window.menuBar().actions() if "Presets" in a.text())
    next(a for a in menu.actions() if a.text() == "srr-openmodes").trigger()
    panel = open_solve(window, qtbot)
    type_into(panel.frequency, "6")
    click(qtbot, panel.solve_button)
    assert panel.cancel_button.isEnabled()
    window.close()  # no crash, no traceback: the job is cancelled and waited for
    assert panel.jobs.active == 0
    qtbot.wait(50)
    assert panel.solution is None


def test_cancel_stops_a_sweep_between_frequencies(window, qtbot):
    menu = next(a.menu() for a in window.menuBar().actions() if "Presets" in a.text())
    next(a for a in menu.actions() if a.text() == "srr-openmodes").trigger()
    panel = open_solve(window, qtbot)
    bar = panel.tabs.tabBar()
    qtbot.mouseClick(bar, Qt.MouseButton.LeftButton, pos=bar.tabRect(1).center())
    assert panel.tabs.currentIndex() == 1
    click(qtbot, panel.sweep_button)  # 46 frequencies, 3–12 GHz, 448 unknowns
    qtbot.waitUntil(lambda: panel.progress.value() >= 1, timeout=60_000)
    assert panel.progress.maximum() == 46
    click(qtbot, panel.cancel_button)
    assert "sweep was cancelled" in panel.status.text()
    assert panel.jobs.wait(60_000)
    qtbot.waitUntil(lambda: panel.last_outcome is not None)
    outcome = panel.last_outcome
    assert outcome.kind == "sweep" and outcome.cancelled
    assert "cancelled after" in outcome.error and "of 46 frequencies" in outcome.error
    assert panel.sweep_result is None


def test_voltage_feed_typed_into_the_panel_gives_the_input_impedance(
    window, qtbot, tmp_path, monkeypatch
):
    from app_user import answer_file_dialogs
    from test_mom_api import strip

    from barymesh.app.model.solve_inputs import format_impedance
    from barymesh.io import write_mesh
    from barymesh.mom import VoltageSource

    # File > Open the 1 m × 20 mm strip of the API tests (40 × 2 cells, a vertex row at x = 0)
    answer = answer_file_dialogs(monkeypatch)
    answer(write_mesh(strip(), tmp_path / "strip.vtu"))
    window.act_open.trigger()
    panel = open_solve(window, qtbot)
    mesh = window.model.result.mesh
    assert mesh.n_triangles == 160 and len(mesh.rwg) > AUTO_SOLVE_UNKNOWNS

    choose(panel.excitation, "feed")
    assert panel.feed_start.isVisible() and not panel.direction.isVisible()
    type_into(panel.frequency, "140")
    choose(panel.unit, "MHz")
    type_into(panel.feed_start, "3, -10")  # not on a mesh line: said at once, nothing solved
    type_into(panel.feed_end, "3, 10")
    click(qtbot, panel.solve_button)
    assert "no interior edge lies on the feed segment" in panel.error.text()
    assert panel.solution is None
    type_into(panel.feed_start, "0, -10")
    type_into(panel.feed_end, "0, 10")
    click(qtbot, panel.solve_button)
    qtbot.waitUntil(lambda: panel.solution is not None, timeout=120_000)

    direct = solve(strip(), 140e6, VoltageSource((0.0, -10.0), (0.0, 10.0)))
    z = panel.solution.input_impedance
    assert z == pytest.approx(direct.input_impedance, rel=1e-9)
    # just below the strip's half-wave series resonance: R_in near 70 Ω, X_in < 0
    assert 55 < z.real < 80 and z.imag < 0
    assert f"input impedance {format_impedance(z)}" in panel.summary.text()
    assert panel.layer._surface_actor.GetVisibility()
    # the Sweep tab plots a plane wave's extinction: with the feed it says so, runs nothing
    bar = panel.tabs.tabBar()
    qtbot.mouseClick(bar, Qt.MouseButton.LeftButton, pos=bar.tabRect(1).center())
    assert panel.tabs.currentIndex() == 1
    click(qtbot, panel.sweep_button)
    assert "choose Excitation: plane wave" in panel.resonance_label.text()
    assert panel.sweep_result is None and not panel.progress.isVisible()
    qtbot.mouseClick(bar, Qt.MouseButton.LeftButton, pos=bar.tabRect(0).center())

    # back to a plane wave: its rows return
    choose(panel.excitation, "plane")
    assert panel.direction.isVisible() and not panel.feed_start.isVisible()


def test_solution_warnings_are_shown_in_the_panel(window, qtbot, tmp_path, monkeypatch):
    from app_user import answer_file_dialogs
    from test_mom_api import t_junction

    from barymesh.io import write_mesh

    panel = open_solve(window, qtbot)
    mesh = window.model.result.mesh  # the 100 mm patch, 40 unknowns: solved as typed
    type_into(panel.frequency, "3")
    choose(panel.unit, "kHz")
    assert panel.solution is not None and panel.solution.frequency == 3e3
    direct = solve(mesh, 3e3)
    assert len(direct.warnings) == 1 and "low-frequency breakdown" in direct.warnings[0]
    assert panel.solution.warnings == direct.warnings
    assert "warning: low-frequency breakdown of the EFIE: k·D = " in panel.summary.text()
    # 3 GHz: k·D = 8.9, but edges of 25 and 35 mm are over λ/10 = 10 mm (issue 30)
    choose(panel.unit, "GHz")
    assert panel.solution.frequency == 3e9
    assert panel.solution.warnings == solve(mesh, 3e9).warnings
    (coarse,) = panel.solution.warnings
    assert coarse.startswith("mesh too coarse for the wavelength: at 3 GHz (λ = 99.93 mm)")
    assert f"warning: {coarse}" in panel.summary.text()
    assert "low-frequency" not in panel.summary.text()
    type_into(panel.frequency, "300")  # 300 MHz: λ/10 = 100 mm, no warning left on screen
    choose(panel.unit, "MHz")
    assert panel.solution.frequency == 300e6 and panel.solution.warnings == ()
    assert "warning" not in panel.summary.text()

    # File > Open a plate with a fin: its 10 junction edges carry no unknown, and it says so
    answer = answer_file_dialogs(monkeypatch)
    answer(write_mesh(t_junction(), tmp_path / "fin.vtu"))
    window.act_open.trigger()
    settle(window, qtbot)
    opened = window.model.result.mesh
    assert len(opened.junction_edges) == 10
    if panel.solution is None or panel.solution_mesh is not opened:
        click(qtbot, panel.solve_button)
        qtbot.waitUntil(lambda: panel.solution_mesh is opened, timeout=120_000)
    assert "warning: 10 junction edges (shared by three or more triangles)" in (
        panel.summary.text()
    )
    assert panel.solution.warnings == solve(opened, 300e6).warnings


def test_a_sweep_shows_its_warnings_under_the_resonances(window, qtbot):
    panel = open_solve(window, qtbot)
    panel.tabs.setCurrentIndex(1)
    type_into(panel.sweep_from, "0.000001")  # GHz: 1 kHz to 3 kHz, k·D < 1e-4
    type_into(panel.sweep_to, "0.000003")
    panel.sweep_count.lineEdit().selectAll()
    QTest.keyClicks(panel.sweep_count.lineEdit(), "3")
    click(qtbot, panel.sweep_button)
    qtbot.waitUntil(lambda: panel.sweep_result is not None, timeout=120_000)
    direct = sweep(window.model.result.mesh, [1e3, 2e3, 3e3], PlaneWave(), scattering=False)
    assert panel.sweep_result.warnings == direct.warnings
    assert len(direct.warnings) == 1
    text = panel.resonance_label.text()
    assert f"warning: {direct.warnings[0]}" in text
    assert text.count("low-frequency breakdown") == 1


def test_surface_current_hides_shared_edges_and_centroids_for_its_arrows(window, qtbot):
    panel = open_solve(window, qtbot)
    scene = window.scene
    window.model.set_color_by("area")
    assert scene.actors["shared_edges"].GetVisibility() and scene.scalar_bar.GetVisibility()
    type_into(panel.frequency, "1")  # 40 unknowns: solved at once
    assert panel.layer.shown
    # the arrows (dark, at the centroids) on |J|: no orange edges, no magenta dots, and
    # the faces' legend (under the current's) steps aside; outlines and triangles stay
    for layer in ("shared_edges", "centroids"):
        assert window.model.layers[layer] and not scene.actors[layer].GetVisibility(), layer
    assert not scene.scalar_bar.GetVisibility()
    assert BAR_TITLE in window.plotter.scalar_bars
    assert scene.shows("triangle_edges")
    assert scene.actors["boundary_edges"].GetVisibility()
    assert "Surface current shown" in scene.note.GetInput()
    click_check_box(panel.show_current)  # unticked: the mesh's own drawing is back
    assert not panel.layer.shown
    for layer in ("shared_edges", "centroids"):
        assert scene.actors[layer].GetVisibility(), layer
    assert scene.scalar_bar.GetVisibility()
    click_check_box(panel.show_current)
    assert panel.layer.shown and not scene.actors["centroids"].GetVisibility()
    # a new mesh without a result (auto-solve off): the layer is gone, the edges are back
    panel.auto.click()
    type_into(window.controls.rows["patch_size"].field, "80")
    window.controller.flush()
    assert panel.layer.current is None
    assert scene.actors["shared_edges"].GetVisibility()
    assert scene.actors["centroids"].GetVisibility()


def test_charge_option_reads_without_braces(window, qtbot):
    panel = open_solve(window, qtbot)
    texts = [panel.quantity.itemText(i) for i in range(panel.quantity.count())]
    assert texts == ["current |J|", "charge Re(ρ·exp(jωt))"]
    assert "{" not in panel.phase.toolTip()


@pytest.mark.parametrize("size", [(1300, 800), (1000, 700)])
def test_previous_mesh_warning_is_shown_whole(window, qtbot, size):
    window.resize(*size)
    panel = open_solve(window, qtbot)
    type_into(panel.frequency, "1")
    panel.auto.click()
    type_into(window.controls.rows["patch_size"].field, "80")
    window.controller.flush()
    settle(window, qtbot)
    label = panel.stale
    assert label.isVisible() and "previous mesh" in label.text()
    # as tall as its wrapped text needs at its width (not cut at the top and bottom)
    assert label.height() >= label.heightForWidth(label.width()) > 0
    assert label.height() >= label.fontMetrics().lineSpacing()


def test_auto_solve_while_a_slider_is_dragged_draws_each_new_mesh_in_the_same_actors(window, qtbot):
    """A slider drag with auto-solve on: every new mesh is solved and its current drawn
    in the layer's existing actors (no actor removed and added: two renders saved)."""
    panel = open_solve(window, qtbot)
    type_into(panel.frequency, "1.2")
    layer = panel.layer
    surface_actor, arrow_actor = layer._surface_actor, layer._arrow_actor
    assert surface_actor is not None and arrow_actor is not None
    slider = window.controls.rows["patch_size"].slider
    drag_slider(slider, slider.value() - 20)
    window.controller.flush()
    mesh = window.model.result.mesh
    assert mesh.params.patch_size < 100.0  # a smaller patch, still 40 unknowns
    assert len(mesh.rwg) == 40 and panel.solution_mesh is mesh and layer.mesh is mesh
    assert layer._surface_actor is surface_actor and layer._arrow_actor is arrow_actor
    direct = solve(mesh, 1.2e9)
    window.plotter.render()
    drawn = pv.wrap(surface_actor.GetMapper().GetInput())  # what was drawn
    np.testing.assert_allclose(np.asarray(drawn.points), mesh.points)
    np.testing.assert_allclose(
        np.asarray(drawn.cell_data[MAGNITUDE]),
        np.linalg.norm(np.abs(direct.current_density), axis=1),
        rtol=1e-10,
    )
    assert surface_actor.GetMapper().GetScalarRange()[1] == pytest.approx(largest_j(direct))
    arrows = pv.wrap(arrow_actor.GetMapper().GetInput())
    np.testing.assert_allclose(np.asarray(arrows.points), np.asarray(layer.arrows.points))
    # the arrows sit on the new mesh: inside its (smaller) patch, about its centroids
    xy = np.asarray(arrows.points)[:, :2]
    lo, hi = mesh.points[:, :2].min(axis=0), mesh.points[:, :2].max(axis=0)
    assert (xy >= lo - 1e-6).all() and (xy <= hi + 1e-6).all()
    np.testing.assert_allclose(xy.mean(axis=0), mesh.centroids[:, :2].mean(axis=0), atol=2.0)
    assert BAR_TITLE in window.plotter.scalar_bars


COARSE_MESHES = [
    MeshParams(structure="patch", patch_size=100.0, subdivisions=1),  # 2 triangles
    MeshParams(structure="patch", patch_size=100.0, subdivisions=2),  # 8 triangles
    MeshParams(
        structure="ring",
        mode="conforming",
        inner_radius=40.0,
        patch_size=20.0,
        angle_step=30.0,
        subdivisions=1,
    ),
]


def text_row_runs(image, rect):
    """Runs (first, last) of the image rows inside ``rect`` (x0, x1, y0, y1, VTK display
    pixels) that hold dark grey text pixels (the colour bar's numbers and title)."""
    h = image.shape[0]
    x0, x1, y0, y1 = (int(round(v)) for v in rect)
    part = image[max(h - 1 - y1, 0) : h - y0, max(x0, 0) : x1 + 1].astype(int)
    grey = (part.max(axis=-1) <= 110) & (part.max(axis=-1) - part.min(axis=-1) <= 30)
    rows = np.flatnonzero(grey.any(axis=1))
    runs, start = [], None
    for a, b in zip(rows, [*rows[1:], None], strict=True):
        start = a if start is None else start
        if b is None or b != a + 1:
            runs.append((int(start), int(a)))
            start = None
    return runs


@pytest.mark.parametrize("window_params", COARSE_MESHES)
def test_current_arrows_stay_in_their_triangles_and_off_the_colour_bar(window, qtbot, tmp_path):
    """Issue 30, 1.9: on a coarse mesh the arrows (1.4 √(mean area) long, starting at the
    centroid) stuck out past the patch and covered the colour bar, whose title touched
    its numbers. Each arrow is now centred on its centroid and no longer than its own
    triangle holds; the mesh is framed clear of the bar; a blank line parts the title
    from the numbers."""
    from gui_helpers import display_point

    from barymesh.app.view.current_layer import arrow_room

    window.resize(1300, 800)
    panel = open_solve(window, qtbot)
    type_into(panel.frequency, "1")  # GHz; a few unknowns: solved at once
    layer = panel.layer
    assert layer.shown and panel.solution is not None
    mesh = window.model.result.mesh
    qtbot.wait(50)
    window.plotter.render()
    # every arrow's points (shaft and barbs) inside its own triangle
    pts = np.asarray(pv.wrap(layer._arrow_actor.GetMapper().GetInput()).points)
    pts = pts.reshape(mesh.n_triangles, -1, 3)[..., :2]
    corners = mesh.points[mesh.triangles][..., :2]  # (T, 3, 2)
    a, b, c = corners[:, 0, None], corners[:, 1, None], corners[:, 2, None]
    det = (b[..., 0] - a[..., 0]) * (c[..., 1] - a[..., 1]) - (b[..., 1] - a[..., 1]) * (
        c[..., 0] - a[..., 0]
    )
    u = (
        (pts[..., 0] - a[..., 0]) * (c[..., 1] - a[..., 1])
        - (pts[..., 1] - a[..., 1]) * (c[..., 0] - a[..., 0])
    ) / det
    v = (
        (b[..., 0] - a[..., 0]) * (pts[..., 1] - a[..., 1])
        - (b[..., 1] - a[..., 1]) * (pts[..., 0] - a[..., 0])
    ) / det
    tol = 1e-9
    assert (u >= -tol).all() and (v >= -tol).all() and (u + v <= 1 + tol).all()
    # centred on the centroids, the longest as long as the typical triangle holds
    d = layer.vectors[:, :2] / np.linalg.norm(layer.vectors[:, :2], axis=1, keepdims=True)
    along = np.einsum("tnk,tk->tn", pts - mesh.centroids[:, None, :2], d)  # (T, points)
    lengths = along.max(axis=1) - along.min(axis=1)
    np.testing.assert_allclose(along.max(axis=1), -along.min(axis=1), atol=1e-4 * lengths.max())
    room = arrow_room(mesh.points, mesh.triangles)
    assert (lengths <= room * (1 + 1e-6)).all()
    # proportional to Re(J e^{jφ}), |J|'s peak as long as the typical triangle holds
    expected = np.linalg.norm(layer.vectors, axis=1) / layer.magnitude.max() * np.median(room)
    np.testing.assert_allclose(lengths, np.minimum(expected, room), rtol=1e-4)
    # the colour bar: nothing of the mesh or its arrows under it
    bar = window.plotter.scalar_bars[BAR_TITLE]
    w, h = window.plotter.window_size
    (px, py), (pw, ph) = bar.GetPosition(), bar.GetPosition2()
    rect = (px * w, (px + pw) * w, py * h, (py + ph) * h)
    for world in (*mesh.points, *pts.reshape(-1, 2)):
        x, y = display_point(window.plotter, (world[0], world[1], 0.0))
        assert not (rect[0] <= x <= rect[1] and rect[2] <= y <= rect[3]), (x, y, rect)
    # its title apart from its numbers: separate runs of text rows, blank rows between
    image = np.asarray(window.plotter.screenshot(None, return_img=True))[..., :3]
    if bar.GetOrientation() == 0:  # horizontal (this window's view is tall)
        below = (rect[0], rect[1], rect[2], py * h + 0.6 * ph * h)  # under the gradient
        runs = text_row_runs(image, below)
        assert len(runs) == 2, runs  # the numbers' row, the title's row
        assert runs[1][0] - runs[0][1] >= 3, runs
    window.grab().save(str(tmp_path / "current.png"))

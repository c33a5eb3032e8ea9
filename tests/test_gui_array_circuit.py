"""The Infinite array tab's equivalent circuit in the real window (Xvfb), driven as a user
does (issue 33 §3, the window): a band typed, a slab added and grounded with the mouse,
Run, then **Equivalent circuit** ticked with a click. The circuit's curves drawn are the
numbers of ``ArraySweep.equivalent_circuit()`` computed directly, the schematic shows
its values, Luukkonen et al.'s reference is drawn for square patches on the grounded
slab, and a curve the fit refuses says why in one red line and keeps its picture.

The patch is Luukkonen's example made coarse (a 4 mm patch in a 5 mm cell, 128
triangles), swept as drawn at a handful of frequencies.
"""

import threading

import numpy as np
import pytest

pytest.importorskip("pyvistaqt")
pytest.importorskip("matplotlib")

from app_user import click_check_box, settle  # noqa: E402
from test_gui_array_stack import click, type_cell  # noqa: E402
from test_gui_infinite_array import (  # noqa: E402
    RING,
    open_array_tab,
    run_and_wait,
    save_shot,
    type_band,
)

from barymesh.app.panels import array_circuit, infinite_array_panel  # noqa: E402
from barymesh.app.panels.array_circuit import LUUKKONEN  # noqa: E402
from barymesh.cell import Lattice, PixelGrid, UnitCell  # noqa: E402
from barymesh.mom import Layer, PlaneWave, Stack, periodic_solve  # noqa: E402
from barymesh.mom.circuit import equivalent_circuit, luukkonen_patch_reflection  # noqa: E402

P, GAP = 5.0, 1.0  # mm
GROUNDED = Stack(below=(Layer(1.575, 2.2),), ground=True)
TE = PlaneWave.from_angles(0.0, 0.0, 90.0)


@pytest.fixture
def window_params():
    return RING


def open_patch(window, qtbot):
    """Open a 4 mm square patch in a 5 mm cell and the Infinite array tab."""
    mask = np.zeros((10, 10), dtype=bool)
    mask[1:9, 1:9] = True
    grid = PixelGrid(mask, pixel_size=P / 10, origin=(-P / 2, -P / 2), subdivisions=1)
    cell = UnitCell(Lattice.rectangular(P), pixels=grid, mode="conforming", name="patch")
    window.cell_tools.open_cell(cell, "patch")
    settle(window, qtbot)
    window.solve_dock.raise_()
    window.solve_panel.tabs.setCurrentWidget(window.array_panel)
    qtbot.waitUntil(window.array_panel.plot.isVisible)
    return window.array_panel


def wait_for_circuit(qtbot, tab):
    """Wait for the curve drawn with the circuit of the curve shown."""
    qtbot.waitUntil(
        lambda: (
            tab.circuit_fit is not None
            and tab.circuit_fit.sweep is tab.result
            and tab.plot.picture is not None
            and len(tab.plot.figure.axes) == 3
        ),
        timeout=60_000,
    )
    return tab.circuit_fit


def line(ax, label):
    (found,) = [x for x in ax.lines if x.get_label() == label]
    return np.asarray(found.get_xdata(), dtype=float), np.asarray(found.get_ydata(), dtype=float)


def assert_phase_line(ax, label, curve):
    """The line ``label`` of the phase axes is ∠ of ``curve(f)`` (NaN only at a wrap)."""
    x, y = line(ax, label)
    keep = np.isfinite(y)
    assert (~keep).sum() <= 2
    f = x[keep] * 1e9
    np.testing.assert_allclose(y[keep], np.degrees(np.angle(curve(f))), rtol=0, atol=1e-9)


def test_ticked_circuit_is_the_direct_fit_with_its_schematic_and_luukkonen(
    window, qtbot, monkeypatch
):
    tab = open_patch(window, qtbot)
    threads = []  # where the fits ran: never on the GUI thread

    def fit_circuit(*args):
        threads.append(threading.current_thread() is threading.main_thread())
        return array_circuit.fit_circuit(*args)

    monkeypatch.setattr(infinite_array_panel, "fit_circuit", fit_circuit)
    click_check_box(tab.solver_grade)  # the cell as drawn: 128 triangles
    assert not tab.solver_grade.isChecked()
    type_band(qtbot, tab, "6", "16", 6)
    editor = tab.stack_editor
    click(qtbot, editor.add_button)  # 1.575 mm of εr 2.2 under the sheet
    type_cell(qtbot, editor, 1, "loss_tangent", "0")
    click_check_box(editor.ground)
    assert editor.stack == GROUNDED
    result = run_and_wait(qtbot, tab)
    mesh = window.model.result.mesh
    assert tab.plot.figure is not None and len(tab.plot.figure.axes) == 2  # no circuit yet
    # the curve is the solver's (one frequency checked against a direct solve)
    r0, _ = periodic_solve(mesh, result.frequencies[0], TE, stack=GROUNDED).co_polar()
    assert abs(result.reflection[0] - r0) < 1e-6

    click_check_box(tab.circuit_box)
    assert tab.circuit_box.isChecked()
    fit = wait_for_circuit(qtbot, tab)
    assert threads == [False]  # fitted once, in the worker
    # the circuit, computed here from the same numbers, is the one drawn
    onsets = [hz for hz, _ in result.grating_lobe_onsets] + [
        hz for hz, _, _ in result.guided_onsets
    ]
    direct = equivalent_circuit(
        result.frequencies, result.reflection, GROUNDED, result.inputs.incidence(), onsets=onsets
    )
    circuit = result.equivalent_circuit()
    assert (circuit.kind, circuit.inductance, circuit.capacitance) == (
        direct.kind,
        direct.inductance,
        direct.capacitance,
    )
    assert circuit.kind == "series" and fit.circuit.inductance == circuit.inductance
    mag, phase, schematic = tab.plot.figure.axes
    x, y = line(mag, "circuit (series LC)")
    assert len(x) == 200 and x[0] == pytest.approx(6.0) and x[-1] == pytest.approx(16.0)
    np.testing.assert_allclose(
        y, 20 * np.log10(np.abs(circuit.reflection(x * 1e9))), rtol=0, atol=1e-9
    )
    assert_phase_line(phase, "circuit", circuit.reflection)
    # the circuit follows the patch: within 0.05 of the solved R at every swept frequency
    assert np.max(np.abs(circuit.reflection(result.frequencies) - result.reflection)) < 0.05
    # Luukkonen's model of these patches on this slab, dotted
    assert_phase_line(phase, LUUKKONEN, lambda f: luukkonen_patch_reflection(f, P, GAP, 1.575, 2.2))
    (reference,) = [x for x in phase.lines if x.get_label() == LUUKKONEN]
    assert reference.get_linestyle() == ":"
    # the schematic: the fitted values, a slab section and the ground's short
    texts = [t.get_text() for t in schematic.texts]
    values = texts[-1].split("\n")
    assert values == [
        "series LC",
        f"L = {circuit.inductance * 1e9:.4g} nH",
        f"C = {circuit.capacitance * 1e15:.4g} fF",
        f"f0 = {circuit.resonance / 1e9:.4g} GHz",
    ]
    assert "εr 2.2\n1.575\nmm" in texts and "ground" in texts and "sheet" in texts
    assert tab.circuit_note.isVisible()
    assert tab.circuit_note.text().startswith(f"series LC: L = {circuit.inductance * 1e9:.4g} nH")
    assert LUUKKONEN in tab.circuit_note.text()
    save_shot(window, "array_circuit_window")
    save_shot(tab.curve_area, "array_circuit_curve")

    # unticked with a click: the curve alone again
    click_check_box(tab.circuit_box)
    qtbot.waitUntil(lambda: len(tab.plot.figure.axes) == 2, timeout=30_000)
    assert not tab.circuit_note.isVisible()
    assert [x.get_label() for x in tab.plot.figure.axes[0].lines] == ["|R|"]


def test_a_curve_the_fit_refuses_says_why_and_keeps_its_picture(window, qtbot):
    tab = open_array_tab(window, qtbot)  # the double ring, 12 mm: a grating lobe at 24.98 GHz
    click_check_box(tab.solver_grade)
    click_check_box(tab.circuit_box)  # before Run: fitted to the next curve
    assert "Run" in tab.circuit_note.text()
    type_band(qtbot, tab, "20", "30", 4)  # 20, 23.3, 26.7, 30: two under the onset
    result = run_and_wait(qtbot, tab)
    qtbot.waitUntil(lambda: tab.circuit_fit is not None and tab.circuit_fit.sweep is result)
    assert tab.circuit_fit.circuit is None
    note = tab.circuit_note
    assert note.isVisible() and "#d0021b" in note.styleSheet()
    assert note.text().startswith("No circuit: 2 frequencies to fit (below the first onset 24.98")
    assert "Traceback" not in note.text() and "\n" not in note.text()
    # the picture stays: the solved curve, and the schematic's place says why
    mag, _phase, schematic = tab.plot.figure.axes
    with np.errstate(divide="ignore"):
        np.testing.assert_allclose(
            line(mag, "|R|")[1], 20 * np.log10(np.abs(result.reflection)), rtol=0, atol=1e-12
        )
    assert not [x for x in mag.lines if x.get_label().startswith("circuit")]
    texts = [t.get_text() for t in schematic.texts]
    assert texts[0] == "no circuit" and texts[1].replace("\n", " ").startswith("2 frequencies")
    image = tab.plot.grab().toImage()
    assert len({image.pixel(x, image.height() // 3) for x in range(0, image.width(), 7)}) > 2
    assert not tab.error.text()  # not an error of the sweep
    save_shot(tab.curve_area, "array_circuit_refused")

"""The reflectarray designer in the real window (Xvfb), driven as a user does (issue 33 §2,
in the window): the Reflection phase tab's coarse hexagonal-rings curve solved as in
tests/test_gui_reflection_phase.py, **Design reflectarray…** clicked, the aperture, feed,
beam and bits typed or chosen with the keys; every design against
barymesh.reflectarray.design of the same library called directly. A bad input is said in
one red line and the last design stays; **Open as cell** opens the whole array in the
window as a cell of N1 × N2 elements.
"""

import time

import numpy as np
import pytest

pytest.importorskip("pyvistaqt")
pytest.importorskip("matplotlib")

from app_user import choose, settle, type_into  # noqa: E402
from PySide6.QtCore import Qt, QTimer  # noqa: E402
from test_gui_reflection_phase import (  # noqa: E402
    TIMEOUT,
    add_board,
    open_phase_tab,
    run_and_wait,
    save_shot,
    type_inputs,
)

from barymesh.reflectarray import design, textbook_quantization_loss  # noqa: E402

#: The longest the event loop may stop while a 15 x 15 array is made a cell, opened and
#: meshed: about 0.6 s on an idle machine (the window's own handling of a 225-element cell:
#: the predicted triangle count, the phase tab's parameter list); the cell made on the GUI
#: thread (1 s) and the statistics' table filled column by column (2.5 s) took 3-4 s.
OPEN_GAP = 2.0


def solved_tab(window, qtbot):
    """The tab with the board's 7-value curve of the ring's inner radius at 10 GHz."""
    tab = open_phase_tab(window, qtbot)
    assert not tab.design_button.isEnabled()  # no curve yet
    add_board(qtbot, tab)
    type_inputs(qtbot, tab)
    run_and_wait(qtbot, tab)
    assert tab.design_button.isEnabled()
    assert tab.library.cell is not None  # the designer builds its elements from it
    return tab


def open_designer(qtbot, tab):
    """Click Design reflectarray…; the designer once its first design (the defaults) is shown."""

    def opened():
        return tab.designer is not None and tab.designer.result is not None

    qtbot.mouseClick(tab.design_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(opened, timeout=TIMEOUT)
    designer = tab.designer
    assert designer.isVisible() and not designer.isModal()
    return designer


def redesign(qtbot, designer, action):
    """Do ``action`` (typing, a choice) and wait for the design it asks for."""
    with qtbot.waitSignal(designer.designed, timeout=TIMEOUT) as blocker:
        action()
    return blocker.args[0]


def assert_same_design(shown, want):
    np.testing.assert_array_equal(shown.parameter, want.parameter)
    np.testing.assert_array_equal(shown.achieved_phase, want.achieved_phase)
    np.testing.assert_array_equal(shown.required_phase, want.required_phase)
    np.testing.assert_allclose(shown.positions, want.positions)
    assert shown.beam_direction == pytest.approx(want.beam_direction, abs=0.5)
    assert shown.gain == pytest.approx(want.gain, abs=1e-6)
    assert shown.side_lobe_level == pytest.approx(want.side_lobe_level, abs=1e-6)


def figure_texts(designer):
    fig = designer.plot.figure
    return [t.get_text() for t in fig.texts] + [t.get_text() for ax in fig.axes for t in ax.texts]


@pytest.fixture
def designed(window, qtbot):
    tab = solved_tab(window, qtbot)
    qtbot.wait(50)
    return tab, open_designer(qtbot, tab)


def test_the_designer_draws_what_design_gives_for_the_typed_inputs(designed, qtbot, tmp_path):
    tab, designer = designed
    lib = tab.library
    # the defaults: 15 x 15, feed 150 mm over the centre, beam at 20°, continuous
    shown = designer.result
    want = design(lib, (15, 15), (0.0, 0.0, 150.0), (20.0, 0.0), 10e9)
    assert_same_design(shown.array, want)
    theta, phi = shown.numbers.beam_direction
    assert abs(theta - 20.0) < 1.0 and abs(phi) < 1.0  # the beam goes where it was asked
    assert shown.numbers.quantization_loss is None
    # the picture: the tiles coloured by the parameter and by the phase error, the cut
    param_ax, error_ax = designer.plot.figure.axes[0], designer.plot.figure.axes[1]
    np.testing.assert_array_equal(param_ax.collections[0].get_array(), want.parameter)
    np.testing.assert_allclose(error_ax.collections[0].get_array(), want.phase_error)
    cut_ax = designer.plot.figure.axes[2]
    gains = cut_ax.lines[0].get_ydata()
    np.testing.assert_allclose(gains.max(), want.gain, atol=0.3)  # the cut passes the beam
    texts = figure_texts(designer)
    assert any(t.startswith(f"Main beam θ = {want.beam_direction[0]:.2f}°") for t in texts)
    sll = f"{want.side_lobe_level:.1f}".replace("-", "−")
    assert any(f"side-lobe level {sll} dB" in t.lower().replace("db", "dB") for t in texts)
    # 1 bit, chosen with the keys: the quantisation loss against the textbook −3.9 dB
    shown = redesign(qtbot, designer, lambda: choose(designer.bits, 1))
    one_bit = design(lib, (15, 15), (0.0, 0.0, 150.0), (20.0, 0.0), 10e9, bits=1)
    assert_same_design(shown.array, one_bit)
    assert set(np.unique(shown.array.parameter)) <= set(np.unique(one_bit.parameter))
    assert len(np.unique(shown.array.parameter)) <= 2  # two levels
    assert shown.numbers.quantization_loss == pytest.approx(one_bit.quantization_loss, abs=1e-9)
    assert -6.0 < shown.numbers.quantization_loss < -2.0  # near the textbook's −3.9 dB
    loss = f"{one_bit.quantization_loss:.2f}".replace("-", "−")
    assert f"1-bit quantisation loss {loss} dB (textbook −3.9 dB for 1 bit)" in figure_texts(
        designer
    )
    assert len(designer.plot.figure.axes[2].lines[0].get_xdata()) > 100  # continuous, grey
    shot = save_shot(designer, tmp_path, "reflectarray_designer")
    assert shot.stat().st_size > 20_000
    # a smaller window: the picture is drawn again at the view's new size, the same design
    designer.resize(820, 680)

    def fits():
        (w, h), ratio = designer.plot.request_size()
        rgba = designer.plot.picture.rgba
        return abs(rgba.shape[1] - w * ratio) <= 2 and abs(rgba.shape[0] - h * ratio) <= 2

    qtbot.waitUntil(fits, timeout=TIMEOUT)
    assert designer.result is shown
    save_shot(designer, tmp_path, "reflectarray_designer_small")
    # typed: 9 x 7 elements, the feed off the centre, the beam at 25°, 30°, 2 bits
    for field, text in (
        (designer.n1, "9"),
        (designer.n2, "7"),
        (designer.feed_x, "10"),
        (designer.feed_y, "-5"),
        (designer.feed_z, "120"),
        (designer.theta, "25"),
    ):
        type_into(field, text)
    shown = redesign(qtbot, designer, lambda: type_into(designer.phi, "30"))
    assert designer.error.text() == ""
    shown = redesign(qtbot, designer, lambda: choose(designer.bits, 2))
    two_bit = design(lib, (9, 7), (10.0, -5.0, 120.0), (25.0, 30.0), 10e9, bits=2)
    assert_same_design(shown.array, two_bit)
    assert shown.array.positions.shape == (63, 3)
    assert shown.numbers.textbook_loss == pytest.approx(textbook_quantization_loss(2))
    assert any("(textbook −0.9 dB for 2 bits)" in t for t in figure_texts(designer))


def test_a_bad_input_is_one_red_line_and_the_last_design_stays(designed, qtbot):
    _tab, designer = designed
    good = designer.result
    token = designer._tokens["design"]
    for field, text, message in (
        (designer.n1, "0", "Aperture N1 '0' is invalid; expected a whole number"),
        (designer.n2, "7.5", "Aperture N2 '7.5' is invalid; expected a whole number"),
        (designer.feed_z, "-20", "Feed z -20 mm is invalid; expected the feed above"),
        (designer.feed_x, "left", "Feed x 'left' is not a number"),
        (designer.theta, "95", "Beam θ 95° is out of range; expected 0 <= θ < 90°"),
        (designer.phi, "", "Beam φ '' is not a number"),
    ):
        keep = field.text()
        type_into(field, text)
        assert designer.error.text().startswith(message), designer.error.text()
        assert "\n" not in designer.error.text() and "Traceback" not in designer.error.text()
        assert not designer.design()
        assert designer.result is good and designer._tokens["design"] == token
        type_into(field, keep)  # the good input again: designed again, the line cleared
        assert designer._tokens["design"] == token + 1
        token += 1
        assert designer.error.text() == ""
    qtbot.waitUntil(lambda: designer.result is not good, timeout=TIMEOUT)
    np.testing.assert_array_equal(designer.result.array.parameter, good.array.parameter)
    # 250 x 250 is more than the window designs
    type_into(designer.n1, "250")
    type_into(designer.n2, "250")
    assert designer.error.text().startswith("Aperture 250 × 250 has 62,500 elements")


def test_open_as_cell_opens_the_array_with_n1_n2_elements(designed, window, qtbot):
    tab, designer = designed
    type_into(designer.n1, "4")
    shown = redesign(qtbot, designer, lambda: type_into(designer.n2, "3"))
    assert shown.array.aperture == (4, 3)
    single = window.model.cell
    assert tab.live.isChecked()
    with qtbot.waitSignal(designer.opened, timeout=TIMEOUT):
        qtbot.mouseClick(designer.open_button, Qt.MouseButton.LeftButton)
        assert not designer.open_button.isEnabled()  # the cell is being made
    assert designer.error.text() == ""
    assert designer.open_button.isEnabled()
    cell = window.model.cell
    assert cell is not single and len(cell.elements) == 12
    radii = [e.params.inner_radius for e in cell.elements]
    np.testing.assert_allclose(sorted(radii), sorted(shown.array.parameter))
    a1 = np.asarray(single.lattice.a1)
    np.testing.assert_allclose(cell.lattice.a1, 4 * a1)
    # the Live curve does not follow the array (a long solve): Live is off, said so
    assert not tab.live.isChecked()
    assert "Live is off" in tab.status.text()
    settle(window, qtbot)
    mesh = window.model.result.mesh
    assert mesh.lattice is not None and mesh.n_triangles >= 12 * 100
    assert "12 elements" in designer.status.text()


def test_opening_a_15_by_15_array_keeps_the_event_loop_ticking(designed, window, qtbot):
    _tab, designer = designed
    assert designer.result.array.aperture == (15, 15)
    beats = []
    timer = QTimer()
    timer.setInterval(10)
    timer.timeout.connect(lambda: beats.append(time.perf_counter()))
    timer.start()
    try:
        with qtbot.waitSignal(designer.opened, timeout=TIMEOUT):
            qtbot.mouseClick(designer.open_button, Qt.MouseButton.LeftButton)
        settle(window, qtbot)
        qtbot.wait(300)
    finally:
        timer.stop()
    assert len(window.model.cell.elements) == 225
    assert window.model.result.mesh.n_triangles > 225 * 100
    gaps = np.diff(beats)
    assert len(gaps) > 20 and gaps.max() < OPEN_GAP, np.sort(gaps)[-3:]


def test_a_new_curve_is_designed_again_and_a_lattice_curve_is_no_cell(
    designed, window, qtbot, tmp_path
):
    tab, designer = designed
    first = designer.result
    # 11 GHz typed in the tab (Live): the new whole curve is designed at once
    with qtbot.waitSignal(designer.designed, timeout=TIMEOUT) as blocker:
        type_into(tab.frequency, "11")
    shown = blocker.args[0]
    assert designer.library is tab.library and tab.library.frequencies[0] == 11e9
    assert shown.array.frequency == 11e9 and shown is not first
    want = design(tab.library, (15, 15), (0.0, 0.0, 150.0), (20.0, 0.0), 11e9)
    assert_same_design(shown.array, want)
    assert "at 11 GHz" in designer.library_line.text()
    save_shot(tab, tmp_path, "reflection_phase_tab_with_designer_button")
    # a curve over the lattice's period: designed, but no cell of one lattice holds it
    choose(tab.parameter, "lattice.hexagonal")
    type_into(tab.points.lineEdit(), "2")
    with qtbot.waitSignal(designer.designed, timeout=TIMEOUT):
        qtbot.mouseClick(tab.run_button, Qt.MouseButton.LeftButton)
    assert designer.result.array.library.parameter == "lattice.hexagonal"
    cell = window.model.cell
    qtbot.mouseClick(designer.open_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: designer.error.text() != "", timeout=TIMEOUT)
    assert designer.error.text().startswith("Cannot open the array as a cell: ")
    assert "\n" not in designer.error.text()
    assert window.model.cell is cell  # the window keeps its cell
    assert designer.open_button.isEnabled()

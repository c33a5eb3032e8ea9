"""File → Design study, in a real window under Xvfb: a 3 x 2 study on a local cluster."""

from __future__ import annotations

import imageio.v3 as iio
import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt
from PySide6.QtTest import QTest

pytest.importorskip("pyvistaqt")
pytest.importorskip("distributed")

from app_user import choose  # noqa: E402

from barymesh import MeshParams  # noqa: E402
from barymesh.app.window import MainWindow  # noqa: E402
from barymesh.study import parse_spec, run_serial  # noqa: E402

PATCH = MeshParams(structure="patch", patch_size=15.0, patch_width=12.0, subdivisions=2)


def type_into(qtbot, line_edit, text):
    line_edit.selectAll()
    QTest.keyClick(line_edit, Qt.Key.Key_Backspace)
    QTest.keyClicks(line_edit, text)


@pytest.fixture
def window(qtbot):
    win = MainWindow(PATCH, scripted=True)
    qtbot.addWidget(win)
    win.show()
    qtbot.waitExposed(win)
    win.controller.flush()
    yield win
    win.close()


def test_a_study_from_the_file_menu_maps_the_resonance_and_loads_a_cell(window, qtbot, tmp_path):
    file_menu = window.menuBar().actions()[0].menu()
    assert window.act_study in file_menu.actions()
    window.act_study.trigger()
    d = window.study_dialog
    qtbot.waitExposed(d)
    (name1, start1, stop1, count1), (name2, start2, stop2, count2) = d.axis_rows
    name1.setCurrentIndex(name1.findData("patch_size"))
    name2.setCurrentIndex(name2.findData("patch_width"))
    type_into(qtbot, start1, "13")
    type_into(qtbot, stop1, "15")
    count1.setValue(3)
    type_into(qtbot, start2, "10")
    type_into(qtbot, stop2, "12")
    count2.setValue(2)
    type_into(qtbot, d.frequencies, "6GHz:12GHz:11")
    d.workers.setValue(2)
    steps = []
    d.progressed.connect(lambda done, failed, total: steps.append((done, total)))
    assert d.start()
    assert not d.run_button.isEnabled() and d.cancel_button.isEnabled()
    qtbot.waitUntil(lambda: not d.running, timeout=180_000)
    assert "6 points, 0 failed" in d.message.text(), d.message.text()
    assert steps[-1] == (6, 6) and d.progress.value() == 6

    # the map is the study's resonance frequency over patch size x patch width
    spec = parse_spec(d.spec)
    assert spec.axis_names == ("patch_size", "patch_width")
    assert [a.values for a in spec.axes] == [(13.0, 14.0, 15.0), (10.0, 12.0)]
    serial = run_serial(spec).derived["resonance_frequency_hz"].to_numpy().reshape(3, 2)
    np.testing.assert_allclose(d.grid, serial, rtol=1e-9)
    assert np.all(np.diff(d.grid, axis=0) < 0)  # longer along E (x): lower resonance
    assert d.image is not None and d.image.get_array().shape == (3, 2)

    shot = tmp_path / "study.png"
    assert d.grab().save(str(shot))
    image = iio.imread(shot)
    assert len(np.unique(image[..., :3].reshape(-1, 3), axis=0)) > 50

    # a click on the cell (row 2: patch_size 15, column 0: patch_width 10) loads it
    x, y = d.axes.transData.transform((0.0, 2.0))
    height = d.canvas.figure.bbox.height
    ratio = d.canvas.device_pixel_ratio
    QTest.mouseClick(
        d.canvas,
        Qt.MouseButton.LeftButton,
        pos=QPoint(int(x / ratio), int((height - y) / ratio)),
    )
    qtbot.waitUntil(lambda: window.model.params.patch_width == 10.0, timeout=5000)
    assert window.model.params.patch_size == 15.0
    assert window.model.params.structure == "patch" and window.model.params.subdivisions == 2
    assert "loaded patch_size = 15" in d.message.text()


def test_bad_inputs_are_said_in_the_dialog(window, qtbot):
    window.act_study.trigger()
    d = window.study_dialog
    start1 = d.axis_rows[0][1]
    type_into(qtbot, start1, "abc")
    assert not d.start()
    assert "axis 1: from and to must be numbers" in d.message.text()
    assert "color" in d.message.styleSheet()
    type_into(qtbot, start1, "1")
    type_into(qtbot, d.frequencies, "9GHz:4GHz:3")
    assert not d.start()
    assert "solve.frequencies" in d.message.text() and not d.running


def assert_message_not_cut(qtbot, d):
    """The message shows all its wrapped lines once the layout has run (it was cut to
    one line over the map)."""
    label = d.message
    qtbot.waitUntil(lambda: label.height() >= label.heightForWidth(label.width()), timeout=5000)


SRR_AXES = (("3.15", "3.85"), ("0.9", "1.1"))


def study_through_the_dialog(window, qtbot, polarization):
    """File → Design study on srr-openmodes, inner radius 3.15–3.85 × gap width 0.9–1.1 mm
    at 4–9 GHz in 11 points (the issue's study), the polarisation typed as a user does."""
    window.act_study.trigger()
    d = window.study_dialog
    qtbot.waitExposed(d)
    for (name, start, stop, count), key, (a, b) in zip(
        d.axis_rows, ("inner_radius", "gap_width"), SRR_AXES, strict=True
    ):
        assert name.currentData() == key  # the dialog's default axes
        type_into(qtbot, start, a)
        type_into(qtbot, stop, b)
        count.setFocus()
        count.selectAll()
        QTest.keyClicks(count, "2")
    type_into(qtbot, d.frequencies, "4GHz:9GHz:11")
    type_into(qtbot, d.direction.lineEdit(), "-z")
    type_into(qtbot, d.polarization.lineEdit(), polarization)
    d.workers.setValue(2)
    QTest.mouseClick(d.run_button, Qt.MouseButton.LeftButton)
    assert d.running, d.message.text()
    qtbot.waitUntil(lambda: not d.running, timeout=300_000)
    return d


@pytest.fixture
def srr_window(qtbot):
    from barymesh.presets import load_preset

    win = MainWindow(load_preset("srr-openmodes")[0], scripted=True)
    qtbot.addWidget(win)
    win.show()
    qtbot.waitExposed(win)
    win.controller.flush()
    yield win
    win.close()


def test_a_study_with_no_resonance_in_band_says_so_and_hatches_its_cells(
    srr_window, qtbot, tmp_path
):
    """Issue 30, 1.1: the dialog sent no polarisation (x by default, along the gap of the
    split ring at 180°), every value was NaN, and it said "4 points, 0 failed" over an
    empty map with a colour bar of −0.1…0.1 GHz."""
    # the dialog asks for the incidence, starting from the Solve dock's
    solve = srr_window.solve_panel
    srr_window.act_study.trigger()
    d = srr_window.study_dialog
    assert d.direction.currentText() == solve.direction.currentText() == "-z"
    assert d.polarization.currentText() == solve.polarization.currentText() == "x"
    d.close()
    d = study_through_the_dialog(srr_window, qtbot, "x")
    assert d.spec["solve"]["polarization"] == [1.0, 0.0, 0.0]
    assert d.spec["solve"]["direction"] == [0.0, 0.0, -1.0]
    assert d.statuses.shape == (2, 2) and (d.statuses == "ok").all()
    assert np.isnan(d.grid).all()  # E along x: no peak of σ_ext in 4–9 GHz
    text = d.message.text()
    assert "4 points, 0 failed, 4 with no resonance in band" in text, text
    assert "no peak inside 4–9 GHz" in text and "another polarisation" in text, text
    assert "color" in d.message.styleSheet()  # said as a problem, not a success
    assert_message_not_cut(qtbot, d)
    # no colour bar of a made-up range, every cell hatched, the legend names them
    assert d.colorbar is None
    hatched = [p for p in d.axes.patches if p.get_hatch() == "///"]
    assert len(hatched) == 4
    assert [t.get_text() for t in d.axes.get_legend().get_texts()] == ["no resonance in band"]
    said = [t.get_text() for t in d.axes.texts]
    assert any(t.startswith("No point has a value") for t in said), said
    shot = tmp_path / "study-x.png"
    assert d.grab().save(str(shot))

    # E across the gap (y): the ring resonates inside the band at every point
    d.close()
    d = study_through_the_dialog(srr_window, qtbot, "y")
    assert d.spec["solve"]["polarization"] == [0.0, 1.0, 0.0]
    assert np.isfinite(d.grid).all(), d.grid
    ghz = d.grid / 1e9
    assert ((4 < ghz) & (ghz < 9)).all(), ghz
    assert (ghz[1] < ghz[0]).all()  # a larger ring resonates lower
    assert "4 points, 0 failed. Click a cell" in d.message.text(), d.message.text()
    assert "color" not in d.message.styleSheet()
    assert d.colorbar is not None and not [p for p in d.axes.patches if p.get_hatch()]
    lo, hi = d.colorbar.mappable.get_clim()
    assert lo == pytest.approx(ghz.min()) and hi == pytest.approx(ghz.max())
    # the point (3.15, 0.9) as the study's own serial run gives it
    one = {**d.spec, "axes": {"inner_radius": [3.15], "gap_width": [0.9]}}
    serial = run_serial(parse_spec(one)).derived["resonance_frequency_hz"].to_numpy()
    np.testing.assert_allclose(d.grid[0, 0], serial[0], rtol=1e-9)
    assert d.grab().save(str(tmp_path / "study-y.png"))

    # the same run's Q (no new run): a cell whose peak fits no Lorentzian is hatched
    # beside the coloured ones, under the colour bar of the others
    choose(d.figure_choice, "quality_factor")
    q = d.grids["quality_factor"]
    assert d.grid is q and 0 < np.isnan(q).sum() < q.size, q
    hatched = [p for p in d.axes.patches if p.get_hatch() == "///"]
    assert len(hatched) == np.isnan(q).sum() and d.colorbar is not None
    assert d.colorbar.mappable.get_clim() == pytest.approx((np.nanmin(q), np.nanmax(q)))
    legend = [t.get_text() for t in d.axes.get_legend().get_texts()]
    assert legend == ["no Q (no peak a Lorentzian fits)"]
    assert f"{np.isnan(q).sum()} with no Q" in d.message.text(), d.message.text()
    assert_message_not_cut(qtbot, d)
    assert d.grab().save(str(tmp_path / "study-q.png"))


def test_a_polarisation_along_the_direction_is_refused_in_the_dialog(window, qtbot):
    window.act_study.trigger()
    d = window.study_dialog
    type_into(qtbot, d.polarization.lineEdit(), "z")
    assert not d.start()
    assert "Polarisation" in d.message.text() and "perpendicular" in d.message.text()
    type_into(qtbot, d.polarization.lineEdit(), "up")
    assert not d.start()
    assert "Polarisation 'up' is invalid" in d.message.text(), d.message.text()

"""File → Design study, in a real window under Xvfb: a 3 x 2 study on a local cluster."""

from __future__ import annotations

import imageio.v3 as iio
import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt
from PySide6.QtTest import QTest

pytest.importorskip("pyvistaqt")
pytest.importorskip("distributed")

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
    d.signals.progress.connect(lambda done, failed, total: steps.append((done, total)))
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

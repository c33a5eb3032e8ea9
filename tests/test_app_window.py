"""The desktop window in a real X window (Xvfb, see conftest.py), driven through its widgets."""

import os
import subprocess
import sys

import imageio.v3 as iio
import numpy as np
import pytest

pytest.importorskip("pyvistaqt")

from PySide6.QtCore import Qt  # noqa: E402

from app.model import SPECS, applies  # noqa: E402
from app.window import MainWindow  # noqa: E402
from core import MeshParams, build_mesh  # noqa: E402

COARSE = MeshParams(angle_step=15.0, subdivisions=2)  # = conftest's window_params
COUNTS = ("patches", "vertices", "triangles", "edges", "interior_edges", "boundary_edges",
          "junction_edges")


def assert_counts(win, params):
    stats = build_mesh(params).stats()
    for key in COUNTS:
        assert win.stats.text(key) == f"{stats[key]:,}", key


def test_window_opens_on_the_given_parameters(window):
    assert window.model.params == COARSE
    assert_counts(window, COARSE)
    assert window.scene.datasets["faces"].n_cells == build_mesh(COARSE).n_triangles


@pytest.mark.parametrize("structure", ["double_ring", "split_double_ring", "patch"])
def test_each_slider_updates_the_statistics(window, qtbot, structure):
    window.controls.combos["structure"].setCurrentIndex(
        window.controls.combos["structure"].findData(structure))
    window.controller.flush()
    for name, row in window.controls.rows.items():
        if not applies(name, structure):
            assert not row.slider.isEnabled()
            continue
        before = window.model.params
        row.slider.setFocus()
        qtbot.keyClick(row.slider, Qt.Key.Key_Right)
        window.controller.flush()
        after = window.model.params
        assert getattr(after, name) == SPECS[name].from_slider(row.slider.value()), name
        assert after != before or window.model.error is not None, name
        if window.model.error is None:
            assert_counts(window, after)
            assert window.controls.rows[name].spin.value() == pytest.approx(
                getattr(after, name) or 0)


def test_spinbox_and_slider_agree(window):
    row = window.controls.rows["subdivisions"]
    row.spin.setValue(3)
    window.controller.flush()
    assert row.slider.value() == SPECS["subdivisions"].to_slider(3)
    assert_counts(window, COARSE.replace(subdivisions=3))


def test_each_layer_toggles(window):
    for name, box in window.layers.boxes.items():
        actor = window.scene.actors[name]
        if not box.isEnabled():
            continue
        before = bool(actor.GetVisibility())
        box.click()
        assert window.model.layers[name] is not before or name == "labels"
        assert bool(actor.GetVisibility()) is not before
        assert window.layer_actions[name].isChecked() is box.isChecked()
        box.click()
        assert bool(actor.GetVisibility()) is before


def test_colour_by_shows_a_colour_bar(window):
    combo = window.layers.color_by
    combo.setCurrentIndex(combo.findData("min_angle"))
    assert window.scene.actors["faces"].mapper.GetScalarVisibility()
    assert window.scene.scalar_bar.GetVisibility()
    combo.setCurrentIndex(combo.findData("none"))
    assert not window.scene.scalar_bar.GetVisibility()


def test_screenshot_size_and_not_blank(window, tmp_path):
    path = tmp_path / "view.png"
    assert window.save_view_png(path, scale=2, transparent=False)
    image = iio.imread(path)
    ratio = window.plotter.devicePixelRatioF()
    w, h = window.plotter.width(), window.plotter.height()
    assert image.shape[:2] == (round(2 * h * ratio), round(2 * w * ratio))
    colours = np.unique(image[..., :3].reshape(-1, 3), axis=0)
    assert len(colours) > 10  # faces, edges, centroids, axes: not a blank frame
    transparent = window.view_image(1, transparent=True)
    assert transparent.shape[2] == 4 and (transparent[..., 3] == 0).any()


def test_undo_redo_restore_parameters_and_counts(window, qtbot):
    row = window.controls.rows["subdivisions"]
    row.spin.setValue(3)
    window.controller.flush()
    assert window.act_undo.shortcut().toString() == "Ctrl+Z"
    assert window.act_redo.shortcut().toString() == "Ctrl+Shift+Z"
    window.act_undo.trigger()
    window.controller.flush()
    assert window.model.params == COARSE and row.spin.value() == 2
    assert_counts(window, COARSE)
    window.act_redo.trigger()
    window.controller.flush()
    assert window.model.params.subdivisions == 3
    assert_counts(window, COARSE.replace(subdivisions=3))


def test_invalid_value_keeps_last_mesh_and_shows_message(window):
    shown = window.model.result
    row = window.controls.rows["outer_radius"]
    row.spin.setValue(2.0)  # below the inner radius
    window.controller.flush()
    assert window.model.result is shown
    assert_counts(window, COARSE)
    assert not row.error.isHidden() and "outer_radius" in row.error.text()
    assert "outer_radius" in window.statusBar().currentMessage()
    assert "border" in row.spin.styleSheet()
    row.spin.setValue(12.0)
    window.controller.flush()
    assert row.error.isHidden() and window.model.error is None
    assert_counts(window, COARSE.replace(outer_radius=12.0))


def test_big_meshes_are_built_in_the_worker(window, qtbot):
    window.controller.sync_triangles = 0  # everything goes to the worker
    busy = []
    window.controller.busy_changed.connect(busy.append)
    window.controls.rows["subdivisions"].spin.setValue(3)
    window.controls.rows["subdivisions"].spin.setValue(4)  # the latest value wins
    window.controller.flush()
    qtbot.waitUntil(lambda: busy and busy[-1] is False and not window.controller.busy,
                    timeout=20_000)
    assert window.model.result.params.subdivisions == 4
    assert_counts(window, COARSE.replace(subdivisions=4))


def test_settings_remember_parameters(qtbot):
    win = MainWindow(COARSE.replace(subdivisions=3))
    qtbot.addWidget(win)
    win.close()
    again = MainWindow()
    qtbot.addWidget(again)
    assert again.model.params.subdivisions == 3
    again.close()


def test_closing_leaves_no_error_output(qtbot, capfd):
    win = MainWindow(COARSE, scripted=True)
    qtbot.addWidget(win)
    win.show()
    qtbot.waitExposed(win)
    win.controller.flush()
    win.close()
    out, err = capfd.readouterr()
    assert "Error" not in err and "Traceback" not in err, err


def test_screenshot_and_quit_from_the_command_line(tmp_path):
    out = tmp_path / "window.png"
    env = dict(os.environ, XDG_CONFIG_HOME=str(tmp_path))
    proc = subprocess.run(
        [sys.executable, "-m", "app", "--preset", "paper-fig10", "--set", "subdivisions=2",
         "--screenshot", str(out), "--quit"],
        env=env, capture_output=True, text=True, timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    image = iio.imread(out)
    assert image.shape[0] > 300 and image.shape[1] > 500
    assert len(np.unique(image[..., :3].reshape(-1, 3), axis=0)) > 10
    assert "Traceback" not in proc.stderr


def test_bad_command_line_values_exit_1(tmp_path):
    env = dict(os.environ, XDG_CONFIG_HOME=str(tmp_path))
    proc = subprocess.run([sys.executable, "-m", "app", "--set", "subdivisions=0", "--quit"],
                          env=env, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 1 and "subdivisions" in proc.stderr

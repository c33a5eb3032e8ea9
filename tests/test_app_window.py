"""The desktop window in a real X window (Xvfb, see conftest.py), driven through its widgets."""

import os
import subprocess
import sys

import imageio.v3 as iio
import numpy as np
import pytest

pytest.importorskip("pyvistaqt")

from PySide6.QtCore import Qt  # noqa: E402
from PySide6.QtWidgets import QApplication, QMainWindow, QTabBar  # noqa: E402

from app.model import SPECS, applies, format_value  # noqa: E402
from app.window import MainWindow  # noqa: E402
from core import MeshParams  # noqa: E402
from tests.app_user import (  # noqa: E402
    choose,
    click_check_box,
    drag_slider,
    patch_counts,
    settle,
    shown_counts,
    type_into,
)

COARSE = MeshParams(angle_step=15.0, subdivisions=2)  # = conftest's window_params
#: COARSE has 24 patches on each ring, none touching another: closed forms hold.
COARSE_PATCHES = 48


def assert_counts(win, expected: dict) -> None:
    assert shown_counts(win) == expected


def test_window_opens_on_the_given_parameters(window):
    assert window.model.params == COARSE
    assert_counts(window, patch_counts(COARSE_PATCHES, 2))
    assert window.scene.datasets["faces"].n_cells == 384  # 48 patches x 2 x 2**2


@pytest.mark.parametrize("structure", ["double_ring", "split_double_ring", "patch"])
def test_each_slider_updates_the_statistics(window, qtbot, structure):
    choose(window.controls.combos["structure"], structure)
    window.controller.flush()
    for name, row in window.controls.rows.items():
        if row.slider is None:
            continue
        if not applies(name, structure):
            assert not row.slider.isEnabled() and not row.field.isEnabled()
            continue
        before = window.model.params
        row.slider.setFocus()
        qtbot.keyClick(row.slider, Qt.Key.Key_Right)
        window.controller.flush()
        after = window.model.params
        # a length's slider spans a decade each side of the value it was centred on
        assert getattr(after, name) == row.slider_spec.from_slider(row.slider.value()), name
        assert after != before or window.model.error is not None, name
        if window.model.error is None:
            assert row.field.text() == format_value(getattr(after, name))
            shown = shown_counts(window)
            n = after.subdivisions
            if structure == "patch":  # one patch: the closed form
                assert shown == patch_counts(1, n), name
            else:  # every patch is split in two primary triangles of n² each
                assert shown["triangles"] == shown["patches"] * 2 * n * n, name
            euler = int(window.stats.text("euler_characteristic").replace(",", ""))
            assert euler == shown["vertices"] - shown["edges"] + shown["triangles"]


def test_field_and_slider_agree(window):
    row = window.controls.rows["subdivisions"]
    type_into(row.field, "3")
    window.controller.flush()
    assert row.slider.value() == SPECS["subdivisions"].to_slider(3) == 2
    assert_counts(window, patch_counts(COARSE_PATCHES, 3))


def test_each_layer_toggles(window, qtbot):
    for name, box in window.layers.boxes.items():
        actor = window.scene.actors[name]
        if not box.isEnabled():
            continue
        before = bool(actor.GetVisibility())
        click_check_box(box)
        assert window.model.layers[name] is not before or name == "labels"
        assert bool(actor.GetVisibility()) is not before
        assert window.layer_actions[name].isChecked() is box.isChecked()
        click_check_box(box)
        assert bool(actor.GetVisibility()) is before


def test_colour_by_shows_a_colour_bar(window):
    combo = window.layers.color_by
    choose(combo, "min_angle")
    assert window.scene.actors["faces"].mapper.GetScalarVisibility()
    assert window.scene.scalar_bar.GetVisibility()
    choose(combo, "none")
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


def test_undo_redo_restore_parameters_and_counts(window):
    row = window.controls.rows["subdivisions"]
    type_into(row.field, "3")
    window.controller.flush()
    assert window.act_undo.shortcut().toString() == "Ctrl+Z"
    assert window.act_redo.shortcut().toString() == "Ctrl+Shift+Z"
    window.act_undo.trigger()
    window.controller.flush()
    assert window.model.params == COARSE and row.field.text() == "2"
    assert_counts(window, patch_counts(COARSE_PATCHES, 2))
    window.act_redo.trigger()
    window.controller.flush()
    assert window.model.params.subdivisions == 3 and row.field.text() == "3"
    assert_counts(window, patch_counts(COARSE_PATCHES, 3))


def test_invalid_value_keeps_last_mesh_and_shows_message(window):
    shown = window.model.result
    row = window.controls.rows["outer_radius"]
    type_into(row.field, "2")  # below the inner radius
    window.controller.flush()
    with pytest.raises(ValueError) as refusal:
        COARSE.replace(outer_radius=2.0)
    assert window.model.result is shown
    assert_counts(window, patch_counts(COARSE_PATCHES, 2))
    assert not row.error.isHidden() and row.error.text() == str(refusal.value)
    assert "outer_radius" in window.statusBar().currentMessage()
    assert "border" in row.field.styleSheet() and row.field.text() == "2"
    type_into(row.field, "12")
    window.controller.flush()
    assert row.error.isHidden() and window.model.error is None
    assert window.model.params.outer_radius == 12.0
    assert_counts(window, patch_counts(COARSE_PATCHES, 2))  # 24 separate patches per ring


def test_big_meshes_are_built_in_the_worker(window, qtbot):
    window.controller.sync_triangles = 0  # everything goes to the worker
    busy = []
    window.controller.busy_changed.connect(busy.append)
    field = window.controls.rows["subdivisions"].field
    type_into(field, "3")
    type_into(field, "4")  # the latest value wins
    window.controller.flush()
    qtbot.waitUntil(lambda: busy and busy[-1] is False and not window.controller.busy,
                    timeout=20_000)
    assert window.model.result.params.subdivisions == 4
    assert_counts(window, patch_counts(COARSE_PATCHES, 4))


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


# -- the README says what the window does (issue 3, item 19) -------------------------------

README = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "README.md")


def _readme() -> str:
    with open(README, encoding="utf-8") as f:
        return f.read()


def test_readme_compare_counts_are_what_the_window_shows(qtbot):
    """The compare.png caption gave 3,168 conforming unknowns where the window showed
    2,046: they were different parameters (1 mm patches against paper-fig12c's 2 mm). Each
    pair of counts the README gives is the pair Teach → Paper vs conforming shows."""
    import re

    text = _readme()
    caption = re.search(r"!\[Paper vs conforming[^\]]*\]\(assets/compare\.png\)", text).group(0)
    after = text[text.index(caption) + len(caption):].split("\n\n", 2)[1]
    pairs = {
        "image": re.search(r"([\d,]+) against ([\d,]+) RWG unknowns", caption).groups(),
        "paper-fig12c": re.search(r"`paper-fig12c`.*?([\d,]+) against\s+([\d,]+)", after,
                                  re.S).groups(),
    }
    assert "1 mm patches at 10° steps" in caption
    win = MainWindow(MeshParams(angle_step=10.0), scripted=True)
    qtbot.addWidget(win)
    win.show()
    qtbot.waitExposed(win)
    win.controller.flush()
    for source, (paper, conforming) in pairs.items():
        if source != "image":
            next(a for a in win.menuBar().findChildren(type(win.act_shot))
                 if a.text() == source).trigger()
            win.controller.flush()
        view = win.teaching_windows.show_compare()
        qtbot.waitUntil(lambda v=view: not v.busy and v.shown_generation == v.generation,
                        timeout=30_000)
        shown = {mode: view.stats_of(mode)["interior_edges"] for mode in ("paper", "conforming")}
        assert shown == {"paper": int(paper.replace(",", "")),
                         "conforming": int(conforming.replace(",", ""))}, source
    win.close()


def test_readme_does_not_say_the_feed_is_missing_from_the_window(window):
    """The README said the voltage feed was "Not in the window yet"; the Solve tab has it
    (tests/test_app_solve.py solves with it)."""
    text = _readme()
    assert "Not in the window yet: the delta-gap feed" not in text
    assert "voltage feed" in text
    combo = window.solve_panel.excitation
    assert "feed" in [combo.itemData(i) for i in range(combo.count())]


def _centre(mesh):
    """The area-weighted centroid (x, y) of a mesh."""
    centroids = mesh.points[mesh.triangles].mean(axis=1)
    return (mesh.areas[:, None] * centroids).sum(axis=0)[:2] / mesh.areas.sum()


def test_origin_tooltip_says_where_the_rings_are(window, qtbot):
    """Paper-mode rings sit at origin + (s/2, s/2) (the paper puts each patch's corner at
    (r cos θ, r sin θ)); the tooltip called the origin "the centre of the rings". The
    placement stays the paper's, and the tooltip says what the origin is."""
    row = window.controls.rows["origin"]
    tip = row.field.toolTip()
    assert "centre of the rings" not in tip
    assert "origin + (s/2, s/2)" in tip and "conforming rings" in tip
    s = window.model.params.patch_size
    type_into(row.field, "3, -2")
    window.controller.flush()
    assert window.model.params.origin == (3.0, -2.0)
    # the double ring of the window, in paper mode: centred at origin + (s/2, s/2)
    assert np.allclose(_centre(window.model.result.mesh), (3.0 + s / 2, -2.0 + s / 2))
    choose(window.controls.combos["mode"], "conforming")
    window.controller.flush()
    assert np.allclose(_centre(window.model.result.mesh), (3.0, -2.0), atol=1e-9)


#: The paper's Fig. 12(d): 1 mm patches every 20 degrees on both rings, n = 4.
FIG12D = MeshParams(angle_step=20.0)


@pytest.mark.parametrize("window_params", [FIG12D])
def test_no_progress_message_stays_once_the_mesh_is_shown(window, qtbot):
    """Issue section 3 item 3: drag Inner radius until refused, then drag Angle step."""
    window.controller.sync_triangles = 0  # every build in the worker, with its progress
    settle(window, qtbot)
    inner = window.controls.rows["inner_radius"].slider
    drag_slider(inner, inner.maximum())
    settle(window, qtbot)
    assert "inner_radius" in window.model.errors  # refused: larger than the outer radius
    refused = window.model.errors["inner_radius"].message
    step = window.controls.rows["angle_step"].slider
    shown = window.model.result
    drag_slider(step, step.value() - 12)
    window.controller.flush()
    qtbot.waitUntil(lambda: window.model.result is not shown and not window.controller.busy,
                    timeout=60_000)
    assert window.model.params.angle_step < 20.0
    message = window.statusBar().currentMessage()
    assert "Meshing" not in message and "Esc cancels" not in message
    assert refused in message  # the refusal still standing is said again


# -- issue section 3 item 12: window size and docks ---------------------------------------


def _pump(qtbot, win):
    qtbot.wait(50)
    QApplication.processEvents()


def test_a_later_session_without_a_cell_has_no_elements_dock(qtbot):
    win = MainWindow(COARSE)
    qtbot.addWidget(win)
    win.show()
    qtbot.waitExposed(win)
    win.cell_tools.preset_actions["double-ring-patch"].trigger()  # Cell → Cell presets
    assert win.model.cell_state is not None and not win.cell_tools.dock.isHidden()
    win.close()  # the layout is saved with the Elements dock shown
    again = MainWindow()
    qtbot.addWidget(again)
    again.show()
    qtbot.waitExposed(again)
    assert again.model.cell_state is None
    assert again.cell_tools.dock.isHidden()  # no empty dock for a cell that is not open
    again.close()


@pytest.mark.parametrize("with_cell", [False, True])
def test_the_window_fits_a_768_px_screen(window, qtbot, with_cell):
    if with_cell:
        window.cell_tools.preset_actions["double-ring-patch"].trigger()
        assert not window.cell_tools.dock.isHidden()
    for size in ((1000, 700), (1300, 700), (1000, 600)):
        window.resize(*size)
        _pump(qtbot, window)
        assert (window.width(), window.height()) == size  # not clamped to 733 or 823 px
        assert window.minimumSizeHint().height() <= 600


@pytest.mark.parametrize("width", [1000, 1300])
def test_tabbed_docks_keep_their_whole_titles(window, qtbot, width):
    window.resize(width, 700)
    _pump(qtbot, window)
    window.teaching.set_matrix_active(True)  # one more dock tabbed with Statistics
    _pump(qtbot, window)
    bars = [b for b in window.findChildren(QTabBar)
            if isinstance(b.parent(), QMainWindow) and b.isVisible() and b.count() > 1]
    assert bars
    for bar in bars:
        metrics = bar.fontMetrics()
        for i in range(bar.count()):
            text = bar.tabText(i).replace("&", "")
            assert bar.tabRect(i).width() >= metrics.horizontalAdvance(text), text
            assert bar.elideMode() == Qt.TextElideMode.ElideNone

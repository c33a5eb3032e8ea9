"""Teach → Construction step by step, in a real window under Xvfb (see conftest.py)."""

import imageio.v3 as iio
import numpy as np
import pytest

pytest.importorskip("pyvistaqt")

from gui_helpers import drawn_near, near, pixel, type_into  # noqa: E402
from PySide6.QtCore import Qt  # noqa: E402

from barymesh import MeshParams  # noqa: E402
from barymesh.app.model import AppModel  # noqa: E402
from barymesh.app.teach.construction_view import (  # noqa: E402
    RULER_CLEARANCE,
    ConstructionView,
    label_offsets,
    shown_labels,
)
from barymesh.app.window import MainWindow  # noqa: E402
from barymesh.teach.construction import construction_steps  # noqa: E402

PATCH = MeshParams(structure="patch", patch_size=10.0, subdivisions=4)
#: The paper's n = 4: what each step adds, by the title's first words.
PAPER_STEPS = [
    "Square patch ABCD",
    "Diagonal BC",
    "Edge midpoints",
    "Quarter points",
    "Connecting lines",
    "32 sub-triangles",
    "Centroids",
    "Shared edges",
]


@pytest.fixture
def view(qtbot):
    model = AppModel(PATCH)
    win = ConstructionView(model)
    qtbot.addWidget(win)
    win.resize(1000, 700)
    win.show()
    qtbot.waitExposed(win)
    with qtbot.waitActive(win):  # the step keys are window shortcuts
        win.activateWindow()
    yield win
    win.close()


def go_to_step(qtbot, view, index):
    """Home, then → ``index`` times, with the focus on the step slider (as a user steps)."""
    view.slider.setFocus()
    qtbot.keyClick(view.slider, Qt.Key.Key_Home)
    for _ in range(index):
        qtbot.keyClick(view.slider, Qt.Key.Key_Right)
    assert view.index == index


def test_paper_patch_has_eight_steps_with_their_titles(view, qtbot):
    assert len(view.steps) == 8
    assert view.slider.minimum() == 0 and view.slider.maximum() == 7
    view.slider.setFocus()
    for i, start in enumerate(PAPER_STEPS):
        if i:
            qtbot.keyClick(view.slider, Qt.Key.Key_Right)
        assert view.index == i and view.slider.value() == i
        assert view.title.text().startswith(start)
        assert view.counter.text() == f"Step {i + 1} of 8"
        assert view.description.text()


def test_labels_appear_at_their_step(view, qtbot):
    corners = {"A", "B", "C", "D"}
    midpoints = {"m1", "m2", "m3"}
    quarters = {"m11", "m12", "m21", "m22"}
    go_to_step(qtbot, view, 0)
    assert set(view.labels) == corners
    go_to_step(qtbot, view, 1)
    assert set(view.labels) == corners
    go_to_step(qtbot, view, 2)
    assert set(view.labels) == corners | midpoints
    go_to_step(qtbot, view, 3)
    assert set(view.labels) == corners | midpoints | quarters
    go_to_step(qtbot, view, 7)
    assert set(view.labels) == corners | midpoints | quarters


def test_labels_sit_next_to_their_points_not_on_them(view, qtbot):
    go_to_step(qtbot, view, 3)
    step = view.steps[3]
    anchors = view.label_points.points[:, :2]
    at = {label: np.asarray(p) for label, p in zip(step.labels, step.points, strict=True)}
    size = 10.0
    px = 2.0 * view.plotter.camera.parallel_scale / view.plotter.window_size[1]  # mm per px
    lo, hi = np.min(step.points, axis=0), np.max(step.points, axis=0)
    for label, anchor in zip(view.labels, anchors, strict=True):
        gap = np.linalg.norm(anchor - at[label])
        assert 0.02 * size < gap < 0.25 * size, label
        # points inside the ruled sides (left, bottom): the label lies beyond the tick labels
        x, y = at[label]
        if np.isclose(x, lo[0]) and lo[1] + 1e-9 < y < hi[1] - 1e-9:
            assert lo[0] - anchor[0] > RULER_CLEARANCE["left"] * px, label
        if np.isclose(y, lo[1]) and lo[0] + 1e-9 < x < hi[0] - 1e-9:
            assert lo[1] - anchor[1] > RULER_CLEARANCE["bottom"] * px, label


def test_previous_next_buttons_and_keys(view, qtbot):
    assert not view.prev_button.isEnabled() and view.next_button.isEnabled()
    qtbot.mouseClick(view.next_button, Qt.MouseButton.LeftButton)
    qtbot.mouseClick(view.next_button, Qt.MouseButton.LeftButton)
    assert view.index == 2 and view.slider.value() == 2
    qtbot.mouseClick(view.prev_button, Qt.MouseButton.LeftButton)
    assert view.index == 1
    with qtbot.waitActive(view):
        view.activateWindow()
    keys = view.plotter  # the keys work while the 3D view has the focus
    keys.setFocus()
    qtbot.keyClick(keys, Qt.Key.Key_Right)
    assert view.index == 2
    qtbot.keyClick(keys, Qt.Key.Key_PageDown)  # a presenter's remote
    assert view.index == 3
    qtbot.keyClick(keys, Qt.Key.Key_Left)
    assert view.index == 2
    qtbot.keyClick(keys, Qt.Key.Key_End)
    assert view.index == 7 and not view.next_button.isEnabled()
    view.next_step()  # past the end: stays
    assert view.index == 7
    qtbot.keyClick(keys, Qt.Key.Key_Home)
    assert view.index == 0


def test_each_step_draws_what_it_says(view, qtbot):
    go_to_step(qtbot, view, 1)
    assert view.datasets["highlight"].n_cells == 1  # the diagonal, emphasised
    assert view.datasets["primary_0"].n_cells == 1 and view.datasets["primary_1"].n_cells == 1
    go_to_step(qtbot, view, 4)
    assert view.datasets["highlight"].n_cells == 2 * 3 * 3  # n - 1 lines x 3 per primary
    go_to_step(qtbot, view, 5)
    assert view.datasets["subtriangles"].n_cells == 32
    assert view.datasets["highlight"].n_cells == 0
    go_to_step(qtbot, view, 6)
    assert view.datasets["centroids"].n_points == 32
    go_to_step(qtbot, view, 7)
    assert view.datasets["shared_edges"].n_cells == 40


@pytest.mark.parametrize("n", [1, 2, 3, 5, 8, 16])
def test_any_n_and_the_triangle(qtbot, n):
    for structure in ("patch", "triangle"):
        params = PATCH.replace(structure=structure, subdivisions=n)
        view = ConstructionView(AppModel(params))
        qtbot.addWidget(view)
        expected = construction_steps(params)
        assert len(view.steps) == len(expected)
        view.set_step(len(expected) - 1)
        assert view.datasets["subtriangles"].n_cells == len(expected[-1].triangles)
        assert view.title.text() == expected[-1].title
        assert {"A", "B", "C"} <= set(view.labels)
        view.close()


def test_follows_the_main_parameters_and_drives_n(view, qtbot):
    go_to_step(qtbot, view, 5)
    view.model.set_value("subdivisions", 2)
    assert view.params.subdivisions == 2 and len(view.steps) == 7
    assert view.datasets["subtriangles"].n_cells == 8
    type_into(qtbot, view.n_spin, 4)  # the panel's n changes the model (undoable there)
    assert view.model.params.subdivisions == 4 and len(view.steps) == 8
    view.diagonal.setFocus()
    qtbot.keyClick(view.diagonal, Qt.Key.Key_Down)  # "BC (paper)" -> "AD (Makarov)"
    assert view.model.params.diagonal == "AD"
    assert view.steps[1].title.startswith("Diagonal AD")


def test_unsupported_parameters_keep_the_last_steps(view):
    steps = view.steps
    view.model.set_value("scheme", "barycentric")
    assert view.steps is steps
    assert not view.error.isHidden() and "uniform" in view.error.text()
    view.model.set_value("scheme", "uniform")
    assert view.error.isHidden()


def test_label_helpers():
    assert shown_labels(["A", "m1", "m11", "m111", "ab4", "ab3"], 16) == [
        "A",
        "m1",
        "m11",
        "",
        "ab4",
        "",
    ]
    assert shown_labels(["m111"], 8) == ["m111"]
    offsets = label_offsets(["m1", "m22"], np.array([[0.0, -1.0], [-1.0, 0.0]]), 20, 6)
    assert offsets[0, 0] == 0 and offsets[0, 1] < -12 - 6  # below, clear of half the height
    assert offsets[1, 1] == 0 and offsets[1, 0] < -0.5 * 3 * 0.62 * 20


def test_screenshot_shows_each_layer_where_it_is(view, qtbot, tmp_path):
    """Pixels, not colour counts: step 4 (quarter points) of the 10 mm patch."""
    from barymesh.app.teach.construction_view import COLORS

    with qtbot.waitActive(view):  # the step keys are window shortcuts
        view.activateWindow()
    view.plotter.setFocus()
    for _ in range(3):
        qtbot.keyClick(view.plotter, Qt.Key.Key_Right)
    assert view.index == 3
    image = view.view_image()
    iio.imwrite(tmp_path / "construction.png", image)
    p = view.plotter
    assert near(pixel(image, p, (2.0, 2.0, 0.0)), COLORS["primary_0"], 12)  # triangle ABC
    assert near(pixel(image, p, (8.0, 8.0, 0.0)), COLORS["primary_1"], 12)  # triangle DCB
    for corner in ((0.0, 0.0), (10.0, 0.0), (2.5, 0.0), (0.0, 7.5)):  # A, B, m11, m21
        assert near(pixel(image, p, (*corner, 0.0)), COLORS["points"], 40), corner
    assert drawn_near(image, p, (7.0, 3.0, 0.0), COLORS["segments"], 40)  # diagonal BC
    assert near(pixel(image, p, (10.6, 5.0, 0.0)), "#ffffff", 3)  # right of the patch
    grab = tmp_path / "construction-window.png"
    assert view.grab().save(str(grab))
    assert iio.imread(grab).shape[1] >= 900


def test_opened_from_the_teach_menu_and_closed_with_the_window(qtbot):
    win = MainWindow(PATCH, scripted=True)
    qtbot.addWidget(win)
    win.show()
    qtbot.waitExposed(win)
    win.controller.flush()
    assert win.teaching_windows.act_construction in win.teach_menu.actions()
    with qtbot.waitActive(win):
        win.activateWindow()
    win.plotter.setFocus()
    qtbot.keyClick(win.plotter, Qt.Key.Key_F7)  # Teach → Construction step by step
    view = win.teaching_windows.construction
    assert view is not None and view.isVisible() and len(view.steps) == 8
    type_into(qtbot, win.controls.rows["subdivisions"].spin, 3)
    win.controller.flush()
    assert view.params.subdivisions == 3
    win.close()
    assert view._closed


def test_caption_names_each_step_at_the_top_of_the_view(view, qtbot):
    """The caption (a text actor of a fixed size, centred at the top) follows the steps;
    the sub-triangle step draws the paper's 32 = 2 n² sub-triangles."""
    from barymesh.app.teach.construction_view import CAPTION_PX

    view.slider.setFocus()
    qtbot.keyClick(view.slider, Qt.Key.Key_Home)
    widths = []
    for i, start in enumerate(PAPER_STEPS):
        if i:
            qtbot.mouseClick(view.next_button, Qt.MouseButton.LeftButton)
        assert view.index == i
        assert view.caption.GetInput() == f"{i + 1}/8  {view.steps[i].title}"
        assert view.caption.GetInput().split("  ", 1)[1].startswith(start)
        image = view.view_image()
        dark = np.argwhere(image[: 3 * CAPTION_PX].astype(int).sum(axis=-1) < 300)
        assert len(dark), "no caption drawn"
        (top, left), (bottom, right) = dark.min(axis=0), dark.max(axis=0)
        assert 2 <= top <= 10 and CAPTION_PX * 0.6 <= bottom - top <= CAPTION_PX * 1.2
        assert abs(0.5 * (left + right) - 0.5 * image.shape[1]) <= 3  # centred
        widths.append(right - left)
        if start.startswith("32 sub-triangles"):
            assert view.datasets["subtriangles"].n_cells == 2 * PATCH.subdivisions**2 == 32
    assert len(set(widths)) > 1  # a longer title is drawn wider, at the same size


def _main_window(qtbot):
    win = MainWindow(PATCH, scripted=True)
    qtbot.addWidget(win)
    win.show()
    qtbot.waitExposed(win)
    win.controller.flush()
    with qtbot.waitActive(win):
        win.activateWindow()
    win.plotter.setFocus()
    return win


def test_opening_paints_the_background_first_and_then_the_step(qtbot):
    """F7: the window's first paint is the bare background (the GL context and the first
    shaders in separate passes of the event loop); the step comes by itself right after."""
    from gui_helpers import rendered

    from barymesh.app.teach.construction_view import COLORS

    win = _main_window(qtbot)
    qtbot.keyClick(win.plotter, Qt.Key.Key_F7)
    view = win.teaching_windows.construction
    assert view.isVisible() and len(view.steps) == 8
    assert not view.actors["primary_0"].GetVisibility()  # not in the first paint
    qtbot.waitUntil(lambda: view.actors["primary_0"].GetVisibility(), timeout=5_000)
    assert view._unrevealed is None
    image = rendered(view.plotter)  # without view_image's own reveal
    p = view.plotter
    assert view.index == 0  # the square ABCD: its corners and sides
    for corner in ((0.0, 0.0), (10.0, 0.0), (0.0, 10.0), (10.0, 10.0)):
        assert near(pixel(image, p, (*corner, 0.0)), COLORS["points"], 40), corner
    assert drawn_near(image, p, (5.0, 0.0, 0.0), COLORS["segments"], 40)  # side AB
    assert near(pixel(image, p, (5.0, 5.0, 0.0)), "#ffffff", 3)  # no triangle yet
    win.close()


def test_closing_before_the_first_step_is_shown(qtbot):
    win = _main_window(qtbot)
    qtbot.keyClick(win.plotter, Qt.Key.Key_F7)
    view = win.teaching_windows.construction
    assert view._unrevealed  # the step waits for the next pass
    win.close()  # closes the construction window with it, before that pass
    assert view._closed
    qtbot.wait(50)  # the reveal timer fires on a closed window: nothing happens
    assert view._unrevealed is None

"""Issue 9, "a view that reads at a glance", in the real window (Xvfb, see conftest.py).

Each test drives the window as a user does (keys, mouse presses, moves and releases on
the 3D view, the spy plot and the dialogs) and checks what is on screen: camera,
pixels, texts.
"""

import numpy as np
import pytest

pytest.importorskip("pyvistaqt")

from app_user import wait_for_export  # noqa: E402
from gui_helpers import (  # noqa: E402
    click_world,
    display_point,
    hover_world,
    near,
    pixel,
    rendered,
    share,
    text_display_box,
    type_into,
)
from PySide6.QtCore import QPoint, QPointF, Qt  # noqa: E402
from PySide6.QtGui import QWheelEvent  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

from barymesh import MeshParams  # noqa: E402
from barymesh.app.teach.inspector import COLORS as INSPECTOR_COLORS  # noqa: E402
from barymesh.app.view.highlight import COL_COLOR, ROW_COLOR, SMALL_PIXELS  # noqa: E402
from barymesh.app.window import MainWindow, file_error_sentence  # noqa: E402

FIG10 = MeshParams(structure="patch", patch_size=10.0, subdivisions=4)  # 32 triangles


@pytest.fixture
def window_params():
    return FIG10


@pytest.fixture
def active(window, qtbot):
    """The window, active (its shortcuts need that) with the 3D view focused."""
    with qtbot.waitActive(window):
        window.activateWindow()
    window.plotter.setFocus()
    return window


def key(qtbot, widget, k, modifier=Qt.KeyboardModifier.NoModifier):
    qtbot.keyClick(widget, k, modifier)
    QApplication.processEvents()


def mesh_on_screen(win, bounds=None):
    """(lo, hi) display corners of the mesh's bounding box."""
    x0, x1, y0, y1 = bounds or win.scene.bounds
    pts = np.array([display_point(win.plotter, (x, y, 0.0)) for x in (x0, x1) for y in (y0, y1)])
    return pts.min(axis=0), pts.max(axis=0)


def fully_in_view(win):
    lo, hi = mesh_on_screen(win)
    w, h = win.plotter.window_size
    return (lo >= 0).all() and hi[0] <= w and hi[1] <= h


# -- 8: rulers in the construction window and both halves of the compare view ------------


def ruler_labels(axes, axis):
    labels = axes.GetAxisLabels(axis)
    return [labels.GetValue(i) for i in range(labels.GetNumberOfValues())]


def test_construction_window_has_rulers_in_mm(active, qtbot):
    key(qtbot, active, Qt.Key.Key_F7)
    view = active.teaching_windows.construction
    qtbot.waitExposed(view)
    assert view.rulers.axes.GetVisibility()
    assert ruler_labels(view.rulers.axes, 0) == ["0", "2", "4", "6", "8", "10"]
    assert ruler_labels(view.rulers.axes, 1) == ["0", "2", "4", "6", "8", "10"]
    # the tick label "4" is drawn under the bottom side: dark pixels there, not under a
    # point's label (which sits farther down)
    image = view.view_image()
    x, y = display_point(view.plotter, (4.0, 0.0, 0.0))
    h = image.shape[0]
    band = image[h - int(y) + 6 : h - int(y) + 24, int(x) - 8 : int(x) + 9, :3]
    assert (band.max(axis=2) < 120).any()


def test_compare_view_has_rulers_in_both_halves(active, qtbot):
    key(qtbot, active, Qt.Key.Key_F8)
    view = active.teaching_windows.compare
    qtbot.waitUntil(lambda: not view.busy and len(view.halves) == 2, timeout=20_000)
    image = view.view_image()
    h = image.shape[0]
    for col, mode in enumerate(("paper", "conforming")):
        axes = view.scenes[mode].axes
        renderer = view.plotter.renderers[col]
        assert axes.GetVisibility(), mode
        assert ruler_labels(axes, 0) == ["0", "2", "4", "6", "8", "10"], mode
        # each half's tick value "4" is drawn centred under its tick, just under the
        # bottom ruler (y = 0), inside the half (the cube axes' 2D labels could not do
        # that right of the window's left edge: the half drew labelled points instead)
        actor = axes.label_actors(0)[2]
        assert actor.GetInput() == "4" and actor.GetVisibility()
        box = text_display_box(actor, renderer)
        x, y = display_point(view.plotter, (4.0, 0.0, 0.0), renderer)
        assert abs(0.5 * (box[0] + box[1]) - x) < 2 and y - 25 < box[2] < box[3] < y, mode
        v0, _, v2, _ = renderer.GetViewport()
        width = image.shape[1]
        assert v0 * width <= box[0] < box[1] <= v2 * width, mode
        glyph = image[h - int(box[3]) - 1 : h - int(box[2]) + 1, int(box[0]) : int(box[1]) + 1]
        assert (glyph[..., :3].max(axis=2) < 120).sum() >= 6, mode  # its dark pixels


# -- 9: R frames from above; a narrow window keeps the view wide ------------------------


def test_r_undoes_a_tilt_and_frames_the_whole_mesh(active, qtbot):
    plotter = active.plotter
    start = QPoint(plotter.width() // 2, plotter.height() // 2)
    qtbot.mousePress(plotter, Qt.MouseButton.LeftButton, pos=start)
    for step in range(1, 6):
        qtbot.mouseMove(plotter, start + QPoint(25 * step, 18 * step))
    qtbot.mouseRelease(plotter, Qt.MouseButton.LeftButton, pos=start + QPoint(125, 90))
    tilted = np.asarray(plotter.camera.GetDirectionOfProjection())
    assert abs(tilted[2]) < 0.999  # the drag tilted the view
    key(qtbot, plotter, Qt.Key.Key_R)
    camera = plotter.camera
    assert np.allclose(camera.GetDirectionOfProjection(), (0, 0, -1), atol=1e-9)
    assert np.allclose(camera.up, (0, 1, 0), atol=1e-9)
    qtbot.waitUntil(lambda: fully_in_view(active))  # (framed again after any resize)


def test_t_undoes_a_tilt_and_keeps_the_zoom(active, qtbot):
    plotter = active.plotter
    centre = QPoint(plotter.width() // 2, plotter.height() // 2)
    event = QWheelEvent(
        QPointF(centre),
        QPointF(plotter.mapToGlobal(centre)),
        QPoint(0, 0),
        QPoint(0, 360),
        Qt.MouseButton.NoButton,
        Qt.KeyboardModifier.NoModifier,
        Qt.ScrollPhase.NoScrollPhase,
        False,
    )
    QApplication.sendEvent(plotter, event)
    qtbot.mousePress(plotter, Qt.MouseButton.LeftButton, pos=centre)
    qtbot.mouseMove(plotter, centre + QPoint(60, 40))
    qtbot.mouseRelease(plotter, Qt.MouseButton.LeftButton, pos=centre + QPoint(60, 40))
    scale = plotter.camera.parallel_scale
    key(qtbot, plotter, Qt.Key.Key_T)
    assert np.allclose(plotter.camera.GetDirectionOfProjection(), (0, 0, -1), atol=1e-9)
    assert plotter.camera.parallel_scale == pytest.approx(scale)


def test_a_1000_by_700_window_gives_the_view_most_of_the_width(active, qtbot):
    active.resize(1000, 700)
    qtbot.waitUntil(lambda: active.width() == 1000)
    QApplication.processEvents()
    qtbot.waitUntil(lambda: active.plotter.width() >= 600)
    left = Qt.DockWidgetArea.LeftDockWidgetArea
    assert active.dockWidgetArea(active.statistics_dock) == left
    assert active.statistics_dock in active.tabifiedDockWidgets(active.parameters_dock)
    key(qtbot, active.plotter, Qt.Key.Key_R)
    qtbot.waitUntil(lambda: fully_in_view(active))
    active.resize(1400, 860)
    qtbot.waitUntil(
        lambda: (
            active.dockWidgetArea(active.statistics_dock) == Qt.DockWidgetArea.RightDockWidgetArea
        )
    )
    assert not active.statistics_dock.isHidden() and not active.layers_dock.isHidden()


# -- 12: inspector and matrix together; restored sessions; picking with faces hidden -----


def test_matrix_marks_over_the_inspector_keep_t_plus_and_its_colour_bar(active, qtbot):
    key(qtbot, active.plotter, Qt.Key.Key_I)
    key(qtbot, active.plotter, Qt.Key.Key_M)
    mesh = active.model.result.mesh
    rwg = mesh.rwg
    row = 9
    edge = int(rwg.edge[row])
    a, b = mesh.points[mesh.edges[edge]]
    t_plus = int(rwg.t_plus[row])
    mid = 0.5 * (a + b)
    click_world(qtbot, active.plotter, mid + 0.1 * (mesh.centroids[t_plus] - mid))
    inspector = active.teaching.inspector
    assert inspector.edge == edge
    # hover the matrix cell of T+'s row: its mark is an outline, the fill stays T+'s
    view = active.teaching.matrix
    qtbot.waitUntil(lambda: not view.stale)
    qtbot.wait(100)
    view.canvas.draw()
    col = int(rwg.t_minus[row])
    x, y = view.axes.transData.transform((col, t_plus))
    qtbot.mouseMove(view.canvas, QPoint(round(x), round(view.canvas.height() - y)))
    qtbot.waitUntil(lambda: active.teaching.highlight.triangles == (t_plus, col))
    assert active.teaching.highlight.outline_only
    image = rendered(active.plotter)
    corners = mesh.points[mesh.triangles[t_plus]]
    # T+ is drawn in the divergence map's red (coolwarm's top, at 75 % over the faces),
    # not in the row mark's orange
    sample = [
        pixel(image, active.plotter, w @ corners)
        for w in (np.array([0.6, 0.2, 0.2]), np.array([0.2, 0.6, 0.2]), np.array([0.2, 0.2, 0.6]))
    ]
    orange_like = [near(p, ROW_COLOR, 45) for p in sample]
    red_like = [p[0] > 150 and p[1] < 120 and p[2] < 120 for p in sample]
    assert sum(red_like) >= 2 and not any(orange_like), sample
    assert inspector.overlay.scalar_bar.GetVisibility()


def test_a_restored_session_shows_a_dock_only_with_its_tool(qtbot):
    first = MainWindow(FIG10)
    qtbot.addWidget(first)
    first.show()
    qtbot.waitExposed(first)
    first.controller.flush()
    with qtbot.waitActive(first):
        first.activateWindow()
    first.teaching.act_inspector.trigger()  # Teach → RWG basis inspector
    assert first.teaching.inspector_active and first.teaching.inspector_dock.isVisible()
    first.close()
    second = MainWindow(FIG10)
    qtbot.addWidget(second)
    second.show()
    qtbot.waitExposed(second)
    second.controller.flush()
    dock = second.teaching.inspector_dock
    assert not dock.isHidden()
    assert second.teaching.inspector_active and second.teaching.act_inspector.isChecked()
    assert not second.teaching.matrix_dock.isVisible() and not second.teaching.matrix_active
    second.close()


def test_clicks_pick_with_the_triangles_layer_hidden(active, qtbot):
    key(qtbot, active.plotter, Qt.Key.Key_1, Qt.KeyboardModifier.ControlModifier)
    assert not active.model.layers["faces"]
    assert not active.scene.actors["faces"].GetVisibility()
    key(qtbot, active.plotter, Qt.Key.Key_I)
    mesh = active.model.result.mesh
    edge = int(mesh.rwg.edge[20])
    a, b = mesh.points[mesh.edges[edge]]
    t = int(mesh.rwg.t_minus[20])
    click_world(qtbot, active.plotter, 0.5 * (a + b) + 0.05 * (mesh.centroids[t] - 0.5 * (a + b)))
    assert active.teaching.inspector.edge == edge
    assert not active.scene.actors["faces"].GetVisibility()  # still hidden after the pick


# -- 15: file errors in one sentence -------------------------------------------------------


def test_file_error_sentences_name_the_file_once():
    path = "/data/run 3/truncated.msh"
    said = file_error_sentence(
        "Could not open truncated.msh",
        ValueError(f"{path}: {path}: the file ends after 3 of 423 nodes"),
        path,
    )
    assert said == "Could not open truncated.msh: the file ends after 3 of 423 nodes."
    said = file_error_sentence(
        "Could not open x.obj", UnicodeDecodeError("utf-8", b"ab\xf3", 2, 3, "invalid"), "x.obj"
    )
    assert said == "Could not open x.obj: it is not UTF-8 text (byte 0xf3 at offset 2)."
    said = file_error_sentence(
        "Could not open gone.msh",
        FileNotFoundError(2, "No such file or directory", "/a/gone.msh"),
        "/a/gone.msh",
    )
    assert said == "Could not open gone.msh: no such file or directory."


def test_a_bad_file_is_reported_with_its_name_once(active, tmp_path):
    bad = tmp_path / "truncated.msh"
    bad.write_text("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n423\n1 0 0 0\n")
    assert not active.open_mesh_file(bad)
    message = active.statusBar().currentMessage()
    assert message.startswith("Could not open truncated.msh: ")
    assert message.count("truncated.msh") == 1 and str(tmp_path) not in message
    assert "\n" not in message and message.endswith(".")


# -- 16: status bar, preset note, help, keys from teaching windows, presentation ----------


def test_a_long_status_message_is_not_cut_by_the_triangle_count(active):
    assert active.summary.isVisible()
    text = "Could not open a-file-with-a-long-name.msh: " + "a long reason " * 6
    active.statusBar().showMessage(text)
    assert not active.summary.isVisible()
    assert active.statusBar().toolTip() == text
    active.statusBar().clearMessage()
    assert active.summary.isVisible()


def test_a_preset_description_stays_until_the_parameters_change(active, qtbot):
    from barymesh.presets import preset_descriptions

    name, description = next(iter(preset_descriptions().items()))
    menu = next(a.menu() for a in active.menuBar().actions() if a.text() == "&Presets")
    next(a for a in menu.actions() if a.text() == name).trigger()
    active.controller.flush()
    qtbot.waitUntil(lambda: not active.controller.busy, timeout=20_000)
    QApplication.processEvents()
    note = active.view_tools.note.text()
    assert note == f"Preset {name}: {description}"
    # a parameter typed by the user: the description no longer describes the mesh
    value = active.model.params.subdivisions
    new = value + 1 if value < 6 else value - 1
    type_into(qtbot, active.controls.rows["subdivisions"].field, new)
    qtbot.waitUntil(lambda: active.view_tools.note.text() == "")


def test_f1_help_fits_the_screen_and_scrolls(active, qtbot):
    key(qtbot, active, Qt.Key.Key_F1)
    dialog = active.help_dialog
    qtbot.waitExposed(dialog)
    room = dialog.screen().availableGeometry()
    assert dialog.frameGeometry().height() <= room.height()
    assert dialog.height() <= 600
    bar = dialog.browser.verticalScrollBar()
    assert bar.maximum() > 0  # the shortcuts table is longer than the dialog: it scrolls
    assert "Measure distance" in dialog.browser.toPlainText()
    dialog.close()


def test_f8_and_f1_work_while_the_construction_window_has_focus(active, qtbot):
    key(qtbot, active, Qt.Key.Key_F7)
    construction = active.teaching_windows.construction
    qtbot.waitExposed(construction)
    with qtbot.waitActive(construction):
        construction.activateWindow()
    key(qtbot, construction, Qt.Key.Key_F8)
    compare = active.teaching_windows.compare
    assert compare is not None
    qtbot.waitExposed(compare)
    qtbot.waitUntil(lambda: not compare.busy and len(compare.halves) == 2, timeout=20_000)
    compare.close()
    construction.activateWindow()
    qtbot.waitUntil(lambda: QApplication.activeWindow() is construction)
    key(qtbot, construction, Qt.Key.Key_F5)  # presents the construction window itself
    assert construction.presenting
    qtbot.waitUntil(lambda: construction.geometry() == construction.screen().geometry())
    key(qtbot, construction, Qt.Key.Key_F5)
    assert not construction.presenting
    key(qtbot, construction, Qt.Key.Key_F1)
    assert active.help_dialog.isVisible()
    active.help_dialog.close()


def test_presentation_mode_enlarges_the_mesh(active, qtbot):
    def mesh_width():
        lo, hi = mesh_on_screen(active)
        return float(hi[0] - lo[0])

    key(qtbot, active.plotter, Qt.Key.Key_R)
    qtbot.waitUntil(lambda: fully_in_view(active))
    qtbot.wait(100)
    before = mesh_width()
    key(qtbot, active, Qt.Key.Key_F5)
    qtbot.waitUntil(lambda: active.geometry() == active.screen().geometry())
    qtbot.waitUntil(lambda: mesh_width() > 1.25 * before)
    assert fully_in_view(active)
    key(qtbot, active, Qt.Key.Key_F5)
    qtbot.waitUntil(lambda: abs(mesh_width() - before) < 2)


# -- 17: hover readout, measuring, zoom to selection, export unit --------------------------


def test_hover_readout_names_what_is_under_the_cursor(active, qtbot):
    mesh = active.model.result.mesh
    readout = active.view_tools.readout
    t = 13
    hover_world(qtbot, active.plotter, mesh.centroids[t])
    qtbot.waitUntil(lambda: f"triangle {t} " in readout.text())
    cx, cy = mesh.centroids[t][:2]
    decimals = int(readout.text().split("x = ")[1].split(",")[0].split(".")[1].__len__())
    assert f"centroid ({cx:.{decimals}f}, {cy:.{decimals}f}) mm" in readout.text()
    v = int(mesh.triangles[t][0])
    hover_world(qtbot, active.plotter, mesh.points[v])
    qtbot.waitUntil(lambda: f"vertex {v} at " in readout.text())
    edge = int(mesh.triangle_edges[t][1])
    a, b = mesh.points[mesh.edges[edge]]
    hover_world(qtbot, active.plotter, 0.5 * (a + b))
    qtbot.waitUntil(lambda: f"edge {edge} " in readout.text())
    length = np.linalg.norm(a - b)
    assert f"l = {length:.4g} mm" in readout.text() or f"l = {length:.3g} mm" in readout.text()


def test_measure_distance_with_two_clicks_snaps_to_vertices(active, qtbot):
    key(qtbot, active.plotter, Qt.Key.Key_D)
    tool = active.view_tools.measure
    assert tool.active and "first point" in active.view_tools.readout.text()
    # clicks a pixel or two off the patch corners A (0, 0) and B (10, 0): snapped
    click_world(qtbot, active.plotter, (0.04, 0.03, 0.0))
    assert "second point" in active.view_tools.readout.text()
    click_world(qtbot, active.plotter, (9.97, -0.02, 0.0))
    assert tool.distance == pytest.approx(10.0, abs=1e-12)
    assert "|AB| = 10.0" in active.view_tools.readout.text()
    image = rendered(active.plotter)
    from barymesh.app.view.measure import COLOR

    assert near(pixel(image, active.plotter, (5.0, 0.0, 0.0)), COLOR, 50)
    key(qtbot, active.plotter, Qt.Key.Key_D)
    assert not tool.active and not tool.actors["line"].GetVisibility()


def test_click_a_triangle_then_z_zooms_to_it(active, qtbot):
    mesh = active.model.result.mesh
    t = 21
    click_world(qtbot, active.plotter, mesh.centroids[t])
    assert active.view_tools.selected.triangle == t
    assert "selected: triangle 21" in active.view_tools.readout.text()
    key(qtbot, active.plotter, Qt.Key.Key_Z)
    corners = mesh.points[mesh.triangles[t]]
    xy = np.array([display_point(active.plotter, c) for c in corners])
    w, h = active.plotter.window_size
    assert (xy.max(axis=0) - xy.min(axis=0)).max() > 0.25 * min(w, h)
    image = rendered(active.plotter)
    # the selected triangle is marked in the row colour (80 % over the faces)
    assert share(image, active.plotter, corners, ROW_COLOR, tol=60) > 0.6


def test_export_dialog_writes_in_the_chosen_unit(active, qtbot, tmp_path):
    import meshio

    key(qtbot, active, Qt.Key.Key_E, Qt.KeyboardModifier.ControlModifier)
    dialog = active.export_dialog
    qtbot.waitExposed(dialog)
    written = {}
    for name in ("mm", "m"):
        path = tmp_path / f"out-{name}.msh"
        dialog.path.selectAll()
        qtbot.keyClicks(dialog.path, str(path))
        dialog.unit.setFocus()
        # "the format's default", "m", "mm", "um": Down twice from the top is mm
        qtbot.keyClick(dialog.unit, Qt.Key.Key_Home)
        for _ in range(2 if name == "mm" else 1):
            qtbot.keyClick(dialog.unit, Qt.Key.Key_Down)
        assert dialog.unit.currentData() == name
        assert name in dialog.format_label.text()
        qtbot.mouseClick(dialog.export_button, Qt.MouseButton.LeftButton)
        wait_for_export(active)  # written in a worker thread while the window answers
        written[name] = meshio.read(path).points
        if name == "mm":
            key(qtbot, active, Qt.Key.Key_E, Qt.KeyboardModifier.ControlModifier)
            dialog = active.export_dialog
            qtbot.waitExposed(dialog)
    mesh = active.model.result.mesh
    assert np.allclose(written["mm"][:, :2], mesh.points[:, :2])
    assert np.allclose(written["m"], written["mm"] * 1e-3)
    assert active.settings.value("export/unit") == "m"


# -- 14: the connectivity matrix on 23,040 triangles ---------------------------------------


@pytest.mark.parametrize("window_params", [MeshParams()])  # the paper's Fig. 12(a)
def test_big_matrix_hover_blits_marks_tiny_triangles_and_a_click_zooms(active, qtbot):
    # Fig. 12(a) is built in the worker thread: wait for it to be on screen
    qtbot.waitUntil(
        lambda: active.model.result is not None and not active.controller.busy, timeout=30_000
    )
    mesh = active.model.result.mesh
    assert mesh.n_triangles == 23_040
    key(qtbot, active.plotter, Qt.Key.Key_M)
    view = active.teaching.matrix
    qtbot.waitUntil(lambda: not view.stale and view.full_draws > 0, timeout=20_000)
    qtbot.wait(100)
    view.canvas.draw()
    QApplication.processEvents()
    draws, blits = view.full_draws, view.blits
    i = 5000
    j = int(mesh.connectivity[i].indices[0])

    def cell_pos(row, col):
        x, y = view.axes.transData.transform((col, row))
        return QPoint(round(x), round(view.canvas.height() - y))

    for dx in (-2, 0):  # moves over the cell: a pixel holds ~80 rows, a zero next to a
        qtbot.mouseMove(view.canvas, cell_pos(i, j) + QPoint(dx, 0))  # one means the one
    # the 3D view is not repainted per hover: one repaint waits for the pointer to rest
    assert active.teaching._repaint.isActive()
    qtbot.waitUntil(lambda: view.cell is not None and abs(view.cell[0] - i) < 200)
    i, j = view.cell
    assert mesh.connectivity[i, j] == 1
    assert active.teaching.highlight.triangles == (i, j)
    assert view.full_draws == draws and view.blits > blits  # no full redraw per hover
    assert f"T{i} and T{j} share edge" in view.cell_label.text()
    highlight = active.teaching.highlight
    assert highlight.markers_shown  # the triangles are below a pixel: markers show them
    image = rendered(active.plotter)
    # the column's small square on the row's larger one, centred on the two triangles
    x, y = display_point(active.plotter, mesh.centroids[i])
    h = image.shape[0]
    centre = tuple(int(v) for v in image[h - 1 - round(y), round(x)])
    ring = tuple(int(v) for v in image[h - 1 - round(y), round(x) + 9])
    assert near(centre, COL_COLOR, 40) and near(ring, ROW_COLOR, 40), (centre, ring)
    # a click offers the zoom; the button frames the two triangles, large enough to see
    qtbot.mouseClick(view.canvas, Qt.MouseButton.LeftButton, pos=cell_pos(i, j))
    assert view.zoom_button.isEnabled() and view.zoom_button.text().startswith("Zoom to T")
    i, j = view.cell
    qtbot.mouseClick(view.zoom_button, Qt.MouseButton.LeftButton)
    corners = mesh.points[mesh.triangles[i]]
    xy = np.array([display_point(active.plotter, c) for c in corners])
    assert (xy.max(axis=0) - xy.min(axis=0)).max() > SMALL_PIXELS
    assert not highlight.markers_shown
    image = rendered(active.plotter)
    # in paper mode the column's triangle may overlap the row's (overlapping patches) and is
    # drawn on top: the row's colour is looked for where the column's triangle is not
    column = mesh.points[mesh.triangles[j]]
    seen = share(image, active.plotter, corners, ROW_COLOR, tol=60, samples=13, outside=column)
    assert seen > 0.6


def test_inspector_overlay_colours_on_screen(active, qtbot):
    """The inspector's edge in yellow over its black rim, T+ red and T− blue."""
    key(qtbot, active.plotter, Qt.Key.Key_I)
    mesh = active.model.result.mesh
    row = 17
    edge = int(mesh.rwg.edge[row])
    a, b = mesh.points[mesh.edges[edge]]
    click_world(
        qtbot,
        active.plotter,
        0.5 * (a + b) + 0.1 * (mesh.centroids[mesh.rwg.t_plus[row]] - 0.5 * (a + b)),
    )
    assert active.teaching.inspector.edge == edge
    image = rendered(active.plotter)
    assert near(pixel(image, active.plotter, 0.4 * a + 0.6 * b), INSPECTOR_COLORS["edge"], 40)
    for t, red in ((int(mesh.rwg.t_plus[row]), True), (int(mesh.rwg.t_minus[row]), False)):
        corners = mesh.points[mesh.triangles[t]]
        samples = [
            pixel(image, active.plotter, np.array([i, j, 10 - i - j]) / 10 @ corners)
            for i in range(1, 9)
            for j in range(1, 9 - i)
        ]
        # between the arrows of f_n and rho, T+ is red and T- blue (coolwarm's ends)
        tinted = [(p[0] > p[2] + 60) if red else (p[2] > p[0] + 60) for p in samples]
        assert np.mean(tinted) > 0.5, (t, samples)


def test_a_big_mesh_gets_its_readout_from_a_locator_built_in_the_worker(active, qtbot, monkeypatch):
    import barymesh.app.view.view_tools as view_tools

    monkeypatch.setattr(view_tools, "SYNC_LOCATOR", 10)  # 32 triangles count as big here
    tools = active.view_tools
    type_into(qtbot, active.controls.rows["subdivisions"].spin, 3)
    active.controller.flush()
    mesh = active.model.result.mesh
    assert mesh.n_triangles == 18 and tools.mesh is mesh
    assert tools.locator is None  # not built until the pointer comes over the view
    hover_world(qtbot, active.plotter, mesh.centroids[7])
    qtbot.waitUntil(lambda: tools.locator is not None and tools.locator.mesh is mesh)
    qtbot.waitUntil(lambda: "triangle 7 " in tools.readout.text())

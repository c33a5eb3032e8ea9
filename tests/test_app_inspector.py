"""The RWG basis inspector and presentation mode in a real window (Xvfb, see conftest.py)."""

import imageio.v3 as iio
import numpy as np
import pytest

pytest.importorskip("pyvistaqt")

from app_user import settle  # noqa: E402
from gui_helpers import near, type_into, widget_pos  # noqa: E402
from PySide6.QtCore import QPoint, Qt  # noqa: E402

from barymesh import MeshParams, build_mesh  # noqa: E402
from barymesh.app.teach.inspector import (  # noqa: E402
    COLORS,  # noqa: E402
    arrow_polygons,
    edge_info,
    nearest_edge,
    step_edge,
)

FIG10 = MeshParams(structure="patch", patch_size=10.0, subdivisions=4)  # the paper's Fig. 10


@pytest.fixture
def window_params():
    return FIG10


@pytest.fixture
def window(window, qtbot):
    """The main window on Fig. 10 with the inspector on."""
    with qtbot.waitActive(window):  # shortcuts (I, N, P, F5) need the active window
        window.activateWindow()
    window.plotter.setFocus()
    qtbot.keyClick(window.plotter, Qt.Key.Key_I)  # Teach → RWG basis inspector
    assert window.teaching.inspector_active
    qtbot.wait(50)
    window.plotter.render()
    return window


def display_point(win, world):
    """World (x, y, z) -> VTK display pixels (origin bottom left), as the camera sees it."""
    renderer = win.plotter.renderer
    renderer.SetWorldPoint(float(world[0]), float(world[1]), float(world[2]), 1.0)
    renderer.WorldToDisplay()
    x, y, _ = renderer.GetDisplayPoint()
    return x, y


def click_world(win, qtbot, world):
    """A left click (press and release, no drag) on the 3D view at a world point."""
    x, y = display_point(win, world)
    ratio = win.plotter.devicePixelRatioF()
    pos = QPoint(round(x / ratio), round(win.plotter.height() - 1 - y / ratio))
    qtbot.mouseClick(win.plotter, Qt.MouseButton.LeftButton, pos=pos)


def choose_edge(qtbot, win, edge):
    """Type an edge id into the inspector's Edge box."""
    type_into(qtbot, win.teaching.inspector.edge_spin, edge)


def assert_overlay_on_screen(image, win, edge, offset=(0, 0)):
    """The edge drawn yellow; T+ red and T- blue between the arrows (pixels of ``image``,
    a picture of the 3D view placed at ``offset`` (x, y) in it)."""
    mesh = win.model.result.mesh
    row = int(np.searchsorted(mesh.rwg.edge, edge))
    a, b = mesh.points[mesh.edges[edge]]
    h = win.plotter.height()

    def at(world):
        x, y = display_point(win, world)
        return tuple(int(v) for v in image[offset[1] + h - 1 - round(y), offset[0] + round(x)])

    assert near(at(0.4 * a + 0.6 * b), COLORS["edge"], 40)
    for t, red in ((int(mesh.rwg.t_plus[row]), True), (int(mesh.rwg.t_minus[row]), False)):
        corners = mesh.points[mesh.triangles[t]]
        samples = [
            at(np.array([i, j, 10 - i - j]) / 10 @ corners)
            for i in range(1, 9)
            for j in range(1, 9 - i)
        ]
        tinted = [(p[0] > p[2] + 60) if red else (p[2] > p[0] + 60) for p in samples]
        assert np.mean(tinted) > 0.5, (t, samples)


# -- pure selection logic ---------------------------------------------------------------


def test_nearest_edge_and_stepping_follow_the_rwg_table():
    mesh = build_mesh(FIG10)
    rows = mesh.rwg.edge
    assert step_edge(mesh, int(rows[0]), 1) == rows[1]
    assert step_edge(mesh, int(rows[0]), -1) == rows[-1]  # wraps
    boundary = int(mesh.boundary_edges[0])
    after = rows[np.searchsorted(rows, boundary) % len(rows)]
    assert step_edge(mesh, boundary, 1) == after
    t = 5
    for edge in mesh.triangle_edges[t]:
        a, b = mesh.points[mesh.edges[edge]]
        assert nearest_edge(mesh, t, 0.9 * (a + b) / 2 + 0.1 * mesh.centroids[t]) == edge


def test_edge_info_for_interior_and_boundary_edges():
    mesh = build_mesh(FIG10)
    row = 7
    info = edge_info(mesh, int(mesh.rwg.edge[row]))
    assert info.is_rwg and info.sample.row == row
    assert (info.sample.t_plus, info.sample.t_minus) == (
        mesh.rwg.t_plus[row],
        mesh.rwg.t_minus[row],
    )
    labels = dict(info.rows())
    assert labels["RWG row n"] == str(row)
    boundary = edge_info(mesh, int(mesh.boundary_edges[0]))
    assert not boundary.is_rwg and boundary.status.startswith("boundary edge")


def test_arrow_polygons_have_seven_corners_per_arrow():
    arrows = arrow_polygons(np.zeros((3, 3)), np.array([[1, 0, 0], [0, 2, 0], [0, 0, 0]]), 0.1)
    assert arrows.n_cells == 2 and arrows.n_points == 14  # the zero vector is dropped


# -- in the window ------------------------------------------------------------------------


def test_clicking_an_edge_selects_its_t_plus_and_t_minus(window, qtbot):
    mesh = window.model.result.mesh
    rwg = mesh.rwg
    for row in (0, 17, len(rwg.edge) - 1):
        edge = int(rwg.edge[row])
        a, b = mesh.points[mesh.edges[edge]]
        # a point on the edge, nudged into T+ so that the face under it is certainly T+ or T-
        target = 0.5 * (a + b) + 0.02 * (mesh.centroids[rwg.t_plus[row]] - 0.5 * (a + b))
        click_world(window, qtbot, target)
        panel = window.teaching.inspector
        assert panel.edge == edge, row
        s = panel.info.sample
        assert (s.t_plus, s.t_minus) == (rwg.t_plus[row], rwg.t_minus[row])
        assert (s.free_plus, s.free_minus) == (
            rwg.free_vertex_plus[row],
            rwg.free_vertex_minus[row],
        )
        assert panel.overlay.datasets["triangles"].n_cells == 2
        # 4² quadrature points on each of T+ and T-: 32 arrows
        assert panel.overlay.datasets["arrows"].n_cells == 2 * 16
        assert f"{s.t_plus} / {s.t_minus}" in panel.info_label.text()


def test_picker_at_a_display_position_returns_the_triangle(window):
    mesh = window.model.result.mesh
    for t in (0, 9, 31):
        x, y = display_point(window, mesh.centroids[t])
        hit = window.teaching.picker.pick_display(x, y)
        assert hit is not None and hit[0] == t


def test_a_drag_rotates_and_does_not_pick(window, qtbot):
    panel = window.teaching.inspector
    before = panel.edge
    mesh = window.model.result.mesh
    x, y = display_point(window, mesh.centroids[3])
    start = QPoint(round(x), round(window.plotter.height() - 1 - y))
    qtbot.mousePress(window.plotter, Qt.MouseButton.LeftButton, pos=start)
    qtbot.mouseMove(window.plotter, start + QPoint(40, 30))
    qtbot.mouseRelease(window.plotter, Qt.MouseButton.LeftButton, pos=start + QPoint(40, 30))
    assert panel.edge == before


def test_next_and_previous_edge_keys(window, qtbot):
    mesh = window.model.result.mesh
    rows = mesh.rwg.edge
    panel = window.teaching.inspector
    choose_edge(qtbot, window, int(rows[3]))
    assert panel.edge == rows[3]
    window.plotter.setFocus()
    qtbot.keyClick(window.plotter, Qt.Key.Key_N)
    assert panel.edge == rows[4] and panel.info.sample.row == 4
    qtbot.keyClick(window.plotter, Qt.Key.Key_BracketRight)
    assert panel.edge == rows[5]
    qtbot.keyClick(window.plotter, Qt.Key.Key_P)
    qtbot.keyClick(window.plotter, Qt.Key.Key_BracketLeft)
    assert panel.edge == rows[3]
    qtbot.mouseClick(panel.next_button, Qt.MouseButton.LeftButton)
    assert panel.edge == rows[4]


def test_boundary_edge_says_why_it_has_no_rwg_function(window, qtbot):
    mesh = window.model.result.mesh
    edge = int(mesh.boundary_edges[2])
    (t,) = np.flatnonzero((mesh.triangle_edges == edge).any(axis=1))
    a, b = mesh.points[mesh.edges[edge]]
    click_world(window, qtbot, 0.5 * (a + b) + 0.05 * (mesh.centroids[t] - 0.5 * (a + b)))
    panel = window.teaching.inspector
    assert panel.edge == edge
    assert panel.info.sample is None
    assert "no RWG basis function" in panel.status_text
    assert "boundary edge" in panel.info_label.text()
    assert panel.overlay.datasets["arrows"].n_cells == 0
    assert panel.overlay.datasets["others"].n_cells == 1


def test_junction_edge_message():
    from barymesh.mesh import TriMesh
    from barymesh.teach.rwg_basis import edge_status

    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1.0]])
    tris = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    mesh = TriMesh(points, tris, np.zeros(3), np.ones(3), 1, mode="imported")
    edge = int(mesh.junction_edges[0])
    info = edge_info(mesh, edge)
    assert info.sample is None and info.status == edge_status(mesh, edge)
    assert "junction" in info.status and len(info.triangles) == 3


def test_selection_survives_a_mesh_change(window, qtbot):
    panel = window.teaching.inspector
    mesh = window.model.result.mesh
    edge = int(mesh.rwg.edge[10])
    choose_edge(qtbot, window, edge)
    type_into(qtbot, window.controls.rows["subdivisions"].spin, 3)
    window.controller.flush()
    new = window.model.result.mesh
    assert panel.mesh is new and panel.edge is not None and panel.edge < len(new.edges)


def test_presentation_mode_hides_panels_and_comes_back(window, qtbot, tmp_path):
    docks = [
        window.parameters_dock,
        window.statistics_dock,
        window.layers_dock,
        window.teaching.inspector_dock,
    ]
    shown = {d: d.isVisible() for d in docks}
    width = window.scene.actors["triangle_edges"].prop.line_width
    qtbot.keyClick(window, Qt.Key.Key_F5)
    assert window.teaching.presentation.active and window.teaching.act_presentation.isChecked()
    assert not any(d.isVisible() for d in docks)
    assert window.scene.actors["triangle_edges"].prop.line_width > width
    assert window.teaching.inspector.overlay.visible  # the overlay stays on the slide
    path = tmp_path / "presentation.png"
    qtbot.waitUntil(lambda: window.geometry() == window.screen().geometry())
    qtbot.wait(100)
    window.plotter.render()
    window.grab().save(str(path))
    corner = window.plotter.mapTo(window, QPoint(0, 0))
    assert_overlay_on_screen(
        iio.imread(path)[..., :3], window, window.teaching.inspector.edge, (corner.x(), corner.y())
    )
    qtbot.keyClick(window, Qt.Key.Key_F5)
    assert not window.teaching.presentation.active
    assert {d: d.isVisible() for d in docks} == shown
    assert window.scene.actors["triangle_edges"].prop.line_width == pytest.approx(width)
    assert window.teaching.inspector_active


def test_inspector_screenshot_shows_the_overlay_where_it_is(window, qtbot, tmp_path):
    mesh = window.model.result.mesh
    edge = int(mesh.rwg.edge[20])
    choose_edge(qtbot, window, edge)
    view = tmp_path / "inspector-view.png"
    assert window.save_view_png(view)
    assert_overlay_on_screen(iio.imread(view)[..., :3], window, edge)
    whole = tmp_path / "inspector-window.png"
    window.plotter.render()
    window.grab().save(str(whole))
    corner = window.plotter.mapTo(window, QPoint(0, 0))
    assert_overlay_on_screen(iio.imread(whole)[..., :3], window, edge, (corner.x(), corner.y()))


def test_turning_the_inspector_off_hides_the_overlay(window, qtbot):
    qtbot.keyClick(window.plotter, Qt.Key.Key_I)
    assert not window.teaching.inspector_active
    assert not window.teaching.inspector.overlay.visible
    assert not window.teaching.picker.enabled
    assert not window.teaching.act_next.isEnabled()


def test_zoom_to_edge_frames_its_triangles(window, qtbot):
    type_into(qtbot, window.controls.rows["subdivisions"].spin, 16)  # 512 small triangles
    window.controller.flush()
    qtbot.waitUntil(lambda: window.model.result.mesh.n_triangles == 2 * 16 * 16)
    mesh = window.model.result.mesh
    panel = window.teaching.inspector
    choose_edge(qtbot, window, int(mesh.rwg.edge[100]))
    corners = mesh.points[mesh.triangles[list(panel.info.triangles)]].reshape(-1, 3)

    def on_screen():
        xy = np.array([display_point(window, c) for c in corners])
        return xy.min(axis=0), xy.max(axis=0)

    lo, hi = on_screen()
    before = float((hi - lo).max())
    window.plotter.setFocus()
    qtbot.keyClick(window.plotter, Qt.Key.Key_Z)
    lo, hi = on_screen()
    w, h = window.plotter.window_size
    # the two triangles fill about a third of the view, wholly inside it, in its middle
    assert (hi - lo).max() > 2 * before
    assert 0.25 * min(w, h) < (hi - lo).max() <= 0.4 * min(w, h) + 1
    assert (lo >= 0).all() and hi[0] <= w and hi[1] <= h
    assert np.allclose((lo + hi) / 2, (w / 2, h / 2), atol=2)


# -- picking at every mesh size (issue section 3, item 1) ------------------------------

#: The paper's Fig. 12(a) at n = 6: 720 patches × 2 × 6² = 51,840 triangles, drawn reduced.
FIG12A_N6 = MeshParams(subdivisions=6)


def _clicked_point(win, pos):
    """The point of the plane z = 0 a click at widget ``pos`` means (VTK's own inversion)."""
    renderer = win.plotter.renderer
    ratio = win.plotter.devicePixelRatioF()
    renderer.SetDisplayPoint(pos.x() * ratio, (win.plotter.height() - 1 - pos.y()) * ratio, 0.0)
    renderer.DisplayToWorld()
    near_point = np.array(renderer.GetWorldPoint()[:3]) / renderer.GetWorldPoint()[3]
    direction = np.array(win.plotter.camera.GetDirectionOfProjection())
    return near_point - near_point[2] / direction[2] * direction


def _triangles_holding(mesh, point):
    """Every triangle whose xy projection holds ``point`` (brute force over the mesh)."""
    c = mesh.points[mesh.triangles][:, :, :2]
    p = np.asarray(point)[:2]

    def cross(a, b):
        return (b[:, 0] - a[:, 0]) * (p[1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (p[0] - a[:, 0])

    s = np.stack([cross(c[:, 0], c[:, 1]), cross(c[:, 1], c[:, 2]), cross(c[:, 2], c[:, 0])], 1)
    return np.flatnonzero((s >= -1e-12).all(axis=1) | (s <= 1e-12).all(axis=1))


@pytest.mark.parametrize("window_params", [FIG12A_N6])
def test_clicks_on_a_dense_mesh_select_the_edge_under_them(window, qtbot):
    settle(window, qtbot)
    mesh = window.model.result.mesh
    assert mesh.n_triangles == 720 * 2 * 6 * 6
    assert window.scene.reduced  # not drawn triangle by triangle: VTK has no cell to pick
    panel = window.teaching.inspector
    rwg = mesh.rwg
    for row in (len(rwg.edge) // 3, 2 * len(rwg.edge) // 3, len(rwg.edge) - 5):
        edge = int(rwg.edge[row])
        a, b = mesh.points[mesh.edges[edge]]
        target = 0.5 * (a + b)
        pos = widget_pos(window.plotter, target)
        before = panel.edge
        qtbot.mouseClick(window.plotter, Qt.MouseButton.LeftButton, pos=pos)
        # a big mesh's search structure may still be built in a worker: the click waits
        qtbot.waitUntil(lambda b=before: panel.edge != b, timeout=30_000)
        clicked = _clicked_point(window, pos)
        # the click lands within 0.1 mm of the edge picked, the nearest edge of a triangle
        # the click is in (found here by brute force over the whole mesh; Fig. 12(a)'s
        # patches overlap, so a point may be in several)
        assert np.linalg.norm(clicked - target) < 0.1
        p, q = mesh.points[mesh.edges[panel.edge]]
        s = np.clip(np.dot(clicked - p, q - p) / np.dot(q - p, q - p), 0.0, 1.0)
        assert np.linalg.norm(p + s * (q - p) - clicked) < 0.1
        holding = _triangles_holding(mesh, clicked)
        assert len(holding) >= 1
        assert panel.edge in {nearest_edge(mesh, int(h), clicked) for h in holding}
        assert panel.info.sample is not None  # an interior edge: T+ and T- shown


# -- issue 30, 1.11: the inspector's header and the dock tabs ----------------------------


def drag_separator_right(qtbot, win, dock, dx):
    """Drag the main window's separator at ``dock``'s left edge by ``dx`` pixels (positive:
    to the right, the dock narrower), as a user drags it."""
    left = dock.mapTo(win, QPoint(0, dock.height() // 2))
    start = QPoint(left.x() - 3, left.y())  # on the separator, between view and dock
    qtbot.mousePress(win, Qt.MouseButton.LeftButton, pos=start)
    for k in range(1, 7):
        qtbot.wait(10)  # the separator follows the moves as the event loop runs
        qtbot.mouseMove(win, QPoint(start.x() + dx * k // 6, start.y()))
    qtbot.wait(10)
    qtbot.mouseRelease(win, Qt.MouseButton.LeftButton, pos=QPoint(start.x() + dx, start.y()))


def dock_tab_bars(win):
    from PySide6.QtWidgets import QMainWindow, QTabBar

    return [
        bar
        for bar in win.findChildren(QTabBar)
        if isinstance(bar.parent(), QMainWindow) and bar.isVisible()
    ]


def tab_titles(bar):
    return [bar.tabText(i) for i in range(bar.count())]


def click_tab(qtbot, bar, title):
    qtbot.mouseClick(
        bar, Qt.MouseButton.LeftButton, pos=bar.tabRect(tab_titles(bar).index(title)).center()
    )


def narrow_view_layout(win, qtbot):
    """The issue's layout: the right docks at their narrowest, the 3D view wide (the
    mesh then fills the view's height, up to its top)."""
    qtbot.keyClick(win.plotter, Qt.Key.Key_I)  # off, to lay out the docks as before it
    assert not win.teaching.inspector_active
    win.resize(1400, 860)
    qtbot.wait(50)
    drag_separator_right(qtbot, win, win.statistics_dock, 120)
    qtbot.wait(50)
    assert win.statistics_dock.width() <= 320
    win.plotter.setFocus()


def test_the_inspector_header_stays_above_the_mesh(window, qtbot, tmp_path):
    """The inspector's caption box covered the top of the mesh and its colour bar the
    labels 16 and 18 (a wide view, the mesh framed to its full height): the mesh is framed
    under the header while the inspector is on."""
    narrow_view_layout(window, qtbot)
    qtbot.keyClick(window.plotter, Qt.Key.Key_I)
    assert window.teaching.inspector_active
    qtbot.wait(50)
    window.plotter.render()
    overlay = window.teaching.inspector.overlay
    from vtkmodules.vtkRenderingCore import vtkTextRenderer

    text = overlay.caption.GetInput()
    assert text.count("\n") == 2  # three lines: edge, T+, T−
    box = [0, 0, 0, 0]
    prop = overlay.caption.GetTextProperty()
    assert vtkTextRenderer().GetBoundingBox(prop, text, box, window.plotter.ren_win.GetDPI())
    h = window.plotter.window_size[1]
    caption_bottom = overlay.caption.GetPosition()[1] * h - (box[3] - box[2])  # top-justified
    bar_bottom = overlay.scalar_bar.GetPosition()[1] * h  # its numbers are above this
    mesh = window.model.result.mesh
    top = max(display_point(window, p)[1] for p in mesh.points)
    assert top < caption_bottom and top < bar_bottom, (top, caption_bottom, bar_bottom)
    # every triangle's number (at its centroid, 16 and 18 among them) under the bar
    labels = [display_point(window, c)[1] for c in mesh.centroids]
    assert max(labels) + 10 < bar_bottom
    window.grab().save(str(tmp_path / "inspector-header.png"))
    # off again: the mesh takes the whole height back
    qtbot.keyClick(window.plotter, Qt.Key.Key_I)
    qtbot.wait(50)
    assert max(display_point(window, p)[1] for p in mesh.points) > top + 20


def test_dock_tabs_keep_their_titles_with_the_inspector_and_matrix(window, qtbot, tmp_path):
    """With the inspector's (or the matrix's) tab added to the Statistics' tab bar, the
    right dock area could be narrowed below its tabs (a drag of the separator), and
    "Statistics" showed as "stics" (the bar scrolled): the docks of a tab bar keep its
    width."""
    narrow_view_layout(window, qtbot)

    def titles_whole():
        return all(
            0 <= bar.tabRect(i).left() and bar.tabRect(i).right() < bar.width()
            for bar in dock_tab_bars(window)
            for i in range(bar.count())
        )

    for key, dock in (
        (Qt.Key.Key_I, window.teaching.inspector_dock),
        (Qt.Key.Key_M, window.teaching.matrix_dock),
    ):
        qtbot.keyClick(window.plotter, key)
        qtbot.waitUntil(titles_whole, timeout=3000)  # once the docks have moved
        drag_separator_right(qtbot, window, dock, 200)  # the user narrows the area
        qtbot.wait(300)
        assert titles_whole(), [(tab_titles(b), b.tabRect(0)) for b in dock_tab_bars(window)]
    bars = [b for b in dock_tab_bars(window) if "Statistics" in tab_titles(b)]
    assert len(bars) == 1 and "Connectivity matrix" in tab_titles(bars[0])
    assert window.centralWidget().width() >= 480
    window.grab().save(str(tmp_path / "dock-tabs.png"))


def test_closing_the_inspector_brings_back_the_users_tab(window, qtbot):
    """Closing the inspector raised Quality (its neighbour) instead of the tab the user had."""
    qtbot.keyClick(window.plotter, Qt.Key.Key_I)  # off (the fixture turned it on)
    qtbot.wait(50)
    (bar,) = [b for b in dock_tab_bars(window) if "Statistics" in tab_titles(b)]
    for had in ("Statistics", "Solve"):
        click_tab(qtbot, bar, had)
        assert bar.tabText(bar.currentIndex()) == had
        window.plotter.setFocus()
        qtbot.keyClick(window.plotter, Qt.Key.Key_I)  # on: its tab on top
        qtbot.wait(50)
        (bar,) = [b for b in dock_tab_bars(window) if "Statistics" in tab_titles(b)]
        assert bar.tabText(bar.currentIndex()) == "RWG inspector"
        qtbot.keyClick(window.plotter, Qt.Key.Key_I)  # off by its key
        qtbot.wait(50)
        (bar,) = [b for b in dock_tab_bars(window) if "Statistics" in tab_titles(b)]
        assert bar.tabText(bar.currentIndex()) == had
    # closed with the dock's own close button
    from PySide6.QtWidgets import QAbstractButton

    click_tab(qtbot, bar, "Statistics")
    window.plotter.setFocus()
    qtbot.keyClick(window.plotter, Qt.Key.Key_I)
    qtbot.wait(50)
    dock = window.teaching.inspector_dock
    close = dock.findChild(QAbstractButton, "qt_dockwidget_closebutton")
    qtbot.mouseClick(close, Qt.MouseButton.LeftButton)
    qtbot.wait(50)
    assert not window.teaching.inspector_active
    (bar,) = [b for b in dock_tab_bars(window) if "Statistics" in tab_titles(b)]
    assert bar.tabText(bar.currentIndex()) == "Statistics"
